// track_features end to end on synthetic EuRoC folders: the tracks it
// writes, its --json, and the error contract (docs/programs.md).
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include <posefuse/io/feature_tracks.hpp>

#include "frontend/synthetic_images.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace syn = posefuse_test::frontend;
namespace t = posefuse::test;

namespace {
std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }
}  // namespace

TEST_CASE("track_features: tracks of a EuRoC folder, summary and --json", "[frontend]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "track_features");
  t::TempDir dir("frontend-program");
  syn::write_folder(dir.path() / "cam0", 6, 1.5, -0.5);
  const auto out = dir.path() / "tracks.csv";
  const t::Run r = t::run(exe, "--images " + q(dir.path() / "cam0") + " --out " + q(out), dir);
  REQUIRE(r.status == 0);
  CHECK(r.err.empty());
  CHECK_THAT(r.out, Catch::Contains("6 frames") && Catch::Contains("ms per frame"));
  posefuse::FeatureTrackReadOptions ro;
  ro.image_width = syn::kWidth;
  ro.image_height = syn::kHeight;
  const posefuse::FeatureTracks tracks = posefuse::read_feature_tracks(out, ro);
  REQUIRE(tracks.size() == 6);
  CHECK(tracks[0].t_ns == 1'000'000'000);
  for (const auto& f : tracks) CHECK(f.features.size() == 150);

  const auto out2 = dir.path() / "tracks2.csv";
  const t::Run j = t::run(exe, "--images " + q(dir.path() / "cam0") + " --out " + q(out2) + " --json --clahe", dir);
  REQUIRE(j.status == 0);
  const t::Json v = t::Json::parse(j.out);
  CHECK(v["frames"].number() == 6);
  REQUIRE(v["per_frame"].array().size() == 6);
  CHECK(v["per_frame"][5]["features"].number() == 150);
  CHECK(v["per_frame"][0]["t_ns"].number() == 1e9);
  CHECK(v["ms_per_frame"].number() > 0);
}

TEST_CASE("track_features: usage errors exit 2, data errors exit 1 naming the file", "[frontend]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "track_features");
  t::TempDir dir("frontend-program");
  const auto cam = dir.path() / "cam0";
  syn::write_folder(cam, 2, 1.0, 0.0);
  const auto out = dir.path() / "tracks.csv";

  SECTION("usage") {
    for (const std::string& args :
         {std::string("--out ") + q(out), "--images " + q(cam), "--images " + q(cam) + " --out " + q(out) + " --max-features 0",
          "--images " + q(cam) + " --out " + q(out) + " --ransac-px -1",
          "--images " + q(cam) + " --out " + q(cam / "data.csv"),
          "--images " + q(cam) + " --out " + q(cam / "sensor.yaml"),
          "--images " + q(cam) + " --out " + q(cam / "data" / "1000000000.png")}) {
      CAPTURE(args);
      const t::Run r = t::run(exe, args, dir);
      CHECK(r.status == 2);
      CHECK_THAT(r.err, Catch::EndsWith("(try --help)\n"));
      CHECK(t::count_lines(r.err) == 1);
    }
  }
  SECTION("an image of the wrong size") {
    (void)dir.write("cam0/sensor.yaml", syn::sensor_yaml(640, 480));
    const t::Run r = t::run(exe, "--images " + q(cam) + " --out " + q(out) + " --json", dir);
    CHECK(r.status == 1);
    CHECK(r.out.empty());
    CHECK_THAT(r.err, Catch::StartsWith("track_features: ") && Catch::Contains(".png") &&
                          Catch::Contains("752x480") && Catch::Contains("640x480"));
    CHECK(t::count_lines(r.err) == 1);
    CHECK_FALSE(std::filesystem::exists(out));
  }
  SECTION("a stamp that goes back") {
    (void)dir.write("cam0/data.csv", "#timestamp [ns],filename\n1050000000,1050000000.png\n1000000000,1000000000.png\n");
    const t::Run r = t::run(exe, "--images " + q(cam) + " --out " + q(out), dir);
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains("data.csv:3:"));
    CHECK_FALSE(std::filesystem::exists(out));
  }
  SECTION("no sensor.yaml") {
    std::filesystem::remove(cam / "sensor.yaml");
    const t::Run r = t::run(exe, "--images " + q(cam) + " --out " + q(out), dir);
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains("sensor.yaml"));
    // --camera names another yaml.
    (void)dir.write("other.yaml", syn::sensor_yaml(752, 480));
    const t::Run ok = t::run(exe, "--images " + q(cam) + " --camera " + q(dir.path() / "other.yaml") + " --out " + q(out), dir);
    CHECK(ok.status == 0);
  }
}

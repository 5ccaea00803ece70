// visual_inertial_odometry's loop-closure and map options end to end: usage
// errors exit 2 with one line; a malformed loop-candidate file or map file
// exits 1 naming file:line, before any estimation.
#include <catch2/catch.hpp>

#include <string>

#include "support/run_program.hpp"

using posefuse::test::Run;
using posefuse::test::run;

namespace {

std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

// Three seconds of the synthetic flight: tracks, IMU, and a camera yaml.
struct Inputs {
  std::filesystem::path tracks, imu, camera;
};

Inputs synthetic_inputs(const std::filesystem::path& sim, const posefuse::test::TempDir& dir) {
  Inputs in{dir.path() / "t.csv", dir.path() / "imu.csv", dir.path() / "cam.yaml"};
  REQUIRE(run(sim, "--duration 3 --recurring-ids --out " + q(in.tracks) + " --imu-out " + q(in.imu), dir).status == 0);
  (void)dir.write("cam.yaml",
                  "resolution: [752, 480]\ncamera_model: pinhole\nintrinsics: [458.654, 457.296, 367.215, 248.375]\n"
                  "distortion_model: radial-tangential\n"
                  "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"
                  "T_BS: [0,0,1,0.05, -1,0,0,0, 0,-1,0,0]\n");
  return in;
}

}  // namespace

TEST_CASE("visual_inertial_odometry: loop and map usage errors exit 2", "[vio][cli][loop]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "visual_inertial_odometry");
  posefuse::test::TempDir dir("violoop");
  const std::string base = "--tracks t.csv --camera c.yaml --imu i.csv ";
  for (const std::string& args : {base + "--save-map m.txt", base + "--load-map m.txt",
                                 base + "--loops ''", base + "--loops a.csv --loops b.csv"}) {
    INFO(args);
    const Run r = run(exe, args, dir);
    CHECK(r.status == 2);
    CHECK(posefuse::test::count_lines(r.err) == 1);
    CHECK_THAT(r.err, Catch::Contains("(try --help)"));
  }
  const Run help = run(exe, "--help", dir);
  CHECK(help.status == 0);
  CHECK_THAT(help.out, Catch::Contains("--loops FILE|recurring-ids") && Catch::Contains("--save-map FILE") &&
                           Catch::Contains("--load-map FILE") && Catch::Contains("--out-odometry FILE"));
}

TEST_CASE("visual_inertial_odometry: bad loop and map files exit 1 naming file:line", "[vio][cli][loop]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "visual_inertial_odometry");
  POSEFUSE_REQUIRE_EXAMPLE(sim, "simulate_tracks");
  posefuse::test::TempDir dir("violoop");
  const Inputs in = synthetic_inputs(sim, dir);
  const std::string base = "--tracks " + q(in.tracks) + " --camera " + q(in.camera) + " --imu " + q(in.imu) + " ";
  const auto loops = dir.write("loops.csv", "t_ns_query,t_ns_match\n20,10\n10,20\n");
  const auto out = dir.path() / "traj.tum";
  Run r = run(exe, base + "--loops " + q(loops) + " --out " + q(out), dir);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("loops.csv:3: the match 20 ns is not earlier than the query 10 ns"));
  CHECK(posefuse::test::count_lines(r.err) == 1);
  CHECK_FALSE(std::filesystem::exists(out));
  const auto map = dir.write("map.txt", "posefuse_vio_map 1\nkeyframe 0 0 100\n");
  r = run(exe, base + "--loops recurring-ids --load-map " + q(map), dir);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("map.txt:2: a keyframe record has 25 fields, found 4"));
  r = run(exe, base + "--loops " + q(dir.path() / "missing.csv"), dir);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("missing.csv: cannot open"));
}

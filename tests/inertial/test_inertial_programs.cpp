// The seed-003 example programs end to end: usage errors exit 2, data
// errors 1 naming file:line, and on the real EuRoC V1_01_easy recording
// (skipped visibly without it) the JSON carries the README's figures.
#include <catch2/catch.hpp>

#include <string>

#include "support/data_path.hpp"
#include "support/run_program.hpp"

using posefuse::test::Json;
using posefuse::test::Run;
using posefuse::test::run;

TEST_CASE("imu_preintegration_check: usage and data errors", "[inertial][cli]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "imu_preintegration_check");
  posefuse::test::TempDir dir("imu_check");
  const Run usage = run(exe, "--imu x.csv", dir);
  CHECK(usage.status == 2);
  CHECK_THAT(usage.err, Catch::Contains("required"));
  CHECK(run(exe, "--imu a --groundtruth b --window -1", dir).status == 2);
  const auto imu = dir.write("imu.csv", "1000,0,0,0,0,0,9.81\n2000,0,0,0,0,0,9.81\n1500,0,0,0,0,0,9.81\n");
  const auto gt = dir.write("gt.csv", "1000,0,0,0,1,0,0,0\n");
  const Run data = run(exe, "--imu '" + imu.string() + "' --groundtruth '" + gt.string() + "'", dir);
  CHECK(data.status == 1);
  CHECK_THAT(data.err, Catch::Contains("imu.csv:3: timestamp 1500 is earlier"));
  CHECK(posefuse::test::count_lines(data.err) == 1);
}

TEST_CASE("imu_preintegration_check: EuRoC V1_01_easy", "[inertial][cli][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  POSEFUSE_REQUIRE_EXAMPLE(exe, "imu_preintegration_check");
  posefuse::test::TempDir dir("imu_check");
  const Run r = run(exe, "--imu '" + (d / "imu0.csv").string() + "' --groundtruth '" +
                             (d / "groundtruth_20hz.csv").string() + "' --window 1 --json --svg '" +
                             (dir.path() / "p.svg").string() + "'",
                    dir);
  REQUIRE(r.status == 0);
  const Json j = Json::parse(r.out);
  CHECK(j["windows"].number() == 144);
  CHECK(j["skipped"].number() == 0);
  // The README's figures (rounded there).
  CHECK(j["position_error_rmse"].number() == Approx(0.0242).margin(5e-4));
  CHECK(j["rotation_error_rmse_deg"].number() == Approx(0.125).margin(5e-3));
  CHECK(j["nees_mean"].number() > j["nees_mean_upper"].number());  // over-confident: see README
  CHECK(std::filesystem::file_size(dir.path() / "p.svg") > 1000);
}

TEST_CASE("vi_alignment_check: usage errors and EuRoC V1_01_easy", "[inertial][cli][data]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "vi_alignment_check");
  posefuse::test::TempDir dir("vi_check");
  CHECK(run(exe, "--imu a --groundtruth b --stride 0", dir).status == 2);
  CHECK(run(exe, "--groundtruth b", dir).status == 2);
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  const Run r = run(exe, "--imu '" + (d / "imu0.csv").string() + "' --groundtruth '" +
                             (d / "groundtruth_20hz.csv").string() + "' --json --svg '" +
                             (dir.path() / "a.svg").string() + "'",
                    dir);
  REQUIRE(r.status == 0);
  const Json j = Json::parse(r.out);
  CHECK(j["windows"].number() == 100);
  // The README's figures (rounded there).
  CHECK(j["success_rate"].number() == Approx(0.92).margin(1e-9));
  CHECK(j["scale_error_percent"].number() == Approx(11.9).margin(0.1));
  CHECK(j["gravity_error_deg"].number() == Approx(0.97).margin(0.01));
  CHECK(std::filesystem::file_size(dir.path() / "a.svg") > 1000);
}

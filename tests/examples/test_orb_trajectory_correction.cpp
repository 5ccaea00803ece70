// The orb_trajectory_correction example end to end: the seed-000 row says
// 0 %, smoothing helps on the synthetic drive (jitter) and the corrected
// trajectory is written; bad input exits non-zero with one line on stderr.
#include <catch2/catch.hpp>
#include <posefuse/io/formats.hpp>
#include <algorithm>
#include <string>

#include "support/data_path.hpp"
#include "support/run_program.hpp"

namespace {
/// The number after `"key": ` in the n-th (0-based) occurrence.
double json_value(const std::string& json, const std::string& key, int nth = 0) {
  const std::string tag = "\"" + key + "\": ";
  std::size_t at = json.find(tag);
  for (int i = 0; i < nth && at != std::string::npos; ++i) at = json.find(tag, at + 1);
  REQUIRE(at != std::string::npos);
  return std::stod(json.substr(at + tag.size()));
}
}  // namespace

TEST_CASE("orb_trajectory_correction: built-in drive reproduces the seed-000 identity",
          "[examples][seed000]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto r = posefuse::test::run(exe, "--json", dir);
  REQUIRE(r.status == 0);
  // methods in order: seed000, cv, cv+rts
  CHECK(json_value(r.out, "reduction_percent", 0) == Approx(0.0).margin(1e-9));
  CHECK(json_value(r.out, "reduction_percent", 2) > 3.0);  // smoothing removes the jitter

  const auto table = posefuse::test::run(exe, "", dir);
  REQUIRE(table.status == 0);
  CHECK(table.out.find("0.00 %") != std::string::npos);
  CHECK(table.out.find("returns its input") != std::string::npos);
}

TEST_CASE("orb_trajectory_correction: writes the corrected trajectory and rejects bad input",
          "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 2\n"
                                      "1 0 0 2 0 1 0 0 0 0 1 4\n1 0 0 3 0 1 0 0 0 0 1 6\n");
  const auto est = dir.write("est.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1.1 0 1 0 0 0 0 1 2\n"
                                        "1 0 0 2.1 0 1 0 0 0 0 1 3.9\n1 0 0 3 0 1 0 0 0 0 1 6.2\n");
  const std::string files = "--groundtruth '" + gt.string() + "' --estimate '" + est.string() + "'";
  const auto out = dir.path() / "corrected.txt";
  const auto r = posefuse::test::run(exe, files + " --out '" + out.string() + "'", dir);
  REQUIRE(r.status == 0);
  const posefuse::Trajectory written = posefuse::read_kitti(out);
  const posefuse::Trajectory raw = posefuse::read_kitti(est);
  REQUIRE(written.size() == 4);
  for (std::size_t k = 0; k < 4; ++k)  // seed000 returns its input
    CHECK((written.poses[k].translation() - raw.poses[k].translation()).norm() < 1e-12);

  const auto bad = dir.write("bad.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
  for (const std::string& args :
       {std::string("--groundtruth '") + gt.string() + "'",  // no estimate
        files + " --plane ab", files + " --R -1", files + " --bogus 3",
        "--groundtruth '" + gt.string() + "' --estimate '" + bad.string() + "'"}) {
    const auto e = posefuse::test::run(exe, args, dir);
    INFO(args);
    CHECK(e.status != 0);
    CHECK(std::count(e.err.begin(), e.err.end(), '\n') == 1);
  }
  const auto e = posefuse::test::run(exe, "--groundtruth '" + gt.string() + "' --estimate '" +
                                              bad.string() + "'", dir);
  CHECK(e.err.find("bad.txt:1") != std::string::npos);
}

TEST_CASE("orb_trajectory_correction: KITTI 06 ORB-SLAM2 stereo, seed 000 returns its input",
          "[examples][data]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  POSEFUSE_REQUIRE_DATASET(kitti, "kitti/06");
  posefuse::test::TempDir dir("orb");
  const auto r = posefuse::test::run(
      exe,
      "--json --groundtruth '" + (kitti / "groundtruth.txt").string() + "' --times '" +
          (kitti / "times.txt").string() + "' --estimate '" +
          (kitti / "orbslam2_stereo.txt").string() + "'",
      dir);
  REQUIRE(r.status == 0);
  // Planar (x-z) RMSE of the raw stereo trajectory, no alignment.
  CHECK(json_value(r.out, "rmse_before") == Approx(0.874250).margin(1e-5));
  CHECK(json_value(r.out, "reduction_percent", 0) == Approx(0.0).margin(1e-9));
}

// The orb_trajectory_correction example end to end: the seed-000 row says
// 0 %, smoothing helps on the synthetic drive (jitter), the corrected
// trajectory is written, --json is valid JSON; usage errors exit 2, data
// errors exit 1 with one line on stderr (file:line where a file is at fault),
// and no output file is left behind by a failed run.
#include <catch2/catch.hpp>
#include <posefuse/io/formats.hpp>
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "support/data_path.hpp"
#include "support/run_program.hpp"

namespace {

using posefuse::test::count_lines;
using posefuse::test::Json;

/// Four KITTI poses moving along x-z.
constexpr const char* kGroundTruth =
    "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 2\n"
    "1 0 0 2 0 1 0 0 0 0 1 4\n1 0 0 3 0 1 0 0 0 0 1 6\n";
constexpr const char* kEstimate =
    "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1.1 0 1 0 0 0 0 1 2\n"
    "1 0 0 2.1 0 1 0 0 0 0 1 3.9\n1 0 0 3 0 1 0 0 0 0 1 6.2\n";

/// True when `text` contains an inf or nan as a printf would print it.
bool has_non_finite(const std::string& text) {
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return lower.find("nan") != std::string::npos || lower.find("inf ") != std::string::npos ||
         lower.find(" inf") != std::string::npos;
}

}  // namespace

TEST_CASE("orb_trajectory_correction: built-in drive reproduces the seed-000 identity",
          "[examples][seed000]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto r = posefuse::test::run(exe, "--json", dir);
  REQUIRE(r.status == 0);
  CHECK(r.err.empty());
  const Json j = Json::parse(r.out);
  CHECK(j["plane"].string() == "xz");
  CHECK(j["alignment"].string() == "none");
  REQUIRE(j["estimates"].array().size() == 1);
  const Json& e = j["estimates"][0];
  CHECK(e["name"].string() == "synthetic");
  CHECK(e["frames"].number() > 1000);
  const auto& methods = e["methods"].array();
  REQUIRE(methods.size() == 5);
  CHECK(methods[0]["method"].string() == "seed000");
  CHECK(methods[1]["method"].string() == "cv");
  CHECK(methods[2]["method"].string() == "cv+rts");
  CHECK(methods[3]["method"].string() == "ctrv");
  CHECK(methods[4]["method"].string() == "ctrv+rts");
  CHECK(methods[0]["reduction_percent"].number() == Approx(0.0).margin(1e-9));
  CHECK(methods[0]["rmse_after"].number() == Approx(e["rmse_before"].number()).epsilon(1e-12));
  CHECK(methods[0]["verdict"].string() == "returns its input (docs/reproductions.md)");
  CHECK(methods[2]["reduction_percent"].number() > 3.0);  // smoothing removes the jitter
  CHECK(methods[4]["reduction_percent"].number() > 3.0);
  // One flat row per estimate and method, as in folder mode.
  REQUIRE(j["rows"].array().size() == 5);
  CHECK(j["rows"][4]["sequence"].string() == "synthetic");
  CHECK(j["rows"][4]["method"].string() == "ctrv+rts");
  CHECK(j["rows"][4]["rmse_after"].number() == methods[4]["rmse_after"].number());
  CHECK(j["seed000_covariance"]["initial"].number() == 1.0);
  CHECK(j["seed000_covariance"]["steady_frame"].number() >= 1);

  const auto table = posefuse::test::run(exe, "", dir);
  REQUIRE(table.status == 0);
  CHECK(table.out.find("0.00 %") != std::string::npos);
  CHECK(table.out.find("returns its input") != std::string::npos);
}

TEST_CASE("orb_trajectory_correction: docs/reproductions-seed000.md's table and the example's comment are its output",
          "[examples][seed000]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto r = posefuse::test::run(exe, "", dir);
  REQUIRE(r.status == 0);
  // The five synthetic rows, with the estimate column narrowed as in the comment.
  std::vector<std::string> rows;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("synthetic ", 0) == 0) rows.push_back(line);
  REQUIRE(rows.size() == 5);
  const std::filesystem::path root =
      std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
  const std::string page = posefuse::test::slurp(root / "docs" / "reproductions-seed000.md");
  const std::string example = posefuse::test::slurp(root / "examples" / "orb_trajectory_correction.cpp");
  for (const std::string& row : rows) {
    INFO(row);
    CHECK(page.find(row) != std::string::npos);
    // The example's comment drops 10 columns of padding after "synthetic".
    CHECK(example.find("//   " + row.substr(0, 13) + row.substr(23)) != std::string::npos);
  }
}

TEST_CASE("orb_trajectory_correction: writes the corrected trajectory; usage errors exit 2",
          "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", kGroundTruth);
  const auto est = dir.write("est.txt", kEstimate);
  const std::string files = "--groundtruth '" + gt.string() + "' --estimate '" + est.string() + "'";
  const auto out = dir.path() / "corrected.txt";
  const auto r = posefuse::test::run(exe, files + " --out '" + out.string() + "'", dir);
  REQUIRE(r.status == 0);
  const posefuse::Trajectory written = posefuse::read_kitti(out);
  const posefuse::Trajectory raw = posefuse::read_kitti(est);
  REQUIRE(written.size() == 4);
  for (std::size_t k = 0; k < 4; ++k)  // seed000 returns its input
    CHECK((written.poses[k].translation() - raw.poses[k].translation()).norm() < 1e-12);

  for (const std::string& args :
       {std::string("--groundtruth '") + gt.string() + "'",  // no estimate
        files + " --plane ab", files + " --R -1", files + " --R 1,abc", files + " --Q 0",
        files + " --bogus 3", files + " --cv-q 1e400", files + " --cv-q inf", files + " --cv-q",
        files + " --method kalman", files + " --format tum --times '" + gt.string() + "'",
        files + " --method seed000/tuned --tune --out x.txt", files + " --method cv/tuned --out x.txt",
        files + " --method control --out x.txt", files + " --sweep-svg s.svg", files + " --ctrv-q 0",
        "--control '" + est.string() + "'",  // no estimate to drive
        "--tune --estimate '" + est.string() + "' --plot p.svg",  // tune-only mode writes nothing
        files + " --max-time-diff -1", files + " stray", files + " --json --json",
        "--groundtruth '" + gt.string() + "' --estimate '" + est.string() + "' --estimate '" +
            est.string() + "' --out '" + dir.path().string() + "/o'"}) {  // two estimates named est
    const auto e = posefuse::test::run(exe, args, dir);
    INFO(args << " -> " << e.err);
    CHECK(e.status == 2);
    CHECK(count_lines(e.err) == 1);
    CHECK(e.err.rfind("orb_trajectory_correction: ", 0) == 0);
    CHECK(e.err.find("(try --help)") != std::string::npos);
    CHECK(e.out.empty());
  }
  const auto help = posefuse::test::run(exe, "--help", dir);
  CHECK(help.status == 0);
  CHECK(help.err.empty());
  for (const char* flag : {"--groundtruth", "--estimate", "--control", "--format", "--times",
                           "--plane", "--R", "--Q", "--cv-q", "--ctrv-q", "--align",
                           "--max-time-diff", "--tune", "--sweep", "--sweep-svg", "--method",
                           "--out", "--plot", "--json", "--help"})
    CHECK(help.out.find(std::string("  ") + flag + " ") != std::string::npos);
}

TEST_CASE("orb_trajectory_correction: bad data exits 1 with one line, never prints inf or nan",
          "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", kGroundTruth);
  const auto bad = dir.write("bad.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  const auto big = dir.write("big.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1e308 0 1 0 0 0 0 1 2\n"
                                        "1 0 0 -1e308 0 1 0 0 0 0 1 4\n1 0 0 3 0 1 0 0 0 0 1 6\n");
  const auto short_est = dir.write("short.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  struct Case {
    std::string args, expect;
  };
  const std::string g = "--groundtruth '" + gt.string() + "'";
  const Case cases[] = {
      {g + " --estimate '" + bad.string() + "'", "bad.txt:2: expected 12"},
      {g + " --estimate '" + (dir.path() / "absent.txt").string() + "'", "absent.txt: cannot open"},
      {g + " --estimate '" + big.string() + "'", "big.txt:2: position coordinate of magnitude 1e+308 m is beyond 1e+100 m"},
      {g + " --estimate '" + short_est.string() + "'", "short.txt has 1 poses but the ground truth has 4"},
  };
  for (const auto& c : cases) {
    const auto r = posefuse::test::run(exe, c.args, dir);
    INFO(c.args << " -> " << r.err);
    CHECK(r.status == 1);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.find(c.expect) != std::string::npos);
    CHECK(r.err.find("try --help") == std::string::npos);
    CHECK(r.out.empty());
    CHECK_FALSE(has_non_finite(r.out));
  }
  // Noise no filter step can use (--R 1e308, --cv-q 1e308) is the flag's
  // fault: a usage error naming it, before any work.
  for (const char* flag : {"--R", "--cv-q"}) {
    const auto huge_r = posefuse::test::run(exe, std::string(flag) + " 1e308", dir);
    INFO(huge_r.err);
    CHECK(huge_r.status == 2);
    CHECK(huge_r.err.find(std::string(flag) + ": expected a number from 1e-08 to 1e+08") != std::string::npos);
    CHECK(huge_r.out.empty());
  }
}

TEST_CASE("orb_trajectory_correction: zero error before gives a defined reduction",
          "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", kGroundTruth);
  const std::string args = "--groundtruth '" + gt.string() + "' --estimate '" + gt.string() + "'";
  const auto table = posefuse::test::run(exe, args, dir);
  REQUIRE(table.status == 0);
  CHECK_FALSE(has_non_finite(table.out));
  CHECK(table.out.find("gt                     seed000             0.000           0.000     0.00 %   "
                       "returns its input (docs/reproductions.md)") != std::string::npos);
  CHECK(table.out.find("n/a   worse than raw") != std::string::npos);  // cv moves off the truth
  const auto json = posefuse::test::run(exe, args + " --json", dir);
  REQUIRE(json.status == 0);
  const Json j = Json::parse(json.out);
  const auto& methods = j["estimates"][0]["methods"].array();
  CHECK(j["estimates"][0]["rmse_before"].number() == 0.0);
  CHECK(methods[0]["reduction_percent"].number() == 0.0);
  CHECK(methods[1]["rmse_after"].number() > 0.0);
  CHECK(methods[1]["reduction_percent"].is_null());
  CHECK(methods[1]["verdict"].string() == "worse than raw");
}

TEST_CASE("orb_trajectory_correction: outputs are written only when the whole run succeeds",
          "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", kGroundTruth);
  const auto est = dir.write("est.txt", kEstimate);
  const std::string files = "--groundtruth '" + gt.string() + "' --estimate '" + est.string() + "'";
  const auto out = dir.path() / "corrected.txt";
  const auto plot = dir.path() / "plot.svg";

  SECTION("--out and --plot together") {
    const auto r = posefuse::test::run(
        exe, files + " --out '" + out.string() + "' --plot '" + plot.string() + "'", dir);
    REQUIRE(r.status == 0);
    CHECK(posefuse::read_kitti(out).size() == 4);
    const std::string svg = posefuse::test::slurp(plot);
    CHECK(svg.rfind("<svg", 0) == 0);
    CHECK(svg.find("</svg>") != std::string::npos);
    CHECK(svg.find("ground truth") != std::string::npos);
    CHECK(svg.find("variance (m^2)") != std::string::npos);
    CHECK_FALSE(has_non_finite(svg));
  }
  SECTION("--plot cannot be written: exit 1 and --out is not written either") {
    const auto r = posefuse::test::run(
        exe, files + " --out '" + out.string() + "' --plot '" + (dir.path() / "no" / "p.svg").string() + "'", dir);
    CHECK(r.status == 1);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.find("no/p.svg") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out));
    CHECK(r.out.empty());
  }
  SECTION("--plot /dev/full: exit 1, an existing --out keeps its content") {
    (void)dir.write("corrected.txt", "previous\n");
    const auto r = posefuse::test::run(
        exe, files + " --out '" + out.string() + "' --plot /dev/full", dir);
    CHECK(r.status == 1);
    CHECK(r.err.find("/dev/full: write failed") != std::string::npos);
    CHECK(posefuse::test::slurp(out) == "previous\n");
  }
  SECTION("a data error writes nothing") {
    const auto short_est = dir.write("short.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
    const auto r = posefuse::test::run(exe, "--groundtruth '" + gt.string() + "' --estimate '" + short_est.string() +
                                                "' --out '" + out.string() + "' --plot '" + plot.string() + "'",
                                       dir);
    CHECK(r.status == 1);
    CHECK_FALSE(std::filesystem::exists(out));
    CHECK_FALSE(std::filesystem::exists(plot));
  }
  // No temporary file is ever left in the folder.
  for (const auto& f : std::filesystem::directory_iterator(dir.path()))
    CHECK(f.path().filename().string().find(".tmp.") == std::string::npos);
}

TEST_CASE("orb_trajectory_correction: several estimates write a folder", "[examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "orb_trajectory_correction");
  posefuse::test::TempDir dir("orb");
  const auto gt = dir.write("gt.txt", kGroundTruth);
  const auto a = dir.write("a.txt", kEstimate);
  const auto b = dir.write("b.txt", kGroundTruth);
  const auto folder = dir.path() / "corrected";
  const auto r = posefuse::test::run(exe, "--groundtruth '" + gt.string() + "' --estimate '" +
                                              a.string() + "' --estimate '" + b.string() +
                                              "' --method cv --out '" + folder.string() + "'",
                                     dir);
  REQUIRE(r.status == 0);
  CHECK(posefuse::read_kitti(folder / "a_cv.txt").size() == 4);
  CHECK(posefuse::read_kitti(folder / "b_cv.txt").size() == 4);
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
  const Json j = Json::parse(r.out);
  // Planar (x-z) RMSE of the raw stereo trajectory, no alignment.
  CHECK(j["estimates"][0]["rmse_before"].number() == Approx(0.874250).margin(1e-5));
  CHECK(j["estimates"][0]["methods"][0]["reduction_percent"].number() == Approx(0.0).margin(1e-9));
}

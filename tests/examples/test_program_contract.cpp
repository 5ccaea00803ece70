// The programs' contract (docs/programs.md), probed as a new user would: one
// row per bad or unusual input, each with the exit status it must give and
// what its one line on stderr must (and must not) say. A program that is not
// built is skipped visibly.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "examples/program_probe.hpp"
#include "support/data_path.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using posefuse::test::check;
using posefuse::test::count_lines;
using posefuse::test::Probe;
using posefuse::test::Run;
using posefuse::test::TempDir;

namespace {

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

/// A TUM trajectory of n poses on a planar loop (x, y vary), 0.1 s apart.
std::string tum_loop(int n, double scale = 1.0) {
  std::ostringstream s;
  s.precision(17);
  for (int k = 0; k < n; ++k) {
    const double a = 0.05 * k;
    s << 0.1 * k << ' ' << scale * 10 * std::cos(a) << ' ' << scale * 10 * std::sin(a) << ' ' << 0.01 * k
      << " 0 0 0 1\n";
  }
  return s.str();
}

/// A EuRoC recording of a body at rest (identity attitude, zero biases):
/// imu0 csv at 200 Hz and a 17-column ground truth at 20 Hz whose steps
/// alternate 49999872 / 50000128 ns as EuRoC's do. `skip` ground-truth rows
/// after row 100 are left out (a gap).
struct RestRecording {
  std::string imu, gt;
};
RestRecording rest_recording(double seconds, int skip = 0) {
  RestRecording r;
  const std::int64_t t0 = 1403715273262142976;
  for (std::int64_t k = 0; k * 5000000 <= std::int64_t(seconds * 1e9); ++k)
    r.imu += std::to_string(t0 + k * 5000000) + ",0,0,0,0,0,9.81\n";
  std::int64_t t = t0;
  for (int k = 0; (t - t0) < std::int64_t(seconds * 1e9); ++k) {
    if (k <= 100 || k > 100 + skip) r.gt += std::to_string(t) + ",1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n";
    t += k % 2 == 0 ? 49999872 : 50000128;
  }
  return r;
}

}  // namespace

TEST_CASE("Programs keep the exit-status and one-line contract on bad input", "[examples][contract]") {
  const TempDir dir("contract");
  (void)dir.write("gt.tum", tum_loop(200));
  (void)dir.write("est.tum", tum_loop(200));
  // A huge but finite position on line 3.
  std::string huge = tum_loop(200);
  {
    std::size_t at = 0;
    for (int k = 0; k < 2; ++k) at = huge.find('\n', at) + 1;
    huge.replace(at, huge.find('\n', at) - at, "0.2 1e200 0 0 0 0 0 1");
  }
  (void)dir.write("huge.tum", huge);
  // A ground truth that never moves: no rigid alignment is defined.
  std::string still;
  for (int k = 0; k < 50; ++k) still += std::to_string(0.1 * k) + " 1 2 3 0 0 0 1\n";
  (void)dir.write("still.tum", still);
  // Repeated stamps on line 3.
  (void)dir.write("dup.tum", "0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.1 2 0 0 0 0 0 1\n0.2 3 0 0 0 0 0 1\n");
  // Loop edges: to a frame that does not exist (line 2), and a huge translation (line 1).
  const std::string info = " 100 0 0 0 100 0 0 100 0 400\n";
  (void)dir.write("loops_missing.txt", "# i j x y z yaw I\n10 5000 0 0 0 0" + info);
  (void)dir.write("loops_huge.txt", "10 150 1e308 0 0 0" + info);
  (void)dir.write("loops_ok.txt", "10 150 0 0 0 0" + info);
  // Saved results that evaluate_trajectory never writes.
  const std::string result_head =
      R"({"metric": "ape", "pose_relation": "trans_part", "alignment": "se3", "unit": "m", )";
  const std::string stats = R"("mean": 1, "median": 1, "std": 0, "min": 1, "max": 1})";
  (void)dir.write("null_rmse.json", result_head + R"("count": 5, "rmse": null, )" + stats);
  (void)dir.write("negative_count.json", result_head + R"("count": -5, "rmse": 1, )" + stats);
  (void)dir.write("fraction_count.json", result_head + R"("count": 2.5, "rmse": 1, )" + stats);
  fs::create_directory(dir.path() / "folder");
  // g2o edges on line 3 whose values the solver cannot hold.
  const std::string vertices = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  (void)dir.write("huge.g2o", vertices + "EDGE_SE2 0 1 1e308 0 0 1 0 0 1 0 1\n");
  (void)dir.write("strong.g2o", vertices + "EDGE_SE2 0 1 1 0 0 1e300 0 0 1e300 0 1e300\n");
  // Node 2 (line 3) tied by an edge of zero information, by one without
  // position information, and by one without information on y: refused
  // from the default start and from the file's poses alike.
  const std::string three = vertices + "VERTEX_SE2 2 2 0.5 0.1\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n";
  (void)dir.write("zero_info.g2o", three + "EDGE_SE2 1 2 1 0 0 0 0 0 0 0 0\n");
  (void)dir.write("heading_only.g2o", three + "EDGE_SE2 1 2 1 0 0 0 0 0 0 0 100\n");
  (void)dir.write("no_y.g2o", three + "EDGE_SE2 1 2 1 0 0 100 0 0 0 0 100\n");
  // A ground truth whose odometry edge names vertex "x1" on line 2.
  (void)dir.write("two.g2o", vertices + "EDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n");
  (void)dir.write("bad_id_gt.txt", "# i j dx dy dtheta\nEDGE2 0 x1 1 0 0\n");

  // EuRoC files: a recording at rest, and one with an accelerometer reading of 1e308 on line 3.
  const RestRecording rest = rest_recording(12.0);
  (void)dir.write("imu0.csv", rest.imu);
  (void)dir.write("gt.csv", rest.gt);
  const std::string euroc = "--imu '{dir}/imu0.csv' --groundtruth '{dir}/gt.csv' ";

  const std::string eval = "--groundtruth '{dir}/gt.tum' --estimate ";
  const std::vector<Probe> probes = {
      // 11. the tutorial parses its (empty) command line
      {"ekf_custom_model", "--bogus", 2, {"unknown option '--bogus'"}, {}},
      {"ekf_custom_model", "extra", 2, {"unexpected argument"}, {}},
      // 5. the loops file and its line are at fault, not the odometry
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/est.tum' --groundtruth '{dir}/gt.tum' --loops '{dir}/loops_missing.txt'",
       1,
       {"{dir}/loops_missing.txt:2: node 5000 is not a frame of the odometry"},
       {"est.tum", "edge 0", "pose graph:"}},
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/est.tum' --groundtruth '{dir}/gt.tum' --loops '{dir}/loops_huge.txt'",
       1,
       {"{dir}/loops_huge.txt:1: ", "1e+308"},
       {"est.tum", "a result is not finite"}},
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/est.tum' --groundtruth '{dir}/gt.tum' --loops '{dir}/loops_ok.txt' --json",
       0,
       {},
       {}},
      // 6. huge finite values and degenerate ground truth name the file
      {"evaluate_trajectory", eval + "'{dir}/huge.tum'", 1, {"{dir}/huge.tum:3: ", "1e+200"},
       {"compute_statistics", "error 2"}},
      {"evaluate_trajectory", "--groundtruth '{dir}/still.tum' --estimate '{dir}/still.tum' --align se3", 1,
       {"{dir}/still.tum", "--align none"},
       {"umeyama"}},
      {"optimize_pose_graph", "--input '{dir}/huge.g2o'", 1, {"{dir}/huge.g2o:3: ", "1e+308"}, {"singular"}},
      {"optimize_pose_graph", "--input '{dir}/two.g2o' --groundtruth '{dir}/bad_id_gt.txt'", 1,
       {"{dir}/bad_id_gt.txt:2: ", "'x1'", "vertex id"},
       {"stol"}},
      {"optimize_pose_graph", "--input '{dir}/strong.g2o'", 1, {"{dir}/strong.g2o:3: ", "1e+300"},
       {"singular", "too weak"}},
      // A node the information leaves free is refused from every start.
      {"optimize_pose_graph", "--input '{dir}/zero_info.g2o'", 1,
       {"{dir}/zero_info.g2o:3: node 2 is tied to the fixed node only through edges of zero information"},
       {"singular", "initialisation"}},
      {"optimize_pose_graph", "--input '{dir}/zero_info.g2o' --init file --json", 1,
       {"{dir}/zero_info.g2o:3: node 2 is tied to the fixed node only through edges of zero information"},
       {}},
      {"optimize_pose_graph", "--input '{dir}/heading_only.g2o' --init file", 1,
       {"{dir}/heading_only.g2o:3: node 2 has no position information"},
       {}},
      {"optimize_pose_graph", "--input '{dir}/no_y.g2o'", 1,
       {"{dir}/no_y.g2o: the information does not fix every node"},
       {"singular", "initialisation"}},
      {"optimize_pose_graph", "--input '{dir}/no_y.g2o' --init file", 1,
       {"{dir}/no_y.g2o: the information does not fix every node"},
       {}},
      // 7. a folder given as a result
      {"compare_results", "--result '{dir}/folder'", 1, {"{dir}/folder: ", "folder"}, {"basic_filebuf"}},
      // 8. programs without --duplicates do not offer it
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/dup.tum' --groundtruth '{dir}/dup.tum' --oracle-loops", 1,
       {"{dir}/dup.tum:3: timestamp 0.1 repeats the previous one"},
       {"--duplicates"}},
      {"orb_trajectory_correction", "--format tum --groundtruth '{dir}/dup.tum' --estimate '{dir}/dup.tum'", 1,
       {"{dir}/dup.tum:3: timestamp 0.1 repeats the previous one"},
       {"--duplicates"}},
      {"evaluate_trajectory", eval + "'{dir}/dup.tum' --duplicates error", 1,
       {"{dir}/dup.tum:3: ", "(--duplicates)"},
       {}},
      // 10. saved results that cannot be right
      {"compare_results", "--result '{dir}/null_rmse.json'", 1, {"{dir}/null_rmse.json: ", "rmse"}, {"nan"}},
      {"compare_results", "--result '{dir}/negative_count.json'", 1, {"{dir}/negative_count.json: ", "count"}, {}},
      {"compare_results", "--result '{dir}/fraction_count.json'", 1, {"{dir}/fraction_count.json: ", "2.5"}, {}},
      // Smaller: an output over an input, flags that do nothing alone
      {"evaluate_trajectory", eval + "'{dir}/est.tum' --save-results '{dir}/gt.tum'", 2,
       {"--save-results {dir}/gt.tum is the input of --groundtruth"},
       {}},
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/est.tum' --groundtruth '{dir}/gt.tum' --oracle-loops --out '{dir}/./est.tum'", 2,
       {"is the input of --odometry"},
       {}},
      {"optimize_pose_graph", "--robust-scale 2", 2, {"--robust-scale needs a robust loss"}, {}},
      {"pose_graph_correction", "--robust none --robust-scale 2", 2, {"--robust-scale needs a robust loss"}, {}},
      {"orb_trajectory_correction", "--method cv", 2, {"give --out"}, {}},
      // 1. a zero noise density: a zero covariance cannot score an error
      {"imu_preintegration_check",
       euroc + "--gyro-noise 0 --accel-noise 0 --gyro-walk 0 --accel-walk 0", 2, {"--gyro-noise"}, {}},
      {"imu_preintegration_check", euroc + "--accel-noise 0", 2, {"--accel-noise"}, {}},
      {"imu_preintegration_check", euroc + "--gyro-noise 1e300", 2, {"--gyro-noise 1e+300"}, {}},
      {"imu_preintegration_check", euroc + "--gravity 1e308", 2, {"--gravity 1e+308"}, {}},
      // 3, 4. intervals whose seconds -> ns conversion overflows
      {"imu_preintegration_check", euroc + "--window 1e10", 2, {"--window 1e+10 s does not fit"}, {}},
      {"imu_preintegration_check", euroc + "--window 1e308", 2, {"--window 1e+308 s does not fit"}, {}},
      {"imu_preintegration_check", euroc + "--window 1e-12", 2, {"shorter than 1 ns"}, {}},
      {"vi_alignment_check", euroc + "--keyframe-interval 1e10", 2,
       {"--keyframe-interval 1e+10 s does not fit"}, {}},
      // 2. values that can only fail
      {"vi_alignment_check", euroc + "--sfm-scale 1e300", 2, {"--sfm-scale 1e+300"}, {}},
      {"vi_alignment_check", euroc + "--rot-noise-deg 1e6", 2, {"--rot-noise-deg 1e+06"}, {}},
  };
  for (const Probe& p : probes) check(p, dir);
  // The refused runs left the inputs as they were.
  CHECK(posefuse::test::slurp(dir.path() / "gt.tum") == tum_loop(200));
  CHECK(posefuse::test::slurp(dir.path() / "est.tum") == tum_loop(200));
}

TEST_CASE("optimize_pose_graph --init file starts from the file's poses after the fixedness check",
          "[examples][contract][graph]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "optimize_pose_graph");
  const TempDir dir("contract-init-file");
  // A triangle with a loop, poses away from the measurements.
  const fs::path g = dir.write("loop.g2o",
                               "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1.3 0.2 1.4\nVERTEX_SE2 2 0.8 1.1 3.0\n"
                               "EDGE_SE2 0 1 1 0 1.5708 100 0 0 100 0 100\n"
                               "EDGE_SE2 1 2 1 0 1.5708 100 0 0 100 0 100\n"
                               "EDGE_SE2 2 0 1.4142 0 -3.1416 10 0 0 10 0 10\n");
  const Run r = posefuse::test::run(exe, "--input '" + g.string() + "' --init file --json", dir);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = posefuse::test::Json::parse(r.out);
  // The check ran the rotation-first systems, yet the solve starts from the file.
  CHECK(j["initial_cost"].number() == j["file_cost"].number());
  CHECK(j["file_cost"].number() > 1.0);
  CHECK(j["final_cost"].number() < j["file_cost"].number());
}

TEST_CASE("optimize_pose_graph and pose_graph_correction show progress only on a terminal",
          "[examples][contract][progress]") {
  const TempDir dir("contract-progress");
  for (const char* program : {"optimize_pose_graph", "pose_graph_correction"}) {
    const fs::path exe = posefuse::test::example(program);
    if (exe.empty()) {
      WARN("SKIPPED: example '" << program << "' not built");
      continue;
    }
    INFO(program);
    // Standard error not a terminal (a file): nothing but the result.
    const Run plain = posefuse::test::run(exe, "--json", dir);
    REQUIRE(plain.status == 0);
    CHECK(plain.err.empty());
    CHECK_NOTHROW(posefuse::test::Json::parse(plain.out));
    // Standard error a terminal (script(1) runs the program on a pseudo-
    // terminal; standard output goes to a file): one status line rewritten
    // in place with the solver's iterations, erased at the end.
    if (!fs::exists("/usr/bin/script")) {
      WARN("SKIPPED: /usr/bin/script is not installed");
      continue;
    }
    const fs::path out = dir.path() / "out.json", tty = dir.path() / "tty.txt";
    const std::string inner = "'" + exe.string() + "' --json 2>&1 >'" + out.string() + "'";
    const std::string cmd = "/usr/bin/script -qec \"" + inner + "\" /dev/null > '" + tty.string() + "' 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const std::string shown = posefuse::test::slurp(tty);
    INFO(shown);
    CHECK(shown.find(std::string("\r") + program + ": solving: ") != std::string::npos);
    CHECK(shown.find(std::string("\r") + program + ": iteration 1/100  cost ") != std::string::npos);
    CHECK(shown.size() >= 4);
    CHECK(shown.substr(shown.size() - 4) == "\r\033[K");
    CHECK(shown.find('\n') == std::string::npos);
    CHECK_NOTHROW(posefuse::test::Json::parse(posefuse::test::slurp(out)));
  }
}

TEST_CASE("evaluate_trajectory shows its stages only on a terminal", "[examples][contract][progress]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  const TempDir dir("contract-progress-eval");
  const fs::path gt = dir.write("gt.tum", tum_loop(200));
  const std::string args = "--groundtruth '" + gt.string() + "' --estimate '" + gt.string() + "' --json";
  const Run plain = posefuse::test::run(exe, args, dir);
  REQUIRE(plain.status == 0);
  CHECK(plain.err.empty());
  if (!fs::exists("/usr/bin/script")) {
    WARN("SKIPPED: /usr/bin/script is not installed");
    return;
  }
  const fs::path out = dir.path() / "out.json", tty = dir.path() / "tty.txt";
  const std::string inner = "'" + exe.string() + "' " + args + " 2>&1 >'" + out.string() + "'";
  const std::string cmd = "/usr/bin/script -qec \"" + inner + "\" /dev/null > '" + tty.string() + "' 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::string shown = posefuse::test::slurp(tty);
  INFO(shown);
  CHECK(shown.find("\revaluate_trajectory: reading " + gt.string()) != std::string::npos);
  CHECK(shown.find("\revaluate_trajectory: APE of 200 pose pairs") != std::string::npos);
  CHECK(shown.size() >= 4);
  CHECK(shown.substr(shown.size() - 4) == "\r\033[K");
  // The result on standard output is the one printed without a terminal.
  CHECK(posefuse::test::slurp(out) == plain.out);
}

TEST_CASE("imu_preintegration_check and vi_alignment_check show their windows only on a terminal",
          "[examples][contract][progress][inertial]") {
  const TempDir dir("contract-progress-inertial");
  const RestRecording rest = rest_recording(12.0);
  const fs::path imu = dir.write("imu0.csv", rest.imu);
  const fs::path gt = dir.write("gt.csv", rest.gt);
  const std::string args = "--imu '" + imu.string() + "' --groundtruth '" + gt.string() + "' --json";
  for (const char* program : {"imu_preintegration_check", "vi_alignment_check"}) {
    const fs::path exe = posefuse::test::example(program);
    if (exe.empty()) {
      WARN("SKIPPED: example '" << program << "' not built");
      continue;
    }
    INFO(program);
    const Run plain = posefuse::test::run(exe, args, dir);
    REQUIRE(plain.status == 0);
    CHECK(plain.err.empty());
    if (!fs::exists("/usr/bin/script")) {
      WARN("SKIPPED: /usr/bin/script is not installed");
      continue;
    }
    const fs::path out = dir.path() / "out.json", tty = dir.path() / "tty.txt";
    const std::string inner = "'" + exe.string() + "' " + args + " 2>&1 >'" + out.string() + "'";
    const std::string cmd = "/usr/bin/script -qec \"" + inner + "\" /dev/null > '" + tty.string() + "' 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const std::string shown = posefuse::test::slurp(tty);
    INFO(shown);
    CHECK(shown.find(std::string("\r") + program + ": reading " + imu.string()) != std::string::npos);
    CHECK(shown.find(std::string("\r") + program + ": window ") != std::string::npos);
    CHECK(shown.size() >= 4);
    CHECK(shown.substr(shown.size() - 4) == "\r\033[K");
    CHECK(posefuse::test::slurp(out) == plain.out);
  }
}

TEST_CASE("ekf_custom_model: --help prints usage only, unwritable output fails",
          "[examples][contract][tutorial]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "ekf_custom_model");
  const TempDir dir("contract-tutorial");
  const Run help = posefuse::test::run(exe, "--help", dir);
  CHECK(help.status == 0);
  CHECK(help.out.rfind("usage: ekf_custom_model", 0) == 0);
  CHECK(help.out.find("position RMSE") == std::string::npos);  // the demo did not run
  if (fs::exists("/dev/full")) {
    const std::string cmd = "'" + exe.string() + "' > /dev/full 2> '" + (dir.path() / "err.txt").string() + "'";
    const int raw = std::system(cmd.c_str());
    CHECK(WIFEXITED(raw));
    CHECK(WEXITSTATUS(raw) == 1);
    CHECK(posefuse::test::slurp(dir.path() / "err.txt") ==
          "ekf_custom_model: cannot write to standard output\n");
  }
}

TEST_CASE("evaluate_trajectory reads a named pipe once when it detects the format",
          "[examples][contract][eval]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  const TempDir dir("contract-fifo");
  const fs::path gt = dir.write("gt.tum", tum_loop(100));
  const fs::path fifo = dir.path() / "est.fifo";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // The writer blocks until the program opens the pipe; `timeout` ends a
  // program that would open it a second time and wait forever.
  const std::string writer = "cat '" + gt.string() + "' > '" + fifo.string() + "' &";
  REQUIRE(std::system(writer.c_str()) == 0);
  const Run r = posefuse::test::run("/usr/bin/timeout",
                                    "20 '" + exe.string() + "' --groundtruth '" + gt.string() +
                                        "' --estimate '" + fifo.string() + "' --json",
                                    dir);
  // Unblocks the writer if the program never opened the pipe.
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  if (fd >= 0) ::close(fd);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(posefuse::test::Json::parse(r.out)["rmse"].number() == 0.0);
  CHECK(r.err.empty());
}

// An accelerometer reading of 1e308 would overflow the pre-integration; the
// EuRoC reader refuses a specific force beyond its physical bound
// (kMaxAbsSpecificForce) at the reading's line.
TEST_CASE("imu_preintegration_check: a huge IMU reading is refused at its line",
          "[examples][contract][inertial]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "imu_preintegration_check");
  const TempDir dir("contract-imu-huge");
  const RestRecording rest = rest_recording(12.0);
  std::string imu_huge = rest.imu;
  const std::size_t at = imu_huge.find('\n', imu_huge.find('\n') + 1) + 1;  // line 3
  const std::size_t end = imu_huge.find('\n', at);
  imu_huge.replace(at, end - at, imu_huge.substr(at, imu_huge.find(',', at) - at) + ",0,0,0,1e308,0,9.81");
  const fs::path imu = dir.write("imu_huge.csv", imu_huge);
  const fs::path gt = dir.write("gt.csv", rest.gt);
  const Run r = posefuse::test::run(exe, "--imu " + quoted(imu) + " --groundtruth " + quoted(gt), dir);
  INFO(r.err);
  CHECK(r.status == 1);
  CHECK(count_lines(r.err) == 1);
  CHECK(r.err.find(imu.string() + ":3: ") != std::string::npos);
  CHECK(r.err.find("specific force") != std::string::npos);
}

TEST_CASE("imu_preintegration_check and vi_alignment_check: windows, gaps and empty summaries",
          "[examples][contract][inertial]") {
  const TempDir dir("contract-inertial");
  const RestRecording rest = rest_recording(12.0);
  const fs::path imu = dir.write("imu0.csv", rest.imu);
  const fs::path gt = dir.write("gt.csv", rest.gt);
  const fs::path gap = dir.write("gap.csv", rest_recording(12.0, 6).gt);
  const std::string files = "--imu " + quoted(imu) + " --groundtruth " + quoted(gt);
  SECTION("imu_preintegration_check") {
    POSEFUSE_REQUIRE_EXAMPLE(exe, "imu_preintegration_check");
    // 4. windows as short as the jittered 50 ms step: no gap is seen.
    const Run step = posefuse::test::run(exe, files + " --window 0.05 --json", dir);
    INFO(step.err);
    REQUIRE(step.status == 0);
    CHECK(step.err.empty());
    const auto j = posefuse::test::Json::parse(step.out);
    CHECK(j["skipped"].number() == 0);
    CHECK(j["windows"].number() >= 230);
    CHECK(j["window_s"].number() == Approx(0.05).margin(1e-6));
    // A real gap (six states missing, 0.35 s) is one, whatever the window.
    for (const char* w : {"0.05", "1", "3"}) {
      const Run g = posefuse::test::run(
          exe, "--imu " + quoted(imu) + " --groundtruth " + quoted(gap) + " --json --window " + w, dir);
      INFO(w << ": " << g.err);
      REQUIRE(g.status == 0);
      CHECK(posefuse::test::Json::parse(g.out)["skipped"].number() == 1);
    }
    // 3. a window shorter than the ground truth's period: a warning, and
    // the length used is the one printed.
    const Run shorter = posefuse::test::run(exe, files + " --window 0.01", dir);
    INFO(shorter.err);
    REQUIRE(shorter.status == 0);
    CHECK(shorter.err.rfind("warning: --window 0.01 s is shorter than the ground truth's period (0.05 s)", 0) == 0);
    CHECK(shorter.out.find("windows of 0.05 s (asked 0.01 s") != std::string::npos);
  }
  SECTION("vi_alignment_check") {
    POSEFUSE_REQUIRE_EXAMPLE(exe, "vi_alignment_check");
    // 2. at rest no window aligns: no medians, JSON nulls, exit 0 (a 0 % rate is a result).
    const Run table = posefuse::test::run(exe, files, dir);
    INFO(table.err);
    REQUIRE(table.status == 0);
    CHECK(table.out.find("success rate 0.0 %") != std::string::npos);
    CHECK(table.out.find("no successful window") != std::string::npos);
    CHECK(table.out.find("median") == std::string::npos);
    const Run json = posefuse::test::run(exe, files + " --json", dir);
    REQUIRE(json.status == 0);
    const auto j = posefuse::test::Json::parse(json.out);
    CHECK(j["success_rate"].number() == 0.0);
    for (const char* k : {"scale_error_percent", "gravity_error_deg", "velocity_error", "gyro_bias_error"})
      CHECK(j[k].is_null());
    // 3. an interval shorter than the ground truth's period
    const Run shorter = posefuse::test::run(exe, files + " --keyframe-interval 0.01 --json", dir);
    INFO(shorter.err);
    REQUIRE(shorter.status == 0);
    CHECK(shorter.err.rfind("warning: --keyframe-interval 0.01 s is shorter than the ground truth's period", 0) == 0);
    CHECK(posefuse::test::Json::parse(shorter.out)["keyframe_interval_s"].number() == Approx(0.05).margin(1e-6));
  }
}

TEST_CASE("imu_preintegration_check and vi_alignment_check keep the contract on EuRoC V1_01_easy",
          "[examples][contract][inertial][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  const TempDir dir("contract-inertial-data");
  const std::string files =
      "--imu " + quoted(d / "imu0.csv") + " --groundtruth " + quoted(d / "groundtruth_20hz.csv");
  SECTION("imu_preintegration_check --window 0.05 sees no gap") {
    POSEFUSE_REQUIRE_EXAMPLE(exe, "imu_preintegration_check");
    const Run r = posefuse::test::run(exe, files + " --window 0.05 --json", dir);
    INFO(r.err);
    REQUIRE(r.status == 0);
    CHECK(posefuse::test::Json::parse(r.out)["skipped"].number() == 0);
  }
  SECTION("vi_alignment_check --stride 1000000 prints no median") {
    POSEFUSE_REQUIRE_EXAMPLE(exe, "vi_alignment_check");
    const Run r = posefuse::test::run(exe, files + " --stride 1000000 --json", dir);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto j = posefuse::test::Json::parse(r.out);
    if (j["success_rate"].number() == 0.0) CHECK(j["scale_error_percent"].is_null());
    else CHECK(j["scale_error_percent"].is_number());
  }
}

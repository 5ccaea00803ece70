// The programs' contract, second table: outputs over inputs (one rule in the
// command-line layer, for every program), values that can only fail,
// flags that do nothing in a combination, structural faults of 3-D graphs,
// the IMU reader's bounds and the number formatter of messages. One row per
// case, on tiny inputs written here; each refused run is checked to leave
// its inputs as they were and its outputs unwritten.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "examples/program_probe.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using posefuse::test::check;
using posefuse::test::Probe;
using posefuse::test::TempDir;

namespace {

/// A TUM trajectory of n poses on a planar loop (x, y vary), 0.1 s apart.
std::string tum_loop(int n) {
  std::ostringstream s;
  s.precision(17);
  for (int k = 0; k < n; ++k) {
    const double a = 0.05 * k;
    s << 0.1 * k << ' ' << 10 * std::cos(a) << ' ' << 10 * std::sin(a) << ' ' << 0.01 * k << " 0 0 0 1\n";
  }
  return s.str();
}

/// A TUM trajectory of n poses on a straight line along x.
std::string tum_line(int n) {
  std::ostringstream s;
  for (int k = 0; k < n; ++k) s << 0.1 * k << ' ' << k << " 0 0 0 0 0 1\n";
  return s.str();
}

/// imu0.csv of a body at rest, 200 Hz for `seconds`, and a 17-column ground
/// truth at 20 Hz; `gyro` replaces the gyroscope x reading of line 3.
struct Rest {
  std::string imu, gt;
};
Rest rest(double seconds, const std::string& gyro = "0") {
  Rest r;
  const std::int64_t t0 = 1403715273262142976;
  for (std::int64_t k = 0; k * 5000000 <= std::int64_t(seconds * 1e9); ++k)
    r.imu += std::to_string(t0 + k * 5000000) + "," + (k == 2 ? gyro : "0") + ",0,0,0,0,9.81\n";
  for (std::int64_t k = 0; k * 50000000 <= std::int64_t(seconds * 1e9); ++k)
    r.gt += std::to_string(t0 + k * 50000000) + ",1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n";
  return r;
}

/// A 3-D g2o chain 0-1-2 whose edge 1-2 has `info12` (21 upper-triangle numbers).
std::string se3_chain(const std::string& info12) {
  const std::string full = " 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400";
  return "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\nVERTEX_SE3:QUAT 2 2 0.3 0 0 0 0.2 0.98\n"
         "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1" + full + "\nEDGE_SE3:QUAT 1 2 1 0 0 0 0 0 1" + info12 + "\n";
}

}  // namespace

TEST_CASE("Every program refuses an output that names an input or another output",
          "[examples][contract][outputs]") {
  const TempDir dir("contract-outputs");
  const std::string loop = tum_loop(100);
  (void)dir.write("gt.tum", loop);
  (void)dir.write("est.tum", loop);
  fs::create_symlink(dir.path() / "est.tum", dir.path() / "link.tum");
  const Rest r = rest(3.0);
  (void)dir.write("imu0.csv", r.imu);
  (void)dir.write("gt.csv", r.gt);
  (void)dir.write("g.g2o", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n");
  // Folder mode of orb_trajectory_correction: same-named files in two folders.
  fs::create_directory(dir.path() / "gts");
  fs::create_directory(dir.path() / "ests");
  (void)dir.write("gts/seq.tum", loop);
  (void)dir.write("ests/seq.tum", loop);
  const std::string eval = "--groundtruth '{dir}/gt.tum' --estimate '{dir}/est.tum' ";
  const std::string euroc = "--imu '{dir}/imu0.csv' --groundtruth '{dir}/gt.csv' ";
  const std::vector<Probe> probes = {
      // ./a, a symbolic link, dir/../a: the file, not the spelling, counts
      {"evaluate_trajectory", eval + "--plot '{dir}/./gt.tum'", 2,
       {"--plot {dir}/./gt.tum is the input of --groundtruth"}, {}},
      {"evaluate_trajectory", eval + "--save-results '{dir}/link.tum'", 2,
       {"--save-results {dir}/link.tum is the input of --estimate"}, {}},
      {"evaluate_trajectory", eval + "--save-results '{dir}/x.json' --plot '{dir}/gts/../x.json'", 2,
       {"--save-results {dir}/x.json and --plot {dir}/gts/../x.json name the same file"}, {},
       {"{dir}/x.json"}},
      {"pose_graph_correction",
       "--format tum --odometry '{dir}/est.tum' --groundtruth '{dir}/gt.tum' --oracle-loops --out '{dir}/o.tum' "
       "--svg '{dir}/./o.tum'",
       2, {"--out {dir}/o.tum and --svg {dir}/./o.tum name the same file"}, {}, {"{dir}/o.tum"}},
      {"optimize_pose_graph", "--input '{dir}/g.g2o' --out '{dir}/./g.g2o'", 2,
       {"--out {dir}/./g.g2o is the input of --input"}, {}},
      {"imu_preintegration_check", euroc + "--svg '{dir}/imu0.csv'", 2,
       {"--svg {dir}/imu0.csv is the input of --imu"}, {}},
      {"vi_alignment_check", euroc + "--svg '{dir}/./gt.csv'", 2, {"--svg {dir}/./gt.csv is the input of --groundtruth"},
       {}},
      {"corridor_fusion", "--log '{dir}/gts' --write-log '{dir}/gts/'", 2,
       {"--write-log {dir}/gts/ is the input of --log"}, {}},
      // The output folder of folder mode is an input folder.
      {"orb_trajectory_correction",
       "--format tum --groundtruth '{dir}/gts' --estimate '{dir}/ests' --method cv --out '{dir}/ests'", 2,
       {"--out {dir}/ests is the input of --estimate"}, {}, {"{dir}/ests/seq_cv.tum"}},
      {"orb_trajectory_correction",
       "--format tum --groundtruth '{dir}/gts' --estimate '{dir}/ests' --method cv --out '{dir}/gts/'", 2,
       {"--out {dir}/gts/ is the input of --groundtruth"}, {}, {"{dir}/gts/seq_cv.tum"}},
      // Devices replace no file: two outputs may both be /dev/null.
      {"evaluate_trajectory", eval + "--save-results /dev/null --plot /dev/null", 0, {}, {}},
  };
  for (const Probe& p : probes) check(p, dir);
  CHECK(posefuse::test::slurp(dir.path() / "gt.tum") == loop);
  CHECK(posefuse::test::slurp(dir.path() / "est.tum") == loop);
  CHECK(posefuse::test::slurp(dir.path() / "imu0.csv") == r.imu);
  CHECK(posefuse::test::slurp(dir.path() / "gt.csv") == r.gt);
  CHECK(posefuse::test::slurp(dir.path() / "ests/seq.tum") == loop);
}

TEST_CASE("Values that can only fail, flags that do nothing, and the file at fault",
          "[examples][contract][outputs]") {
  const TempDir dir("contract-bounds");
  (void)dir.write("gt.tum", tum_loop(100));
  (void)dir.write("est.tum", tum_loop(100));
  (void)dir.write("two.tum", tum_line(2));
  (void)dir.write("line.tum", tum_line(50));
  const Rest r = rest(3.0);
  (void)dir.write("imu0.csv", r.imu);
  (void)dir.write("gt.csv", r.gt);
  (void)dir.write("fast_gyro.csv", rest(3.0, "9000").imu);
  (void)dir.write("rotation_free.g2o", se3_chain(" 100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 0 0 0 0 0 0"));
  (void)dir.write("zero_info.g2o", se3_chain(" 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0"));
  (void)dir.write("no_position.g2o", se3_chain(" 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 400 0 0 400 0 400"));
  const std::string orb = "--format tum --groundtruth '{dir}/gt.tum' --estimate '{dir}/est.tum' ";
  const std::string euroc = "--imu '{dir}/imu0.csv' --groundtruth '{dir}/gt.csv' ";
  const std::vector<Probe> probes = {
      // Noise the filters cannot use: the flag, not the estimate, is at fault.
      {"orb_trajectory_correction", orb + "--cv-q 1e300", 2, {"--cv-q: expected a number from 1e-08 to 1e+08"},
       {"est.tum", "not applied"}},
      {"orb_trajectory_correction", orb + "--ctrv-q 1e-300", 2, {"--ctrv-q: expected a number from 1e-08 to 1e+08"},
       {}},
      {"orb_trajectory_correction", orb + "--R 1e300", 2, {"--R: expected a number from 1e-08 to 1e+08"}, {}},
      {"orb_trajectory_correction", orb + "--Q 1,1e-300", 2, {"--Q: expected a number from 1e-08 to 1e+08"}, {}},
      {"orb_trajectory_correction", orb + "--cv-q 1e8 --ctrv-q 1e-8 --R 1e-8 --Q 1e8 --json", 0, {}, {}},
      // --align without a ground truth or a control aligns nothing.
      {"orb_trajectory_correction", "--format tum --estimate '{dir}/est.tum' --tune --align sim3", 2,
       {"--align", "does nothing"}, {}},
      // Alignments that are not defined name the estimate, not the solver.
      {"orb_trajectory_correction", "--format tum --groundtruth '{dir}/two.tum' --estimate '{dir}/two.tum' --align sim3",
       1, {"{dir}/two.tum: --align sim3 cannot align its 2 poses"}, {"umeyama"}},
      {"orb_trajectory_correction",
       "--format tum --groundtruth '{dir}/line.tum' --estimate '{dir}/line.tum' --align se3", 1,
       {"{dir}/line.tum: --align se3 cannot align its 50 poses"}, {"umeyama"}},
      // 3-D graphs whose information leaves a node free: refused from both starts.
      {"optimize_pose_graph", "--input '{dir}/rotation_free.g2o'", 1,
       {"{dir}/rotation_free.g2o:3: node 2 is tied to the fixed node only through edges of zero rotation information"},
       {"singular"}},
      {"optimize_pose_graph", "--input '{dir}/rotation_free.g2o' --init file", 1,
       {"{dir}/rotation_free.g2o:3: node 2 is tied to the fixed node only through edges of zero rotation"}, {}},
      {"optimize_pose_graph", "--input '{dir}/zero_info.g2o' --init file", 1,
       {"{dir}/zero_info.g2o:3: node 2 is tied to the fixed node only through edges of zero information"}, {}},
      {"optimize_pose_graph", "--input '{dir}/no_position.g2o' --init file", 1,
       {"{dir}/no_position.g2o:3: node 2 has no position information"}, {}},
      // The IMU reader's bound: a stated default, a flag to widen it.
      {"imu_preintegration_check", "--imu '{dir}/fast_gyro.csv' --groundtruth '{dir}/gt.csv'", 1,
       {"{dir}/fast_gyro.csv:3: angular rate of magnitude 9000 rad/s is beyond the physical bound 50 rad/s"}, {}},
      {"vi_alignment_check", "--imu '{dir}/fast_gyro.csv' --groundtruth '{dir}/gt.csv'", 1,
       {"{dir}/fast_gyro.csv:3: angular rate of magnitude 9000 rad/s"}, {}},
      {"imu_preintegration_check", euroc + "--imu-max-gyro 1e5", 2, {"--imu-max-gyro: expected a number from 1 to 10000"},
       {}},
      {"imu_preintegration_check", euroc + "--imu-max-accel 5", 2, {"--imu-max-accel: expected a number from 10 to"},
       {}},
  };
  for (const Probe& p : probes) check(p, dir);
}

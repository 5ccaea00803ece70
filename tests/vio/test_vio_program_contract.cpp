// visual_inertial_odometry and simulate_tracks keep the programs' contract
// (docs/programs.md): one row per bad or unusual input, on a few seconds of
// a body at rest written here (no dataset). Outputs over inputs exit 2
// naming both flags; values that can only fail exit 2 naming the flag; a
// ground truth that cannot be compared with the run exits 1 naming it and
// writes nothing; pixels just outside the image are dropped with a warning.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
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

constexpr std::int64_t kT0 = 1403715273262142976;

/// imu0.csv of a body at rest: 200 Hz for `seconds`; samples k in
/// [gap_from, gap_to) left out.
std::string rest_imu(double seconds, int gap_from = -1, int gap_to = -1) {
  std::string s;
  for (std::int64_t k = 0; k * 5000000 <= std::int64_t(seconds * 1e9); ++k)
    if (k < gap_from || k >= gap_to) s += std::to_string(kT0 + k * 5000000) + ",0,0,0,0,0,9.81\n";
  return s;
}

/// Tracks of a still camera: 40 features on a grid, 20 Hz for `seconds`;
/// feature 0 of frame 30 at `u0` (its usual u is 30).
std::string still_tracks(double seconds, const std::string& u0 = "30") {
  std::string s = "t_ns,feature_id,u,v\n";
  for (std::int64_t k = 0; k * 50000000 <= std::int64_t(seconds * 1e9); ++k)
    for (int i = 0; i < 40; ++i)
      s += std::to_string(kT0 + k * 50000000) + "," + std::to_string(i) + "," +
           (k == 30 && i == 0 ? u0 : std::to_string(30 + (i % 8) * 90)) + "," + std::to_string(40 + (i / 8) * 90) +
           "\n";
  return s;
}

/// A ground truth (EuRoC, 8 columns) at 20 Hz: `rows` poses from `t0`.
std::string groundtruth(std::int64_t t0, int rows) {
  std::string s;
  for (std::int64_t k = 0; k < rows; ++k) s += std::to_string(t0 + k * 50000000) + ",1,2,3,1,0,0,0\n";
  return s;
}

const char* const kCamera =
    "resolution: [752, 480]\ncamera_model: pinhole\nintrinsics: [458.654, 457.296, 367.215, 248.375]\n"
    "distortion_model: radial-tangential\n"
    "distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"
    "T_BS: [0,0,1,0.05, -1,0,0,0, 0,-1,0,0]\n";

}  // namespace

TEST_CASE("visual_inertial_odometry keeps the contract on bad and unusual input", "[vio][cli][contract]") {
  const TempDir dir("vio-contract");
  const std::string imu = rest_imu(4.0), tracks = still_tracks(4.0);
  (void)dir.write("imu0.csv", imu);
  (void)dir.write("t.csv", tracks);
  (void)dir.write("cam.yaml", kCamera);
  (void)dir.write("map.txt", "posefuse_vio_map 1\n");
  (void)dir.write("gap.csv", rest_imu(4.0, 100, 120));
  (void)dir.write("late_gt.csv", groundtruth(kT0 + 100'000'000'000, 40));
  (void)dir.write("one_gt.csv", groundtruth(kT0 + 2'000'000'000, 1));
  (void)dir.write("two_gt.csv", groundtruth(kT0 + 2'000'000'000, 2));
  (void)dir.write("still_gt.csv", groundtruth(kT0, 80));
  (void)dir.write("edge.csv", still_tracks(4.0, "-0.51"));
  (void)dir.write("far.csv", still_tracks(4.0, "-5"));
  (void)dir.write("tiny_focal.yaml", std::string(kCamera).replace(std::string(kCamera).find("458.654"), 7, "1e-300"));
  {
    // The same IMU 100 s later, and with its stamps in microseconds.
    std::string later, micro;
    for (std::int64_t k = 0; k <= 800; ++k) {
      later += std::to_string(kT0 + 100'000'000'000 + k * 5000000) + ",0,0,0,0,0,9.81\n";
      micro += std::to_string(kT0 / 1000 + k * 5000) + ",0,0,0,0,0,9.81\n";
    }
    (void)dir.write("later_imu.csv", later);
    (void)dir.write("micro_imu.csv", micro);
    (void)dir.write("short_imu.csv", rest_imu(2.5));
    (void)dir.write("one_frame.csv", still_tracks(0.01));
  }
  const std::string base = "--tracks '{dir}/t.csv' --camera '{dir}/cam.yaml' --imu '{dir}/imu0.csv' ";
  const std::string out = "--out '{dir}/o.tum' ";
  const std::vector<Probe> probes = {
      // An output over an input, or over another output: exit 2 before any work.
      {"visual_inertial_odometry", base + "--out '{dir}/./t.csv'", 2, {"--out {dir}/./t.csv is the input of --tracks"},
       {}},
      {"visual_inertial_odometry", base + "--out '{dir}/imu0.csv'", 2, {"is the input of --imu"}, {}},
      {"visual_inertial_odometry", base + "--groundtruth '{dir}/still_gt.csv' --out '{dir}/./still_gt.csv'", 2,
       {"is the input of --groundtruth"}, {}},
      {"visual_inertial_odometry", base + "--out '{dir}/cam.yaml'", 2, {"is the input of --camera"}, {}},
      {"visual_inertial_odometry", base + "--loops recurring-ids --save-map '{dir}/t.csv'", 2,
       {"--save-map {dir}/t.csv is the input of --tracks"}, {}},
      {"visual_inertial_odometry", base + "--loops recurring-ids --load-map '{dir}/map.txt' --save-map '{dir}/./map.txt'",
       2, {"is the input of --load-map"}, {}},
      {"visual_inertial_odometry", base + "--loops '{dir}/./o.tum' " + out, 2, {"is the input of --loops"}, {}},
      {"visual_inertial_odometry", base + out + "--out-odometry '{dir}/./o.tum'", 2,
       {"--out {dir}/o.tum and --out-odometry {dir}/./o.tum name the same file"}, {}, {"{dir}/o.tum"}},
      // Values that can only fail (or switch vision off): the flag, bounded.
      {"visual_inertial_odometry", base + "--max-imu-gap-ms 1e300", 2, {"--max-imu-gap-ms: expected a number from"},
       {"read_euroc_imu_checked"}},
      {"visual_inertial_odometry", base + "--max-imu-gap-ms 1e-9", 2, {"--max-imu-gap-ms: expected a number from"}, {}},
      {"visual_inertial_odometry", base + "--imu-noise 1e-300,1.7e-4,3e-3,1.9e-5", 2, {"--imu-noise: "},
       {"ImuFactor"}},
      {"visual_inertial_odometry", base + "--pixel-sigma 1e-300", 2, {"--pixel-sigma: expected a number from"}, {}},
      {"visual_inertial_odometry", base + "--outlier-px 1e-300", 2, {"--outlier-px: expected a number from"}, {}},
      {"visual_inertial_odometry", base + "--pixel-sigma 2 --outlier-px 1", 2,
       {"--outlier-px 1 is below --pixel-sigma 2"}, {}},
      {"visual_inertial_odometry", base + "--window 41", 2, {"--window: expected an integer from 2 to 40"}, {}},
      {"visual_inertial_odometry", base + "--imu-max-gyro 0", 2, {"--imu-max-gyro"}, {}},
      // Data at fault: the file, and short numbers in the message.
      {"visual_inertial_odometry", "--tracks '{dir}/t.csv' --camera '{dir}/cam.yaml' --imu '{dir}/gap.csv' " + out, 1,
       {"{dir}/gap.csv:101: gap of 105 ms after line 100 (the limit is 50 ms)"}, {}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", "--tracks '{dir}/t.csv' --camera '{dir}/tiny_focal.yaml' --imu '{dir}/imu0.csv'", 1,
       {"{dir}/tiny_focal.yaml: the camera is not usable: focal lengths (1e-300, 457.296 px)"}, {"PinholeRadtan"}},
      {"visual_inertial_odometry", "--tracks '{dir}/far.csv' --camera '{dir}/cam.yaml' --imu '{dir}/imu0.csv'", 1,
       {"{dir}/far.csv:", "pixel (-5, 40) is outside the 752x480 image", "more than the 1 px margin"}, {}},
      // A ground truth that cannot be compared: exit 1 naming it, nothing written.
      {"visual_inertial_odometry", base + "--groundtruth '{dir}/late_gt.csv' " + out, 1,
       {"{dir}/late_gt.csv: 0 poses within 10 ms of an estimated frame"}, {"associate"}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", base + "--groundtruth '{dir}/one_gt.csv' " + out, 1,
       {"{dir}/one_gt.csv: 1 poses within 10 ms", "at least 3"}, {"associate", "umeyama"}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", base + "--groundtruth '{dir}/two_gt.csv' " + out, 1,
       {"{dir}/two_gt.csv: 2 poses within 10 ms"}, {"umeyama"}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", base + "--groundtruth '{dir}/still_gt.csv' " + out, 1,
       {"{dir}/still_gt.csv: the ", "cannot be aligned"}, {"umeyama"}, {"{dir}/o.tum"}},
      // Starts: a mode that does not exist, a ground-truth start without the
      // ground truth or its velocity, a start in motion on a still camera.
      {"visual_inertial_odometry", base + "--init sideways", 2,
       {"--init: expected auto, static, dynamic or groundtruth, got 'sideways'"}, {}},
      {"visual_inertial_odometry", base + "--init groundtruth " + out, 2, {"--init groundtruth needs --groundtruth"},
       {}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", base + "--init groundtruth --groundtruth '{dir}/still_gt.csv' " + out, 1,
       {"{dir}/still_gt.csv: --init groundtruth needs the velocity columns"}, {}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", base + "--init dynamic " + out, 1,
       {"no frame was estimated: start in motion: "}, {}, {"{dir}/o.tum"}},
      // The real cause of a run that cannot start: no overlap in time (with
      // the unit when it is the cause), one frame; an IMU that ends early.
      {"visual_inertial_odometry", "--tracks '{dir}/t.csv' --camera '{dir}/cam.yaml' --imu '{dir}/later_imu.csv' " + out,
       1, {"the tracks ({dir}/t.csv, ", ") do not overlap in time"}, {"look like"}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", "--tracks '{dir}/t.csv' --camera '{dir}/cam.yaml' --imu '{dir}/micro_imu.csv' " + out,
       1, {"do not overlap in time (the IMU stamps look like microseconds; both files need nanoseconds)"}, {},
       {"{dir}/o.tum"}},
      {"visual_inertial_odometry", "--tracks '{dir}/one_frame.csv' --camera '{dir}/cam.yaml' --imu '{dir}/imu0.csv' " + out,
       1, {"{dir}/one_frame.csv: 1 frame(s); the estimator needs at least 2"}, {}, {"{dir}/o.tum"}},
      {"visual_inertial_odometry", "--tracks '{dir}/t.csv' --camera '{dir}/cam.yaml' --imu '{dir}/short_imu.csv' --json", 0,
       {"warning: the IMU ends at ", " s: 30 frame(s) after it not estimated"}, {}},
      // A pixel 0.01 px outside the image is dropped, counted and warned
      // about; a still camera triangulates nothing: a warning too.
      {"visual_inertial_odometry", "--tracks '{dir}/edge.csv' --camera '{dir}/cam.yaml' --imu '{dir}/imu0.csv' --json", 0,
       {"warning: {dir}/edge.csv: dropped 1 observations outside the 752x480 image by up to 0.01 px (first on line 1202",
        "warning: no estimated frame used a visual feature"},
       {}},
  };
  for (const Probe& p : probes) check(p, dir);
  CHECK(posefuse::test::slurp(dir.path() / "t.csv") == tracks);
  CHECK(posefuse::test::slurp(dir.path() / "imu0.csv") == imu);
  CHECK(posefuse::test::slurp(dir.path() / "cam.yaml") == kCamera);
}

TEST_CASE("simulate_tracks keeps the contract on bad and unusual input", "[vio][cli][contract]") {
  const TempDir dir("sim-contract");
  (void)dir.write("cam.yaml", kCamera);
  std::string narrow = kCamera;
  narrow.replace(narrow.find("458.654, 457.296"), 16, "1e5, 1e5");
  (void)dir.write("narrow.yaml", narrow);
  std::string huge = kCamera;
  huge.replace(huge.find("458.654, 457.296"), 16, "1e300, 1e300");
  (void)dir.write("huge_focal.yaml", huge);
  (void)dir.write("gt.csv", groundtruth(kT0, 40));
  const std::string gt = "--groundtruth '{dir}/gt.csv' --camera '{dir}/cam.yaml' ";
  const std::string out = "--out '{dir}/t.csv' ";
  const std::vector<Probe> probes = {
      {"simulate_tracks", gt + "--out '{dir}/./gt.csv'", 2, {"--out {dir}/./gt.csv is the input of --groundtruth"}, {}},
      {"simulate_tracks", gt + "--out '{dir}/cam.yaml'", 2, {"--out {dir}/cam.yaml is the input of --camera"}, {}},
      {"simulate_tracks", out + "--groundtruth-out '{dir}/g.csv' --imu-out '{dir}/./g.csv'", 2,
       {"--groundtruth-out {dir}/g.csv and --imu-out {dir}/./g.csv name the same file"}, {}, {"{dir}/g.csv"}},
      {"simulate_tracks", out + "--rate 2e6", 2, {"--rate: expected a number from 0.1 to 1000"}, {"frame_stamps"}},
      {"simulate_tracks", out + "--noise-px 1e6", 2, {"--noise-px: expected a number from 0 to 20"}, {}},
      {"simulate_tracks", out + "--room-margin 1e6", 2, {"--room-margin: expected a number"}, {}},
      {"simulate_tracks", out + "--duration 1e300", 2, {"--duration: expected a number from 0.1 to 3600"}, {}},
      {"simulate_tracks", out + "--max-pose-gap 1e300", 2, {"--max-pose-gap: expected a number"}, {}},
      {"simulate_tracks", out + "--wall-density 0 --free-points 0", 2, {"leave the room without landmarks"},
       {"TrackSimConfig"}},
      // Sizes estimated before anything is allocated.
      {"simulate_tracks", out + "--wall-density 1000 --room-margin 100", 2,
       {"--wall-density 1000", "--room-margin", "landmarks, more than the 1e+07 one run may hold"}, {}, {"{dir}/t.csv"}},
      {"simulate_tracks", out + "--duration 3600 --rate 1000", 2,
       {"--rate 1000 Hz over --duration 3600 s gives 3.6e+06 frames", "5.4e+08 observations"}, {}},
      // A camera that can see nothing is the camera file's fault.
      {"simulate_tracks", "--groundtruth '{dir}/gt.csv' --camera '{dir}/huge_focal.yaml' " + out, 1,
       {"{dir}/huge_focal.yaml: the camera is not usable: focal lengths"}, {"PinholeRadtan"}, {"{dir}/t.csv"}},
      {"simulate_tracks", "--groundtruth '{dir}/gt.csv' --camera '{dir}/narrow.yaml' --free-points 0 " + out, 1,
       {"the camera saw no landmark in any of the 40 frames", "nothing was written"}, {}, {"{dir}/t.csv"}},
  };
  for (const Probe& p : probes) check(p, dir);
}

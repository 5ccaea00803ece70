// visual_inertial_odometry: the sliding-window visual-inertial estimator
// (posefuse/vio/estimator.hpp) on feature tracks (t_ns,feature_id,u,v csv),
// a EuRoC camera sensor.yaml and a EuRoC imu0.csv; writes the trajectory
// (TUM) and, with a ground truth, prints the errors.
//
// Semi-real V1_01_easy (real IMU and motion, tracks from simulate_tracks):
//
//   simulate_tracks --groundtruth V1_01_easy/groundtruth_20hz.csv
//                   --camera V1_01_easy/cam0_sensor.yaml --out cam0_tracks.csv
//   visual_inertial_odometry --tracks cam0_tracks.csv --camera V1_01_easy/cam0_sensor.yaml
//                   --imu V1_01_easy/imu0.csv --groundtruth V1_01_easy/groundtruth_20hz.csv
//                   --out traj.tum
//
// --init auto (default) starts at rest when the IMU is at rest before a
// frame, otherwise in motion (structure from motion on frames with parallax
// and the visual-inertial alignment); static and dynamic force one of them;
// groundtruth starts from the --groundtruth file's state at the first frame
// (17 columns: velocity and biases). Frames before the start are
// "initializing" and not written. A frame whose state fails a check (too few
// tracked features for too long, a bias or pose jump beyond its bound, a
// speed above --max-speed) is "failed": a warning line names the cause and
// the estimator starts again; the written trajectory has a gap there and the
// summary counts the starts.
//
// Loop closure (posefuse/vio/loop_closure.hpp): --loops FILE reads loop
// candidates (t_ns_query,t_ns_match csv); --loops recurring-ids derives them
// from feature ids that recur in the tracks, an oracle that only simulated
// tracks (simulate_tracks --recurring-ids) can give. Each keyframe leaving
// the estimator's window joins a 4-DoF pose graph; each candidate is
// verified (PnP + RANSAC) and accepted or refused with a reason; an accepted
// one re-optimises the graph, and the drift correction it gives moves every
// later output pose. --out then holds the corrected trajectory,
// --out-odometry the estimator's own; every change of the correction is
// printed with its stamp and the jump it makes (m, deg), and with a ground
// truth the APE of both. --save-map writes the keyframe graph as a map,
// --load-map localises the sequence in a saved map (candidates against the
// map's keyframes: by recurring ids, or from the --loops file).
// With --groundtruth (EuRoC csv; 17 columns give velocity and biases) it
// prints APE of the position after position + yaw alignment and after SE(3)
// alignment, RPE over 10 m, the final yaw error, the bias errors, and the
// processing time per frame. Every written pose is finite; each frame has a
// status (tracking, not enough features, degenerate, reset), counted in the
// summary. A progress line goes to stderr when it is a terminal.
//
// Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <apps/cli.hpp>
#include <apps/imu_flags.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/feature_tracks.hpp>
#include <posefuse/io/imu_gaps.hpp>
#include <posefuse/io/loop_candidates.hpp>
#include <posefuse/io/tum.hpp>
#include <posefuse/vio/estimator.hpp>
#include <posefuse/vio/loop_closure.hpp>
#include <posefuse/vio/vio_map.hpp>

namespace apps = posefuse::apps;

namespace {

// Defaults are the library's (posefuse::VioEstimatorOptions and its parts),
// except where a program needs its own (the IMU gap, the image margin).
struct Options {
  std::filesystem::path tracks, camera, imu;
  std::optional<std::filesystem::path> groundtruth, out, out_odometry, save_map, load_map;
  std::optional<std::string> loops;  // a file, or "recurring-ids"
  double max_imu_gap_ms = 50.0;
  double pixel_sigma_px = posefuse::SlidingWindowOptions{}.pixel_sigma_px;
  int window = posefuse::SlidingWindowOptions{}.window_size;
  int iterations = posefuse::WindowSolveOptions{}.max_iterations;
  std::string loss = "cauchy";
  bool estimate_extrinsic = false;
  bool no_fej = false;
  bool no_reuse = false;
  double min_parallax_px = posefuse::SlidingWindowOptions{}.min_parallax_px;
  double min_keyframe_interval_s = posefuse::SlidingWindowOptions{}.min_keyframe_interval_s;
  double outlier_px = posefuse::SlidingWindowOptions{}.outlier_threshold_px;
  std::size_t max_frames = 0;
  posefuse::ImuNoise noise;  // the EuRoC IMU's datasheet figures (imu0 sensor.yaml)
  posefuse::ImuReadOptions imu_bounds;
  double outside_margin_px = 1.0;
  bool json = false;
  std::string init = "auto";
  double max_speed_mps = posefuse::VioEstimatorOptions{}.max_speed_mps;
};

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  std::optional<std::filesystem::path> tracks, camera, imu;
  apps::Parser cli(cmd.program, "--tracks FILE --camera FILE --imu FILE [options]",
                   "Sliding-window visual-inertial odometry on feature tracks.");
  cli.input({.name = "--tracks", .value = "FILE", .help = "feature tracks t_ns,feature_id,u,v (required)"}, tracks);
  cli.input({.name = "--camera", .value = "FILE", .help = "EuRoC camera sensor.yaml (required)"}, camera);
  cli.input({.name = "--imu", .value = "FILE", .help = "EuRoC imu0.csv (required)"}, imu);
  cli.input({.name = "--groundtruth", .value = "FILE", .help = "EuRoC ground truth csv: print the errors"},
           o.groundtruth);
  cli.output({.name = "--out", .value = "FILE", .help = "write the trajectory (TUM; loop-corrected with --loops)"},
           o.out);
  cli.output({.name = "--out-odometry", .value = "FILE", .help = "write the odometry without loop correction (TUM)"},
           o.out_odometry);
  cli.custom({.name = "--loops", .value = "FILE|recurring-ids",
              .help = "loop candidates: a t_ns_query,t_ns_match csv, or from recurring feature ids\n"
                      "(an oracle: simulated tracks with --recurring-ids only)",
              .role = apps::PathRole::kInput,
              .keywords = {"recurring-ids"}},
             [&](std::string_view v) {
               if (v.empty()) throw apps::usage_error("expected a file or recurring-ids, got ''");
               o.loops = std::string(v);
             });
  cli.output({.name = "--save-map", .value = "FILE", .help = "write the keyframe graph as a map (needs --loops)"},
           o.save_map);
  cli.input({.name = "--load-map", .value = "FILE", .help = "localise in a saved map (needs --loops)"}, o.load_map);
  cli.real_in({.name = "--max-imu-gap-ms", .value = "MS", .help = "longest accepted IMU gap", .unit = "ms"},
              o.max_imu_gap_ms, 0.01, 1e4);
  cli.real_in({.name = "--pixel-sigma", .value = "PX", .help = "pixel noise of the tracks (1 sigma)", .unit = "px"},
              o.pixel_sigma_px, 0.01, 100.0);
  cli.integer({.name = "--window", .value = "N",
               .help = "keyframes in the window, 2 to 40; the solve's time per frame\n"
                       "grows faster than N (at 40, far slower than real time on EuRoC)",
               .default_text = "10"},
              o.window, 2, 40);
  cli.integer({.name = "--iterations", .value = "N", .help = "LM iterations per frame (cap)",
               .default_text = "10"},
              o.iterations, 1, 1000);
  cli.custom({.name = "--loss", .value = "cauchy|huber|none", .help = "robust loss of the reprojection",
              .default_text = "cauchy"},
             [&](std::string_view v) {
               if (v != "cauchy" && v != "huber" && v != "none")
                 throw apps::usage_error("expected cauchy, huber or none, got '" + std::string(v) + "'");
               o.loss = std::string(v);
             });
  cli.custom({.name = "--init", .value = "auto|static|dynamic|groundtruth",
              .help = "how the estimator starts (groundtruth: from the --groundtruth file's state)",
              .default_text = "auto"},
             [&](std::string_view v) {
               if (v != "auto" && v != "static" && v != "dynamic" && v != "groundtruth")
                 throw apps::usage_error("expected auto, static, dynamic or groundtruth, got '" + std::string(v) +
                                         "'");
               o.init = std::string(v);
             });
  cli.real_in({.name = "--max-speed", .value = "MPS",
               .help = "a faster estimate is a failure (the estimator starts again)", .unit = "m/s"},
              o.max_speed_mps, 0.1, 1000.0);
  cli.flag({.name = "--estimate-extrinsic", .help = "estimate the camera-IMU extrinsic too"},
           o.estimate_extrinsic);
  cli.flag({.name = "--no-first-estimate-jacobians",
            .help = "linearise every factor at the current estimate (VINS-Mono's way)"},
           o.no_fej);
  cli.flag({.name = "--no-track-reuse",
            .help = "do not re-anchor the tracks of a marginalised keyframe's features"},
           o.no_reuse);
  cli.real_in({.name = "--min-parallax", .value = "PX", .help = "keyframe parallax", .unit = "px"},
              o.min_parallax_px, 0.1, 1000.0);
  cli.real_in({.name = "--min-keyframe-interval", .value = "S",
               .help = "keyframe: at least this long after the one before", .unit = "s"},
              o.min_keyframe_interval_s, 0.0, 10.0);
  cli.real_in({.name = "--outlier-px", .value = "PX", .help = "reprojection error of an outlier (>= --pixel-sigma)",
               .unit = "px"},
              o.outlier_px, 0.01, 1000.0);
  cli.real_in({.name = "--outside-margin", .value = "PX",
               .help = "observations outside the image by at most this much are\n"
                       "dropped (counted, with a warning); farther out they are refused",
               .unit = "px"},
              o.outside_margin_px, 0.0, 10.0);
  cli.custom({.name = "--imu-noise", .value = "NA,NG,WA,WG",
              .help = "accelerometer and gyroscope noise densities, then their random walks\n"
                      "(m/s^2/sqrt(Hz), rad/s/sqrt(Hz), m/s^3/sqrt(Hz), rad/s^2/sqrt(Hz))",
              .default_text = "2e-3,1.6968e-4,3e-3,1.9393e-5"},
             // A density this small or large makes the IMU's information
             // overflow or vanish: it can only fail.
             [&](std::string_view v) { o.noise = apps::parse_imu_noise(v, 1e-8); });
  cli.integer({.name = "--max-frames", .value = "N", .help = "stop after N frames (0: all)"}, o.max_frames,
              std::size_t{0});
  apps::declare_imu_bounds(cli, o.imu_bounds);
  cli.flag({.name = "--json", .help = "print one JSON object instead of the table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (!tracks || !camera || !imu) throw apps::usage_error("--tracks, --camera and --imu are required");
  if (o.outlier_px < o.pixel_sigma_px)
    throw apps::usage_error("--outlier-px " + apps::num(o.outlier_px) + " is below --pixel-sigma " +
                            apps::num(o.pixel_sigma_px) + ": most true observations would be rejected");
  if ((o.save_map || o.load_map) && !o.loops) throw apps::usage_error("--save-map and --load-map need --loops");
  if (o.init == "groundtruth" && !o.groundtruth) throw apps::usage_error("--init groundtruth needs --groundtruth");
  o.tracks = *tracks;
  o.camera = *camera;
  o.imu = *imu;
  return o;
}

struct Summary {
  std::map<std::string, int> statuses;
  std::size_t frames = 0, written = 0;
  double ms_mean = 0, ms_max = 0, duration_s = 0, processing_s = 0;
  bool have_gt = false;
  std::size_t matched = 0;
  posefuse::Statistics ape_posyaw, ape_se3, rpe10;
  bool have_rpe = false;
  double final_yaw_error_deg = 0, max_yaw_error_deg = 0;
  bool have_bias = false;
  double gyro_bias_rms = 0, gyro_bias_final = 0, accel_bias_rms = 0, accel_bias_final = 0;
  // Loop closure.
  bool loops = false;
  std::size_t candidates = 0, keyframes = 0, map_keyframes = 0;
  std::map<std::string, int> loop_statuses;
  std::map<std::string, std::string> loop_reason;  // one example per refusal status
  struct Jump {
    double t_s, m, deg;
  };
  std::vector<Jump> jumps;
  posefuse::Statistics ape_odometry, ape_keyframes;
  bool have_keyframe_ape = false;
  std::size_t dropped = 0;   // observations outside the image, dropped
  bool vision = true;        // some estimated frame used a visual feature
  bool yaw_defined = true;   // the ground truth moves enough to define the alignment's yaw
  // Starts and failures.
  int starts = 0;
  struct Failure {
    double t_s;
    std::string why;
  };
  std::vector<Failure> failures;
  struct Start {
    double t_s;
    std::string how;
    double gravity_error_deg = std::numeric_limits<double>::quiet_NaN();  // with a ground truth
    double scale_error = std::numeric_limits<double>::quiet_NaN();        // with a ground truth, in motion
    bool anchored = false;  // in the world frame of the output so far; otherwise a new one begins
  };
  std::vector<Start> start_details;
  std::size_t before_imu = 0, after_imu = 0;  // frames outside the IMU's span, not estimated
};

std::string span_text(std::int64_t a_ns, std::int64_t b_ns) {
  return apps::num(posefuse::seconds_from_ns(a_ns)) + " to " + apps::num(posefuse::seconds_from_ns(b_ns)) + " s";
}

// Refuses tracks and an IMU that cannot be run together, naming the cause:
// too few frames, no overlap in time (with a hint when the stamps differ by
// a power of 1000: another unit).
void check_time_overlap(const Options& o, const posefuse::FeatureTracks& tracks,
                        const std::vector<posefuse::ImuSample>& imu) {
  if (tracks.size() < 2)
    throw apps::data_error(o.tracks.string() + ": " + std::to_string(tracks.size()) +
                           " frame(s); the estimator needs at least 2");
  const std::int64_t t0 = tracks.front().t_ns, t1 = tracks.back().t_ns;
  const std::int64_t i0 = imu.front().t_ns, i1 = imu.back().t_ns;
  if (t1 >= i0 && t0 <= i1) return;
  std::string hint;
  const double ratio = double(t0) / double(i0);
  for (const auto& [r, unit] : {std::pair{1e3, "microseconds"}, std::pair{1e6, "milliseconds"},
                                std::pair{1e9, "seconds"}}) {
    if (ratio > 0.5 * r && ratio < 2 * r) hint = " (the IMU stamps look like " + std::string(unit) + "; both files need nanoseconds)";
    if (ratio < 2 / r && ratio > 0.5 / r)
      hint = " (the track stamps look like " + std::string(unit) + "; both files need nanoseconds)";
  }
  throw apps::data_error("the tracks (" + o.tracks.string() + ", " + span_text(t0, t1) + ") and the IMU (" +
                         o.imu.string() + ", " + span_text(i0, i1) + ") do not overlap in time" + hint);
}

// The ground-truth row within 10 ms of `t_ns`, if any.
std::optional<std::size_t> groundtruth_row(const posefuse::EurocGroundTruth& gt, std::int64_t t_ns) {
  const auto it = std::lower_bound(gt.t_ns.begin(), gt.t_ns.end(), t_ns);
  std::optional<std::size_t> best;
  for (auto c : {it, it == gt.t_ns.begin() ? it : it - 1}) {
    if (c == gt.t_ns.end() || std::llabs(*c - t_ns) > 10'000'000) continue;
    if (!best || std::llabs(*c - t_ns) < std::llabs(gt.t_ns[*best] - t_ns)) best = std::size_t(c - gt.t_ns.begin());
  }
  return best;
}

// How good a start was, against the ground truth: the angle between the
// estimated and the true gravity direction in the newest frame's body, and
// the scale of the similarity that best maps the start window's positions
// onto the true ones (Umeyama) minus one, when they span at least 5 cm.
void grade_start(const posefuse::EurocGroundTruth& gt, const posefuse::VioWindow& w, Summary::Start& s) {
  const posefuse::VioFrame& f = w.frames.back();
  if (const auto r = groundtruth_row(gt, f.t_ns)) {
    const Eigen::Vector3d up_est = f.x.R.matrix().transpose() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d up_ref = gt.trajectory.poses[*r].rotation().transpose() * Eigen::Vector3d::UnitZ();
    s.gravity_error_deg = std::atan2(up_est.cross(up_ref).norm(), up_est.dot(up_ref)) * 180.0 / std::numbers::pi;
  }
  std::vector<Eigen::Vector3d> est, ref;
  for (const posefuse::VioFrame& x : w.frames) {
    const auto r = groundtruth_row(gt, x.t_ns);
    if (!r) return;
    est.push_back(x.x.p);
    ref.push_back(gt.trajectory.poses[*r].translation());
  }
  double extent = 0;
  for (const Eigen::Vector3d& p : ref) extent = std::max(extent, (p - ref.front()).norm());
  if (est.size() < 3 || extent < 0.05) return;
  try {
    s.scale_error = posefuse::umeyama_alignment(est, ref, /*with_scale=*/true).scale - 1.0;
  } catch (const posefuse::invalid_argument&) {
    // collinear: no scale
  }
}

// The ground truth's state at `t_ns` (the row within 10 ms), for --init groundtruth.
posefuse::ImuState groundtruth_state(const std::filesystem::path& file, const posefuse::EurocGroundTruth& gt,
                                     std::int64_t t_ns) {
  if (!gt.velocity)
    throw posefuse::io_error(file, "--init groundtruth needs the velocity columns (the 17-column EuRoC ground truth)");
  std::size_t best = 0;
  for (std::size_t i = 1; i < gt.t_ns.size(); ++i)
    if (std::llabs(gt.t_ns[i] - t_ns) < std::llabs(gt.t_ns[best] - t_ns)) best = i;
  if (gt.t_ns.empty() || std::llabs(gt.t_ns[best] - t_ns) > 10'000'000)
    throw posefuse::io_error(file, "no state within 10 ms of the first frame (" +
                                       apps::num(posefuse::seconds_from_ns(t_ns)) + " s) for --init groundtruth");
  posefuse::ImuState x;
  const Eigen::Isometry3d& T = gt.trajectory.poses[best];
  x.p = T.translation();
  x.R = posefuse::SO3d(Eigen::Quaterniond(T.rotation()).normalized());
  x.v = (*gt.velocity)[best];
  if (gt.gyro_bias) x.bias.gyro = (*gt.gyro_bias)[best];
  if (gt.accel_bias) x.bias.accel = (*gt.accel_bias)[best];
  return x;
}

double yaw_error_deg(const Eigen::Matrix3d& R_ref, const Eigen::Matrix3d& R_est) {
  const Eigen::Matrix3d E = R_ref * R_est.transpose();  // world-frame error
  return std::atan2(E(1, 0) - E(0, 1), E(0, 0) + E(1, 1)) * 180.0 / std::numbers::pi;
}

// The ground truth's poses within 10 ms of the estimated frames; at least 3.
// @throws posefuse::io_error naming the ground-truth file otherwise
posefuse::Association associate_groundtruth(const std::filesystem::path& file, const posefuse::Trajectory& gt,
                                            const posefuse::Trajectory& traj) {
  const auto span = [](const posefuse::Trajectory& t) {
    return posefuse::detail::traj_io::format_number(t.t_s.front()) + " to " +
           posefuse::detail::traj_io::format_number(t.t_s.back()) + " s";
  };
  posefuse::Association a;
  try {
    a = posefuse::associate(gt.t_s, traj.t_s, 0.01, 0.0);
  } catch (const posefuse::invalid_argument&) {
    a = {};
  }
  if (a.size() < 3)
    throw posefuse::io_error(file, std::to_string(a.size()) + " poses within 10 ms of an estimated frame (the ground "
                                   "truth spans " + span(gt) + ", the estimate " + span(traj) +
                                   "); the errors need at least 3");
  return a;
}

// APE of the positions after `alignment`; a ground truth whose matched
// positions cannot be aligned (all on one line for SE(3)) is named.
posefuse::MetricResult aligned_ape(const std::filesystem::path& file, const posefuse::Trajectory& ref,
                                   const posefuse::Trajectory& est, posefuse::Alignment alignment) {
  try {
    return posefuse::ape(ref, est, posefuse::PoseRelation::kTranslation, alignment);
  } catch (const posefuse::invalid_argument&) {
    throw posefuse::io_error(file, "the " + std::to_string(ref.size()) +
                                       " matched ground-truth positions cannot be aligned with the estimate (" +
                                       (alignment == posefuse::Alignment::kSE3 ? "SE(3)" : "position + yaw") +
                                       " needs positions that do not all lie on one point or line)");
  }
}

// APE position+yaw of `traj` against the ground truth (associated within 10 ms).
posefuse::Statistics ape_posyaw(const std::filesystem::path& file, const posefuse::EurocGroundTruth& gt,
                                const posefuse::Trajectory& traj) {
  const posefuse::Association a = associate_groundtruth(file, gt.trajectory, traj);
  return aligned_ape(file, posefuse::select(gt.trajectory, a.ref_ids), posefuse::select(traj, a.est_ids),
                     posefuse::Alignment::kPosYaw)
      .stats;
}

// Below this horizontal extent (m, largest distance of a position from the
// mean in x-y) the yaw of a position + yaw alignment is not defined.
constexpr double kMinYawExtentM = 0.1;

double horizontal_extent(const posefuse::Trajectory& t) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Isometry3d& T : t.poses) mean += T.translation().head<2>();
  mean /= double(t.size());
  double r = 0;
  for (const Eigen::Isometry3d& T : t.poses) r = std::max(r, (T.translation().head<2>() - mean).norm());
  return r;
}

// The loop-closure side of a run: the database, the candidates still to
// try, the oracle against a loaded map.
class Loops {
 public:
  Loops(const Options& o, const posefuse::FeatureTracks& tracks, Summary& s) : s_(s) {
    oracle_ = *o.loops == "recurring-ids";
    if (oracle_) {
      candidates_ = posefuse::loop_candidates_from_recurring_ids(tracks);
    } else {
      candidates_ = posefuse::read_loop_candidates(*o.loops);
    }
    if (o.load_map) {
      const posefuse::VioMap m = posefuse::load_vio_map(*o.load_map);
      s_.map_keyframes = m.keyframes.size();
      (void)lc_.add_map(m, /*fixed=*/true);
      have_map_ = true;
    }
  }

  // A keyframe left the window: add it, then try the candidates it settles.
  /// The next keyframe begins a new sequence (a start in a new world frame).
  void start_sequence() { lc_.start_sequence(); }

  void add_keyframe(const posefuse::KeyframeRecord& r) {
    const std::int64_t id = lc_.add_keyframe(r);
    ++s_.keyframes;
    const auto tol = std::int64_t(lc_options_.stamp_tolerance_s * 1e9);
    while (next_ < candidates_.size() && candidates_[next_].t_query_ns + tol <= r.t_ns) {
      ++s_.candidates;
      record(lc_.add_loop(candidates_[next_++]));
    }
    // Against a loaded map, the oracle looks for the map keyframe sharing
    // the most ids, once a second until the sequence is localised, then
    // every 5 s.
    if (have_map_ && oracle_ && r.t_ns - last_map_try_ >= (localised_ ? 5'000'000'000 : 1'000'000'000)) {
      last_map_try_ = r.t_ns;
      if (const auto m = lc_.shared_id_match(id, 30)) {
        ++s_.candidates;
        const posefuse::LoopResult x = lc_.add_loop_between(id, m->match_id);
        localised_ = localised_ || x.status == posefuse::LoopStatus::kAccepted;
        record(x);
      }
    }
  }

  // The candidates left whose query is not after the last frame processed
  // (no output pose follows them; they still shape the saved map).
  void finish(std::int64_t last_frame_ns) {
    for (; next_ < candidates_.size() && candidates_[next_].t_query_ns <= last_frame_ns; ++next_) {
      ++s_.candidates;
      record(lc_.add_loop(candidates_[next_]));
    }
  }

  // The correction of the live sequence; a change since the last call is a jump of `T`.
  posefuse::SE3d correct(const posefuse::SE3d& T, double t_s) {
    const posefuse::DriftCorrection c = lc_.correction();
    const posefuse::SE3d out = c.apply(T);
    if (have_last_ && (c.yaw != last_.yaw || c.t != last_.t)) {
      const posefuse::SE3d before = last_.apply(T);
      const double m = (out.translation() - before.translation()).norm();
      const double deg = posefuse::wrap_angle(c.yaw - last_.yaw) * 180.0 / std::numbers::pi;
      s_.jumps.push_back(Summary::Jump{t_s, m, deg});
    }
    last_ = c;
    have_last_ = true;
    return out;
  }

  [[nodiscard]] const posefuse::LoopClosure& closure() const { return lc_; }

 private:
  void record(const posefuse::LoopResult& r) {
    const std::string name = posefuse::to_string(r.status);
    ++s_.loop_statuses[name];
    if (r.status != posefuse::LoopStatus::kAccepted && !s_.loop_reason.count(name)) s_.loop_reason[name] = r.reason;
  }

  Summary& s_;
  posefuse::LoopClosureOptions lc_options_;
  posefuse::LoopClosure lc_{lc_options_};
  std::vector<posefuse::LoopCandidate> candidates_;
  std::size_t next_ = 0;
  bool oracle_ = false, have_map_ = false, localised_ = false;
  std::int64_t last_map_try_ = std::numeric_limits<std::int64_t>::min() / 2;
  posefuse::DriftCorrection last_;
  bool have_last_ = false;
};

int run(const Options& o, const std::string& program) {
  apps::TerminalProgress progress(program);
  progress.stage("reading " + o.tracks.string());
  const posefuse::PinholeRadtan cam = posefuse::read_euroc_camera(o.camera);
  const posefuse::FeatureTrackRead track_read = posefuse::read_feature_tracks_counted(
      o.tracks, posefuse::FeatureTrackReadOptions{cam.width, cam.height, o.outside_margin_px});
  const posefuse::FeatureTracks& tracks = track_read.tracks;
  progress.clear();
  if (track_read.dropped > 0)
    std::fprintf(stderr,
                 "warning: %s: dropped %zu observations outside the %dx%d image by up to %s px (first on line "
                 "%zu; --outside-margin %s px)\n",
                 o.tracks.string().c_str(), track_read.dropped, cam.width, cam.height,
                 apps::num(track_read.worst_outside_px).c_str(), track_read.first_dropped_line,
                 apps::num(o.outside_margin_px).c_str());
  const std::vector<posefuse::ImuSample> imu = posefuse::read_euroc_imu_checked(
      o.imu, std::int64_t(std::llround(o.max_imu_gap_ms * 1e6)), o.imu_bounds);
  std::optional<posefuse::EurocGroundTruth> gt;
  if (o.groundtruth) gt = posefuse::read_euroc_groundtruth(*o.groundtruth);
  if (imu.empty()) throw apps::data_error(o.imu.string() + ": no IMU sample");
  check_time_overlap(o, tracks, imu);

  posefuse::VioEstimatorOptions eo;
  eo.window.window_size = o.window;
  eo.window.pixel_sigma_px = o.pixel_sigma_px;
  eo.window.solve.max_iterations = o.iterations;
  eo.window.solve.loss.kind = o.loss == "cauchy"  ? posefuse::ReprojectionLoss::Kind::kCauchy
                              : o.loss == "huber" ? posefuse::ReprojectionLoss::Kind::kHuber
                                                  : posefuse::ReprojectionLoss::Kind::kNone;
  eo.noise = o.noise;
  eo.window.solve.first_estimate_jacobians = !o.no_fej;
  eo.window.reuse_marginalised_tracks = !o.no_reuse;
  eo.window.min_parallax_px = o.min_parallax_px;
  eo.window.min_keyframe_interval_s = o.min_keyframe_interval_s;
  eo.window.outlier_threshold_px = o.outlier_px;
  eo.preintegration.max_gap_ns = std::int64_t(std::llround(o.max_imu_gap_ms * 1e6));
  eo.init = o.init == "static" ? posefuse::VioInit::kStatic
            : o.init == "dynamic" ? posefuse::VioInit::kDynamic
                                  : posefuse::VioInit::kAuto;
  eo.max_speed_mps = o.max_speed_mps;
  posefuse::VioEstimator est(cam, eo);
  if (o.estimate_extrinsic) est.set_estimate_extrinsic(true);
  if (o.init == "groundtruth") {
    // The first frame with IMU samples before it.
    std::size_t f0 = 0;
    while (f0 < tracks.size() && tracks[f0].t_ns < imu.front().t_ns) ++f0;
    est.set_initial_state(groundtruth_state(*o.groundtruth, *gt, tracks[std::min(f0, tracks.size() - 1)].t_ns));
  }

  Summary s;
  s.dropped = track_read.dropped;
  std::optional<Loops> loops;
  if (o.loops) {
    loops.emplace(o, tracks, s);
    s.loops = true;
  }
  posefuse::Trajectory traj, odometry;
  std::vector<posefuse::ImuState> states;
  std::size_t k = 0;
  double total_ms = 0;
  long long visual_features = 0;  // triangulated features over the estimated frames
  std::string waiting;            // why the last frame was still initializing
  const std::size_t last = o.max_frames > 0 ? std::min(o.max_frames, tracks.size()) : tracks.size();
  for (std::size_t f = 0; f < last; ++f) {
    const posefuse::TrackFrame& frame = tracks[f];
    if (frame.t_ns < imu.front().t_ns) {  // before the IMU: nothing to start from
      ++s.before_imu;
      continue;
    }
    if (imu.back().t_ns < frame.t_ns) {  // no IMU after this frame
      s.after_imu = last - f;
      break;
    }
    // IMU up to the first sample at or after the frame (the pre-integration interpolates).
    while (k < imu.size() && (k == 0 || imu[k - 1].t_ns < frame.t_ns)) est.add_imu(imu[k++]);
    const auto t0 = std::chrono::steady_clock::now();
    const posefuse::VioFrameResult r = est.add_frame(frame);
    // A start that is not anchored begins a new world frame: no sequential
    // edge may join its keyframes to the earlier ones.
    if (loops && r.started && !r.anchored) loops->start_sequence();
    if (loops && r.keyframe) loops->add_keyframe(*r.keyframe);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++s.frames;
    ++s.statuses[posefuse::to_string(r.status)];
    if (r.started) {
      ++s.starts;
      Summary::Start st{posefuse::seconds_from_ns(frame.t_ns), r.message};
      st.anchored = r.anchored;
      if (gt) grade_start(*gt, est.window(), st);
      s.start_details.push_back(st);
    }
    if (r.status == posefuse::VioStatus::kFailed) {
      const double t_s = posefuse::seconds_from_ns(frame.t_ns);
      s.failures.push_back(Summary::Failure{t_s, r.message});
      progress.clear();
      std::fprintf(stderr, "warning: t = %.3f s: the estimator failed (%s); it starts again\n", t_s,
                   r.message.c_str());
      continue;
    }
    if (r.status == posefuse::VioStatus::kInitializing) {
      waiting = r.message;
      continue;
    }
    total_ms += ms;
    s.ms_max = std::max(s.ms_max, ms);
    visual_features += r.features;
    const posefuse::SE3d T(r.state.p, r.state.R);
    if (!T.translation().allFinite() || !T.so3().quaternion().coeffs().allFinite())
      throw apps::data_error("a non-finite state at t = " + std::to_string(frame.t_ns) + " ns");
    const double t_s = posefuse::seconds_from_ns(frame.t_ns);
    odometry.push_back(t_s, T.isometry());
    traj.push_back(t_s, (loops ? loops->correct(T, t_s) : T).isometry());
    states.push_back(r.state);
    progress.update([&] {
      return "frame " + std::to_string(f + 1) + "/" + std::to_string(tracks.size()) + "  (" +
             posefuse::to_string(r.status) + ")";
    });
  }
  progress.clear();
  std::int64_t last_frame_ns = 0;
  if (s.frames > 0) last_frame_ns = tracks[s.before_imu + s.frames - 1].t_ns;
  if (loops) loops->finish(last_frame_ns);
  s.written = traj.size();
  if (s.before_imu > 0)
    std::fprintf(stderr, "warning: %zu frame(s) before the first IMU sample (%s s) not estimated\n", s.before_imu,
                 apps::num(posefuse::seconds_from_ns(imu.front().t_ns)).c_str());
  if (s.after_imu > 0)
    std::fprintf(stderr, "warning: the IMU ends at %s s: %zu frame(s) after it not estimated\n",
                 apps::num(posefuse::seconds_from_ns(imu.back().t_ns)).c_str(), s.after_imu);
  if (traj.empty())
    throw apps::data_error("no frame was estimated" + (waiting.empty() ? std::string() : ": " + waiting));
  s.ms_mean = total_ms / double(s.written);
  s.processing_s = total_ms * 1e-3;
  s.duration_s = traj.t_s.back() - traj.t_s.front();

  s.vision = visual_features > 0;
  if (!s.vision)
    std::fprintf(stderr,
                 "warning: no estimated frame used a visual feature (none was triangulated or every one was "
                 "rejected): the trajectory is the IMU's alone; check --pixel-sigma, --outlier-px and %s\n",
                 o.tracks.string().c_str());

  // Every figure is computed before any output is written: a ground truth
  // that cannot be compared with the run (no pose in time, fewer than 3)
  // fails the run (exit 1) and writes nothing.
  if (gt) {
    const posefuse::Association a = associate_groundtruth(*o.groundtruth, gt->trajectory, traj);
    s.have_gt = true;
    s.matched = a.size();
    const posefuse::Trajectory ref = posefuse::select(gt->trajectory, a.ref_ids);
    const posefuse::Trajectory es = posefuse::select(traj, a.est_ids);
    const posefuse::MetricResult py = aligned_ape(*o.groundtruth, ref, es, posefuse::Alignment::kPosYaw);
    s.ape_posyaw = py.stats;
    s.ape_se3 = aligned_ape(*o.groundtruth, ref, es, posefuse::Alignment::kSE3).stats;
    // A position + yaw alignment of points that do not move horizontally has
    // no defined yaw: the yaw errors would be arbitrary.
    s.yaw_defined = horizontal_extent(ref) >= kMinYawExtentM;
    if (!s.yaw_defined)
      std::fprintf(stderr,
                   "warning: %s: the matched ground-truth positions stay within %s m horizontally; the "
                   "alignment's yaw is not defined, so no yaw error is given\n",
                   o.groundtruth->string().c_str(), apps::num(kMinYawExtentM).c_str());
    try {
      posefuse::RpeOptions ro;
      ro.delta = 10.0;
      ro.delta_unit = posefuse::DeltaUnit::kMeters;
      ro.alignment = posefuse::Alignment::kPosYaw;
      s.rpe10 = posefuse::rpe(ref, es, ro).stats;
      s.have_rpe = true;
    } catch (const posefuse::invalid_argument&) {
      s.have_rpe = false;  // shorter than 10 m
    }
    for (std::size_t i = 0; i < ref.size(); ++i) {
      const double e = yaw_error_deg(ref.poses[i].linear(), py.alignment.rotation * es.poses[i].linear());
      s.max_yaw_error_deg = std::max(s.max_yaw_error_deg, std::abs(e));
      s.final_yaw_error_deg = e;
    }
    if (gt->gyro_bias && gt->accel_bias) {
      s.have_bias = true;
      double sg = 0, sa = 0;
      for (std::size_t i = 0; i < a.size(); ++i) {
        const posefuse::ImuState& x = states[a.est_ids[i]];
        const double eg = (x.bias.gyro - (*gt->gyro_bias)[a.ref_ids[i]]).norm();
        const double ea = (x.bias.accel - (*gt->accel_bias)[a.ref_ids[i]]).norm();
        sg += eg * eg;
        sa += ea * ea;
        s.gyro_bias_final = eg;
        s.accel_bias_final = ea;
      }
      s.gyro_bias_rms = std::sqrt(sg / double(a.size()));
      s.accel_bias_rms = std::sqrt(sa / double(a.size()));
    }
    if (loops) {
      s.ape_odometry = ape_posyaw(*o.groundtruth, *gt, odometry);
      // The live sequence's keyframes at their final graph poses.
      posefuse::Trajectory kf;
      const posefuse::LoopClosure& lc = loops->closure();
      for (const auto& x : lc.keyframes())
        if (x.sequence == lc.live_sequence())
          kf.push_back(posefuse::seconds_from_ns(x.record.t_ns), lc.corrected_pose(x.id).isometry());
      if (kf.size() >= 3) {
        s.ape_keyframes = ape_posyaw(*o.groundtruth, *gt, kf);
        s.have_keyframe_ape = true;
      }
    }
  }

  apps::OutputFiles files;
  if (o.out) files.add_with(*o.out, [&](const std::filesystem::path& p) { posefuse::write_tum(p, traj); });
  if (o.out_odometry)
    files.add_with(*o.out_odometry, [&](const std::filesystem::path& p) { posefuse::write_tum(p, odometry); });
  if (o.save_map)
    files.add_with(*o.save_map,
                   [&](const std::filesystem::path& p) { posefuse::save_vio_map(p, loops->closure().to_map()); });
  files.commit();

  if (o.json) {
    apps::JsonWriter j(std::cout);
    j.begin_object(apps::JsonWriter::Layout::kBlock);
    j.member("frames", s.frames).member("written", s.written);
    j.member("starts", s.starts).member("frames_before_imu", s.before_imu).member("frames_after_imu", s.after_imu);
    j.key("start_details").begin_array(apps::JsonWriter::Layout::kBlock);
    for (const Summary::Start& x : s.start_details) {
      j.begin_object(apps::JsonWriter::Layout::kInline);
      j.member("t_s", x.t_s).member("how", x.how).member("anchored", x.anchored);
      j.member("gravity_error_deg", x.gravity_error_deg).member("scale_error", x.scale_error);
      j.end_object();
    }
    j.end_array();
    j.key("failures").begin_array(apps::JsonWriter::Layout::kBlock);
    for (const Summary::Failure& x : s.failures) {
      j.begin_object(apps::JsonWriter::Layout::kInline);
      j.member("t_s", x.t_s).member("reason", x.why);
      j.end_object();
    }
    j.end_array();
    j.member("observations_dropped_outside_image", s.dropped).member("vision_used", s.vision);
    j.key("statuses").begin_object(apps::JsonWriter::Layout::kInline);
    for (const auto& [name, n] : s.statuses) j.member(name, n);
    j.end_object();
    j.member("time_per_frame_ms", s.ms_mean).member("time_per_frame_max_ms", s.ms_max);
    j.member("duration_s", s.duration_s).member("processing_s", s.processing_s);
    if (s.loops) {
      j.member("keyframes", s.keyframes).member("map_keyframes", s.map_keyframes);
      j.member("loop_candidates", s.candidates);
      j.key("loop_statuses").begin_object(apps::JsonWriter::Layout::kInline);
      for (const auto& [name, n] : s.loop_statuses) j.member(name, n);
      j.end_object();
      j.key("corrections").begin_array(apps::JsonWriter::Layout::kBlock);
      for (const Summary::Jump& x : s.jumps) {
        j.begin_object(apps::JsonWriter::Layout::kInline);
        j.member("t_s", x.t_s).member("jump_m", x.m).member("jump_deg", x.deg);
        j.end_object();
      }
      j.end_array();
    }
    if (s.have_gt) {
      j.member("matched", s.matched);
      j.member("ape_posyaw_rmse_m", s.ape_posyaw.rmse).member("ape_posyaw_max_m", s.ape_posyaw.max);
      j.member("ape_se3_rmse_m", s.ape_se3.rmse).member("ape_se3_max_m", s.ape_se3.max);
      if (s.loops) {
        j.member("ape_posyaw_odometry_rmse_m", s.ape_odometry.rmse);
        if (s.have_keyframe_ape) j.member("ape_posyaw_keyframes_graph_rmse_m", s.ape_keyframes.rmse);
      }
      if (s.have_rpe) j.member("rpe_10m_rmse_m", s.rpe10.rmse);
      if (s.yaw_defined) {
        j.member("final_yaw_error_deg", s.final_yaw_error_deg).member("max_yaw_error_deg", s.max_yaw_error_deg);
      } else {
        j.key("final_yaw_error_deg").null();
        j.key("max_yaw_error_deg").null();
      }
      if (s.have_bias) {
        j.member("gyro_bias_error_rms_radps", s.gyro_bias_rms).member("gyro_bias_error_final_radps", s.gyro_bias_final);
        j.member("accel_bias_error_rms_mps2", s.accel_bias_rms).member("accel_bias_error_final_mps2", s.accel_bias_final);
      }
    }
    j.end_object().finish();
    return 0;
  }
  std::printf("frames                 %zu (%zu estimated)\n", s.frames, s.written);
  std::printf("starts                 %d", s.starts);
  if (!s.failures.empty()) std::printf(" (%zu failure(s): the trajectory has a gap at each)", s.failures.size());
  std::printf("\n");
  for (const Summary::Start& x : s.start_details) {
    std::printf("  t = %.3f s: %s%s", x.t_s, x.how.c_str(), x.anchored ? ", anchored to the last good state" : "");
    if (std::isfinite(x.gravity_error_deg)) std::printf("; gravity error %.2f deg", x.gravity_error_deg);
    if (std::isfinite(x.scale_error)) std::printf(", scale error %+.1f %%", 100.0 * x.scale_error);
    std::printf("\n");
  }
  if (s.dropped > 0) std::printf("dropped                %zu observations outside the image\n", s.dropped);
  if (!s.vision) std::printf("vision                 not used: IMU only\n");
  std::printf("status               ");
  for (const auto& [name, n] : s.statuses) std::printf("  %s %d", name.c_str(), n);
  std::printf("\n");
  std::printf("time per frame         %.2f ms mean, %.2f ms max (%.1f s for %.1f s of data)\n", s.ms_mean,
              s.ms_max, s.processing_s, s.duration_s);
  if (s.loops) {
    std::printf("keyframes              %zu", s.keyframes);
    if (s.map_keyframes > 0) std::printf(" (and %zu in the loaded map)", s.map_keyframes);
    std::printf("\nloop candidates        %zu:", s.candidates);
    for (const auto& [name, n] : s.loop_statuses) std::printf("  %s %d", name.c_str(), n);
    std::printf("\n");
    for (const auto& [name, why] : s.loop_reason) std::printf("  refused, %s: e.g. %s\n", name.c_str(), why.c_str());
    for (const Summary::Jump& x : s.jumps)
      std::printf("correction at t = %.3f s: output jumps %.4f m, %.3f deg\n", x.t_s, x.m, x.deg);
  }
  if (s.have_gt) {
    if (s.loops) {
      std::printf("APE position+yaw       rmse %.4f m without loop closure (odometry)\n", s.ape_odometry.rmse);
      if (s.have_keyframe_ape)
        std::printf("APE position+yaw       rmse %.4f m, keyframes at their final graph poses\n",
                    s.ape_keyframes.rmse);
    }
    std::printf("APE position+yaw       rmse %.4f m, max %.4f m (%zu poses%s)\n", s.ape_posyaw.rmse, s.ape_posyaw.max,
                s.matched, s.loops ? ", written with loop correction" : "");
    std::printf("APE SE(3)              rmse %.4f m, max %.4f m\n", s.ape_se3.rmse, s.ape_se3.max);
    if (s.have_rpe) std::printf("RPE per 10 m           rmse %.4f m\n", s.rpe10.rmse);
    if (s.yaw_defined)
      std::printf("yaw error              final %.3f deg, max %.3f deg (after position+yaw alignment)\n",
                  s.final_yaw_error_deg, s.max_yaw_error_deg);
    else
      std::printf("yaw error              not defined (the ground truth does not move horizontally)\n");
    if (s.have_bias) {
      std::printf("gyro bias error        rms %.5f rad/s, final %.5f rad/s\n", s.gyro_bias_rms, s.gyro_bias_final);
      std::printf("accel bias error       rms %.4f m/s^2, final %.4f m/s^2\n", s.accel_bias_rms, s.accel_bias_final);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o, cmd.program) : 0;
  });
}

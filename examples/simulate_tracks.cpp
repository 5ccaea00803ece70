// simulate_tracks: feature tracks (t_ns,feature_id,u,v csv, docs/feature-tracks.md)
// that a visual front end would report for a camera moving along a
// trajectory through a room of point landmarks (sim/feature_tracks.hpp).
//
// Semi-real sequences: the real motion of a EuRoC recording and its real IMU,
// with synthetic vision:
//
//   simulate_tracks --groundtruth V1_01_easy/groundtruth_20hz.csv
//                   --camera V1_01_easy/cam0_sensor.yaml --out cam0_tracks.csv
//
// With --imu-out the program also writes an IMU synthesised from that motion
// (sim::imu_from_trajectory: a spline through the ground-truth poses, its
// readings plus seeded noise of --imu-noise densities, starting from the
// ground truth's first bias), which agrees with the tracks up to that noise.
//
// Without --groundtruth the camera flies the built-in synthetic flight
// (sim::synthetic_flight, --duration seconds) and --groundtruth-out /
// --imu-out write its ground truth and a simulated IMU (EuRoC csv layouts),
// so that a whole synthetic sequence can be made.
//
// Prints one summary (or --json one object): frames, observations per frame,
// wrong associations, tracks and their mean length, landmarks. Exit status:
// 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <apps/cli.hpp>
#include <apps/imu_flags.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/feature_tracks.hpp>
#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/sim/imu_from_trajectory.hpp>
#include <posefuse/vio/camera.hpp>

namespace {

namespace apps = posefuse::apps;
namespace sim = posefuse::sim;

struct Options {
  std::optional<std::filesystem::path> groundtruth, camera, out, groundtruth_out, imu_out;
  sim::TrackSimConfig config;
  double duration_s = 60.0;
  posefuse::ImuNoise imu_noise;  // EuRoC's ADIS16448 datasheet
  double imu_rate_hz = 200.0;
  double imu_knot_spacing_s = 0.0;
  double imu_smoothing = 0.0;
  bool json = false;
};

// The largest IMU one run may write (samples): about 5 GB of csv.
constexpr double kMaxImuSamples = 5e7;

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  sim::TrackSimConfig& c = o.config;
  apps::Parser cli(cmd.program,
                   "--out FILE [--groundtruth FILE --camera FILE | --duration S] [options]",
                   "Simulates the feature tracks of a camera moving along a EuRoC ground truth "
                   "(or the built-in synthetic flight) through a room of point landmarks, and "
                   "writes them as t_ns,feature_id,u,v csv. The vision is synthetic; with a real "
                   "ground truth and its IMU the sequence is semi-real.");
  cli.output({.name = "--out", .value = "FILE", .help = "feature-track csv to write (required)"}, o.out);
  cli.input({.name = "--groundtruth", .value = "FILE",
            .help = "EuRoC ground truth csv (8 or 17 columns): the motion\n(default: the synthetic flight)"},
           o.groundtruth);
  cli.input({.name = "--camera", .value = "FILE",
            .help = "EuRoC camera sensor.yaml (required with --groundtruth;\ndefault: EuRoC cam0 intrinsics looking along body x)"},
           o.camera);
  cli.real_in({.name = "--rate", .value = "HZ", .help = "frame rate", .unit = "Hz"}, c.rate_hz, 0.1, 1000.0);
  cli.real_in({.name = "--noise-px", .value = "S", .help = "pixel noise sigma per axis", .unit = "px"},
              c.pixel_noise_px, 0.0, 20.0);
  cli.real_in({.name = "--outliers", .value = "F", .help = "fraction of wrong associations"},
              c.outlier_fraction, 0.0, 0.9);
  cli.integer({.name = "--features", .value = "N", .help = "tracked features wanted per frame"},
              c.features_per_frame, 1, 100000);
  cli.integer({.name = "--max-track-length", .value = "N", .help = "longest track (frames)"},
              c.max_track_length, 2, 1000000);
  cli.real_in({.name = "--min-distance", .value = "PX", .help = "new features this far from tracked ones",
               .unit = "px"},
              c.min_feature_distance_px, 0.0, 1000.0);
  cli.real_in({.name = "--room-margin", .value = "M", .help = "walls beyond the path's bounding box", .unit = "m"},
              c.room_margin_m, 0.1, 1000.0);
  cli.real_in({.name = "--wall-density", .value = "D", .help = "wall landmarks per square metre"},
              c.wall_density_per_m2, 0.0, 1000.0);
  cli.integer({.name = "--free-points", .value = "N", .help = "free landmarks inside the room"}, c.free_points,
              0, 10000000);
  cli.real_in({.name = "--max-pose-gap", .value = "S",
               .help = "longest ground-truth interval a frame may be\ninterpolated across", .unit = "s"},
              c.max_pose_gap_s, 0.001, 3600.0);
  cli.integer({.name = "--seed", .value = "N", .help = "random seed"}, c.seed);
  cli.flag({.name = "--recurring-ids",
            .help = "a landmark keeps its id when seen again (an oracle for\nloop closure: perfect re-identification)"},
           c.recurring_ids);
  cli.real_in({.name = "--duration", .value = "S", .help = "synthetic flight length", .unit = "s"}, o.duration_s,
              0.1, 3600.0);
  cli.output({.name = "--groundtruth-out", .value = "FILE",
            .help = "synthetic flight only: write its ground truth (EuRoC csv,\n17 columns, 200 Hz)"},
           o.groundtruth_out);
  cli.output({.name = "--imu-out", .value = "FILE",
            .help = "write an IMU (EuRoC imu0 csv, seeded with --seed): with --groundtruth\n"
                    "synthesised from its poses (a spline through them, starting from the\n"
                    "first row's biases when it has 17 columns); else simulated on the\n"
                    "synthetic flight"},
           o.imu_out);
  cli.custom({.name = "--imu-noise", .value = "NA,NG,WA,WG",
              .help = "with --imu-out: accelerometer and gyroscope noise densities, then\n"
                      "their random walks (m/s^2/sqrt(Hz), rad/s/sqrt(Hz), m/s^3/sqrt(Hz),\n"
                      "rad/s^2/sqrt(Hz)), by default EuRoC's ADIS16448; 0,0,0,0: none",
              .default_text = "2e-3,1.6968e-4,3e-3,1.9393e-5"},
             [&](std::string_view v) { o.imu_noise = apps::parse_imu_noise(v, 0.0); });
  cli.real_in({.name = "--imu-rate", .value = "HZ", .help = "with --imu-out: IMU sample rate", .unit = "Hz"},
              o.imu_rate_hz, 1.0, 10000.0);
  cli.real_in({.name = "--imu-knot-spacing", .value = "S",
               .help = "with --groundtruth --imu-out: knot spacing of the spline\n(0: the ground truth's mean spacing, "
                       "a fit through the poses;\nlarger smooths)",
               .unit = "s"},
              o.imu_knot_spacing_s, 0.0, 60.0);
  cli.real_in({.name = "--imu-smoothing", .value = "L",
               .help = "with --groundtruth --imu-out: weight of the spline's second\ndifferences (0: a fit through the "
                       "poses; larger smooths)"},
              o.imu_smoothing, 0.0, 1e12);
  cli.flag({.name = "--json", .help = "print one JSON object instead of the summary"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (!o.out) throw apps::usage_error("--out is required");
  if (o.groundtruth && !o.camera) throw apps::usage_error("--groundtruth needs --camera");
  if (o.groundtruth && (o.groundtruth_out || cli.given("--duration")))
    throw apps::usage_error("--duration and --groundtruth-out are for the synthetic flight only");
  for (const char* f : {"--imu-noise", "--imu-rate", "--imu-knot-spacing", "--imu-smoothing"})
    if (cli.given(f) && !o.imu_out) throw apps::usage_error(std::string(f) + " needs --imu-out");
  for (const char* f : {"--imu-knot-spacing", "--imu-smoothing"})
    if (cli.given(f) && !o.groundtruth) throw apps::usage_error(std::string(f) + " needs --groundtruth");
  if (c.wall_density_per_m2 == 0 && c.free_points == 0)
    throw apps::usage_error("--wall-density 0 and --free-points 0 leave the room without landmarks");
  c.validate();  // every field is bounded by its flag above; a failure here is a bug
  return o;
}

// Refuses (usage_error, before anything is allocated) a simulation larger
// than sim::kMaxSimulatedLandmarks landmarks or sim::kMaxSimulatedObservations
// observations, naming the flags that make it so.
void check_size(const Options& o, double frames, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                const std::string& span) {
  const sim::TrackSimSize size = sim::track_simulation_size(frames, lo, hi, o.config);
  if (size.landmarks > sim::kMaxSimulatedLandmarks)
    throw apps::usage_error("--wall-density " + apps::num(o.config.wall_density_per_m2) + " on the walls of a room " +
                            apps::num(o.config.room_margin_m) + " m (--room-margin) beyond the path gives about " +
                            apps::num(size.landmarks) + " landmarks, more than the " +
                            apps::num(sim::kMaxSimulatedLandmarks) + " one run may hold");
  if (size.max_observations > sim::kMaxSimulatedObservations)
    throw apps::usage_error("--rate " + apps::num(o.config.rate_hz) + " Hz over " + span + " gives " +
                            apps::num(frames) + " frames of up to " + std::to_string(o.config.features_per_frame) +
                            " features (--features): up to " + apps::num(size.max_observations) +
                            " observations, more than the " + apps::num(sim::kMaxSimulatedObservations) +
                            " one run may hold");
}

// The bounding box of a trajectory's positions, grown by the camera's lever arm.
void path_box(const std::vector<Eigen::Isometry3d>& poses, const posefuse::PinholeRadtan& camera,
              Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = hi = poses.front().translation();
  for (const Eigen::Isometry3d& T : poses) {
    lo = lo.cwiseMin(T.translation());
    hi = hi.cwiseMax(T.translation());
  }
  lo.array() -= camera.T_BS.translation().norm();
  hi.array() += camera.T_BS.translation().norm();
}

// Refuses (usage_error) an IMU of more than kMaxImuSamples samples.
void check_imu_size(const Options& o, double span_s, const std::string& span) {
  const double n = std::floor(span_s * o.imu_rate_hz) + 1;
  if (n > kMaxImuSamples)
    throw apps::usage_error("--imu-rate " + apps::num(o.imu_rate_hz) + " Hz over " + span + " gives " + apps::num(n) +
                            " IMU samples, more than the " + apps::num(kMaxImuSamples) + " one run may write");
}

// The IMU synthesised from the ground truth's poses (sim::imu_from_trajectory),
// from the first row's biases when the file has them.
std::vector<posefuse::ImuSample> synthesised_imu(const Options& o, const posefuse::EurocGroundTruth& gt) {
  std::vector<sim::StampedPose> poses(gt.size());
  for (std::size_t k = 0; k < gt.size(); ++k) {
    const Eigen::Isometry3d& T = gt.trajectory.poses[k];
    poses[k] = {gt.t_ns[k], T.translation(), Eigen::Quaterniond(T.linear()).normalized()};
  }
  sim::ImuFromTrajectoryConfig c;
  c.rate_hz = o.imu_rate_hz;
  c.noise = o.imu_noise;
  c.seed = o.config.seed;
  c.knot_spacing_s = o.imu_knot_spacing_s;
  c.smoothing = o.imu_smoothing;
  if (gt.has_velocity_and_biases()) c.initial_bias = posefuse::ImuBias{gt.accel_bias->front(), gt.gyro_bias->front()};
  try {
    return sim::imu_from_trajectory(poses, c).samples;
  } catch (const posefuse::invalid_argument& e) {  // fewer than 4 poses
    throw posefuse::io_error(*o.groundtruth, std::string(e.what()) + " (--imu-out)");
  }
}

std::string num(double v) { return posefuse::detail::traj_io::format_number(v); }

std::string groundtruth_csv(const posefuse::EurocGroundTruth& gt) {
  std::string s = "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,bw_x,bw_y,bw_z,ba_x,ba_y,ba_z\n";
  for (std::size_t k = 0; k < gt.size(); ++k) {
    const Eigen::Isometry3d& T = gt.trajectory.poses[k];
    const Eigen::Quaterniond q(T.linear());
    const Eigen::Vector3d p = T.translation(), v = (*gt.velocity)[k], bw = (*gt.gyro_bias)[k],
                          ba = (*gt.accel_bias)[k];
    s += std::to_string(gt.t_ns[k]);
    for (const double x : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z(), bw.x(), bw.y(),
                           bw.z(), ba.x(), ba.y(), ba.z()})
      s += "," + num(x);
    s += "\n";
  }
  return s;
}

std::string imu_csv(const std::vector<posefuse::ImuSample>& imu) {
  std::string s = "#timestamp [ns],w_x [rad s^-1],w_y,w_z,a_x [m s^-2],a_y,a_z\n";
  for (const posefuse::ImuSample& m : imu) {
    s += std::to_string(m.t_ns);
    for (const double x : {m.gyro_radps.x(), m.gyro_radps.y(), m.gyro_radps.z(), m.accel_mps2.x(),
                           m.accel_mps2.y(), m.accel_mps2.z()})
      s += "," + num(x);
    s += "\n";
  }
  return s;
}

int run(const Options& o, const std::string& program) {
  apps::TerminalProgress progress(program);
  const posefuse::PinholeRadtan camera =
      o.camera ? posefuse::read_euroc_camera(*o.camera) : sim::synthetic_camera();
  sim::SimulatedTracks s;
  apps::OutputFiles files;
  Eigen::Vector3d lo, hi;
  if (o.groundtruth) {
    progress.stage("reading " + o.groundtruth->string());
    const posefuse::EurocGroundTruth gt = posefuse::read_euroc_groundtruth(*o.groundtruth);
    const double span_s = double(gt.t_ns.back() - gt.t_ns.front()) * 1e-9;
    path_box(gt.trajectory.poses, camera, lo, hi);
    check_size(o, std::floor(span_s * o.config.rate_hz) + 1, lo, hi,
               "the " + apps::num(span_s) + " s of --groundtruth");
    progress.stage("simulating " + apps::num(std::floor(span_s * o.config.rate_hz) + 1) + " frames");
    if (o.imu_out) check_imu_size(o, span_s, "the " + apps::num(span_s) + " s of --groundtruth");
    try {
      s = sim::simulate_feature_tracks(gt, camera, o.config);
    } catch (const posefuse::invalid_argument& e) {  // a gap longer than --max-pose-gap
      throw posefuse::io_error(*o.groundtruth, std::string(e.what()) + " (--max-pose-gap)");
    }
    if (o.imu_out) {
      progress.stage("synthesising the IMU");
      files.add(*o.imu_out, imu_csv(synthesised_imu(o, gt)));
    }
  } else {
    posefuse::sim::ImuSimConfig flight = sim::synthetic_flight();
    path_box(sim::synthetic_groundtruth(flight, o.duration_s, 10.0).trajectory.poses, camera, lo, hi);
    check_size(o, std::floor(o.duration_s * o.config.rate_hz) + 1, lo, hi,
               "--duration " + apps::num(o.duration_s) + " s");
    progress.stage("simulating " + apps::num(std::floor(o.duration_s * o.config.rate_hz) + 1) + " frames");
    s = sim::simulate_feature_tracks(flight, o.duration_s, camera, o.config);
    if (o.groundtruth_out)
      files.add(*o.groundtruth_out, groundtruth_csv(sim::synthetic_groundtruth(flight, o.duration_s, 200.0)));
    if (o.imu_out) {
      check_imu_size(o, o.duration_s, "--duration " + apps::num(o.duration_s) + " s");
      flight.noise = o.imu_noise;
      flight.rate_hz = o.imu_rate_hz;
      flight.seed = o.config.seed;
      files.add(*o.imu_out, imu_csv(sim::simulate_imu(flight, o.duration_s).samples));
    }
  }
  if (s.observations == 0)
    throw apps::data_error("the camera saw no landmark in any of the " + std::to_string(s.tracks.size()) +
                           " frames (is the camera's image in the room? see --camera, --noise-px, --room-margin, "
                           "--wall-density, --free-points); nothing was written");
  files.add_with(*o.out, [&s](const std::filesystem::path& p) { posefuse::write_feature_tracks(p, s.tracks); });
  progress.stage("writing " + o.out->string());
  files.commit();
  progress.clear();

  const double frames = double(s.tracks.size());
  const double per_frame = frames > 0 ? double(s.observations) / frames : 0.0;
  const double wrong = s.observations > 0 ? double(s.wrong_associations) / double(s.observations) : 0.0;
  const double mean_length =
      s.landmark_of_id.empty() ? 0.0 : double(s.observations) / double(s.landmark_of_id.size());
  if (o.json) {
    apps::JsonWriter j(std::cout);
    j.begin_object(apps::JsonWriter::Layout::kInline);
    j.member("frames", s.tracks.size()).member("observations", s.observations);
    j.member("features_per_frame", per_frame).member("frames_below_target", s.frames_below_target);
    j.member("wrong_association_fraction", wrong).member("tracks", s.landmark_of_id.size());
    j.member("mean_track_length", mean_length).member("landmarks", s.landmarks_w.size());
    j.member("wall_landmarks", s.wall_landmarks);
    j.end_object().finish();
  } else {
    std::printf("%zu frames at %g Hz, %zu observations (%.1f per frame, %zu frames below %d)\n",
                s.tracks.size(), o.config.rate_hz, s.observations, per_frame, s.frames_below_target,
                o.config.features_per_frame);
    std::printf("%zu tracks, mean length %.1f frames; wrong associations %.2f %%; pixel noise %g px\n",
                s.landmark_of_id.size(), mean_length, 100.0 * wrong, o.config.pixel_noise_px);
    std::printf("%zu landmarks (%zu on walls, %zu free); vision synthetic, motion %s\n", s.landmarks_w.size(),
                s.wall_landmarks, s.landmarks_w.size() - s.wall_landmarks,
                o.groundtruth ? "from the ground truth" : "the synthetic flight");
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

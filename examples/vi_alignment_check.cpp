// vi_alignment_check: visual-inertial alignment (inertial/alignment.hpp) on
// a real IMU recording, with the ground truth turned into an up-to-scale
// stand-in for vision-only SfM.
//
// Scenario: EuRoC V1_01_easy (euroc/ of the data folder). Keyframes every
// --keyframe-interval seconds (default 0.25 s, on ground-truth stamps);
// sliding windows of 10 keyframes, starting every --stride keyframes. In each
// window the camera poses T_c0_ck come from the ground-truth body poses and
// the EuRoC cam0 extrinsic T_b_c (cam0/sensor.yaml of the dataset), then
//   * each keyframe after the first gets rotation noise Exp(n_R), n_R ~ N(0, σ_R² I)
//     (--rot-noise-deg, default 0.1°) and position noise N(0, σ_p² I) in c0
//     (--pos-noise, default 0.005 m),
//   * positions are multiplied by an arbitrary SfM scale (--sfm-scale, default
//     0.37 SfM units per metre; the metric scale to recover is 1 / 0.37),
// with one std::mt19937_64 seeded with --seed, draws one statement each.
// The IMU is pre-integrated between keyframes about a zero bias; the
// alignment estimates the gyroscope bias, scale, gravity and velocities; they
// are compared with the ground truth (gravity and velocities in c0; the gyro
// bias with the ground-truth bias at the window's start).
//
//   vi_alignment_check --imu euroc/V1_01_easy/imu0.csv
//                      --groundtruth euroc/V1_01_easy/groundtruth_20hz.csv
//
// Expected output (format; figures in docs/inertial.md):
//
//   Visual-inertial alignment, windows of 10 keyframes 0.25 s apart: ... windows
//   status: ok ..., insufficient excitation ..., ...
//   error (ok windows)          median       p95       max
//   scale [%]                 ...
//   gravity direction [deg]   ...
//   velocity rms [m/s]        ...
//   gyro bias [rad/s]         ...
//
// --json prints scale_error_percent, gravity_error_deg, gyro_bias_error,
// velocity_error (medians over the successful windows; null, and "no
// successful window" in the table, when none succeeded: a 0 % success rate
// is a result, exit 0), success_rate and the status counts; --svg FILE plots
// the per-window errors. An interval shorter than the ground truth's period
// is reported as a warning and the period is printed as the interval used.
// Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad
// usage (including values that can only fail: an interval beyond 9e9 s).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <apps/cli.hpp>
#include <apps/imu_flags.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <apps/svg.hpp>
#include <posefuse/inertial/alignment.hpp>
#include <posefuse/io/euroc.hpp>

namespace {

namespace apps = posefuse::apps;
constexpr int kFrames = 10;

struct Options {
  std::filesystem::path imu, groundtruth;
  std::optional<std::filesystem::path> svg;
  posefuse::ImuReadOptions imu_bounds;
  double keyframe_interval_s = 0.25;
  int stride = 5;
  double sfm_scale = 0.37;
  double rot_noise_deg = 0.1;
  double pos_noise_m = 0.005;
  std::uint64_t seed = 1;
  bool gt_accel_bias = false;
  bool json = false;
};

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// Refuses values no run can succeed with, before any file is read.
void check_ranges(const Options& o) {
  // The interval becomes integer nanoseconds: at most ~9.2e9 s, at least 1 ns.
  if (o.keyframe_interval_s > 9e9)
    throw apps::usage_error("--keyframe-interval " + short_number(o.keyframe_interval_s) +
                            " s does not fit nanosecond stamps (at most 9e9 s)");
  if (o.keyframe_interval_s < 1e-9)
    throw apps::usage_error("--keyframe-interval " + short_number(o.keyframe_interval_s) +
                            " s is shorter than 1 ns");
  // Scaled positions and their squares must stay finite in the alignment.
  if (o.sfm_scale < 1e-100 || o.sfm_scale > 1e100)
    throw apps::usage_error("--sfm-scale " + short_number(o.sfm_scale) + " is outside [1e-100, 1e100]");
  // A rotation noise beyond half a turn is no longer a noise about the pose.
  if (o.rot_noise_deg > 180)
    throw apps::usage_error("--rot-noise-deg " + short_number(o.rot_noise_deg) + " is above 180");
  if (o.pos_noise_m > 1e100)
    throw apps::usage_error("--pos-noise " + short_number(o.pos_noise_m) + " m is above 1e100");
}

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  std::optional<std::filesystem::path> imu, gt;
  apps::Parser cli(cmd.program, "--imu FILE --groundtruth FILE [options]",
                   "Runs visual-inertial alignment over sliding windows of 10 keyframes with "
                   "up-to-scale poses made from the ground truth, and scores it.");
  cli.input({.name = "--imu", .value = "FILE", .help = "EuRoC imu0 csv (required)"}, imu);
  cli.input({.name = "--groundtruth", .value = "FILE",
            .help = "EuRoC state ground truth csv with velocity and biases (required)"},
           gt);
  cli.real({.name = "--keyframe-interval", .value = "S", .help = "time between keyframes",
            .unit = "s"},
           o.keyframe_interval_s, apps::Domain::kPositive);
  cli.integer({.name = "--stride", .value = "K", .help = "keyframes between window starts"},
              o.stride);
  cli.real({.name = "--sfm-scale", .value = "K", .help = "SfM units per metre"}, o.sfm_scale,
           apps::Domain::kPositive);
  cli.real({.name = "--rot-noise-deg", .value = "X", .help = "SfM rotation noise (1 sigma)",
            .unit = "deg"},
           o.rot_noise_deg, apps::Domain::kNonNegative);
  cli.real({.name = "--pos-noise", .value = "X", .help = "SfM position noise (1 sigma, metric)",
            .unit = "m"},
           o.pos_noise_m, apps::Domain::kNonNegative);
  cli.integer({.name = "--seed", .value = "N", .help = "random seed of the SfM noise"}, o.seed);
  cli.flag({.name = "--gt-accel-bias",
            .help = "pre-integrate about the ground-truth accelerometer bias (the alignment does "
                    "not estimate it)"},
           o.gt_accel_bias);
  cli.output({.name = "--svg", .value = "FILE", .help = "plot the per-window errors"}, o.svg);
  apps::declare_imu_bounds(cli, o.imu_bounds);
  cli.flag({.name = "--json", .help = "print one JSON object instead of the table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (!imu || !gt) throw apps::usage_error("--imu and --groundtruth are required");
  if (o.stride < 1) throw apps::usage_error("--stride must be >= 1");
  check_ranges(o);
  o.imu = *imu;
  o.groundtruth = *gt;
  return o;
}

/// EuRoC cam0 extrinsic T_BS (camera pose in the IMU body frame), from the
/// dataset's cam0/sensor.yaml.
posefuse::SE3d euroc_cam0_extrinsic() {
  Eigen::Matrix3d R;
  R << 0.0148655429818, -0.999880929698, 0.00414029679422,  //
      0.999557249008, 0.0149672133247, 0.025715529948,      //
      -0.0257744366974, 0.00375618835797, 0.999660727178;
  return posefuse::SE3d(Eigen::Vector3d(-0.0216401454975, -0.064676986768, 0.00981073058949),
                        posefuse::SO3d(R));
}

struct WindowResult {
  double t_s;
  posefuse::VisualInertialAlignmentStatus status;
  double scale_pct = 0, gravity_deg = 0, velocity_rms = 0, gyro_bias = 0;
};

struct Report {
  std::vector<WindowResult> windows;
  double keyframe_interval_s = 0;  // what was used: the asked one, or the ground truth's period
  std::size_t skipped = 0;
  std::map<std::string, std::size_t> statuses;
};

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

Report run_check(const Options& o) {
  // On a terminal, standard error shows the files being read and the windows.
  apps::TerminalProgress progress("vi_alignment_check");
  progress.stage("reading " + o.imu.string());
  const std::vector<posefuse::ImuSample> imu = posefuse::read_euroc_imu(o.imu, o.imu_bounds);
  progress.stage("reading " + o.groundtruth.string());
  const posefuse::EurocGroundTruth gt = posefuse::read_euroc_groundtruth(o.groundtruth);
  progress.clear();
  if (!gt.has_velocity_and_biases())
    throw apps::data_error(o.groundtruth.string() +
                           ": needs velocity and biases (17 columns); this file has poses only");
  // Keyframes: ground-truth states at least keyframe_interval apart.
  const auto interval_ns = std::int64_t(std::llround(o.keyframe_interval_s * 1e9));  // range checked
  Report r;
  r.keyframe_interval_s = o.keyframe_interval_s;
  if (gt.size() >= 2) {
    std::vector<std::int64_t> steps;
    for (std::size_t k = 1; k < gt.size(); ++k) steps.push_back(gt.t_ns[k] - gt.t_ns[k - 1]);
    std::nth_element(steps.begin(), steps.begin() + std::ptrdiff_t(steps.size() / 2), steps.end());
    const std::int64_t step_ns = steps[steps.size() / 2];
    // (the stamps jitter by well under 1 % of the step)
    if (interval_ns < step_ns - step_ns / 100) {
      r.keyframe_interval_s = double(step_ns) * 1e-9;
      std::fprintf(stderr,
                   "warning: --keyframe-interval %g s is shorter than the ground truth's period "
                   "(%.4g s); every ground-truth state is a keyframe\n",
                   o.keyframe_interval_s, r.keyframe_interval_s);
    }
  }
  std::vector<std::size_t> kf;
  for (std::size_t i = 0; i < gt.size(); ++i)
    if (kf.empty() || gt.t_ns[i] - gt.t_ns[kf.back()] >= interval_ns) kf.push_back(i);
  const posefuse::SE3d T_b_c = euroc_cam0_extrinsic();
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sigma_r = o.rot_noise_deg * std::numbers::pi / 180.0;
  for (std::size_t w0 = 0; w0 + kFrames <= kf.size(); w0 += std::size_t(o.stride)) {
    progress.update([&] {
      return "window at keyframe " + std::to_string(w0 + 1) + " of " + std::to_string(kf.size());
    });
    std::array<posefuse::SE3d, kFrames> T_w_c;
    for (int k = 0; k < kFrames; ++k) {
      const std::size_t i = kf[w0 + std::size_t(k)];
      T_w_c[std::size_t(k)] = posefuse::SE3d(gt.trajectory.poses[i]).compose(T_b_c);
    }
    const posefuse::SE3d T_c0_w = T_w_c[0].inverse();
    std::array<posefuse::SE3d, kFrames> T_c0_c;
    for (int k = 0; k < kFrames; ++k) {
      const posefuse::SE3d T = T_c0_w.compose(T_w_c[std::size_t(k)]);
      Eigen::Vector3d dr = Eigen::Vector3d::Zero(), dp = Eigen::Vector3d::Zero();
      if (k > 0) {
        for (int a = 0; a < 3; ++a) dr(a) = sigma_r * n01(rng);
        for (int a = 0; a < 3; ++a) dp(a) = o.pos_noise_m * n01(rng);
      }
      T_c0_c[std::size_t(k)] =
          posefuse::SE3d((T.translation() + dp) * o.sfm_scale, T.so3().plus(dr));
    }
    std::array<posefuse::Preintegration, kFrames - 1> pre;
    if (o.gt_accel_bias)
      for (posefuse::Preintegration& p : pre)
        p = posefuse::Preintegration(posefuse::ImuNoise{},
                                     posefuse::ImuBias{(*gt.accel_bias)[kf[w0]], Eigen::Vector3d::Zero()});
    bool ok = true;
    for (int k = 0; k + 1 < kFrames && ok; ++k)
      ok = posefuse::preintegrate(imu, gt.t_ns[kf[w0 + std::size_t(k)]],
                                  gt.t_ns[kf[w0 + std::size_t(k) + 1]], pre[std::size_t(k)]) ==
           posefuse::ImuStatus::kApplied;
    if (!ok) {
      ++r.skipped;
      continue;
    }
    const auto res = posefuse::align_visual_inertial<kFrames>(T_c0_c, T_b_c, pre);
    WindowResult wr;
    wr.t_s = posefuse::seconds_between(gt.t_ns[kf[w0]], gt.t_ns.front());
    wr.status = res.status;
    ++r.statuses[posefuse::to_string(res.status)];
    if (res.status == posefuse::VisualInertialAlignmentStatus::kOk) {
      const double s_true = 1.0 / o.sfm_scale;
      const posefuse::SO3d R_c0_w = T_c0_w.so3();
      wr.scale_pct = 100.0 * std::abs(res.scale - s_true) / s_true;
      wr.gravity_deg = angle_deg(res.gravity_c0, R_c0_w.act(Eigen::Vector3d(0, 0, -9.81)));
      double sq = 0;
      for (int k = 0; k < kFrames; ++k) {
        const Eigen::Vector3d v_true = R_c0_w.act((*gt.velocity)[kf[w0 + std::size_t(k)]]);
        sq += (res.velocity_c0[std::size_t(k)] - v_true).squaredNorm();
      }
      wr.velocity_rms = std::sqrt(sq / kFrames);
      wr.gyro_bias = (res.gyro_bias - (*gt.gyro_bias)[kf[w0]]).norm();
      if (!std::isfinite(wr.scale_pct) || !std::isfinite(wr.velocity_rms))
        throw apps::data_error("non-finite alignment result in the window at t = " +
                               short_number(wr.t_s) + " s");
    }
    r.windows.push_back(wr);
  }
  if (r.windows.empty())
    throw apps::data_error("no window of 10 keyframes could be evaluated");
  return r;
}

struct Dist {
  double median = 0, p95 = 0, max = 0;
};

Dist dist(std::vector<double> v) {
  Dist d;
  if (v.empty()) return d;
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[std::size_t(std::floor(q * double(v.size() - 1) + 0.5))]; };
  d.median = at(0.5);
  d.p95 = at(0.95);
  d.max = v.back();
  return d;
}

struct Summary {
  std::size_t ok = 0;
  double success_rate = 0;
  Dist scale, gravity, velocity, gyro;
};

Summary summarise(const Report& r) {
  Summary s;
  std::vector<double> sc, gr, ve, gy;
  for (const WindowResult& w : r.windows) {
    if (w.status != posefuse::VisualInertialAlignmentStatus::kOk) continue;
    ++s.ok;
    sc.push_back(w.scale_pct);
    gr.push_back(w.gravity_deg);
    ve.push_back(w.velocity_rms);
    gy.push_back(w.gyro_bias);
  }
  s.success_rate = double(s.ok) / double(r.windows.size());
  s.scale = dist(sc);
  s.gravity = dist(gr);
  s.velocity = dist(ve);
  s.gyro = dist(gy);
  return s;
}

std::string plot_svg(const Report& r) {
  std::vector<apps::svg::Point> sc, gr;
  for (const WindowResult& w : r.windows) {
    if (w.status != posefuse::VisualInertialAlignmentStatus::kOk) continue;
    sc.push_back({w.t_s, w.scale_pct});
    gr.push_back({w.t_s, w.gravity_deg});
  }
  apps::svg::Plot ps("scale error per window");
  ps.x_axis("window start", "s").y_axis("|s - s_true| / s_true", "%").include({0, 0});
  ps.markers("ok windows", sc, apps::svg::Marker::kCircle, {"#1f77b4", 1.0, {}});
  apps::svg::Plot pg("gravity direction error per window");
  pg.x_axis("window start", "s").y_axis("angle", "deg").include({0, 0});
  pg.markers("ok windows", gr, apps::svg::Marker::kCircle, {"#d62728", 1.0, {}});
  apps::svg::Document doc(1100, 480);
  doc.plot(ps, {0, 0, 550, 480}).plot(pg, {550, 0, 550, 480});
  return doc.str();
}

void print_table(const Options& o, const Report& r, const Summary& s) {
  std::printf("Visual-inertial alignment, windows of %d keyframes %g s apart (stride %d): %zu "
              "windows (%zu skipped)\n",
              kFrames, r.keyframe_interval_s, o.stride, r.windows.size(), r.skipped);
  std::printf("status:");
  for (const auto& kv : r.statuses) std::printf(" %s %zu;", kv.first.c_str(), kv.second);
  std::printf(" success rate %.1f %%\n", 100.0 * s.success_rate);
  if (s.ok == 0) {
    std::printf("no successful window: no error to summarise\n");
    return;
  }
  std::printf("error (ok windows)          median       p95       max\n");
  const auto row = [](const char* name, const Dist& d, const char* fmt) {
    std::printf("%-24s", name);
    std::printf(fmt, d.median);
    std::printf(fmt, d.p95);
    std::printf(fmt, d.max);
    std::printf("\n");
  };
  row("scale [%]", s.scale, " %9.3f");
  row("gravity direction [deg]", s.gravity, " %9.3f");
  row("velocity rms [m/s]", s.velocity, " %9.4f");
  row("gyro bias [rad/s]", s.gyro, " %9.5f");
}

void print_json(const Options&, const Report& r, const Summary& s) {
  apps::JsonWriter j(std::cout);
  j.begin_object(apps::JsonWriter::Layout::kInline);
  j.member("keyframes", kFrames).member("keyframe_interval_s", r.keyframe_interval_s);
  j.member("windows", r.windows.size()).member("skipped", r.skipped);
  j.member("success_rate", s.success_rate);
  // With no successful window there is no error to summarise: null.
  const auto figure = [&](const char* name, double v) {
    if (s.ok == 0) j.key(name).null();
    else j.member(name, v);
  };
  figure("scale_error_percent", s.scale.median);
  figure("scale_error_percent_p95", s.scale.p95);
  figure("gravity_error_deg", s.gravity.median);
  figure("gravity_error_deg_p95", s.gravity.p95);
  figure("velocity_error", s.velocity.median);
  figure("gyro_bias_error", s.gyro.median);
  j.key("statuses").begin_object(apps::JsonWriter::Layout::kInline);
  for (const auto& kv : r.statuses) j.member(kv.first, kv.second);
  j.end_object();
  j.end_object().finish();
}

int run(const Options& o) {
  const Report r = run_check(o);
  const Summary s = summarise(r);
  apps::OutputFiles files;
  if (o.svg) files.add(*o.svg, plot_svg(r));
  files.commit();
  if (o.json) print_json(o, r, s);
  else print_table(o, r, s);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

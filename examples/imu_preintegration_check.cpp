// imu_preintegration_check: IMU pre-integration (inertial/preintegration.hpp)
// against the ground-truth relative motion of a real recording, and whether
// its errors are consistent with the propagated covariance.
//
// Scenario: EuRoC V1_01_easy (euroc/ of the data folder, docs/programs.md). Cut the
// sequence into consecutive windows of S seconds that start and end on
// ground-truth states i, j (the IMU stream is interpolated at those stamps);
// pre-integrate the IMU with the ground-truth biases of state i; compare
// Δp, ΔR, Δv with the ground truth's
//   ΔR = R_i^T R_j,  Δv = R_i^T (v_j - v_i - g Δt),
//   Δp = R_i^T (p_j - p_i - v_i Δt - ½ g Δt²),   g = (0, 0, -9.81) m/s²,
// and compute the 9-dof NEES e^T P⁻¹ e of the error e = truth ⊖ pre-integration
// with P the propagated covariance of [δp, δφ, δv].
//
//   imu_preintegration_check --imu euroc/V1_01_easy/imu0.csv
//                            --groundtruth euroc/V1_01_easy/groundtruth_20hz.csv --window 1
//
// Expected output (format; the figures are in docs/inertial.md):
//
//   IMU pre-integration vs ground truth: 143 windows of 1 s (0 skipped)
//   error                 rmse    median       p95       max
//   position [m]        ...
//   rotation [deg]      ...
//   velocity [m/s]      ...
//   NEES (9 dof): mean ..., 95 % interval of the mean [..., ...]; ... % of windows inside the
//   per-window 95 % interval [2.70, 19.02]
//   verdict: ...
//
// --json prints one object (position_error_rmse, rotation_error_rmse_deg,
// velocity_error_rmse, nees_mean, ...); --svg FILE plots the per-window
// errors with the covariance's 3-sigma. The noise densities default to the
// EuRoC ADIS16448 figures of imu0_sensor.yaml; the white-noise densities
// must be > 0 (a zero covariance cannot score a non-zero error). Windows end
// on the ground-truth state nearest to their start + S; the length printed is
// the median of the windows used. A window holding a ground-truth step longer
// than 2.5 times the file's median step is skipped as a gap. Exit status: 0
// ok, 1 bad data (file:line where a file is at fault), 2 bad usage
// (including values that can only fail: zero noise, a window beyond 9e9 s).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include <apps/cli.hpp>
#include <apps/imu_flags.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <apps/svg.hpp>
#include <posefuse/core/chi_square.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/io/euroc.hpp>

namespace {

namespace apps = posefuse::apps;

struct Options {
  std::filesystem::path imu, groundtruth;
  std::optional<std::filesystem::path> svg;
  posefuse::ImuReadOptions imu_bounds;
  double window_s = 1.0;
  double gravity = 9.81;
  posefuse::ImuNoise noise;  // EuRoC ADIS16448 defaults
  bool json = false;
};

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// Refuses values no run can succeed with, before any file is read.
void check_ranges(const Options& o) {
  // The window becomes integer nanoseconds: at most ~9.2e9 s, at least 1 ns.
  if (o.window_s > 9e9)
    throw apps::usage_error("--window " + short_number(o.window_s) +
                            " s does not fit nanosecond stamps (at most 9e9 s)");
  if (o.window_s < 1e-9)
    throw apps::usage_error("--window " + short_number(o.window_s) + " s is shorter than 1 ns");
  // A zero density gives a zero covariance for δp, δφ or δv: no error can be
  // scored against it (its NEES is infinite). Squares of densities outside
  // [1e-100, 1e100] under- or overflow the covariance.
  const auto density = [](const char* flag, double v, bool zero_ok) {
    if (zero_ok && v == 0.0) return;
    if (v < 1e-100 || v > 1e100)
      throw apps::usage_error(std::string(flag) + " " + short_number(v) +
                              " is outside [1e-100, 1e100]" + (zero_ok ? " (or 0)" : ""));
  };
  density("--gyro-noise", o.noise.gyro_noise_density, false);
  density("--accel-noise", o.noise.accel_noise_density, false);
  density("--gyro-walk", o.noise.gyro_random_walk, true);
  density("--accel-walk", o.noise.accel_random_walk, true);
  if (o.gravity > 1e100)
    throw apps::usage_error("--gravity " + short_number(o.gravity) + " m/s^2 is above 1e100");
}

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  std::optional<std::filesystem::path> imu, gt;
  apps::Parser cli(cmd.program, "--imu FILE --groundtruth FILE [--window S] [options]",
                   "Pre-integrates a EuRoC IMU csv over windows of S seconds and compares it "
                   "with the ground-truth relative motion.");
  cli.input({.name = "--imu", .value = "FILE", .help = "EuRoC imu0 csv (required)"}, imu);
  cli.input({.name = "--groundtruth", .value = "FILE",
            .help = "EuRoC state ground truth csv with velocity and biases (required)"},
           gt);
  cli.real({.name = "--window", .value = "S", .help = "window length", .unit = "s"}, o.window_s,
           apps::Domain::kPositive);
  cli.real({.name = "--gravity", .value = "G", .help = "gravity magnitude", .unit = "m/s^2"},
           o.gravity, apps::Domain::kPositive);
  cli.real({.name = "--gyro-noise", .value = "X", .help = "gyroscope noise density (> 0: a zero covariance cannot score an error)",
            .unit = "rad/s/sqrt(Hz)"},
           o.noise.gyro_noise_density, apps::Domain::kPositive);
  cli.real({.name = "--accel-noise", .value = "X", .help = "accelerometer noise density (> 0)",
            .unit = "m/s^2/sqrt(Hz)"},
           o.noise.accel_noise_density, apps::Domain::kPositive);
  cli.real({.name = "--gyro-walk", .value = "X", .help = "gyroscope bias random walk",
            .unit = "rad/s^2/sqrt(Hz)"},
           o.noise.gyro_random_walk, apps::Domain::kNonNegative);
  cli.real({.name = "--accel-walk", .value = "X", .help = "accelerometer bias random walk",
            .unit = "m/s^3/sqrt(Hz)"},
           o.noise.accel_random_walk, apps::Domain::kNonNegative);
  cli.output({.name = "--svg", .value = "FILE", .help = "plot the per-window errors"}, o.svg);
  apps::declare_imu_bounds(cli, o.imu_bounds);
  cli.flag({.name = "--json", .help = "print one JSON object instead of the table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (!imu || !gt) throw apps::usage_error("--imu and --groundtruth are required");
  check_ranges(o);
  o.imu = *imu;
  o.groundtruth = *gt;
  return o;
}

struct Window {
  double t_s;                 // start, seconds since the first ground-truth state
  double pos_m, rot_deg, vel_mps;
  double pos_3sigma_m, rot_3sigma_deg;
  double nees;
};

struct Stats {
  double rmse = 0, median = 0, p95 = 0, max = 0;
};

Stats stats_of(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  double sq = 0;
  for (double x : v) sq += x * x;
  s.rmse = std::sqrt(sq / double(v.size()));
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) { return v[std::size_t(std::floor(q * double(v.size() - 1) + 0.5))]; };
  s.median = at(0.5);
  s.p95 = at(0.95);
  s.max = v.back();
  return s;
}

struct Report {
  std::vector<Window> windows;
  double window_s = 0;    // median length of the evaluated windows
  double gt_step_s = 0;   // median step of the ground truth
  std::size_t skipped = 0;
  std::string first_skip_reason;
  double nees_mean = 0, nees_lo = 0, nees_hi = 0, inside = 0, win_lo = 0, win_hi = 0;
  Stats pos, rot, vel;
};

Report run_check(const Options& o) {
  // On a terminal, standard error shows the files being read and the windows.
  apps::TerminalProgress progress("imu_preintegration_check");
  progress.stage("reading " + o.imu.string());
  const std::vector<posefuse::ImuSample> imu = posefuse::read_euroc_imu(o.imu, o.imu_bounds);
  progress.stage("reading " + o.groundtruth.string());
  const posefuse::EurocGroundTruth gt = posefuse::read_euroc_groundtruth(o.groundtruth);
  progress.clear();
  if (!gt.has_velocity_and_biases())
    throw apps::data_error(o.groundtruth.string() +
                           ": needs velocity and biases (17 columns); this file has poses only");
  const auto window_ns = std::int64_t(std::llround(o.window_s * 1e9));  // range checked
  const Eigen::Vector3d g_w(0, 0, -o.gravity);
  Report r;
  if (gt.size() < 2)
    throw apps::data_error(o.groundtruth.string() + ": fewer than two ground-truth states");
  // The file's own sampling period: a gap is a step longer than 2.5 of it,
  // whatever the window.
  std::vector<std::int64_t> steps;
  for (std::size_t k = 1; k < gt.size(); ++k) steps.push_back(gt.t_ns[k] - gt.t_ns[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + std::ptrdiff_t(steps.size() / 2), steps.end());
  const std::int64_t step_ns = steps[steps.size() / 2];
  r.gt_step_s = double(step_ns) * 1e-9;
  // (the stamps jitter by well under 1 % of the step)
  if (window_ns < step_ns - step_ns / 100)
    std::fprintf(stderr,
                 "warning: --window %g s is shorter than the ground truth's period (%.4g s); each "
                 "window is one ground-truth step\n",
                 o.window_s, r.gt_step_s);
  std::vector<double> lengths;
  std::size_t i = 0;
  const double span_s = posefuse::seconds_between(gt.t_ns.back(), gt.t_ns.front());
  while (i + 1 < gt.size()) {
    progress.update([&] {
      char line[120];
      std::snprintf(line, sizeof line, "window %zu at t = %.1f of %.1f s", r.windows.size() + r.skipped + 1,
                    posefuse::seconds_between(gt.t_ns[i], gt.t_ns.front()), span_s);
      return std::string(line);
    });
    // Windows end on the ground-truth state nearest to t_i + window (at
    // least one step on), so the stamps' jitter does not add a step.
    std::size_t j = i + 1;
    while (j < gt.size() && gt.t_ns[j] - gt.t_ns[i] < window_ns - step_ns / 2) ++j;
    if (j == gt.size()) break;
    const std::int64_t t0 = gt.t_ns[i], t1 = gt.t_ns[j];
    const std::size_t start = i;
    i = j;
    bool gap = false;
    for (std::size_t k = start + 1; k <= j; ++k)
      gap = gap || double(gt.t_ns[k] - gt.t_ns[k - 1]) > 2.5 * double(step_ns);
    if (gap) {
      ++r.skipped;
      if (r.first_skip_reason.empty()) r.first_skip_reason = "a ground-truth gap";
      continue;
    }
    posefuse::Preintegration p(o.noise, posefuse::ImuBias{(*gt.accel_bias)[start], (*gt.gyro_bias)[start]});
    const posefuse::ImuStatus st = posefuse::preintegrate(imu, t0, t1, p);
    if (st != posefuse::ImuStatus::kApplied) {
      ++r.skipped;
      if (r.first_skip_reason.empty()) r.first_skip_reason = posefuse::to_string(st);
      continue;
    }
    const double T = p.dt_s();
    const posefuse::SO3d Ri(Eigen::Matrix3d(gt.trajectory.poses[start].linear()));
    const posefuse::SO3d Rj(Eigen::Matrix3d(gt.trajectory.poses[j].linear()));
    const Eigen::Vector3d pi = gt.trajectory.poses[start].translation();
    const Eigen::Vector3d pj = gt.trajectory.poses[j].translation();
    const Eigen::Vector3d vi = (*gt.velocity)[start], vj = (*gt.velocity)[j];
    const posefuse::SO3d Ri_inv = Ri.inverse();
    const posefuse::ImuDelta truth{Ri_inv.act(pj - pi - vi * T - 0.5 * g_w * T * T), Ri.between(Rj),
                                   Ri_inv.act(vj - vi - g_w * T)};
    const Eigen::Matrix<double, 9, 1> e = truth.minus(p.delta());
    const Eigen::Matrix<double, 9, 9> P = p.covariance().topLeftCorner<9, 9>();
    const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(P);
    const std::string at = short_number(posefuse::seconds_between(t0, gt.t_ns.front()));
    if (!P.allFinite() || !e.allFinite())
      throw apps::data_error("non-finite error or covariance in the window starting at t = " + at + " s");
    if (llt.info() != Eigen::Success)
      throw apps::data_error("the propagated covariance of the window at t = " + at +
                             " s is not positive definite");
    Window w;
    w.t_s = posefuse::seconds_between(t0, gt.t_ns.front());
    w.pos_m = e.head<3>().norm();
    w.rot_deg = e.segment<3>(3).norm() * 180.0 / std::numbers::pi;
    w.vel_mps = e.tail<3>().norm();
    w.pos_3sigma_m = 3.0 * std::sqrt(P.topLeftCorner<3, 3>().trace());
    w.rot_3sigma_deg = 3.0 * std::sqrt(P.block<3, 3>(3, 3).trace()) * 180.0 / std::numbers::pi;
    w.nees = e.dot(llt.solve(e));
    if (!std::isfinite(w.nees) || !std::isfinite(w.pos_m))
      throw apps::data_error("non-finite error in the window starting at t = " +
                             short_number(posefuse::seconds_between(t0, gt.t_ns.front())) + " s");
    r.windows.push_back(w);
    lengths.push_back(double(t1 - t0) * 1e-9);
  }
  if (r.windows.empty())
    throw apps::data_error("no window of " + short_number(o.window_s) +
                           " s could be evaluated (first reason: " +
                           (r.first_skip_reason.empty() ? std::string("sequence too short")
                                                        : r.first_skip_reason) +
                           ")");
  std::vector<double> pos, rot, vel;
  double nees_sum = 0;
  r.win_lo = posefuse::chi_square_quantile(0.025, 9);
  r.win_hi = posefuse::chi_square_quantile(0.975, 9);
  std::size_t inside = 0;
  for (const Window& w : r.windows) {
    pos.push_back(w.pos_m);
    rot.push_back(w.rot_deg);
    vel.push_back(w.vel_mps);
    nees_sum += w.nees;
    if (w.nees >= r.win_lo && w.nees <= r.win_hi) ++inside;
  }
  std::nth_element(lengths.begin(), lengths.begin() + std::ptrdiff_t(lengths.size() / 2), lengths.end());
  r.window_s = lengths[lengths.size() / 2];
  const int n = int(r.windows.size());
  r.pos = stats_of(pos);
  r.rot = stats_of(rot);
  r.vel = stats_of(vel);
  r.nees_mean = nees_sum / n;
  r.nees_lo = posefuse::chi_square_quantile(0.025, 9 * n) / n;
  r.nees_hi = posefuse::chi_square_quantile(0.975, 9 * n) / n;
  r.inside = double(inside) / n;
  return r;
}

const char* verdict(const Report& r) {
  if (r.nees_mean > r.nees_hi) return "over-confident: the errors are larger than the covariance says";
  if (r.nees_mean < r.nees_lo) return "under-confident: the covariance is larger than the errors";
  return "consistent: the mean NEES is inside its 95 % interval";
}

std::string plot_svg(const Report& r) {
  std::vector<apps::svg::Point> pe, ps, re, rs;
  for (const Window& w : r.windows) {
    pe.push_back({w.t_s, w.pos_m});
    ps.push_back({w.t_s, w.pos_3sigma_m});
    re.push_back({w.t_s, w.rot_deg});
    rs.push_back({w.t_s, w.rot_3sigma_deg});
  }
  apps::svg::Plot pos("position error per window");
  pos.x_axis("t", "s").y_axis("|e_p|", "m").include({0, 0});
  pos.line("error", pe, {"#d62728", 1.2, {}}).line("3 sigma (covariance)", ps, {"#1f77b4", 1.0, "5,3"});
  apps::svg::Plot rot("rotation error per window");
  rot.x_axis("t", "s").y_axis("|e_phi|", "deg").include({0, 0});
  rot.line("error", re, {"#d62728", 1.2, {}}).line("3 sigma (covariance)", rs, {"#1f77b4", 1.0, "5,3"});
  apps::svg::Document doc(1100, 480);
  doc.plot(pos, {0, 0, 550, 480}).plot(rot, {550, 0, 550, 480});
  return doc.str();
}

void print_table(const Options& o, const Report& r) {
  std::printf("IMU pre-integration vs ground truth: %zu windows of %.4g s", r.windows.size(), r.window_s);
  if (std::abs(r.window_s - o.window_s) > 1e-3 * o.window_s)
    std::printf(" (asked %g s; ground-truth states are %.4g s apart)", o.window_s, r.gt_step_s);
  std::printf(" (%zu skipped%s%s)\n", r.skipped, r.skipped ? ", first: " : "", r.first_skip_reason.c_str());
  std::printf("error                 rmse    median       p95       max\n");
  const auto row = [](const char* name, const Stats& s) {
    std::printf("%-16s %9.4f %9.4f %9.4f %9.4f\n", name, s.rmse, s.median, s.p95, s.max);
  };
  row("position [m]", r.pos);
  row("rotation [deg]", r.rot);
  row("velocity [m/s]", r.vel);
  std::printf("NEES (9 dof): mean %.2f, 95 %% interval of the mean [%.2f, %.2f]; %.0f %% of windows "
              "inside the per-window 95 %% interval [%.2f, %.2f]\n",
              r.nees_mean, r.nees_lo, r.nees_hi, 100.0 * r.inside, r.win_lo, r.win_hi);
  std::printf("verdict: %s\n", verdict(r));
}

void print_json(const Options& o, const Report& r) {
  apps::JsonWriter j(std::cout);
  j.begin_object(apps::JsonWriter::Layout::kInline);
  j.member("window_s", r.window_s).member("window_asked_s", o.window_s);
  j.member("windows", r.windows.size()).member("skipped", r.skipped);
  j.member("position_error_rmse", r.pos.rmse).member("position_error_median", r.pos.median);
  j.member("position_error_max", r.pos.max);
  j.member("rotation_error_rmse_deg", r.rot.rmse).member("rotation_error_median_deg", r.rot.median);
  j.member("rotation_error_max_deg", r.rot.max);
  j.member("velocity_error_rmse", r.vel.rmse);
  j.member("nees_mean", r.nees_mean).member("nees_mean_lower", r.nees_lo);
  j.member("nees_mean_upper", r.nees_hi).member("nees_fraction_inside", r.inside);
  j.member("consistent", r.nees_mean >= r.nees_lo && r.nees_mean <= r.nees_hi);
  j.end_object().finish();
}

int run(const Options& o) {
  const Report r = run_check(o);
  apps::OutputFiles files;
  if (o.svg) files.add(*o.svg, plot_svg(r));
  files.commit();
  if (o.json) print_json(o, r);
  else print_table(o, r);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

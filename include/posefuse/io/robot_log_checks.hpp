#pragma once
/// @file
/// Plausibility checks of a whole seed-001 robot log (robot_log.hpp), for
/// logs from robots the project has not seen: a log that parses but would
/// silently give wrong numbers is rejected with posefuse::io_error naming the
/// file (and line, where the problem is one line), and softer doubts are
/// returned as warnings.
///
/// Errors (check_robot_log, also run by read_robot_log):
/// * clocks: every stream's [first, last] t_ns must overlap wheels.csv's by at
///   least 50 % of the shorter of the two spans, and the spans must not differ
///   by more than 100x (a file written in µs, ms or s, or on another epoch);
/// * imu.csv: the median of the first 50 rows must have az > 0 and gravity
///   mostly on z (specific force +9.81 on z at rest, z up, REP-103);
/// * slam.csv: at most half of the valid poses may be tilted by more than 20°
///   from z-up (a camera-frame pose, z forward, y down, is tilted by 90°);
/// * wheels.csv: no increment may imply more than 10 m/s at the robot.txt
///   geometry (a counter wrapping around or being reset).
///
/// Warnings (returned): a minority of tilted SLAM poses; an encoder path that
/// turns far more than it travels, front and back wheels of one side that
/// disagree, or a mostly backwards path (an encoder counting backwards);
/// ground truth whose first pose is not at the odometry origin with yaw 0.
///
/// Every time and tick difference is computed without integer overflow
/// (seconds_between, saturating_difference), so stamps or counters anywhere
/// in the int64 range give messages, not undefined behaviour.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <span>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/io/robot_log_records.hpp>

namespace posefuse {

/// Thresholds of the robot-log checks (see the file comment).
struct RobotLogLimits {
  double max_wheel_speed_mps = 10.0;  ///< one encoder increment may imply at most this
  double max_slam_tilt_deg = 20.0;    ///< a SLAM pose tilted more than this counts as tilted
  double min_clock_overlap = 0.5;     ///< of the shorter span
  double max_span_ratio = 100.0;      ///< longest / shortest span of a stream and wheels.csv
  std::size_t imu_rest_rows = 50;     ///< rows whose median checks the IMU axes
  double gt_origin_tol_m = 0.1;       ///< first ground-truth pose: distance from the origin
  double gt_yaw_tol_deg = 5.0;        ///< first ground-truth pose: yaw
};

namespace detail {

template <class Lazy = void>
std::filesystem::path log_file(const std::filesystem::path& dir, const char* name) {
  return dir.empty() ? std::filesystem::path(name) : dir / name;
}

/// `v` in fixed notation with `prec` decimals, never truncated (1e300 takes
/// 301 digits) and locale-free ("C" formatting of std::to_chars).
template <class Lazy = void>
std::string num_text(double v, int prec) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
  // Digits before the point: at most 309 for a double; after it: prec.
  std::string s(std::size_t(330 + std::max(0, prec)), '\0');
  const auto [ptr, ec] =
      std::to_chars(s.data(), s.data() + s.size(), v, std::chars_format::fixed, std::max(0, prec));
  s.resize(ec == std::errc{} ? std::size_t(ptr - s.data()) : 0);
  return s;
}

template <class Lazy = void>
double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + std::ptrdiff_t(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace detail

/// True when a SLAM pose's body z axis is more than `max_deg` from the map's z:
/// \f$ R_{22} = 1 - 2 (q_x^2 + q_y^2) / |q|^2 < \cos(\mathrm{max\_deg}) \f$.
/// @param[in] r the SLAM sample (its quaternion need not be normalised)
/// @param[in] max_deg tilt limit (deg)
/// @return true when tilted; false for a zero or NaN quaternion
template <class Lazy = void>
[[nodiscard]] bool slam_pose_tilted(const SlamSample& r, double max_deg = 20.0) noexcept {
  const auto& q = r.orientation.coeffs();  // x, y, z, w
  const double n2 = q(0) * q(0) + q(1) * q(1) + q(2) * q(2) + q(3) * q(3);
  if (!(n2 > 0)) return false;
  const double cos_tilt = 1.0 - 2.0 * (q(0) * q(0) + q(1) * q(1)) / n2;  // R(2, 2)
  return cos_tilt < std::cos(max_deg * std::numbers::pi / 180.0);
}

/// Throws when one wheels.csv increment implies more than the speed limit.
/// @param[in] w the wheel samples of wheels.csv
/// @param[in] p the robot's parameters (ticks per revolution, wheel radius)
/// @param[in] file wheels.csv's path, for the messages
/// @param[in] lim the limits (the speed limit among them)
/// @param[in] lines 1-based line of each row (empty: "data row K" is named)
/// @throws posefuse::io_error (file:line) naming wheel, ticks, time and speed
template <class Lazy = void>
void check_wheel_increments(const std::vector<WheelSample>& w, const RobotLogParams& p,
                            const std::filesystem::path& file,
                            std::span<const std::size_t> lines = {},
                            const RobotLogLimits& lim = {}) {
  const double m_per_tick = 2 * std::numbers::pi * p.wheel_radius_m / p.ticks_per_rev;
  if (!(m_per_tick > 0) || !std::isfinite(m_per_tick)) return;  // robot.txt is checked elsewhere
  static constexpr const char* kNames[4] = {"fl", "fr", "bl", "br"};
  for (std::size_t i = 1; i < w.size(); ++i) {
    const double dt = seconds_between(w[i].t_ns, w[i - 1].t_ns);
    const WheelTicks& x = w[i - 1].ticks;
    const WheelTicks& y = w[i].ticks;
    const std::int64_t a[4] = {x.fl, x.fr, x.bl, x.br};
    const std::int64_t b[4] = {y.fl, y.fr, y.bl, y.br};
    for (std::size_t k = 0; k < 4; ++k) {
      const double d = std::abs(double(saturating_difference(b[k], a[k])));
      const double v = std::max(0.0, d - 1.0) * m_per_tick / dt;  // one tick of quantisation
      if (!(v > lim.max_wheel_speed_mps)) continue;
      const std::string why =
          std::string(kNames[k]) + " jumps from " + std::to_string(a[k]) + " to " +
          std::to_string(b[k]) + " ticks in " + detail::num_text(dt, 4) + " s, i.e. " +
          detail::num_text(v, 1) + " m/s with ticks_per_rev " + detail::num_text(p.ticks_per_rev, 0) +
          " and wheel_radius_m " + detail::num_text(p.wheel_radius_m, 4) + " (more than " +
          detail::num_text(lim.max_wheel_speed_mps, 0) +
          " m/s): encoder counter wrap-around or reset (wheels.csv needs cumulative, unwrapped "
          "ticks), or t_ns not in nanoseconds?";
      if (lines.size() == w.size()) throw io_error(file, lines[i], why);
      throw io_error(file, "data row " + std::to_string(i + 1) + ": " + why);
    }
  }
}

/// Throws unless the first rows of imu.csv read gravity as +z (REP-103).
template <class Lazy = void>
void check_imu_axes(const std::vector<ImuSample>& imu, const std::filesystem::path& file,
                    const RobotLogLimits& lim = {}) {
  const std::size_t n = std::min(imu.size(), lim.imu_rest_rows);
  if (n == 0) return;
  std::vector<double> ax, ay, az;
  for (std::size_t i = 0; i < n; ++i) {
    ax.push_back(imu[i].accel_mps2.x());
    ay.push_back(imu[i].accel_mps2.y());
    az.push_back(imu[i].accel_mps2.z());
  }
  const double mx = detail::median_of(ax), my = detail::median_of(ay), mz = detail::median_of(az);
  const std::string med = "median (ax, ay, az) of the first " + std::to_string(n) + " rows is (" +
                          detail::num_text(mx, 2) + ", " + detail::num_text(my, 2) + ", " +
                          detail::num_text(mz, 2) + ") m/s^2";
  const char* expect = "expected specific force +9.81 on z at rest, z up (REP-103)";
  if (!(mz > 0)) throw io_error(file, med + ": az is not positive; " + expect);
  if (std::hypot(mx, my) > mz)
    throw io_error(file, med + ": gravity is mostly on x/y, not z; " + expect);
}

/// Counts the valid SLAM poses tilted more than the limit from z-up.
/// @return the count; throws when it is more than half of the valid poses
/// @throws posefuse::io_error naming the file
template <class Lazy = void>
int check_slam_tilt(const std::vector<SlamSample>& slam, const std::filesystem::path& file,
                    const RobotLogLimits& lim = {}) {
  int valid = 0, tilted = 0;
  for (const SlamSample& r : slam) {
    if (r.state == SlamState::kLost) continue;
    ++valid;
    tilted += slam_pose_tilted(r, lim.max_slam_tilt_deg);
  }
  if (2 * tilted > valid)
    throw io_error(file, std::to_string(tilted) + " of " + std::to_string(valid) +
                             " poses tilted more than " + detail::num_text(lim.max_slam_tilt_deg, 0) +
                             " deg from z-up; expected robot body poses in a z-up map frame "
                             "(REP-103), not camera poses (z forward, y down): convert them first");
  return tilted;
}

/// Throws when a stream's time span does not match wheels.csv's (another
/// unit or epoch; see the file comment).
template <class Lazy = void>
void check_stream_clocks(const RobotLog& log, const std::filesystem::path& dir,
                         const RobotLogLimits& lim = {}) {
  if (log.wheels.size() < 2) return;
  const double wa = double(log.wheels.front().t_ns), wb = double(log.wheels.back().t_ns);
  const auto check = [&](const char* name, double a, double b) {
    const double sw = wb - wa, ss = b - a;
    const double overlap = std::max(0.0, std::min(b, wb) - std::max(a, wa));
    const double shorter = std::min(sw, ss), longer = std::max(sw, ss);
    const bool ok = shorter > 0 ? overlap >= lim.min_clock_overlap * shorter &&
                                      longer <= lim.max_span_ratio * shorter
                                : a >= wa && a <= wb;  // a single row must lie inside
    if (ok) return;
    const auto span = [](double x, double y) {
      return "[" + detail::num_text(x, 0) + ", " + detail::num_text(y, 0) + "] (" +
             detail::num_text((y - x) * 1e-9, 3) + " s)";
    };
    throw io_error(detail::log_file(dir, name),
                   "t_ns spans " + span(a, b) + " but wheels.csv spans " + span(wa, wb) +
                       ": they overlap by " + detail::num_text(shorter > 0 ? 100 * overlap / shorter : 0, 0) +
                       " % of the shorter span (at least " +
                       detail::num_text(100 * lim.min_clock_overlap, 0) +
                       " % needed, spans within " + detail::num_text(lim.max_span_ratio, 0) +
                       "x); every file needs t_ns in nanoseconds on the same clock");
  };
  if (!log.imu.empty()) check("imu.csv", double(log.imu.front().t_ns), double(log.imu.back().t_ns));
  if (!log.slam.empty())
    check("slam.csv", double(log.slam.front().t_ns), double(log.slam.back().t_ns));
  if (!log.groundtruth.empty())
    check("groundtruth.csv", double(log.groundtruth.front().t_ns),
          double(log.groundtruth.back().t_ns));
}

/// Warnings about the encoder path: turning far more than travelling, front
/// and back wheels of a side disagreeing, driving mostly backwards.
template <class Lazy = void>
[[nodiscard]] std::vector<std::string> wheel_path_warnings(const std::vector<WheelSample>& w,
                                                           const RobotLogParams& p,
                                                           const std::filesystem::path& file) {
  std::vector<std::string> out;
  if (w.size() < 2 || !(p.ticks_per_rev > 0) || !(p.track_width_m > 0)) return out;
  const double m = 2 * std::numbers::pi * p.wheel_radius_m / p.ticks_per_rev;
  double sum_th = 0, sum_abs_ds = 0, sum_ds = 0;
  // Tick differences saturate instead of overflowing; their sums are taken in
  // double (exact for the counts of any real log, |sum| < 2^53).
  const auto delta = [](std::int64_t now, std::int64_t before) {
    return double(saturating_difference(now, before));
  };
  for (std::size_t i = 1; i < w.size(); ++i) {
    const WheelTicks& a = w[i - 1].ticks;
    const WheelTicks& b = w[i].ticks;
    const double dl = 0.5 * m * (delta(b.fl, a.fl) + delta(b.bl, a.bl));
    const double dr = 0.5 * m * (delta(b.fr, a.fr) + delta(b.br, a.br));
    sum_ds += 0.5 * (dl + dr);
    sum_abs_ds += std::abs(0.5 * (dl + dr));
    sum_th += (dr - dl) / p.track_width_m;
  }
  const std::string f = file.string() + ": ";
  if (std::abs(sum_th) > 4 * std::numbers::pi && std::abs(sum_th) > 2.0 * sum_abs_ds)
    out.push_back(f + "the encoder path turns " + detail::num_text(std::abs(sum_th) / (2 * std::numbers::pi), 1) +
                  " full turns over only " + detail::num_text(sum_abs_ds, 2) +
                  " m of travel: does one side count backwards (signs of fl, fr, bl, br)?");
  if (sum_ds < -0.5 * sum_abs_ds && sum_abs_ds > 1.0)
    out.push_back(f + "the encoder path runs mostly backwards (net " + detail::num_text(sum_ds, 2) +
                  " m of " + detail::num_text(sum_abs_ds, 2) +
                  " m): forward motion must count up on every wheel");
  const auto side = [&](const char* name, double front, double back) {
    const double a = m * front, b = m * back;
    if (std::max(std::abs(a), std::abs(b)) > 1.0 && std::abs(a - b) > 0.25 * std::max(std::abs(a), std::abs(b)))
      out.push_back(f + "the " + name + " wheels disagree (front " + detail::num_text(a, 2) +
                    " m, back " + detail::num_text(b, 2) +
                    " m net): an encoder counts backwards, is mislabelled or slips");
  };
  const WheelTicks& first = w.front().ticks;
  const WheelTicks& last = w.back().ticks;
  side("left", delta(last.fl, first.fl), delta(last.bl, first.bl));
  side("right", delta(last.fr, first.fr), delta(last.br, first.br));
  return out;
}

/// Runs every check of the file comment on a whole log.
/// @param[in] lim the limits of the checks
/// @param[in] log the log
/// @param[in] dir its folder, for the file names in messages (empty: bare names)
/// @return the warnings, each starting with the file name
/// @throws posefuse::io_error for the errors of the file comment
template <class Lazy = void>
[[nodiscard]] std::vector<std::string> check_robot_log(const RobotLog& log,
                                                       const std::filesystem::path& dir = {},
                                                       const RobotLogLimits& lim = {}) {
  std::vector<std::string> warnings;
  check_stream_clocks(log, dir, lim);
  check_wheel_increments(log.wheels, log.params, detail::log_file(dir, "wheels.csv"), {}, lim);
  check_imu_axes(log.imu, detail::log_file(dir, "imu.csv"), lim);
  const auto slam_file = detail::log_file(dir, "slam.csv");
  const int tilted = check_slam_tilt(log.slam, slam_file, lim);
  if (tilted > 0)
    warnings.push_back(slam_file.string() + ": " + std::to_string(tilted) +
                       " valid poses are tilted more than " +
                       detail::num_text(lim.max_slam_tilt_deg, 0) +
                       " deg from z-up (expected robot body poses in a z-up map frame)");
  for (auto& s : wheel_path_warnings(log.wheels, log.params, detail::log_file(dir, "wheels.csv")))
    warnings.push_back(std::move(s));
  if (!log.groundtruth.empty()) {
    const Eigen::Vector3d& g = log.groundtruth.front().pose;  // x, y, yaw
    const double yaw = std::remainder(g(2), 2 * std::numbers::pi);
    if (std::hypot(g(0), g(1)) > lim.gt_origin_tol_m ||
        std::abs(yaw) > lim.gt_yaw_tol_deg * std::numbers::pi / 180.0)
      warnings.push_back(detail::log_file(dir, "groundtruth.csv").string() +
                         ": the first pose is (" + detail::num_text(g(0), 2) + " m, " +
                         detail::num_text(g(1), 2) + " m, " +
                         detail::num_text(yaw * 180.0 / std::numbers::pi, 1) +
                         " deg), not the origin with yaw 0; the metrics (RMSE, yaw errors) assume "
                         "ground truth in the odometry frame (the robot's pose at its first sample)");
  }
  return warnings;
}

}  // namespace posefuse

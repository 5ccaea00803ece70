#pragma once
/// @file
/// The recorded-log folder of seed 001's corridor experiment (docs/programs.md):
/// reader and writer with file:line errors. The rows become the library's raw
/// samples (core/samples.hpp): WheelSample, ImuSample, SlamSample and, for
/// ground truth, PlanarPoseSample.
///
/// A log is a folder holding
///
/// | file              | columns                                   | units                     |
/// |-------------------|-------------------------------------------|---------------------------|
/// | `wheels.csv`      | `t_ns,fl,fr,bl,br`                        | cumulative encoder ticks  |
/// | `imu.csv`         | `t_ns,ax,ay,az,gx,gy,gz,mx,my,mz`         | m/s², rad/s, µT           |
/// | `slam.csv`        | `t_ns,state,x,y,z,qx,qy,qz,qw`            | m, unit quaternion        |
/// | `robot.txt`       | `key value` lines                         | see RobotLogParams        |
/// | `groundtruth.csv` | `t_ns,x,y,yaw` (optional)                 | m, rad                    |
///
/// * IMU axes are the robot body frame of ROS REP-103 (x forward, y left,
///   z up); the accelerometer reads specific force (+9.81 on z at rest).
/// * `state` is `tracking`, `lost` or `reinit` (any letter case); a `reinit`
///   row starts a new SLAM map frame (its pose is the first pose in that
///   frame). The SLAM pose is the body pose in the current map frame, z up.
///   In `lost` rows the pose is ignored and may be NaN or empty. Quaternions
///   of other rows must have unit length within 1e-2.
/// * The ground-truth world frame is the odometry frame: origin and heading
///   of the robot at its first sample.
/// * Lines starting with `#` are comments; blank lines are skipped; one
///   column-name line without `#` (e.g. `t_ns,fl,fr,bl,br`) is accepted before
///   the first data row. `\r\n` line ends and spaces around fields are fine.
/// * `t_ns` must increase strictly within each file; the files need not share
///   timestamps.
/// * A present `groundtruth.csv` must have data rows (remove it otherwise);
///   `wheels.csv` needs two rows and `imu.csv` one. Lines are at most
///   kMaxLineBytes long.
///
/// Every malformed input throws posefuse::io_error whose what() is
/// `"<file>:<line>: <reason>"` (wrong column count, bad number, NaN/Inf,
/// unknown state, non-increasing t_ns, unknown/duplicate/missing key,
/// non-positive parameter, missing required file), and so does a log that
/// parses but cannot be right (robot_log_checks.hpp: clocks in another unit,
/// IMU axes not z-up, camera-frame SLAM poses, encoder wrap-around).

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <Eigen/Core>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/io/detail/robot_log_csv.hpp>
#include <posefuse/io/robot_log_checks.hpp>
#include <posefuse/io/robot_log_records.hpp>

namespace posefuse {

/// Reads `robot.txt` (`key value` lines, `#` comments, also after a value).
/// @param[in] file path of robot.txt
/// @return the five parameters
/// @throws posefuse::io_error (file:line) for a missing file, an unknown or
///         duplicate key, a line that is not `key value`, a bad, non-finite or
///         non-positive value, alpha outside (0, 1), or a missing key
template <class Lazy = void>
[[nodiscard]] RobotLogParams read_robot_params(const std::filesystem::path& file) {
  RobotLogParams p;
  struct Key {
    std::string_view name;
    double* value;
    std::size_t line;
  };
  std::array<Key, 5> keys{{{"ticks_per_rev", &p.ticks_per_rev, 0},
                           {"wheel_radius_m", &p.wheel_radius_m, 0},
                           {"track_width_m", &p.track_width_m, 0},
                           {"complementary_alpha", &p.complementary_alpha, 0},
                           {"fuser_threshold", &p.fuser_threshold, 0}}};
  for (const auto& [n, full] : detail::read_content_lines(file)) {
    std::string_view text = full;
    if (const std::size_t h = text.find('#'); h != std::string_view::npos)
      text = detail::trim_blanks(text.substr(0, h));
    const std::size_t sp = text.find_first_of(" \t=");
    if (sp == std::string_view::npos)
      throw io_error(file, n, "expected 'key value', got '" + std::string(text) + "'");
    const std::string key = detail::lower(detail::trim_blanks(text.substr(0, sp)));
    std::string_view val = detail::trim_blanks(text.substr(sp + 1));
    if (!val.empty() && val.front() == '=') val = detail::trim_blanks(val.substr(1));
    Key* k = nullptr;
    for (Key& c : keys) {
      if (c.name == key) k = &c;
    }
    if (k == nullptr)
      throw io_error(file, n, "unknown key '" + key +
                                  "' (expected ticks_per_rev, wheel_radius_m, track_width_m, "
                                  "complementary_alpha, fuser_threshold)");
    if (k->line != 0)
      throw io_error(file, n, "duplicate key '" + key + "' (first on line " +
                                  std::to_string(k->line) + ")");
    double v = 0;
    const auto [ptr, ec] = std::from_chars(val.data(), val.data() + val.size(), v);
    if (val.empty() || ec != std::errc{} || ptr != val.data() + val.size())
      throw io_error(file, n, "value of '" + key + "' is not a number ('" + std::string(val) + "')");
    if (!std::isfinite(v) || v <= 0)
      throw io_error(file, n, "value of '" + key + "' must be positive and finite, got " +
                                  std::string(val));
    if (key == "complementary_alpha" && v >= 1)
      throw io_error(file, n, "complementary_alpha must lie in (0, 1), got " + std::string(val));
    *k->value = v;
    k->line = n;
  }
  for (const Key& k : keys) {
    if (k.line == 0) throw io_error(file, "missing required key '" + std::string(k.name) + "'");
  }
  return p;
}

/// Reads a log folder (see the file comment for the format).
/// @param[in] dir the folder holding wheels.csv, imu.csv, slam.csv, robot.txt
///            and optionally groundtruth.csv
/// @return the log, rows in file order
/// @throws posefuse::io_error naming file and line for anything malformed;
///         also when wheels.csv has fewer than two rows, imu.csv or a present
///         groundtruth.csv none, a path cannot be accessed (e.g. a name too
///         long), a read fails or a line is longer than kMaxLineBytes, and
///         for the errors of check_robot_log()
template <class Lazy = void>
[[nodiscard]] RobotLog read_robot_log(const std::filesystem::path& dir) {
  using detail::CsvLine;
  if (!std::filesystem::is_directory(detail::checked_status(dir)))
    throw io_error(dir, "log folder does not exist");
  RobotLog log;
  log.params = read_robot_params(dir / "robot.txt");
  const auto wheels_file = dir / "wheels.csv";
  std::vector<std::size_t> wheel_lines;
  log.wheels = detail::read_csv<WheelSample>(wheels_file, detail::kWheelCols, [](CsvLine& c) {
    WheelSample r;
    r.t_ns = c.integer();
    r.ticks.fl = c.integer();
    r.ticks.fr = c.integer();
    r.ticks.bl = c.integer();
    r.ticks.br = c.integer();
    return r;
  }, &wheel_lines);
  if (log.wheels.size() < 2) throw io_error(wheels_file, "needs at least two data rows");
  check_wheel_increments(log.wheels, log.params, wheels_file, wheel_lines);
  const auto imu_file = dir / "imu.csv";
  log.imu = detail::read_csv<ImuSample>(imu_file, detail::kImuCols, [](CsvLine& c) {
    ImuSample r;
    r.t_ns = c.integer();
    for (Eigen::Index i = 0; i < 3; ++i) r.accel_mps2(i) = c.real();
    for (Eigen::Index i = 0; i < 3; ++i) r.gyro_radps(i) = c.real();
    for (Eigen::Index i = 0; i < 3; ++i) r.mag_uT(i) = c.real();
    return r;
  });
  if (log.imu.empty()) throw io_error(imu_file, "has no data rows");
  const auto slam_file = dir / "slam.csv";
  log.slam = detail::read_csv<SlamSample>(slam_file, detail::kSlamCols, [](CsvLine& c) {
    SlamSample r;
    r.t_ns = c.integer();
    const std::string_view s = c.text();
    const std::string st = detail::lower(s);
    if (st == "tracking") r.state = SlamState::kTracking;
    else if (st == "lost") r.state = SlamState::kLost;
    else if (st == "reinit") r.state = SlamState::kReinit;
    else c.fail("tracking, lost or reinit", s);
    const bool lost = r.state == SlamState::kLost;
    for (Eigen::Index i = 0; i < 3; ++i) r.position_m(i) = c.real(lost);
    auto& q = r.orientation.coeffs();  // x, y, z, w: the file's column order
    for (Eigen::Index i = 0; i < 4; ++i) q(i) = c.real(lost);
    if (!lost) {
      const double n2 = q(0) * q(0) + q(1) * q(1) + q(2) * q(2) + q(3) * q(3);
      if (!(std::abs(std::sqrt(n2) - 1.0) < 1e-2))
        c.error("quaternion (qx,qy,qz,qw) is not unit length (|q| = " +
                detail::fmt(std::sqrt(n2)) + ")");
    }
    return r;
  });
  const auto gt_file = dir / "groundtruth.csv";
  if (detail::checked_status(gt_file).type() != std::filesystem::file_type::not_found) {
    log.groundtruth =
        detail::read_csv<PlanarPoseSample>(gt_file, detail::kTruthCols, [](CsvLine& c) {
          PlanarPoseSample r;
          r.t_ns = c.integer();
          for (Eigen::Index i = 0; i < 3; ++i) r.pose(i) = c.real();  // x, y, yaw
          return r;
        });
    // An empty file would otherwise be read as "no ground truth" in silence.
    if (log.groundtruth.empty())
      throw io_error(gt_file, "has no data rows (remove the file when there is no ground truth)");
  }
  (void)check_robot_log(log, dir);  // clocks, IMU axes, SLAM tilt; warnings: run_corridor
  return log;
}

/// Writes a log folder in exactly the format read_robot_log reads (creating
/// the folder). Numbers are written in the shortest form that reads back to
/// the same double, so a written log reads back bit-identical. Every file is
/// written with the classic "C" locale, whatever the global locale (a digit
/// grouping such as `1,700,000,000` would not read back).
/// @param[in] dir destination folder (created if absent; files overwritten)
/// @param[in] log the log; groundtruth.csv is written only when non-empty
/// @throws posefuse::io_error when a file cannot be written
template <class Lazy = void>
void write_robot_log(const std::filesystem::path& dir, const RobotLog& log) {
  using detail::fmt;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw io_error(dir, "cannot create folder: " + ec.message());
  const auto write = [&dir](const char* name, const char* header, auto&& body) {
    auto out = detail::open_for_writing(dir / name);
    out << header;
    body(out);
    if (!out.flush()) throw io_error(dir / name, "write failed");
  };
  const auto& P = log.params;
  write("robot.txt", "# posefuse robot log parameters (key value)\n", [&](std::ostream& o) {
    o << "ticks_per_rev " << fmt(P.ticks_per_rev) << "\nwheel_radius_m " << fmt(P.wheel_radius_m)
      << "\ntrack_width_m " << fmt(P.track_width_m) << "\ncomplementary_alpha "
      << fmt(P.complementary_alpha) << "\nfuser_threshold " << fmt(P.fuser_threshold) << "\n";
  });
  write("wheels.csv", "# t_ns,fl,fr,bl,br\n", [&](std::ostream& o) {
    for (const auto& r : log.wheels)
      o << r.t_ns << ',' << r.ticks.fl << ',' << r.ticks.fr << ',' << r.ticks.bl << ','
        << r.ticks.br << '\n';
  });
  write("imu.csv", "# t_ns,ax,ay,az,gx,gy,gz,mx,my,mz\n", [&](std::ostream& o) {
    for (const auto& r : log.imu) {
      o << r.t_ns;
      for (const Eigen::Vector3d* a : {&r.accel_mps2, &r.gyro_radps, &r.mag_uT})
        for (Eigen::Index i = 0; i < 3; ++i) o << ',' << fmt((*a)(i));
      o << '\n';
    }
  });
  write("slam.csv", "# t_ns,state,x,y,z,qx,qy,qz,qw\n", [&](std::ostream& o) {
    for (const auto& r : log.slam) {
      o << r.t_ns << ',' << to_string(r.state);
      for (Eigen::Index i = 0; i < 3; ++i) o << ',' << fmt(r.position_m(i));
      for (Eigen::Index i = 0; i < 4; ++i) o << ',' << fmt(r.orientation.coeffs()(i));  // x y z w
      o << '\n';
    }
  });
  if (log.groundtruth.empty()) {
    std::filesystem::remove(dir / "groundtruth.csv", ec);  // no stale ground truth
    return;
  }
  write("groundtruth.csv", "# t_ns,x,y,yaw\n", [&](std::ostream& o) {
    for (const auto& r : log.groundtruth)
      o << r.t_ns << ',' << fmt(r.pose(0)) << ',' << fmt(r.pose(1)) << ',' << fmt(r.pose(2)) << '\n';
  });
}

}  // namespace posefuse

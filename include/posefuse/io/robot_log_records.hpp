#pragma once
/// @file
/// The contents of a seed-001 robot log folder: the robot.txt parameters and
/// the RobotLog container, whose streams are the library's raw sample types
/// (core/samples.hpp). See robot_log.hpp for the format, reader and writer,
/// and robot_log_checks.hpp for the plausibility checks applied to a whole log.

#include <string_view>
#include <vector>

#include <posefuse/core/samples.hpp>

namespace posefuse {

/// The `robot.txt` parameters; all are required and must be positive.
struct RobotLogParams {
  double ticks_per_rev{0};        ///< encoder ticks per wheel revolution
  double wheel_radius_m{0};       ///< wheel radius (m) — seed eq 9 (not the diameter)
  double track_width_m{0};        ///< distance between left and right wheels (m), seed eq 9 `d`
  double complementary_alpha{0};  ///< complementary-filter constant, 0 < alpha < 1 (seed eq 3-4)
  double fuser_threshold{0};      ///< seed eq 15 threshold on O_diff (m·rad)
  /// All parameters equal.
  friend bool operator==(const RobotLogParams&, const RobotLogParams&) = default;
};

/// A whole recorded log: one stream per file, rows in file order (`t_ns`
/// strictly increasing within each stream when read by read_robot_log).
struct RobotLog {
  RobotLogParams params;                        ///< robot.txt
  std::vector<WheelSample> wheels;              ///< wheels.csv
  std::vector<ImuSample> imu;                   ///< imu.csv
  std::vector<SlamSample> slam;                 ///< slam.csv
  std::vector<PlanarPoseSample> groundtruth;    ///< groundtruth.csv (x, y, yaw; empty when absent)
  /// Every stream and parameter equal (NaN compares unequal).
  friend bool operator==(const RobotLog&, const RobotLog&) = default;
};

/// The text `slam.csv` uses for a state.
[[nodiscard]] constexpr std::string_view to_string(SlamState s) noexcept {
  return s == SlamState::kTracking ? "tracking" : s == SlamState::kLost ? "lost" : "reinit";
}

}  // namespace posefuse

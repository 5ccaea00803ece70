#pragma once
/// @file
/// The records of a seed-001 robot log folder (see robot_log.hpp for the
/// format, reader and writer, and robot_log_checks.hpp for the plausibility
/// checks applied to a whole log).

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace posefuse {

/// One row of `wheels.csv`: cumulative ticks of the four wheels at `t_ns`.
struct WheelRecord {
  std::int64_t t_ns{0};  ///< timestamp (ns)
  std::int64_t fl{0};    ///< front-left cumulative ticks
  std::int64_t fr{0};    ///< front-right cumulative ticks
  std::int64_t bl{0};    ///< back-left cumulative ticks
  std::int64_t br{0};    ///< back-right cumulative ticks
  friend bool operator==(const WheelRecord&, const WheelRecord&) = default;
};

/// One row of `imu.csv`, body frame x forward, y left, z up (REP-103).
struct ImuRecord {
  std::int64_t t_ns{0};                 ///< timestamp (ns)
  std::array<double, 3> accel_mps2{};   ///< specific force (m/s²), +9.81 on z at rest
  std::array<double, 3> gyro_radps{};   ///< angular rate (rad/s)
  std::array<double, 3> mag_uT{};       ///< magnetic field (µT), as measured (uncalibrated)
  friend bool operator==(const ImuRecord&, const ImuRecord&) = default;
};

/// Tracking state of a SLAM row.
enum class SlamState {
  kTracking,  ///< pose valid in the current map frame
  kLost,      ///< no pose (the row's pose fields are ignored)
  kReinit     ///< first pose of a new map frame
};

/// One row of `slam.csv`: body pose in the current SLAM map frame.
struct SlamRecord {
  std::int64_t t_ns{0};                   ///< timestamp (ns)
  SlamState state{SlamState::kLost};      ///< tracking / lost / reinit
  std::array<double, 3> p{};              ///< position (m) in the map frame
  std::array<double, 4> q{0, 0, 0, 1};    ///< orientation quaternion (x, y, z, w)
  friend bool operator==(const SlamRecord&, const SlamRecord&) = default;
};

/// One row of the optional `groundtruth.csv` (world = odometry frame).
struct GroundTruthRecord {
  std::int64_t t_ns{0};  ///< timestamp (ns)
  double x{0};           ///< position x (m)
  double y{0};           ///< position y (m)
  double yaw{0};         ///< heading (rad)
  friend bool operator==(const GroundTruthRecord&, const GroundTruthRecord&) = default;
};

/// The `robot.txt` parameters; all are required and must be positive.
struct RobotLogParams {
  double ticks_per_rev{0};        ///< encoder ticks per wheel revolution
  double wheel_radius_m{0};       ///< wheel radius (m) — seed eq 9 (not the diameter)
  double track_width_m{0};        ///< distance between left and right wheels (m), seed eq 9 `d`
  double complementary_alpha{0};  ///< complementary-filter constant, 0 < alpha < 1 (seed eq 3-4)
  double fuser_threshold{0};      ///< seed eq 15 threshold on O_diff (m·rad)
  friend bool operator==(const RobotLogParams&, const RobotLogParams&) = default;
};

/// A whole recorded log (all streams kept in file order).
struct RobotLog {
  RobotLogParams params;                     ///< robot.txt
  std::vector<WheelRecord> wheels;           ///< wheels.csv
  std::vector<ImuRecord> imu;                ///< imu.csv
  std::vector<SlamRecord> slam;              ///< slam.csv
  std::vector<GroundTruthRecord> groundtruth;  ///< groundtruth.csv (empty when absent)
  friend bool operator==(const RobotLog&, const RobotLog&) = default;
};

/// The text `slam.csv` uses for a state.
[[nodiscard]] constexpr std::string_view to_string(SlamState s) noexcept {
  return s == SlamState::kTracking ? "tracking" : s == SlamState::kLost ? "lost" : "reinit";
}

}  // namespace posefuse

#pragma once
/// @file
/// The raw sensor samples of the library: one type per kind of measurement,
/// each stamped with an integer `t_ns` (the time convention of
/// core/time.hpp). Readers (io/robot_log.hpp) produce them, the sensor
/// stages (sensors/) consume them, the time-ordered merge
/// (core/stream_merge.hpp) visits them.
///
/// Frames: body frame of ROS REP-103 (x forward, y left, z up). A sample is
/// what the sensor measured; nothing here is calibrated or filtered.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>

namespace posefuse {

/// One sample of a 9-axis IMU in the REP-103 body frame (x forward, y left, z up).
struct ImuSample {
  std::int64_t t_ns{0};                                  ///< stamp (ns)
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  ///< specific force (m/s²), +9.81 on z at rest
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  ///< angular rate about x, y, z (rad/s)
  Eigen::Vector3d mag_uT = Eigen::Vector3d::Zero();      ///< magnetic field (µT), as measured (uncalibrated)
  /// All fields equal (NaN compares unequal).
  friend bool operator==(const ImuSample&, const ImuSample&) = default;
};

/// Cumulative encoder counts of a four-wheel robot (ticks; front/back, left/right).
struct WheelTicks {
  std::int64_t fl{0};  ///< front left
  std::int64_t fr{0};  ///< front right
  std::int64_t bl{0};  ///< back left
  std::int64_t br{0};  ///< back right
  /// All counts equal.
  friend constexpr bool operator==(const WheelTicks&, const WheelTicks&) = default;
};

/// Cumulative encoder counts of the four wheels at one time.
struct WheelSample {
  std::int64_t t_ns{0};  ///< stamp (ns)
  WheelTicks ticks;      ///< cumulative counts (ticks)
  /// Stamp and counts equal.
  friend constexpr bool operator==(const WheelSample&, const WheelSample&) = default;
};

/// Tracking state of a SLAM system at one sample.
enum class SlamState {
  kTracking,  ///< pose valid in the current map frame
  kLost,      ///< no pose (the sample's pose fields are meaningless)
  kReinit     ///< first pose of a new map frame
};

/// One output of a SLAM system: the body pose \f$ T_{map,body} \f$ in its
/// current map frame (z up), or a `kLost` marker.
struct SlamSample {
  std::int64_t t_ns{0};                  ///< stamp (ns)
  SlamState state{SlamState::kLost};     ///< tracking / lost / reinit
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< body origin in the map frame (m)
  /// Rotation body → map, \f$ q_{map,body} \f$ (stored as given, not normalised;
  /// Eigen's coefficient order x, y, z, w).
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  /// All fields equal, the quaternion coefficient by coefficient (NaN compares unequal).
  friend bool operator==(const SlamSample& a, const SlamSample& b) {
    return a.t_ns == b.t_ns && a.state == b.state && a.position_m == b.position_m &&
           a.orientation.coeffs() == b.orientation.coeffs();
  }
};

/// A planar pose at one time, e.g. ground truth of a ground robot:
/// `pose` = (x m, y m, θ rad) of the body in a planar world frame, θ
/// counter-clockwise from the world x axis. The same (x, y, θ) layout as
/// PlanarTrajectory (core/trajectory.hpp) and `PlanarPose::vector()`.
struct PlanarPoseSample {
  std::int64_t t_ns{0};                            ///< stamp (ns)
  Eigen::Vector3d pose = Eigen::Vector3d::Zero();  ///< (x m, y m, θ rad)
  /// Stamp and pose equal (NaN compares unequal).
  friend bool operator==(const PlanarPoseSample&, const PlanarPoseSample&) = default;
};

/// The difference `a - b` of two counters (encoder ticks), saturated to the
/// int64 range instead of overflowing (which would be undefined behaviour):
/// exact whenever the true difference fits in an int64, else
/// `std::numeric_limits<std::int64_t>::max()` or `min()`.
/// @param[in] a, b counter values
/// @return \f$ \mathrm{clamp}(a - b, -2^{63}, 2^{63} - 1) \f$
[[nodiscard]] constexpr std::int64_t saturating_difference(std::int64_t a, std::int64_t b) noexcept {
  constexpr std::int64_t lo = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int64_t>::max();
  if (b > 0 && a < lo + b) return lo;  // a - b < min
  if (b < 0 && a > hi + b) return hi;  // a - b > max
  return a - b;
}

}  // namespace posefuse

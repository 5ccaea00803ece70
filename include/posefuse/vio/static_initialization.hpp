#pragma once
/// @file
/// Initial state of a visual-inertial estimator from a start at rest: over
/// the first `duration_s` seconds of IMU samples the body must not move;
/// gravity then gives roll and pitch (the mean specific force is
/// \f$ R^\top(0, 0, g) \f$ plus the accelerometer bias) and the mean rate is
/// the gyroscope bias. Yaw and position are unobservable and set to zero,
/// the velocity to zero, the accelerometer bias to zero (inseparable from
/// tilt at rest: a bias b tilts the estimate by about |b| / g rad).
///
/// Rest test: the standard deviation of every accelerometer axis below
/// `max_accel_std_mps2`, of every gyroscope axis below `max_gyro_std_radps`,
/// and \f$ |\bar a| \f$ within `max_gravity_error_mps2` of g.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/inertial/imu_factor.hpp>

namespace posefuse {

/// Options of the static start (see the file comment).
struct StaticInitOptions {
  double duration_s = 1.0;              ///< rest needed before the first frame (s)
  double max_accel_std_mps2 = 0.15;     ///< rest test, accelerometer
  double max_gyro_std_radps = 0.02;     ///< rest test, gyroscope
  double max_gravity_error_mps2 = 0.5;  ///< rest test, | |mean specific force| - g |
  double gravity_mps2 = 9.81;           ///< g
};

/// Result of a static start.
struct StaticInitResult {
  std::optional<ImuState> state;  ///< the state at the last sample used, when at rest
  std::string reason;             ///< why not, otherwise empty
};

/// Static start from the samples with stamps in [t_end - duration, t_end].
/// @param[in] samples time-ordered IMU samples
/// @param[in] t_end_ns the stamp the state is for (the first frame)
template <class Lazy = void>
[[nodiscard]] StaticInitResult static_initialize(std::span<const ImuSample> samples, std::int64_t t_end_ns,
                                                 const StaticInitOptions& o = {}) {
  StaticInitResult out;
  const std::int64_t t0 = t_end_ns - std::int64_t(std::llround(o.duration_s * 1e9));
  Eigen::Vector3d sa = Eigen::Vector3d::Zero(), sg = Eigen::Vector3d::Zero();
  Eigen::Vector3d qa = Eigen::Vector3d::Zero(), qg = Eigen::Vector3d::Zero();
  int n = 0;
  std::int64_t first = 0, last = 0;
  for (const ImuSample& s : samples) {
    if (s.t_ns < t0 || s.t_ns > t_end_ns) continue;
    if (n == 0) first = s.t_ns;
    last = s.t_ns;
    sa += s.accel_mps2;
    sg += s.gyro_radps;
    qa += s.accel_mps2.cwiseAbs2();
    qg += s.gyro_radps.cwiseAbs2();
    ++n;
  }
  if (n < 10 || seconds_between(last, first) < 0.9 * o.duration_s) {
    out.reason = "fewer than " + std::to_string(o.duration_s) + " s of IMU samples before the first frame";
    return out;
  }
  const Eigen::Vector3d ma = sa / n, mg = sg / n;
  const Eigen::Vector3d va = (qa / n - ma.cwiseAbs2()).cwiseMax(0.0), vg = (qg / n - mg.cwiseAbs2()).cwiseMax(0.0);
  if (va.cwiseSqrt().maxCoeff() > o.max_accel_std_mps2 || vg.cwiseSqrt().maxCoeff() > o.max_gyro_std_radps) {
    out.reason = "the IMU is not at rest over the first " + std::to_string(o.duration_s) + " s";
    return out;
  }
  if (std::abs(ma.norm() - o.gravity_mps2) > o.max_gravity_error_mps2) {
    out.reason = "the mean specific force is not gravity";
    return out;
  }
  // R^T e_z = a / |a|: the rotation taking the measured up direction to e_z, with zero yaw.
  const Eigen::Vector3d up = ma.normalized();
  Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ());
  const Eigen::Matrix3d R0 = q.toRotationMatrix();
  const double yaw = std::atan2(R0(1, 0), R0(0, 0));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0;
  ImuState x;
  x.R = SO3d(Eigen::Quaterniond(R).normalized());
  x.bias.gyro = mg;
  out.state = x;
  return out;
}

}  // namespace posefuse

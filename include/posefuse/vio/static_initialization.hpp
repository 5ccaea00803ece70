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
/// Rest test: the interval is cut into `chunks` equal parts; the mean of
/// each part must agree with the overall mean within `max_accel_dev_mps2`
/// (every accelerometer axis) and `max_gyro_dev_radps` (every gyroscope
/// axis), and \f$ |\bar a| \f$ must be within `max_gravity_error_mps2` of g.
/// Means over parts, not the samples' spread, so that the vibration of
/// running motors (EuRoC's MAV on the ground: about 1 m/s² and 0.08 rad/s
/// standard deviation at 200 Hz) passes while sustained motion does not.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>
#include <algorithm>

#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/inertial/imu_factor.hpp>

namespace posefuse {

/// Options of the static start (see the file comment).
struct StaticInitOptions {
  double duration_s = 1.0;              ///< rest needed before the first frame (s)
  int chunks = 5;                       ///< rest test: parts of the interval
  double max_accel_dev_mps2 = 0.6;      ///< rest test, accelerometer
  double max_gyro_dev_radps = 0.05;     ///< rest test, gyroscope
  double max_gravity_error_mps2 = 0.5;  ///< rest test, | |mean specific force| - g |
  double gravity_mps2 = 9.81;           ///< g
};

/// Result of a static start.
struct StaticInitResult {
  std::optional<ImuState> state;  ///< the state at the last sample used, when at rest
  std::string reason;             ///< why not, otherwise empty
};

/// Static start from the samples with stamps in [t_end - duration, t_end].
/// @param[in] o the rest test's settings and g
/// @param[in] samples time-ordered IMU samples
/// @param[in] t_end_ns the stamp the state is for (the first frame)
template <class Lazy = void>
[[nodiscard]] StaticInitResult static_initialize(std::span<const ImuSample> samples, std::int64_t t_end_ns,
                                                 const StaticInitOptions& o = {}) {
  StaticInitResult out;
  const std::int64_t t0 = t_end_ns - std::int64_t(std::llround(o.duration_s * 1e9));
  std::vector<const ImuSample*> in;
  for (const ImuSample& s : samples)
    if (s.t_ns >= t0 && s.t_ns <= t_end_ns) in.push_back(&s);
  const int parts = std::max(1, o.chunks);
  if (int(in.size()) < 2 * parts || seconds_between(in.back()->t_ns, in.front()->t_ns) < 0.9 * o.duration_s) {
    out.reason = "fewer than " + std::to_string(o.duration_s) + " s of IMU samples before the first frame";
    return out;
  }
  const auto mean = [&](std::size_t a, std::size_t b, Eigen::Vector3d& ma, Eigen::Vector3d& mg) {
    ma.setZero();
    mg.setZero();
    for (std::size_t i = a; i < b; ++i) {
      ma += in[i]->accel_mps2;
      mg += in[i]->gyro_radps;
    }
    ma /= double(b - a);
    mg /= double(b - a);
  };
  Eigen::Vector3d ma, mg;
  mean(0, in.size(), ma, mg);
  for (int c = 0; c < parts; ++c) {
    Eigen::Vector3d ca, cg;
    mean(in.size() * std::size_t(c) / std::size_t(parts), in.size() * std::size_t(c + 1) / std::size_t(parts), ca, cg);
    if ((ca - ma).cwiseAbs().maxCoeff() > o.max_accel_dev_mps2 || (cg - mg).cwiseAbs().maxCoeff() > o.max_gyro_dev_radps) {
      out.reason = "the IMU is not at rest over the " + std::to_string(o.duration_s) + " s before the first frame";
      return out;
    }
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

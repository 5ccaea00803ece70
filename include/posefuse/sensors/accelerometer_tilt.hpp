#pragma once
/// @file
/// Roll and pitch from the accelerometer's measurement of gravity (seed 001
/// eq 1-2, in the REP-103 body frame), and the first stage of the attitude
/// chain (its input is the library's raw ImuSample, core/samples.hpp).
///
/// accelerometer_tilt_rep103() uses the REP-103 body frame (x forward, y
/// left, z up) with the accelerometer reading specific force, i.e.
/// \f$ a = R^\top (0, 0, +g) \f$ at rest (+9.81 m/s² on z when level).
/// For \f$ R = R_z R_y(\mathrm{pitch}) R_x(\mathrm{roll}) \f$ this gives
/// \f$ a = g(-\sin p, \cos p \sin r, \cos p \cos r) \f$, hence
/// roll = atan2(ay, az), pitch = atan2(-ax, sqrt(ay² + az²)).
/// Roll covers (-180°, 180°], pitch [-90°, 90°]. The attitude chain
/// (sensors/pipelines.hpp) uses it.
///
/// Seed 001 eq 1-2 exactly as printed, in the seed's own IMU axes, are
/// posefuse::seed::accelerometer_tilt() (seed/accelerometer_tilt.hpp), a
/// reproduction: its angles are the elevations of the sensor's x and y axes,
/// which in REP-103 axes are \f$ -\mathrm{pitch} \f$ and
/// \f$ \arcsin(\cos p \sin r) \f$ (= roll only when pitch = 0).

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/core/samples.hpp>
#include <posefuse/sensors/sample_status.hpp>

namespace posefuse {

/// Roll and pitch (rad). For the REP-103 functions these are the ZYX Euler
/// roll (about body x) and pitch (about body y) of lie/rotation.hpp; for
/// seed::accelerometer_tilt() they are the seed's \f$ \rho_a \f$ and
/// \f$ \phi_a \f$.
template <std::floating_point T = double>
struct Tilt {
  T roll{0};   ///< rad
  T pitch{0};  ///< rad
};

/// Roll and pitch from gravity in a REP-103 body frame (x forward, y left, z up),
/// the accelerometer reading specific force (+g on z when level and at rest):
/// \f$ \mathrm{roll} = \mathrm{atan2}(a_y, a_z) \f$,
/// \f$ \mathrm{pitch} = \mathrm{atan2}(-a_x, \sqrt{a_y^2 + a_z^2}) \f$.
/// Exact at rest; under linear acceleration the result is tilted toward the
/// acceleration, which is why the complementary filter (eq 3-4) follows.
/// @param[in] a specific force in the body frame (m/s², or any unit)
/// @return ZYX roll in (-pi, pi] and pitch in [-pi/2, pi/2], rad; NaN components
///         when a is not finite, and roll = pitch = 0 when a is zero
template <std::floating_point T>
[[nodiscard]] inline Tilt<T> accelerometer_tilt_rep103(const Eigen::Matrix<T, 3, 1>& a) noexcept {
  return {std::atan2(a.y(), a.z()),
          std::atan2(-a.x(), std::sqrt(a.y() * a.y() + a.z() * a.z()))};
}

/// An IMU sample with a roll/pitch estimate attached (what flows between the
/// stages of the attitude chain).
struct TiltedImu {
  ImuSample imu;                            ///< the raw sample (stamp t_ns)
  Tilt<double> tilt;                        ///< roll, pitch (rad), REP-103 ZYX
  SampleStatus status{SampleStatus::kOk};  ///< kNonFinite when tilt is unusable
};

/// Attitude-chain stage 1: attaches the accelerometer's REP-103 tilt to each sample.
/// Input ImuSample, Output TiltedImu (status kNonFinite when the accelerometer
/// reading is not finite or zero).
struct AccelerometerTiltStage {
  using Input = ImuSample;
  using Output = TiltedImu;

  /// @param[in] s IMU sample (REP-103 body frame)
  /// @return the sample with tilt = accelerometer_tilt_rep103(s.accel_mps2)
  [[nodiscard]] TiltedImu operator()(const ImuSample& s) const noexcept {
    TiltedImu out{s, accelerometer_tilt_rep103(s.accel_mps2), SampleStatus::kOk};
    if (!s.accel_mps2.allFinite() || s.accel_mps2.squaredNorm() == 0.0) {
      out.status = SampleStatus::kNonFinite;
    }
    return out;
  }
};

}  // namespace posefuse

#pragma once
/// @file
/// Tilt-compensated magnetic heading (seed 001 eq 5-7, corrected) and the
/// compass stage that ends the attitude chain. Eq 5-7 exactly as printed are
/// posefuse::seed::tilt_compensated_heading_seed()
/// (seed/tilt_compensated_heading.hpp), a reproduction that is not invariant
/// to tilt: do not use it for navigation.
///
/// Frames and sign convention (REP-103): body frame x forward, y left, z up;
/// world frame x toward magnetic north, y west, z up. Yaw is the ZYX Euler yaw
/// of lie/rotation.hpp: 0 when the robot faces magnetic north, increasing
/// counter-clockwise seen from above (turning left). The local field in the
/// world frame is \f$ B(\cos I, 0, -\sin I) \f$ (dip I > 0 in the northern
/// hemisphere); only its horizontal part matters. Add the magnetic
/// declination to get yaw from true north.
///
/// Derivation of the correct compensation: the body reading is
/// \f$ m = R^\top m_w \f$ with \f$ R = R_z(\psi) R_y(p) R_x(r) \f$, so the
/// levelled reading \f$ R_y(p) R_x(r)\, m = R_z(\psi)^\top m_w \f$ is
/// \f$ (B_h\cos\psi, -B_h\sin\psi, \cdot) \f$:
/// \f[ X_h = m_x\cos p + m_y \sin p \sin r + m_z \sin p \cos r,\quad
///     Y_h = m_y \cos r - m_z \sin r,\quad \psi = \mathrm{atan2}(-Y_h, X_h). \f]

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <posefuse/core/angles.hpp>
#include <posefuse/sensors/accelerometer_tilt.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <posefuse/sensors/sample_status.hpp>

namespace posefuse {

/// Tilt-compensated yaw from a (calibrated) magnetometer reading, REP-103.
/// \f$ \psi = \mathrm{atan2}(m_z \sin r - m_y \cos r,\;
///            m_x \cos p + m_y \sin p \sin r + m_z \sin p \cos r) \f$
/// (the corrected form of seed 001 eq 5-7). The result does not change when
/// only roll and pitch change.
/// @param[in] mag magnetic field in the body frame (any unit; calibrate first)
/// @param[in] roll ZYX roll, rad
/// @param[in] pitch ZYX pitch, rad
/// @return yaw from magnetic north, counter-clockwise positive, in [-pi, pi); NaN if
///         an input is not finite
template <std::floating_point T>
[[nodiscard]] inline T tilt_compensated_heading(const Eigen::Matrix<T, 3, 1>& mag, T roll,
                                                T pitch) noexcept {
  const T cr = std::cos(roll), sr = std::sin(roll);
  const T cp = std::cos(pitch), sp = std::sin(pitch);
  const T xh = mag.x() * cp + mag.y() * sp * sr + mag.z() * sp * cr;
  const T yh = mag.y() * cr - mag.z() * sr;
  return wrap_angle(std::atan2(-yh, xh));
}

/// Roll, pitch and yaw of the body at one time (rad, REP-103 ZYX; yaw from
/// magnetic north, counter-clockwise positive). Output of the attitude chain.
struct Attitude {
  std::int64_t t_ns{0};  ///< stamp of the IMU sample (ns)
  double roll{0};   ///< rad
  double pitch{0};  ///< rad
  double yaw{0};    ///< rad, [-pi, pi)
  SampleStatus status{SampleStatus::kOk};  ///< kNonFinite: a value was held from the last good sample
};

/// Attitude-chain stage 3: calibrates the magnetometer and computes the
/// tilt-compensated yaw with the incoming roll/pitch. Input TiltedImu,
/// Output Attitude; the input's status is passed on. A non-finite or zero
/// magnetometer reading, or a non-finite tilt, holds the last good yaw and
/// reports kNonFinite.
class CompassStage {
 public:
  using Input = TiltedImu;
  using Output = Attitude;

  /// @param[in] calibration hard/soft-iron correction applied to every reading
  /// @param[in] declination_rad added to the magnetic yaw (east declination
  ///            positive makes yaw relative to true north), rad
  /// @throws posefuse::invalid_argument if the calibration or declination is not finite
  explicit CompassStage(const MagnetometerCalibration& calibration = {}, double declination_rad = 0.0)
      : cal_(calibration), declination_rad_(declination_rad) {
    if (!cal_.hard_iron.allFinite() || !cal_.soft_iron.allFinite() || !std::isfinite(declination_rad))
      throw invalid_argument("posefuse: CompassStage calibration and declination must be finite");
  }

  /// @param[in] in IMU sample with roll/pitch (rad)
  /// @return roll, pitch from `in`, yaw from the calibrated magnetometer
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] Attitude operator()(const TiltedImu& in) noexcept {
    Attitude out{in.imu.t_ns, in.tilt.roll, in.tilt.pitch, last_yaw_, in.status};
    const Eigen::Vector3d m = cal_.apply(in.imu.mag_uT);
    const double yaw = wrap_angle(tilt_compensated_heading(m, in.tilt.roll, in.tilt.pitch) +
                                  declination_rad_);
    if (!std::isfinite(yaw) || m.squaredNorm() == 0.0) {
      out.status = SampleStatus::kNonFinite;
      return out;
    }
    last_yaw_ = yaw;
    out.yaw = yaw;
    return out;
  }

  /// The calibration in use.
  [[nodiscard]] const MagnetometerCalibration& calibration() const noexcept { return cal_; }

 private:
  MagnetometerCalibration cal_;
  double declination_rad_;
  double last_yaw_{0};
};

}  // namespace posefuse

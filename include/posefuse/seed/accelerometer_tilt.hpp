#pragma once
/// @file
/// Seed 001 eq 1-2 exactly as printed: roll and pitch from the accelerometer
/// in the seed's own IMU axes (its Fig. 1, an EBIMU-9DOFV3). A reproduction,
/// in posefuse::seed apart from the recommended API; the library's attitude
/// chain uses posefuse::accelerometer_tilt_rep103()
/// (sensors/accelerometer_tilt.hpp), which covers the full roll range.
///
/// \f$ \rho_a \f$ ("roll") is the elevation of the sensor's x axis above the
/// horizontal plane and \f$ \phi_a \f$ ("pitch") that of its y axis; `atan`
/// (not `atan2`) keeps both in [-90°, 90°], so a sensor upside down reads
/// the same as one upright. In REP-103 axes, \f$ \rho_a = -\mathrm{pitch} \f$
/// and \f$ \phi_a = \arcsin(\cos p \sin r) \f$ (= roll only when pitch = 0).

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/sensors/accelerometer_tilt.hpp>

namespace posefuse::seed {

/// Seed 001 eq 1-2, as printed, in the seed's IMU axes:
/// \f$ \rho_a = \arctan(A_x / \sqrt{A_y^2 + A_z^2}) \f$,
/// \f$ \phi_a = \arctan(A_y / \sqrt{A_x^2 + A_z^2}) \f$.
/// @param[in] a accelerometer reading (any unit; only its direction matters)
/// @return {roll = rho_a, pitch = phi_a} in rad, each in [-pi/2, pi/2]; NaN
///         components when a is zero or not finite
template <std::floating_point T>
[[nodiscard]] inline Tilt<T> accelerometer_tilt(const Eigen::Matrix<T, 3, 1>& a) noexcept {
  return {std::atan(a.x() / std::sqrt(a.y() * a.y() + a.z() * a.z())),   // eq 1
          std::atan(a.y() / std::sqrt(a.x() * a.x() + a.z() * a.z()))};  // eq 2
}

}  // namespace posefuse::seed

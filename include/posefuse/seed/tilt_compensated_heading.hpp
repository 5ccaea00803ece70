#pragma once
/// @file
/// Seed 001 eq 5-7 exactly as printed: the tilt-compensated magnetic heading,
/// kept to reproduce and test its flaws. A reproduction, in posefuse::seed
/// apart from the recommended API. Do not use it for navigation: the correct
/// compensation is posefuse::tilt_compensated_heading()
/// (sensors/compass.hpp), which the attitude chain's CompassStage uses.
///
/// Flaws, measured by the tests:
///  * not invariant to tilt: in REP-103 axes with a 53° dip, a robot at yaw
///    0.70 rad rolled 0.2 rad reads -0.98 rad, where the same formula reads
///    -0.70 rad level (over random tilts up to ±0.6 rad, most readings move
///    by more than 0.05 rad and the worst by more than 0.5 rad);
///  * `atan` folds the heading into [-90°, 90°];
///  * at zero tilt it returns \f$ \arctan(M_y/M_x) \f$, i.e. the clockwise
///    heading \f$ -\psi \f$ for REP-103 axes.

#include <Eigen/Core>
#include <cmath>
#include <concepts>

namespace posefuse::seed {

/// Seed 001 eq 5-7, as printed:
/// \f$ X'_m = M_x\cos\phi + M_y\sin\rho - M_z\cos\rho\sin\phi \f$ (eq 5),
/// \f$ Y'_m = M_y\cos\rho + M_z\sin\phi \f$ (eq 6),
/// \f$ \theta = \arctan(Y'_m / X'_m) \f$ (eq 7).
/// Do not use for navigation; use posefuse::tilt_compensated_heading().
/// @param[in] mag magnetometer components (M_x, M_y, M_z)
/// @param[in] rho the seed's roll \f$ \rho \f$, rad
/// @param[in] phi the seed's pitch \f$ \phi \f$, rad
/// @return \f$ \theta \f$ of eq 7, rad, in [-pi/2, pi/2]
template <std::floating_point T>
[[nodiscard]] inline T tilt_compensated_heading_seed(const Eigen::Matrix<T, 3, 1>& mag, T rho,
                                                     T phi) noexcept {
  const T xm = mag.x() * std::cos(phi) + mag.y() * std::sin(rho) -
               mag.z() * std::cos(rho) * std::sin(phi);            // eq 5
  const T ym = mag.y() * std::cos(rho) + mag.z() * std::sin(phi);  // eq 6
  return std::atan(ym / xm);                                        // eq 7
}

}  // namespace posefuse::seed

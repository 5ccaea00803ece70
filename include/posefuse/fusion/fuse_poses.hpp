#pragma once
/// @file
/// Information-weighted fusion of two estimates of one planar pose, as one
/// Ekf update (GatedFuser's SLAM update without gates or anchoring).

#include <Eigen/Core>
#include <concepts>
#include <limits>

#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/se2_odometry.hpp>

namespace posefuse {

/// A planar pose with its covariance (x, y, theta; m², m·rad, rad²).
template <std::floating_point T = double>
struct PlanarPoseWithCov {
  PlanarPose<T> pose;                                       ///< x, y (m), theta (rad)
  Eigen::Matrix<T, 3, 3> cov = Eigen::Matrix<T, 3, 3>::Zero();  ///< covariance
};

/// Information-weighted fusion of two estimates of one planar pose, angle-aware:
/// one Ekf update of the belief (a, Pa) with b as a PlanarPoseFix of noise Pb,
/// \f$ K = P_a (P_a + P_b)^{-1},\; x = a \boxplus K (b \boxminus a),\;
/// P = (I-K) P_a (I-K)^\top + K P_b K^\top = (P_a^{-1} + P_b^{-1})^{-1} \f$,
/// with the heading residual wrapped, so 179° and -179° with equal weights
/// fuse to 180°, not 0° (cf. seed eq 15-a).
/// @param[in] a, Pa first estimate and its covariance
/// @param[in] b, Pb second estimate and its covariance
/// @return the fused pose and covariance; NaN when Pa + Pb is not positive
///         definite or b is not finite
/// @throws posefuse::invalid_argument if a is not finite, or Pa or Pb is not a
///         finite symmetric positive semi-definite covariance
template <std::floating_point T>
[[nodiscard]] inline PlanarPoseWithCov<T> fuse_poses(const PlanarPose<T>& a,
                                                     const Eigen::Matrix<T, 3, 3>& Pa,
                                                     const PlanarPose<T>& b,
                                                     const Eigen::Matrix<T, 3, 3>& Pb) {
  Ekf<Se2Odometry<T>> ekf{Se2Odometry<T>{}};  // the motion model is not used
  ekf.reset(a, Pa);
  if (!ekf.update_with(PlanarPoseFix<T>(Pb), b)) {
    constexpr T nan = std::numeric_limits<T>::quiet_NaN();
    return {{nan, nan, nan}, Eigen::Matrix<T, 3, 3>::Constant(nan)};
  }
  return {ekf.state(), ekf.covariance()};
}

}  // namespace posefuse

#pragma once
/// @file
/// A direct measurement of a planar pose: \f$ z = h(x) + v = x \boxplus v,\;
/// v \sim N(0, R) \f$, with the residual \f$ z \boxminus h(x) \f$ of
/// PlanarPose::minus (heading wrapped to [-π, π)), so \f$ H = I_3 \f$.
///
/// Use it for any absolute pose in the state's frame: a SLAM pose mapped into
/// the world (\f$ z_w = T_{wm} \oplus z \f$, fusion/gated_fuser.hpp), a
/// second estimate of the same pose (fuse_poses), a GNSS-with-heading fix.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// Measures the whole planar pose (x, y in m, θ in rad) with covariance R.
template <std::floating_point T = double>
class PlanarPoseFix {
 public:
  using State = PlanarPose<T>;        ///< pose in the world frame
  using Measurement = PlanarPose<T>;  ///< the same pose, measured
  using Noise = Eigen::Matrix<T, 3, 3>;
  static constexpr bool kIdentityJacobian = true;  ///< H = I
  static constexpr bool kTimeInvariant = true;     ///< H and R depend on neither x nor time

  /// @param[in] R measurement covariance on (x, y, θ) (m², m·rad, rad²);
  ///            positive semi-definite (a zero variance is an exact
  ///            component; the update still needs HPH^T + R positive definite)
  /// @throws posefuse::invalid_argument unless R is finite, symmetric and PSD
  explicit PlanarPoseFix(const Noise& R) : R_(R) { require_covariance(R_, "PlanarPoseFix"); }

  /// R = diag(σ_xy², σ_xy², σ_θ²).
  /// @param[in] sigma_xy_m      position 1-σ (m), finite, >= 0
  /// @param[in] sigma_theta_rad heading 1-σ (rad), finite, >= 0
  /// @throws posefuse::invalid_argument for a negative or non-finite sigma
  [[nodiscard]] static PlanarPoseFix from_sigmas(T sigma_xy_m, T sigma_theta_rad) {
    if (!std::isfinite(sigma_xy_m) || !std::isfinite(sigma_theta_rad) || sigma_xy_m < T(0) ||
        sigma_theta_rad < T(0))
      throw invalid_argument("PlanarPoseFix::from_sigmas: sigmas must be finite and >= 0");
    const Eigen::Matrix<T, 3, 1> v(sigma_xy_m * sigma_xy_m, sigma_xy_m * sigma_xy_m,
                                   sigma_theta_rad * sigma_theta_rad);
    return PlanarPoseFix(Noise(v.asDiagonal()));
  }

  /// \f$ h(x) = x \f$.
  [[nodiscard]] Measurement predict(const State& x) const noexcept { return x; }
  /// \f$ H = I_3 \f$.
  [[nodiscard]] Noise jacobian(const State&) const noexcept { return Noise::Identity(); }
  /// R.
  [[nodiscard]] const Noise& noise() const noexcept { return R_; }

 private:
  Noise R_;
};

}  // namespace posefuse

#pragma once
/// @file
/// An absolute heading measurement of a planar pose (a compass aligned to the
/// world frame, a heading from a GNSS dual antenna):
/// \f$ z = \mathrm{Exp}(\theta + v),\; v \sim N(0, \sigma^2) \f$ on SO(2), so
/// the residual \f$ z \boxminus h(x) = \mathrm{Log}(R(\theta)^{-1} z) \f$ is
/// the heading difference wrapped to [-π, π), and \f$ H = [0, 0, 1] \f$.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// Measures the heading θ (rad) of a PlanarPose with 1-σ noise sigma (rad).
template <std::floating_point T = double>
class HeadingFix {
 public:
  using State = PlanarPose<T>;  ///< pose in the world frame
  using Measurement = SO2<T>;   ///< heading in the world frame
  static constexpr bool kTimeInvariant = true;  ///< H and R depend on neither x nor time
  /// H = [0, 0, 1] selects the heading (see has_selection_v).
  static constexpr std::array<int, 1> kSelection = {2};

  /// @param[in] sigma_rad 1-σ heading noise (rad), finite and > 0
  /// @throws posefuse::invalid_argument otherwise
  explicit HeadingFix(T sigma_rad) : var_(sigma_rad * sigma_rad) {
    if (!std::isfinite(sigma_rad) || !(sigma_rad > T(0)))
      throw invalid_argument("HeadingFix: sigma must be finite and > 0");
  }

  /// \f$ h(x) = \mathrm{Exp}(\theta) \f$.
  [[nodiscard]] Measurement predict(const State& x) const noexcept { return SO2<T>(x.theta); }
  /// \f$ H = [0, 0, 1] \f$.
  [[nodiscard]] Eigen::Matrix<T, 1, 3> jacobian(const State&) const noexcept {
    return {T(0), T(0), T(1)};
  }
  /// \f$ \sigma^2 \f$ (rad²).
  [[nodiscard]] Eigen::Matrix<T, 1, 1> noise() const noexcept {
    return Eigen::Matrix<T, 1, 1>(var_);
  }

 private:
  T var_;
};

}  // namespace posefuse

#pragma once
/// @file
/// A pose on the plane, \f$ (x, y, \theta) \f$, as a posefuse::State whose
/// heading wraps: `plus` and `minus` act on \f$ \mathbb{R}^2 \times S^1 \f$.

#include <Eigen/Core>
#include <concepts>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/concepts.hpp>

namespace posefuse {

/// Position (m) and heading (rad, wrapped to [-pi, pi)) in a 2-D world frame.
template <std::floating_point T = double>
struct PlanarPose {
  using Scalar = T;
  static constexpr int Dim = 3;
  using Tangent = Eigen::Matrix<T, 3, 1>;

  T x{0};
  T y{0};
  T theta{0};

  /// \f$ (x + \delta_x, y + \delta_y, \mathrm{wrap}(\theta + \delta_\theta)) \f$.
  [[nodiscard]] PlanarPose plus(const Tangent& d) const {
    return {x + d(0), y + d(1), wrap_angle(theta + d(2))};
  }
  /// \f$ (x - o.x, y - o.y, \mathrm{wrap}(\theta - o.\theta)) \f$.
  [[nodiscard]] Tangent minus(const PlanarPose& o) const {
    return {x - o.x, y - o.y, angle_diff(theta, o.theta)};
  }
  /// The position as a vector.
  [[nodiscard]] Eigen::Matrix<T, 2, 1> position() const { return {x, y}; }
  /// All three numbers as a vector (heading as stored).
  [[nodiscard]] Tangent vector() const { return {x, y, theta}; }
};

}  // namespace posefuse

#pragma once
/// @file
/// Seed 000's motion model: road-plane position driven by a displacement.
///
/// \f$ \mu_t = \mu_{t-1} + u_t + w_t,\; G_t = I_2,\; w_t \sim N(0, R_t),\;
/// R_t = \mathrm{diag}(\sigma_x^2, \sigma_y^2) \f$ (seed 000, motion model and
/// Fig. 3). The seed names process noise **R** (Thrun's convention).

#include <Eigen/Core>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>

namespace posefuse {

/// \f$ f(x, u) = x + u \f$ on the road plane; x and u in metres.
template <std::floating_point T = double>
class PlanarDisplacement {
 public:
  using State = Eigen::Matrix<T, 2, 1>;
  using Control = Eigen::Matrix<T, 2, 1>;
  using Matrix = Eigen::Matrix<T, 2, 2>;
  static constexpr bool kIdentityJacobian = true;  ///< G = I

  /// @param[in] R process noise per step (m^2), the seed's R
  /// @throws posefuse::invalid_argument unless R is symmetric PSD and finite
  explicit PlanarDisplacement(const Matrix& R) : R_(R) {
    require_covariance(R_, "PlanarDisplacement: process noise R");
  }
  /// Diagonal process noise \f$ \mathrm{diag}(\sigma_x^2, \sigma_y^2) \f$.
  static PlanarDisplacement from_sigmas(T sigma_x, T sigma_y) {
    return PlanarDisplacement(Eigen::Matrix<T, 2, 1>(sigma_x * sigma_x, sigma_y * sigma_y)
                                  .asDiagonal()
                                  .toDenseMatrix());
  }

  [[nodiscard]] State predict(const State& x, const Control& u, T /*dt*/) const { return x + u; }
  [[nodiscard]] Matrix jacobian(const State&, const Control&, T) const {
    return Matrix::Identity();
  }
  [[nodiscard]] const Matrix& noise(const State&, const Control&, T) const noexcept { return R_; }

 private:
  Matrix R_;
};

}  // namespace posefuse

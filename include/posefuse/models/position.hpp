#pragma once
/// @file
/// A position fix: the first two (or N) state components are measured.
///
/// \f$ h(x) = [I_N\; 0]\, x,\; v \sim N(0, Q) \f$. For seed 000 the state is the
/// position itself, so \f$ H = I_2 \f$, and the measurement noise is the seed's
/// **Q** \f$ = \mathrm{diag}(\sigma_{x,orb}^2, \sigma_{y,orb}^2) \f$.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/gaussian.hpp>

namespace posefuse {

/// Measures the first `N` components of a vector state of size `StateDim`.
template <int StateDim, int N = 2, std::floating_point T = double>
class PositionFix {
  static_assert(N > 0 && N <= StateDim, "PositionFix: N must be in [1, StateDim]");

 public:
  using State = Eigen::Matrix<T, StateDim, 1>;
  using Measurement = Eigen::Matrix<T, N, 1>;
  using Noise = Eigen::Matrix<T, N, N>;
  static constexpr bool kIdentityJacobian = (N == StateDim);  ///< H = I when square
  static constexpr bool kTimeInvariant = true;  ///< H and Q depend on neither x nor time
  /// H selects state components 0 .. N-1 (see has_selection_v).
  static constexpr std::array<int, std::size_t(N)> kSelection = [] {
    std::array<int, std::size_t(N)> s{};
    for (std::size_t i = 0; i < s.size(); ++i) s[i] = int(i);
    return s;
  }();

  /// @param[in] Q measurement noise (m^2), the seed's Q
  /// @throws posefuse::invalid_argument unless Q is symmetric positive definite
  explicit PositionFix(const Noise& Q) : Q_(Q) {
    if (!is_positive_definite(Q_))
      throw invalid_argument("PositionFix: measurement noise Q must be symmetric positive definite");
  }
  /// Isotropic noise with standard deviation sigma (m) on every axis.
  static PositionFix isotropic(T sigma) { return PositionFix(Noise::Identity() * sigma * sigma); }

  [[nodiscard]] Measurement predict(const State& x) const { return x.template head<N>(); }
  [[nodiscard]] Eigen::Matrix<T, N, StateDim> jacobian(const State&) const {
    Eigen::Matrix<T, N, StateDim> H = Eigen::Matrix<T, N, StateDim>::Zero();
    H.template leftCols<N>().setIdentity();
    return H;
  }
  [[nodiscard]] const Noise& noise() const noexcept { return Q_; }

 private:
  Noise Q_;
};

}  // namespace posefuse

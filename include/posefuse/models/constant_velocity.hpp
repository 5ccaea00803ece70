#pragma once
/// @file
/// Constant-velocity motion on the plane with white-noise acceleration.
///
/// State \f$ x = [p_x, p_y, v_x, v_y]^\top \f$ (m, m/s). Over \f$ \Delta t \f$:
/// F = [I, dt I; 0, I] and
/// Q = q [dt^3/3 I, dt^2/2 I; dt^2/2 I, dt I] (blocks 2x2, row by row),
/// with q the acceleration noise spectral density (m^2/s^3) (Bar-Shalom, Li &
/// Kirubarajan, *Estimation with Applications to Tracking and Navigation*,
/// 2001, §6.2.2). Unlike seed 000's model it has dynamics of its own, so
/// position fixes that disagree with smooth motion are actually corrected.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>

namespace posefuse {

/// The control of a model that takes none.
struct NoControl {};

/// Constant velocity in 2-D; see the file comment.
template <std::floating_point T = double>
class ConstantVelocity2 {
 public:
  using State = Eigen::Matrix<T, 4, 1>;
  using Control = NoControl;
  using Matrix = Eigen::Matrix<T, 4, 4>;

  /// @param[in] q acceleration noise spectral density (m^2/s^3), > 0
  /// @throws posefuse::invalid_argument unless q is finite and > 0
  explicit ConstantVelocity2(T q) : q_(q) {
    if (!(q > T(0)) || !std::isfinite(q))
      throw invalid_argument("ConstantVelocity2: acceleration noise q must be finite and > 0");
  }

  [[nodiscard]] State predict(const State& x, const Control&, T dt) const {
    State y = x;
    y.template head<2>() += dt * x.template tail<2>();
    return y;
  }
  [[nodiscard]] Matrix jacobian(const State&, const Control&, T dt) const {
    Matrix F = Matrix::Identity();
    F(0, 2) = dt;
    F(1, 3) = dt;
    return F;
  }
  [[nodiscard]] Matrix noise(const State&, const Control&, T dt) const {
    const T a = q_ * dt * dt * dt / T(3);
    const T b = q_ * dt * dt / T(2);
    const T c = q_ * dt;
    Matrix Q = Matrix::Zero();
    Q(0, 0) = Q(1, 1) = a;
    Q(0, 2) = Q(2, 0) = Q(1, 3) = Q(3, 1) = b;
    Q(2, 2) = Q(3, 3) = c;
    return Q;
  }
  /// \f$ F P F^\top \f$ for F = [I, dt I; 0, I] without the products:
  /// rows, then columns, of the position block gain dt times the velocity
  /// ones (see HasPropagate).
  [[nodiscard]] Matrix propagate(const Matrix& P, const State&, const Control&, T dt) const {
    Matrix B = P;
    B.template topRows<2>() += dt * P.template bottomRows<2>();  // F P
    Matrix out = B;
    out.template leftCols<2>() += dt * B.template rightCols<2>();  // (F P) F^T
    return out;
  }
  [[nodiscard]] T q() const noexcept { return q_; }

 private:
  T q_;
};

}  // namespace posefuse

#pragma once
/// @file
/// SO(2): planar rotations, stored as a unit complex number (cos θ, sin θ).
///
/// Conventions (right perturbations, tangent [θ] in rad) are those of
/// lie/lie.hpp; formulas are from Solà, Deray, Atchuthan, "A micro Lie theory
/// for state estimation in robotics", arXiv:1812.01537, 2018 ("Solà" below):
/// its elementary Jacobian blocks (inverse, composition, Exp, plus/minus, action)
/// specialised as in its App. A. SO(2) is commutative, so every Jacobian of
/// the tangent is a scalar: \f$ J_r = J_l = \mathrm{Ad} = 1 \f$.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <limits>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>

namespace posefuse {

/// A rotation of the plane by an angle θ (rad, counter-clockwise).
///
/// `act` rotates a point: \f$ q = R(\theta)\, p \f$. The class is a
/// posefuse::Manifold: `plus` / `minus` are \f$ x \cdot \mathrm{Exp}(\tau) \f$
/// and \f$ \mathrm{Log}(x^{-1} y) \f$, so estimators can use it as a state.
template <std::floating_point T>
class SO2 {
 public:
  using Scalar = T;                                 ///< floating-point type
  static constexpr int Dim = 1;                     ///< tangent dimension
  static constexpr int PointDim = 2;                ///< dimension of the points it acts on
  using Tangent = Eigen::Matrix<T, 1, 1>;           ///< [θ], rad
  using Jacobian = Eigen::Matrix<T, 1, 1>;          ///< d(tangent) / d(tangent)
  using Point = Eigen::Matrix<T, 2, 1>;             ///< a point of the plane
  using Matrix = Eigen::Matrix<T, 2, 2>;            ///< rotation matrix
  using LieAlgebra = Eigen::Matrix<T, 2, 2>;        ///< hat(θ), skew 2x2
  using ActJacobianGroup = Eigen::Matrix<T, 2, 1>;  ///< d(g p) / d(g)
  using ActJacobianPoint = Eigen::Matrix<T, 2, 2>;  ///< d(g p) / d(p)

  /// The identity rotation.
  SO2() noexcept = default;
  /// The rotation by `theta` rad. Not validated (hot path): a non-finite
  /// angle gives a non-finite element.
  explicit SO2(T theta) noexcept : c_(std::cos(theta)), s_(std::sin(theta)) {}

  /// The rotation whose matrix is \f$ [c, -s; s, c] \f$ after normalising (c, s).
  /// @throws posefuse::invalid_argument when c or s is not finite or
  ///         \f$ \sqrt{c^2 + s^2} < \sqrt{\epsilon} \f$ (no direction)
  [[nodiscard]] static SO2 from_cos_sin(T c, T s) {
    const T n = std::hypot(c, s);
    if (!std::isfinite(c) || !std::isfinite(s))
      throw invalid_argument("SO2::from_cos_sin: cos and sin must be finite");
    if (!(n >= std::sqrt(std::numeric_limits<T>::epsilon())))
      throw invalid_argument("SO2::from_cos_sin: (cos, sin) has (near) zero length");
    return SO2(c / n, s / n, Unchecked{});
  }

  /// The identity rotation.
  [[nodiscard]] static SO2 identity() noexcept { return SO2(); }

  /// \f$ \mathrm{Exp}(\theta) = (\cos\theta, \sin\theta) \f$.
  /// @param[in] tau [θ], rad
  /// @param[out] J_g_tau if not null, \f$ J_r(\theta) = 1 \f$
  [[nodiscard]] static SO2 exp(const Tangent& tau, Jacobian* J_g_tau = nullptr) noexcept {
    if (J_g_tau) J_g_tau->setOnes();
    return SO2(tau(0));
  }
  /// \f$ \mathrm{Log}(g) = \mathrm{atan2}(\sin\theta, \cos\theta) \f$ in [-π, π).
  /// @param[out] J_tau_g if not null, \f$ J_r^{-1} = 1 \f$
  [[nodiscard]] Tangent log(Jacobian* J_tau_g = nullptr) const noexcept {
    if (J_tau_g) J_tau_g->setOnes();
    return Tangent(angle());
  }

  /// \f$ g^{-1} = (\cos\theta, -\sin\theta) \f$.
  /// @param[out] J_inv_g if not null, \f$ -\mathrm{Ad}_g = -1 \f$
  [[nodiscard]] SO2 inverse(Jacobian* J_inv_g = nullptr) const noexcept {
    if (J_inv_g) J_inv_g->setConstant(T(-1));
    return SO2(c_, -s_, Unchecked{});
  }
  /// \f$ c = a \cdot b \f$ (this = a): the angles add.
  /// @param[in] b the right operand
  /// @param[out] J_c_a if not null, \f$ \mathrm{Ad}_b^{-1} = 1 \f$
  /// @param[out] J_c_b if not null, 1
  [[nodiscard]] SO2 compose(const SO2& b, Jacobian* J_c_a = nullptr,
                            Jacobian* J_c_b = nullptr) const noexcept {
    if (J_c_a) J_c_a->setOnes();
    if (J_c_b) J_c_b->setOnes();
    return normalized(c_ * b.c_ - s_ * b.s_, s_ * b.c_ + c_ * b.s_);
  }
  /// \f$ a \cdot b \f$ without Jacobians.
  [[nodiscard]] SO2 operator*(const SO2& b) const noexcept { return compose(b); }
  /// \f$ d = a^{-1} b \f$ (this = a).
  /// @param[in] b the right operand
  /// @param[out] J_d_a if not null, \f$ -\mathrm{Ad}_d^{-1} = -1 \f$
  /// @param[out] J_d_b if not null, 1
  [[nodiscard]] SO2 between(const SO2& b, Jacobian* J_d_a = nullptr,
                            Jacobian* J_d_b = nullptr) const noexcept {
    if (J_d_a) J_d_a->setConstant(T(-1));
    if (J_d_b) J_d_b->setOnes();
    return normalized(c_ * b.c_ + s_ * b.s_, c_ * b.s_ - s_ * b.c_);
  }
  /// \f$ q = R p \f$.
  /// @param[in] p the point
  /// @param[out] J_q_g if not null, \f$ R\,[1]_\times p = R\,(-p_y, p_x)^\top \f$
  /// @param[out] J_q_p if not null, \f$ R \f$
  [[nodiscard]] Point act(const Point& p, ActJacobianGroup* J_q_g = nullptr,
                          ActJacobianPoint* J_q_p = nullptr) const noexcept {
    const Point q(c_ * p.x() - s_ * p.y(), s_ * p.x() + c_ * p.y());
    if (J_q_g) *J_q_g = Point(-q.y(), q.x());  // R [1]x p = [1]x R p in 2-D
    if (J_q_p) *J_q_p = matrix();
    return q;
  }

  /// \f$ y = x \oplus \tau = x \cdot \mathrm{Exp}(\tau) \f$.
  /// @param[in] d the tangent \f$ \tau \f$
  /// @param[out] J_y_x if not null, \f$ \mathrm{Ad}_{\mathrm{Exp}(\tau)}^{-1} = 1 \f$
  /// @param[out] J_y_d if not null, \f$ J_r(\tau) = 1 \f$
  [[nodiscard]] SO2 plus(const Tangent& d, Jacobian* J_y_x = nullptr,
                         Jacobian* J_y_d = nullptr) const noexcept {
    if (J_y_x) J_y_x->setOnes();
    if (J_y_d) J_y_d->setOnes();
    return compose(SO2(d(0)));
  }
  /// \f$ d = y \ominus x = \mathrm{Log}(x^{-1} y) \f$ (this = y), in [-π, π).
  /// @param[in] x the element subtracted
  /// @param[out] J_d_y if not null, \f$ J_r^{-1}(d) = 1 \f$
  /// @param[out] J_d_x if not null, \f$ -J_l^{-1}(d) = -1 \f$
  [[nodiscard]] Tangent minus(const SO2& x, Jacobian* J_d_y = nullptr,
                              Jacobian* J_d_x = nullptr) const noexcept {
    if (J_d_y) J_d_y->setOnes();
    if (J_d_x) J_d_x->setConstant(T(-1));
    return x.between(*this).log();
  }

  /// \f$ \mathrm{Ad}_g = 1 \f$.
  [[nodiscard]] Jacobian adjoint() const noexcept { return Jacobian::Ones(); }
  /// \f$ J_r(\theta) = 1 \f$.
  [[nodiscard]] static Jacobian right_jacobian(const Tangent&) noexcept { return Jacobian::Ones(); }
  /// \f$ J_r^{-1}(\theta) = 1 \f$.
  [[nodiscard]] static Jacobian right_jacobian_inverse(const Tangent&) noexcept {
    return Jacobian::Ones();
  }
  /// \f$ J_l(\theta) = 1 \f$.
  [[nodiscard]] static Jacobian left_jacobian(const Tangent&) noexcept { return Jacobian::Ones(); }
  /// \f$ J_l^{-1}(\theta) = 1 \f$.
  [[nodiscard]] static Jacobian left_jacobian_inverse(const Tangent&) noexcept {
    return Jacobian::Ones();
  }
  /// \f$ \theta^\wedge = [0, -\theta; \theta, 0] \f$.
  [[nodiscard]] static LieAlgebra hat(const Tangent& tau) noexcept {
    LieAlgebra W;
    W << T(0), -tau(0), tau(0), T(0);
    return W;
  }
  /// The θ of a 2x2 skew matrix, \f$ (W_{10} - W_{01}) / 2 \f$ (inverse of hat).
  [[nodiscard]] static Tangent vee(const LieAlgebra& W) noexcept {
    return Tangent((W(1, 0) - W(0, 1)) / T(2));
  }

  /// The angle θ in [-π, π), rad.
  [[nodiscard]] T angle() const noexcept { return wrap_angle(std::atan2(s_, c_)); }
  /// cos θ.
  [[nodiscard]] T cos() const noexcept { return c_; }
  /// sin θ.
  [[nodiscard]] T sin() const noexcept { return s_; }
  /// The rotation matrix \f$ [\cos\theta, -\sin\theta; \sin\theta, \cos\theta] \f$.
  [[nodiscard]] Matrix matrix() const noexcept {
    Matrix R;
    R << c_, -s_, s_, c_;
    return R;
  }

  /// The same rotation in scalar type U (renormalised after rounding).
  template <std::floating_point U>
  [[nodiscard]] SO2<U> cast() const {
    return SO2<U>::from_cos_sin(static_cast<U>(c_), static_cast<U>(s_));
  }
  /// True when \f$ |\mathrm{Log}(o^{-1} g)| \le \f$ tol (rad).
  [[nodiscard]] bool is_approx(const SO2& o, T tol) const noexcept {
    return std::abs(minus(o)(0)) <= tol;
  }

 private:
  template <std::floating_point U>
  friend class SO2;
  struct Unchecked {};
  SO2(T c, T s, Unchecked) noexcept : c_(c), s_(s) {}
  // Products of unit complex numbers drift off the circle by O(eps) per step;
  // dividing by the norm keeps long chains of compositions on it.
  static SO2 normalized(T c, T s) noexcept {
    const T n = std::sqrt(c * c + s * s);
    return SO2(c / n, s / n, Unchecked{});
  }

  T c_{1};
  T s_{0};
};

using SO2d = SO2<double>;  ///< SO(2) in double
using SO2f = SO2<float>;   ///< SO(2) in float

}  // namespace posefuse

#pragma once
/// @file
/// SE(2): rigid motions of the plane, stored as a translation t and an SO2.
///
/// Conventions (right perturbations, tangent \f$ \tau = [\rho_x, \rho_y, \theta] \f$,
/// translation part first) are those of lie/lie.hpp. Formulas: Solà, Deray,
/// Atchuthan, "A micro Lie theory for state estimation in robotics",
/// arXiv:1812.01537, 2018 ("Solà"), its elementary Jacobian blocks and the SE(2)
/// formulas of its App. C. With \f$ [1]_\times = [0, -1; 1, 0] \f$ and
/// \f$ A = \sin\theta/\theta,\; B = (1 - \cos\theta)/\theta \f$:
///  * \f$ \mathrm{Exp}(\tau) = (V(\theta)\rho, \mathrm{Exp}(\theta)) \f$,
///    \f$ V(\theta) = A I + B [1]_\times \f$;
///  * \f$ \mathrm{Ad}_g = [R, -[1]_\times t; 0, 1] \f$;
///  * \f$ J_r(\tau) = [A I - B [1]_\times,\; j_r; 0, 1] \f$ with
///    \f$ j_r = (C\rho_x - D\rho_y,\; D\rho_x + C\rho_y) \f$,
///    \f$ J_l(\tau) = [A I + B [1]_\times,\; j_l; 0, 1] \f$ with
///    \f$ j_l = (C\rho_x + D\rho_y,\; -D\rho_x + C\rho_y) \f$, where
///    \f$ C = (\theta - \sin\theta)/\theta^2,\; D = (1 - \cos\theta)/\theta^2 \f$
///    (these are Solà's SE(2) right / left Jacobians written with C and D).
/// The coefficients switch to Taylor series at small θ (lie/detail/series.hpp).

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/detail/series.hpp>
#include <posefuse/lie/so2.hpp>

namespace posefuse {

namespace detail {
/// The SE(2) coefficient functions A, B, C, D of lie/se2.hpp at angle th.
template <std::floating_point T>
struct Se2Coeffs {
  T A, B, C, D;
  explicit Se2Coeffs(T th) noexcept
      : A(sin_over_x(th)),
        B(one_minus_cos_over_x2(th) * th),
        C(x_minus_sin_over_x3(th) * th),
        D(one_minus_cos_over_x2(th)) {}
};
}  // namespace detail

/// A rigid motion of the plane: \f$ g\,p = R(\theta)\,p + t \f$.
///
/// As a pose, `SE2(x, y, theta)` is the pose of a body frame in a world
/// frame (t in m, θ in rad), and `act` maps body coordinates to world
/// coordinates. A posefuse::Manifold with \f$ x \oplus \tau = x\,\mathrm{Exp}(\tau) \f$:
/// the perturbation is expressed in the body frame.
template <std::floating_point T>
class SE2 {
 public:
  using Scalar = T;                                 ///< floating-point type
  static constexpr int Dim = 3;                     ///< tangent dimension
  static constexpr int PointDim = 2;                ///< dimension of the points it acts on
  using Tangent = Eigen::Matrix<T, 3, 1>;           ///< [ρx, ρy, θ] (m, m, rad)
  using Jacobian = Eigen::Matrix<T, 3, 3>;          ///< d(tangent) / d(tangent)
  using Point = Eigen::Matrix<T, 2, 1>;             ///< a point of the plane (m)
  using Matrix = Eigen::Matrix<T, 3, 3>;            ///< homogeneous matrix [R t; 0 1]
  using LieAlgebra = Eigen::Matrix<T, 3, 3>;        ///< hat(τ)
  using ActJacobianGroup = Eigen::Matrix<T, 2, 3>;  ///< d(g p) / d(g)
  using ActJacobianPoint = Eigen::Matrix<T, 2, 2>;  ///< d(g p) / d(p)

  /// The identity motion.
  SE2() noexcept = default;
  /// The pose with position (x, y) m and heading theta rad. Not validated.
  SE2(T x, T y, T theta) noexcept : t_(x, y), R_(theta) {}
  /// The motion \f$ p \mapsto R p + t \f$.
  SE2(const Point& t, const SO2<T>& R) noexcept : t_(t), R_(R) {}

  /// The identity motion.
  [[nodiscard]] static SE2 identity() noexcept { return SE2(); }

  /// \f$ \mathrm{Exp}(\tau) = (V(\theta)\rho, \mathrm{Exp}(\theta)) \f$ (Solà App. C).
  /// @param[in] tau [ρx, ρy, θ]
  /// @param[out] J_g_tau if not null, \f$ J_r(\tau) \f$
  [[nodiscard]] static SE2 exp(const Tangent& tau, Jacobian* J_g_tau = nullptr) noexcept {
    const detail::Se2Coeffs<T> k(tau(2));
    if (J_g_tau) *J_g_tau = right_jacobian(tau, k);
    const Point t(k.A * tau(0) - k.B * tau(1), k.B * tau(0) + k.A * tau(1));
    return SE2(t, SO2<T>(tau(2)));
  }
  /// \f$ \mathrm{Log}(g) = (V(\theta)^{-1} t, \theta) \f$, θ in [-π, π), with
  /// \f$ V^{-1} = (A I - B [1]_\times) / (A^2 + B^2) \f$.
  /// @param[out] J_tau_g if not null, \f$ J_r^{-1}(\mathrm{Log}\,g) \f$
  [[nodiscard]] Tangent log(Jacobian* J_tau_g = nullptr) const noexcept {
    const T th = R_.angle();
    const detail::Se2Coeffs<T> k(th);
    const T n = k.A * k.A + k.B * k.B;  // (sin(θ/2) / (θ/2))², > 0.4 for |θ| <= π
    const Tangent tau((k.A * t_.x() + k.B * t_.y()) / n, (-k.B * t_.x() + k.A * t_.y()) / n, th);
    if (J_tau_g) *J_tau_g = invert_jacobian(right_jacobian(tau, k));
    return tau;
  }

  /// \f$ g^{-1} = (-R^\top t, R^\top) \f$.
  /// @param[out] J_inv_g if not null, \f$ -\mathrm{Ad}_g \f$ (Solà, Jacobian of the inverse)
  [[nodiscard]] SE2 inverse(Jacobian* J_inv_g = nullptr) const noexcept {
    if (J_inv_g) *J_inv_g = -adjoint();
    const SO2<T> Ri = R_.inverse();
    return SE2(-Ri.act(t_), Ri);
  }
  /// \f$ c = a\,b = (t_a + R_a t_b, R_a R_b) \f$ (this = a).
  /// @param[in] b the right operand
  /// @param[out] J_c_a if not null, \f$ \mathrm{Ad}_b^{-1} \f$ (Solà, Jacobian of the composition)
  /// @param[out] J_c_b if not null, \f$ I \f$
  [[nodiscard]] SE2 compose(const SE2& b, Jacobian* J_c_a = nullptr,
                            Jacobian* J_c_b = nullptr) const noexcept {
    if (J_c_a) *J_c_a = b.inverse().adjoint();
    if (J_c_b) J_c_b->setIdentity();
    return SE2(t_ + R_.act(b.t_), R_.compose(b.R_));
  }
  /// \f$ a\,b \f$ without Jacobians.
  [[nodiscard]] SE2 operator*(const SE2& b) const noexcept { return compose(b); }
  /// \f$ d = a^{-1} b = (R_a^\top (t_b - t_a), R_a^\top R_b) \f$ (this = a): b seen from a.
  /// @param[in] b the right operand
  /// @param[out] J_d_a if not null, \f$ -\mathrm{Ad}_d^{-1} \f$
  /// @param[out] J_d_b if not null, \f$ I \f$
  [[nodiscard]] SE2 between(const SE2& b, Jacobian* J_d_a = nullptr,
                            Jacobian* J_d_b = nullptr) const noexcept {
    const SO2<T> Ri = R_.inverse();
    const SE2 d(Ri.act(b.t_ - t_), R_.between(b.R_));
    if (J_d_a) *J_d_a = -d.inverse().adjoint();
    if (J_d_b) J_d_b->setIdentity();
    return d;
  }
  /// \f$ q = R p + t \f$.
  /// @param[in] p the point
  /// @param[out] J_q_g if not null, \f$ [R,\; R [1]_\times p] \f$
  /// @param[out] J_q_p if not null, \f$ R \f$
  [[nodiscard]] Point act(const Point& p, ActJacobianGroup* J_q_g = nullptr,
                          ActJacobianPoint* J_q_p = nullptr) const noexcept {
    const Point Rp = R_.act(p);
    if (J_q_g) {
      J_q_g->template leftCols<2>() = R_.matrix();
      J_q_g->col(2) = Point(-Rp.y(), Rp.x());  // R [1]x p = [1]x R p
    }
    if (J_q_p) *J_q_p = R_.matrix();
    return Rp + t_;
  }

  /// \f$ y = x \oplus \tau = x\,\mathrm{Exp}(\tau) \f$.
  /// @param[in] d the tangent \f$ \tau \f$
  /// @param[out] J_y_x if not null, \f$ \mathrm{Ad}_{\mathrm{Exp}(\tau)}^{-1} \f$
  /// @param[out] J_y_d if not null, \f$ J_r(\tau) \f$
  [[nodiscard]] SE2 plus(const Tangent& d, Jacobian* J_y_x = nullptr,
                         Jacobian* J_y_d = nullptr) const noexcept {
    const SE2 e = exp(d, J_y_d);
    return compose(e, J_y_x);
  }
  /// \f$ d = y \ominus x = \mathrm{Log}(x^{-1} y) \f$ (this = y).
  /// @param[in] x the element subtracted
  /// @param[out] J_d_y if not null, \f$ J_r^{-1}(d) \f$
  /// @param[out] J_d_x if not null, \f$ -J_l^{-1}(d) \f$
  [[nodiscard]] Tangent minus(const SE2& x, Jacobian* J_d_y = nullptr,
                              Jacobian* J_d_x = nullptr) const noexcept {
    const Tangent d = x.between(*this).log(J_d_y);
    if (J_d_x) *J_d_x = -left_jacobian_inverse(d);
    return d;
  }

  /// \f$ \mathrm{Ad}_g = [R, (t_y, -t_x)^\top; 0, 1] \f$ (Solà App. C), so that
  /// \f$ g\,\mathrm{Exp}(\tau) = \mathrm{Exp}(\mathrm{Ad}_g \tau)\, g \f$.
  [[nodiscard]] Jacobian adjoint() const noexcept {
    Jacobian Ad = Jacobian::Identity();
    Ad.template topLeftCorner<2, 2>() = R_.matrix();
    Ad(0, 2) = t_.y();
    Ad(1, 2) = -t_.x();
    return Ad;
  }
  /// \f$ J_r(\tau) \f$, see the file comment.
  [[nodiscard]] static Jacobian right_jacobian(const Tangent& tau) noexcept {
    return right_jacobian(tau, detail::Se2Coeffs<T>(tau(2)));
  }
  /// \f$ J_r^{-1}(\tau) \f$ (block inverse of \f$ J_r \f$; finite for |θ| < 2π).
  [[nodiscard]] static Jacobian right_jacobian_inverse(const Tangent& tau) noexcept {
    return invert_jacobian(right_jacobian(tau));
  }
  /// \f$ J_l(\tau) = J_r(-\tau) \f$, see the file comment.
  [[nodiscard]] static Jacobian left_jacobian(const Tangent& tau) noexcept {
    return right_jacobian(Tangent(-tau));
  }
  /// \f$ J_l^{-1}(\tau) \f$.
  [[nodiscard]] static Jacobian left_jacobian_inverse(const Tangent& tau) noexcept {
    return invert_jacobian(left_jacobian(tau));
  }
  /// \f$ \tau^\wedge = [[\theta]_\times, \rho; 0, 0] \f$.
  [[nodiscard]] static LieAlgebra hat(const Tangent& tau) noexcept {
    LieAlgebra W;
    W << T(0), -tau(2), tau(0), tau(2), T(0), tau(1), T(0), T(0), T(0);
    return W;
  }
  /// Inverse of hat: \f$ (W_{02}, W_{12}, (W_{10} - W_{01})/2) \f$.
  [[nodiscard]] static Tangent vee(const LieAlgebra& W) noexcept {
    return Tangent(W(0, 2), W(1, 2), (W(1, 0) - W(0, 1)) / T(2));
  }

  /// The translation t (m): the position of the body in the world frame.
  [[nodiscard]] const Point& translation() const noexcept { return t_; }
  /// t_x (m).
  [[nodiscard]] T x() const noexcept { return t_.x(); }
  /// t_y (m).
  [[nodiscard]] T y() const noexcept { return t_.y(); }
  /// The heading θ in [-π, π) (rad).
  [[nodiscard]] T angle() const noexcept { return R_.angle(); }
  /// The rotation part.
  [[nodiscard]] const SO2<T>& so2() const noexcept { return R_; }
  /// The homogeneous matrix \f$ [R, t; 0, 1] \f$.
  [[nodiscard]] Matrix matrix() const noexcept {
    Matrix M = Matrix::Identity();
    M.template topLeftCorner<2, 2>() = R_.matrix();
    M.template topRightCorner<2, 1>() = t_;
    return M;
  }

  /// The same motion in scalar type U.
  template <std::floating_point U>
  [[nodiscard]] SE2<U> cast() const {
    return SE2<U>(t_.template cast<U>(), R_.template cast<U>());
  }
  /// True when \f$ \|g \ominus o\| \le \f$ tol (tangent norm, m and rad mixed).
  [[nodiscard]] bool is_approx(const SE2& o, T tol) const noexcept {
    return minus(o).norm() <= tol;
  }

 private:
  static Jacobian right_jacobian(const Tangent& tau, const detail::Se2Coeffs<T>& k) noexcept {
    Jacobian J;
    J << k.A, k.B, k.C * tau(0) - k.D * tau(1),  //
        -k.B, k.A, k.D * tau(0) + k.C * tau(1),  //
        T(0), T(0), T(1);
    return J;
  }
  // [M w; 0 1]^-1 = [M^-1, -M^-1 w; 0, 1], with M = a I + b [1]x and
  // M^-1 = (a I - b [1]x) / (a² + b²).
  static Jacobian invert_jacobian(const Jacobian& J) noexcept {
    const T a = J(0, 0), b = J(1, 0);
    const T n = a * a + b * b;
    Eigen::Matrix<T, 2, 2> Mi;
    Mi << a / n, b / n, -b / n, a / n;
    Jacobian Ji = Jacobian::Identity();
    Ji.template topLeftCorner<2, 2>() = Mi;
    Ji.template topRightCorner<2, 1>() = -Mi * J.template topRightCorner<2, 1>();
    return Ji;
  }

  Point t_{Point::Zero()};
  SO2<T> R_{};
};

using SE2d = SE2<double>;  ///< SE(2) in double
using SE2f = SE2<float>;   ///< SE(2) in float

}  // namespace posefuse

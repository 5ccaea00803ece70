#pragma once
/// @file
/// SE(3): rigid motions of space, stored as a translation t and an SO3.
///
/// Conventions (right perturbations, tangent \f$ \tau = [\rho, \phi] \f$ with
/// the translation part ρ first) are those of lie/lie.hpp. Formulas: Solà,
/// Deray, Atchuthan, "A micro Lie theory for state estimation in robotics",
/// arXiv:1812.01537, 2018 ("Solà"), App. D; Barfoot, *State Estimation for
/// Robotics*, 2017 ("Barfoot"), §7.1, which uses the same [ρ, φ] order:
///  * \f$ \mathrm{Exp}(\tau) = (J_l(\phi)\rho, \mathrm{Exp}(\phi)) \f$ (Solà eq 172, 174),
///    \f$ \mathrm{Log}(g) = (J_l^{-1}(\phi)\, t, \phi = \mathrm{Log}(R)) \f$ (eq 173);
///  * \f$ \mathrm{Ad}_g = [R, [t]_\times R; 0, R] \f$;
///  * \f$ J_l(\tau) = [J_l(\phi), Q(\rho, \phi); 0, J_l(\phi)] \f$ (Solà eq 180),
///    \f$ J_r(\tau) = J_l(-\tau) = [J_r(\phi), Q(-\rho, -\phi); 0, J_r(\phi)] \f$ (Solà eq 179),
///    with \f$ J_l(\phi), J_r(\phi) \f$ those of SO(3) and, writing
///    \f$ P = [\rho]_\times,\; F = [\phi]_\times,\; \theta = |\phi| \f$ (Barfoot eq 7.86),
///    \f[ Q(\rho, \phi) = \tfrac12 P + c_1 (F P + P F + F P F)
///        + c_2 (F F P + P F F - 3 F P F) + c_3 (F P F F + F F P F), \f]
///    \f$ c_1 = \tfrac{\theta - \sin\theta}{\theta^3},\;
///        c_2 = \tfrac{\theta^2 + 2\cos\theta - 2}{2\theta^4},\;
///        c_3 = \tfrac{2\theta - 3\sin\theta + \theta\cos\theta}{2\theta^5} \f$;
///  * \f$ [A, B; 0, A]^{-1} = [A^{-1}, -A^{-1} B A^{-1}; 0, A^{-1}] \f$ gives the inverses.
/// c1, c2, c3 cancel badly as θ -> 0 and use their Taylor series below 0.5 rad
/// (lie/detail/series.hpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <concepts>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/detail/series.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// A rigid motion of space: \f$ g\,p = R\,p + t \f$.
///
/// As a pose, `SE3` is the pose of a body frame in a world frame (the
/// library's `T_w_b`, t in m): `act` maps body coordinates to world
/// coordinates. A posefuse::Manifold with \f$ x \oplus \tau = x\,\mathrm{Exp}(\tau) \f$,
/// a body-frame perturbation.
template <std::floating_point T>
class SE3 {
 public:
  using Scalar = T;                                          ///< floating-point type
  static constexpr int Dim = 6;                              ///< tangent dimension
  static constexpr int PointDim = 3;                         ///< dimension of the points it acts on
  using Tangent = Eigen::Matrix<T, 6, 1>;                    ///< [ρ (m), φ (rad)]
  using Jacobian = Eigen::Matrix<T, 6, 6>;                   ///< d(tangent) / d(tangent)
  using Point = Eigen::Matrix<T, 3, 1>;                      ///< a point of space (m)
  using Matrix = Eigen::Matrix<T, 4, 4>;                     ///< homogeneous matrix [R t; 0 1]
  using LieAlgebra = Eigen::Matrix<T, 4, 4>;                 ///< hat(τ)
  using Isometry = Eigen::Transform<T, 3, Eigen::Isometry>;  ///< Eigen's rigid transform
  using ActJacobianGroup = Eigen::Matrix<T, 3, 6>;           ///< d(g p) / d(g)
  using ActJacobianPoint = Eigen::Matrix<T, 3, 3>;           ///< d(g p) / d(p)

  /// The identity motion.
  SE3() noexcept = default;
  /// The motion \f$ p \mapsto R p + t \f$. Not validated.
  SE3(const Point& t, const SO3<T>& R) noexcept : t_(t), R_(R) {}
  /// The motion of an Eigen isometry; its linear part is checked and
  /// projected as by SO3's matrix constructor.
  /// @param[in] T_a_b rigid transform (rotation and translation in m)
  /// @param[in] tol orthonormality tolerance of the linear part
  /// @throws posefuse::invalid_argument when the translation is not finite or
  ///         the linear part is not a rotation within tol (see SO3)
  explicit SE3(const Isometry& T_a_b, T tol = SO3<T>::kDefaultOrthonormalityTolerance)
      : t_(T_a_b.translation()), R_(typename SO3<T>::Matrix(T_a_b.linear()), tol) {
    if (!t_.allFinite()) throw invalid_argument("SE3: translation has a non-finite entry");
  }

  /// The identity motion.
  [[nodiscard]] static SE3 identity() noexcept { return SE3(); }

  /// \f$ \mathrm{Exp}(\tau) = (J_l(\phi)\rho, \mathrm{Exp}(\phi)) \f$ (Solà eq 172, 174);
  /// finite for every finite τ (large angles as SO3::exp). Not validated.
  /// @param[in] tau [ρ, φ]
  /// @param[out] J_g_tau if not null, \f$ J_r(\tau) \f$
  [[nodiscard]] static SE3 exp(const Tangent& tau, Jacobian* J_g_tau = nullptr) noexcept {
    const Point rho = tau.template head<3>();
    const Point phi = tau.template tail<3>();
    if (J_g_tau) *J_g_tau = right_jacobian(tau);
    return SE3(SO3<T>::left_jacobian(phi) * rho, SO3<T>::exp(phi));
  }
  /// \f$ \mathrm{Log}(g) = (J_l^{-1}(\phi) t, \phi) \f$, |φ| in [0, π] (Solà eq 173).
  /// @param[out] J_tau_g if not null, \f$ J_r^{-1}(\mathrm{Log}\,g) \f$
  [[nodiscard]] Tangent log(Jacobian* J_tau_g = nullptr) const noexcept {
    const Point phi = R_.log();
    Tangent tau;
    tau.template head<3>() = SO3<T>::left_jacobian_inverse(phi) * t_;
    tau.template tail<3>() = phi;
    if (J_tau_g) *J_tau_g = right_jacobian_inverse(tau);
    return tau;
  }

  /// \f$ g^{-1} = (-R^\top t, R^\top) \f$.
  /// @param[out] J_inv_g if not null, \f$ -\mathrm{Ad}_g \f$ (Solà, Jacobian of the inverse)
  [[nodiscard]] SE3 inverse(Jacobian* J_inv_g = nullptr) const noexcept {
    if (J_inv_g) *J_inv_g = -adjoint();
    const SO3<T> Ri = R_.inverse();
    return SE3(-Ri.act(t_), Ri);
  }
  /// \f$ c = a\,b = (t_a + R_a t_b, R_a R_b) \f$ (this = a).
  /// @param[in] b the right operand
  /// @param[out] J_c_a if not null, \f$ \mathrm{Ad}_b^{-1} \f$ (Solà, Jacobian of the composition)
  /// @param[out] J_c_b if not null, \f$ I \f$
  [[nodiscard]] SE3 compose(const SE3& b, Jacobian* J_c_a = nullptr,
                            Jacobian* J_c_b = nullptr) const noexcept {
    if (J_c_a) *J_c_a = b.inverse().adjoint();
    if (J_c_b) J_c_b->setIdentity();
    return SE3(t_ + R_.act(b.t_), R_.compose(b.R_));
  }
  /// \f$ a\,b \f$ without Jacobians.
  [[nodiscard]] SE3 operator*(const SE3& b) const noexcept { return compose(b); }
  /// \f$ d = a^{-1} b = (R_a^\top (t_b - t_a), R_a^\top R_b) \f$ (this = a).
  /// @param[in] b the right operand
  /// @param[out] J_d_a if not null, \f$ -\mathrm{Ad}_d^{-1} \f$
  /// @param[out] J_d_b if not null, \f$ I \f$
  [[nodiscard]] SE3 between(const SE3& b, Jacobian* J_d_a = nullptr,
                            Jacobian* J_d_b = nullptr) const noexcept {
    const SO3<T> Ri = R_.inverse();
    const SE3 d(Ri.act(Point(b.t_ - t_)), R_.between(b.R_));
    if (J_d_a) *J_d_a = -d.inverse().adjoint();
    if (J_d_b) J_d_b->setIdentity();
    return d;
  }
  /// \f$ q = R p + t \f$.
  /// @param[in] p the point
  /// @param[out] J_q_g if not null, \f$ [R,\; -R[p]_\times] \f$
  /// @param[out] J_q_p if not null, \f$ R \f$
  [[nodiscard]] Point act(const Point& p, ActJacobianGroup* J_q_g = nullptr,
                          ActJacobianPoint* J_q_p = nullptr) const noexcept {
    if (J_q_g || J_q_p) {
      const typename SO3<T>::Matrix R = R_.matrix();
      if (J_q_g) {
        J_q_g->template leftCols<3>() = R;
        J_q_g->template rightCols<3>() = -R * SO3<T>::hat(p);
      }
      if (J_q_p) *J_q_p = R;
    }
    return R_.act(p) + t_;
  }

  /// \f$ y = x \oplus \tau = x\,\mathrm{Exp}(\tau) \f$.
  /// @param[in] d the tangent \f$ \tau \f$
  /// @param[out] J_y_x if not null, \f$ \mathrm{Ad}_{\mathrm{Exp}(\tau)}^{-1} \f$
  /// @param[out] J_y_d if not null, \f$ J_r(\tau) \f$
  [[nodiscard]] SE3 plus(const Tangent& d, Jacobian* J_y_x = nullptr,
                         Jacobian* J_y_d = nullptr) const noexcept {
    return compose(exp(d, J_y_d), J_y_x);
  }
  /// \f$ d = y \ominus x = \mathrm{Log}(x^{-1} y) \f$ (this = y).
  /// @param[in] x the element subtracted
  /// @param[out] J_d_y if not null, \f$ J_r^{-1}(d) \f$
  /// @param[out] J_d_x if not null, \f$ -J_l^{-1}(d) \f$
  [[nodiscard]] Tangent minus(const SE3& x, Jacobian* J_d_y = nullptr,
                              Jacobian* J_d_x = nullptr) const noexcept {
    const Tangent d = x.between(*this).log(J_d_y);
    if (J_d_x) *J_d_x = -left_jacobian_inverse(d);
    return d;
  }

  /// \f$ \mathrm{Ad}_g = [R, [t]_\times R; 0, R] \f$, so that
  /// \f$ g\,\mathrm{Exp}(\tau) = \mathrm{Exp}(\mathrm{Ad}_g\tau)\,g \f$.
  [[nodiscard]] Jacobian adjoint() const noexcept {
    const typename SO3<T>::Matrix R = R_.matrix();
    Jacobian Ad;
    Ad.template topLeftCorner<3, 3>() = R;
    Ad.template topRightCorner<3, 3>() = SO3<T>::hat(t_) * R;
    Ad.template bottomLeftCorner<3, 3>().setZero();
    Ad.template bottomRightCorner<3, 3>() = R;
    return Ad;
  }
  /// \f$ J_r(\tau) = [J_r(\phi), Q(-\rho, -\phi); 0, J_r(\phi)] \f$ (Solà eq 179).
  [[nodiscard]] static Jacobian right_jacobian(const Tangent& tau) noexcept {
    return left_jacobian(Tangent(-tau));
  }
  /// \f$ J_r^{-1}(\tau) = J_l^{-1}(-\tau) \f$.
  [[nodiscard]] static Jacobian right_jacobian_inverse(const Tangent& tau) noexcept {
    return left_jacobian_inverse(Tangent(-tau));
  }
  /// \f$ J_l(\tau) = [J_l(\phi), Q(\rho, \phi); 0, J_l(\phi)] \f$ (Solà eq 180, Barfoot eq 7.86).
  [[nodiscard]] static Jacobian left_jacobian(const Tangent& tau) noexcept {
    const Point rho = tau.template head<3>();
    const Point phi = tau.template tail<3>();
    const typename SO3<T>::Jacobian Jl = SO3<T>::left_jacobian(phi);
    Jacobian J;
    J.template topLeftCorner<3, 3>() = Jl;
    J.template topRightCorner<3, 3>() = q_block(rho, phi);
    J.template bottomLeftCorner<3, 3>().setZero();
    J.template bottomRightCorner<3, 3>() = Jl;
    return J;
  }
  /// \f$ J_l^{-1}(\tau) = [J_l^{-1}, -J_l^{-1} Q J_l^{-1}; 0, J_l^{-1}] \f$
  /// (finite for |φ| < 2π).
  [[nodiscard]] static Jacobian left_jacobian_inverse(const Tangent& tau) noexcept {
    const Point rho = tau.template head<3>();
    const Point phi = tau.template tail<3>();
    const typename SO3<T>::Jacobian Ji = SO3<T>::left_jacobian_inverse(phi);
    Jacobian J;
    J.template topLeftCorner<3, 3>() = Ji;
    J.template topRightCorner<3, 3>() = -Ji * q_block(rho, phi) * Ji;
    J.template bottomLeftCorner<3, 3>().setZero();
    J.template bottomRightCorner<3, 3>() = Ji;
    return J;
  }
  /// \f$ \tau^\wedge = [[\phi]_\times, \rho; 0, 0] \f$ (Solà eq 169).
  [[nodiscard]] static LieAlgebra hat(const Tangent& tau) noexcept {
    LieAlgebra W = LieAlgebra::Zero();
    W.template topLeftCorner<3, 3>() = SO3<T>::hat(tau.template tail<3>());
    W.template topRightCorner<3, 1>() = tau.template head<3>();
    return W;
  }
  /// Inverse of hat.
  [[nodiscard]] static Tangent vee(const LieAlgebra& W) noexcept {
    Tangent tau;
    tau.template head<3>() = W.template topRightCorner<3, 1>();
    tau.template tail<3>() = SO3<T>::vee(W.template topLeftCorner<3, 3>());
    return tau;
  }

  /// The translation t (m).
  [[nodiscard]] const Point& translation() const noexcept { return t_; }
  /// The rotation part.
  [[nodiscard]] const SO3<T>& so3() const noexcept { return R_; }
  /// The homogeneous matrix \f$ [R, t; 0, 1] \f$.
  [[nodiscard]] Matrix matrix() const noexcept {
    Matrix M = Matrix::Identity();
    M.template topLeftCorner<3, 3>() = R_.matrix();
    M.template topRightCorner<3, 1>() = t_;
    return M;
  }
  /// The same motion as an Eigen isometry.
  [[nodiscard]] Isometry isometry() const noexcept {
    Isometry iso = Isometry::Identity();
    iso.linear() = R_.matrix();
    iso.translation() = t_;
    return iso;
  }

  /// The same motion in scalar type U.
  template <std::floating_point U>
  [[nodiscard]] SE3<U> cast() const noexcept {
    return SE3<U>(t_.template cast<U>(), R_.template cast<U>());
  }
  /// True when \f$ \|g \ominus o\| \le \f$ tol (tangent norm, m and rad mixed).
  [[nodiscard]] bool is_approx(const SE3& o, T tol) const noexcept {
    return minus(o).norm() <= tol;
  }

 private:
  // Q(rho, phi) of Barfoot eq 7.86 (the file comment). Above
  // detail::large_angle, with F = θ U (U = [φ/θ]x), the same sum with the
  // powers of θ folded into the coefficients: c1 θ, c1 θ², c2 θ², c3 θ³.
  static typename SO3<T>::Matrix q_block(const Point& rho, const Point& phi) noexcept {
    using M3 = typename SO3<T>::Matrix;
    const T th = detail::overflow_safe_norm(phi);
    const M3 P = SO3<T>::hat(rho);
    if (th > detail::large_angle<T>()) {
      const M3 U = SO3<T>::hat(Point(phi / th));
      const M3 UP = U * P;
      const M3 PU = P * U;
      const M3 UPU = UP * U;
      const T s = std::sin(th);
      const T h = std::sin(th / T(2)) / th;
      const T c1_th = (th - s) / th / th;                                   // c1 θ
      const T c1_th2 = T(1) - s / th;                                       // c1 θ²
      const T c2_th2 = T(0.5) - T(2) * h * h;                               // c2 θ² = 1/2 - (1 - cos θ) / θ²
      const T c3_th3 = (T(2) + std::cos(th)) / (T(2) * th) - T(1.5) * s / th / th;  // c3 θ³
      return T(0.5) * P + c1_th * (UP + PU) + c1_th2 * UPU + c2_th2 * (U * UP + PU * U - T(3) * UPU) +
             c3_th3 * (UPU * U + U * UPU);
    }
    const M3 F = SO3<T>::hat(phi);
    const M3 FP = F * P;
    const M3 PF = P * F;
    const M3 FPF = FP * F;
    const M3 FFP = F * FP;
    return T(0.5) * P + detail::x_minus_sin_over_x3(th) * (FP + PF + FPF) +
           detail::se3_q_c2(th) * (FFP + PF * F - T(3) * FPF) +
           detail::se3_q_c3(th) * (FPF * F + F * FPF);
  }

  Point t_{Point::Zero()};
  SO3<T> R_{};
};

using SE3d = SE3<double>;  ///< SE(3) in double
using SE3f = SE3<float>;   ///< SE(3) in float

}  // namespace posefuse

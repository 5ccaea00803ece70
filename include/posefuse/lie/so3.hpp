#pragma once
/// @file
/// SO(3): rotations of space, stored as a unit quaternion.
///
/// Conventions (right perturbations, tangent \f$ \phi \f$ = rotation vector in
/// rad) are those of lie/lie.hpp. Formulas: Solà, Deray, Atchuthan, "A micro
/// Lie theory for state estimation in robotics", arXiv:1812.01537, 2018
/// ("Solà"), its elementary Jacobian blocks and App. B; Barfoot, *State Estimation for
/// Robotics*, Cambridge University Press, 2017 ("Barfoot"), §7.1. With
/// \f$ \theta = |\phi| \f$ and \f$ [\phi]_\times \f$ the skew matrix:
///  * \f$ \mathrm{Exp}(\phi) = (\cos\tfrac{\theta}{2}, \tfrac{\sin(\theta/2)}{\theta}\phi) \f$
///    as a quaternion, i.e. Rodrigues' formula
///    \f$ R = I + \tfrac{\sin\theta}{\theta}[\phi]_\times
///         + \tfrac{1 - \cos\theta}{\theta^2}[\phi]_\times^2 \f$ (Barfoot §7.1.3);
///  * \f$ J_r(\phi) = I - \tfrac{1 - \cos\theta}{\theta^2}[\phi]_\times
///         + \tfrac{\theta - \sin\theta}{\theta^3}[\phi]_\times^2 \f$ (Solà eq 143),
///    \f$ J_r^{-1}(\phi) = I + \tfrac12[\phi]_\times
///         + \left(\tfrac{1}{\theta^2} - \tfrac{1 + \cos\theta}{2\theta\sin\theta}\right)
///           [\phi]_\times^2 \f$
///    (Solà eq 144), \f$ J_l(\phi) = J_r(-\phi) = J_r(\phi)^\top \f$ (Solà eq 145-146;
///    Barfoot §7.1.5 writes the same left Jacobian and its inverse).
/// Every coefficient switches to its Taylor series at small θ
/// (lie/detail/series.hpp); the \f$ J_r^{-1} \f$ coefficient is evaluated as
/// \f$ (1 - \tfrac{\theta}{2}\cot\tfrac{\theta}{2})/\theta^2 \f$, finite at θ = π.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <concepts>
#include <limits>
#include <string>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/detail/series.hpp>

namespace posefuse {

namespace detail {
/// \f$ |\phi| \f$ without overflow: `phi.norm()` (to the bit) whenever
/// \f$ |\phi|^2 \f$ is finite, else the norm scaled by the largest
/// \f$ |\phi_i| \f$ (finite for every finite φ; ∞ or NaN for a non-finite one).
template <class Derived>
[[nodiscard]] typename Derived::Scalar overflow_safe_norm(const Eigen::MatrixBase<Derived>& phi) noexcept {
  using T = typename Derived::Scalar;
  const T s2 = phi.squaredNorm();
  if (s2 <= std::numeric_limits<T>::max()) return std::sqrt(s2);
  const T m = phi.cwiseAbs().maxCoeff();
  if (!(m <= std::numeric_limits<T>::max())) return std::sqrt(s2);  // an infinite or NaN entry
  return m * (phi / m).norm();
}
}  // namespace detail

/// A rotation of 3-D space: \f$ q = R\,p \f$.
///
/// As an attitude, `SO3` is the orientation of a body frame in a world
/// frame: `act` maps body coordinates to world coordinates (the convention
/// of lie/rotation.hpp). A posefuse::Manifold with
/// \f$ x \oplus \phi = x\,\mathrm{Exp}(\phi) \f$ (a body-frame perturbation).
template <std::floating_point T>
class SO3 {
 public:
  using Scalar = T;                                 ///< floating-point type
  static constexpr int Dim = 3;                     ///< tangent dimension
  static constexpr int PointDim = 3;                ///< dimension of the points it acts on
  using Tangent = Eigen::Matrix<T, 3, 1>;           ///< rotation vector φ (rad)
  using Jacobian = Eigen::Matrix<T, 3, 3>;          ///< d(tangent) / d(tangent)
  using Point = Eigen::Matrix<T, 3, 1>;             ///< a point of space
  using Matrix = Eigen::Matrix<T, 3, 3>;            ///< rotation matrix
  using LieAlgebra = Eigen::Matrix<T, 3, 3>;        ///< hat(φ) = [φ]x
  using Quaternion = Eigen::Quaternion<T>;          ///< unit quaternion (w, x, y, z)
  using ActJacobianGroup = Eigen::Matrix<T, 3, 3>;  ///< d(g p) / d(g)
  using ActJacobianPoint = Eigen::Matrix<T, 3, 3>;  ///< d(g p) / d(p)

  /// Default tolerance of the rotation-matrix constructor on
  /// \f$ \max_{ij} |(R^\top R - I)_{ij}| \f$: accepts matrices printed with
  /// six significant digits, rejects anything that is not a rotation.
  static constexpr T kDefaultOrthonormalityTolerance = T(1e-5);

  /// The identity rotation.
  SO3() noexcept = default;

  /// The rotation of a quaternion, normalised.
  /// @param[in] q any quaternion of non-zero norm (w, x, y, z); q and -q are the same rotation
  /// @throws posefuse::invalid_argument when a coefficient is not finite or
  ///         \f$ |q| < \sqrt{\epsilon} \f$ (no direction)
  explicit SO3(const Quaternion& q) : q_(q) {
    if (!q.coeffs().allFinite())
      throw invalid_argument("SO3: quaternion has a non-finite coefficient");
    const T n = q.norm();
    if (!(n >= std::sqrt(std::numeric_limits<T>::epsilon())))
      throw invalid_argument("SO3: quaternion has (near) zero norm");
    q_.coeffs() /= n;
  }

  /// The rotation of a rotation matrix (body -> world), projected onto SO(3).
  /// @param[in] R 3x3 matrix with \f$ \max|R^\top R - I| \le \f$ tol and det R > 0
  /// @param[in] tol orthonormality tolerance (see kDefaultOrthonormalityTolerance)
  /// @throws posefuse::invalid_argument when R has a non-finite entry, is not
  ///         orthonormal within tol, or is a reflection (det R <= 0)
  explicit SO3(const Matrix& R, T tol = kDefaultOrthonormalityTolerance) {
    if (!R.allFinite()) throw invalid_argument("SO3: rotation matrix has a non-finite entry");
    const T err = (R.transpose() * R - Matrix::Identity()).cwiseAbs().maxCoeff();
    if (!(err <= tol))
      throw invalid_argument("SO3: matrix is not orthonormal (max |R^T R - I| = " +
                             std::to_string(err) + " > " + std::to_string(tol) + ")");
    if (!(R.determinant() > T(0)))
      throw invalid_argument("SO3: matrix is a reflection (det <= 0), not a rotation");
    q_ = Quaternion(R);  // Shepperd-style branch on the largest diagonal: accurate at any angle
    q_.normalize();
  }

  /// The identity rotation.
  [[nodiscard]] static SO3 identity() noexcept { return SO3(); }

  /// \f$ \mathrm{Exp}(\phi) \f$, the rotation by θ = |φ| rad about φ/θ (see the file comment).
  /// @param[in] phi the rotation vector \f$ \phi \f$ (rad)
  /// Every finite φ gives a rotation: above detail::large_angle (6.7e7 rad
  /// in double) the quaternion is \f$ (\cos\tfrac{\theta}{2}, \sin\tfrac{\theta}{2}\,u) \f$
  /// with the unit axis u and θ computed without overflow (the sine and
  /// cosine reduce any finite angle exactly). Not validated (hot path): a
  /// non-finite φ gives a non-finite rotation.
  /// @param[out] J_g_tau if not null, \f$ J_r(\phi) \f$
  [[nodiscard]] static SO3 exp(const Tangent& phi, Jacobian* J_g_tau = nullptr) noexcept {
    const T th = detail::overflow_safe_norm(phi);
    if (J_g_tau) *J_g_tau = right_jacobian(phi);
    if (th > detail::large_angle<T>()) {
      const Tangent u = phi / th;
      const T s = std::sin(th / T(2));
      return SO3(Quaternion(std::cos(th / T(2)), s * u.x(), s * u.y(), s * u.z()), Unchecked{});
    }
    const T k = detail::sin_over_x(th / T(2)) / T(2);  // sin(θ/2) / θ
    return SO3(Quaternion(std::cos(th / T(2)), k * phi.x(), k * phi.y(), k * phi.z()), Unchecked{});
  }

  /// \f$ \mathrm{Log}(g) \f$: the rotation vector with |φ| in [0, π].
  ///
  /// From the quaternion (w, v) with w >= 0:
  /// \f$ \phi = 2\,\mathrm{atan2}(|v|, w)\, v / |v| \f$, accurate at every angle
  /// including π (at θ = π exactly either of ±φ is returned); for
  /// |v| below \f$ \epsilon^{1/4} \f$ the series
  /// \f$ \phi = \tfrac{2}{w}\left(1 - \tfrac{|v|^2}{3w^2} + \tfrac{|v|^4}{5w^4}\right) v \f$.
  /// @param[out] J_tau_g if not null, \f$ J_r^{-1}(\phi) \f$
  [[nodiscard]] Tangent log(Jacobian* J_tau_g = nullptr) const noexcept {
    T w = q_.w();
    Tangent v = q_.vec();
    if (w < T(0)) {
      w = -w;
      v = -v;
    }
    const T n = v.norm();
    T k;  // phi = k v
    if (n < detail::tiny_angle<T>()) {
      const T x2 = (n * n) / (w * w);
      k = (T(2) / w) * (T(1) - x2 / T(3) + x2 * x2 / T(5));
    } else {
      k = T(2) * std::atan2(n, w) / n;
    }
    const Tangent phi = k * v;
    if (J_tau_g) *J_tau_g = right_jacobian_inverse(phi);
    return phi;
  }

  /// \f$ g^{-1} = q^* \f$ (\f$ R^\top \f$).
  /// @param[out] J_inv_g if not null, \f$ -\mathrm{Ad}_g = -R \f$ (Solà, Jacobian of the inverse)
  [[nodiscard]] SO3 inverse(Jacobian* J_inv_g = nullptr) const noexcept {
    if (J_inv_g) *J_inv_g = -matrix();
    return SO3(q_.conjugate(), Unchecked{});
  }
  /// \f$ c = a\,b \f$ (this = a), renormalised so long chains stay unit.
  /// @param[in] b the right operand
  /// @param[out] J_c_a if not null, \f$ \mathrm{Ad}_b^{-1} = R_b^\top \f$
  ///             (Solà, Jacobian of the composition)
  /// @param[out] J_c_b if not null, \f$ I \f$
  [[nodiscard]] SO3 compose(const SO3& b, Jacobian* J_c_a = nullptr,
                            Jacobian* J_c_b = nullptr) const noexcept {
    if (J_c_a) *J_c_a = b.matrix().transpose();
    if (J_c_b) J_c_b->setIdentity();
    return SO3((q_ * b.q_).normalized(), Unchecked{});
  }
  /// \f$ a\,b \f$ without Jacobians.
  [[nodiscard]] SO3 operator*(const SO3& b) const noexcept { return compose(b); }
  /// \f$ d = a^{-1} b \f$ (this = a).
  /// @param[in] b the right operand
  /// @param[out] J_d_a if not null, \f$ -\mathrm{Ad}_d^{-1} = -R_d^\top \f$
  /// @param[out] J_d_b if not null, \f$ I \f$
  [[nodiscard]] SO3 between(const SO3& b, Jacobian* J_d_a = nullptr,
                            Jacobian* J_d_b = nullptr) const noexcept {
    const SO3 d((q_.conjugate() * b.q_).normalized(), Unchecked{});
    if (J_d_a) *J_d_a = -d.matrix().transpose();
    if (J_d_b) J_d_b->setIdentity();
    return d;
  }
  /// \f$ q = R p \f$.
  /// @param[in] p the point
  /// @param[out] J_q_g if not null, \f$ -R [p]_\times \f$
  /// @param[out] J_q_p if not null, \f$ R \f$
  [[nodiscard]] Point act(const Point& p, ActJacobianGroup* J_q_g = nullptr,
                          ActJacobianPoint* J_q_p = nullptr) const noexcept {
    if (J_q_g || J_q_p) {
      const Matrix R = matrix();
      if (J_q_g) *J_q_g = -R * hat(p);
      if (J_q_p) *J_q_p = R;
    }
    return q_ * p;
  }

  /// \f$ y = x \oplus \phi = x\,\mathrm{Exp}(\phi) \f$.
  /// @param[in] d the tangent \f$ \tau \f$
  /// @param[out] J_y_x if not null,
  ///             \f$ \mathrm{Ad}_{\mathrm{Exp}(\phi)}^{-1} = \mathrm{Exp}(\phi)^\top \f$
  /// @param[out] J_y_d if not null, \f$ J_r(\phi) \f$
  [[nodiscard]] SO3 plus(const Tangent& d, Jacobian* J_y_x = nullptr,
                         Jacobian* J_y_d = nullptr) const noexcept {
    return compose(exp(d, J_y_d), J_y_x);
  }
  /// \f$ d = y \ominus x = \mathrm{Log}(x^{-1} y) \f$ (this = y).
  /// @param[in] x the element subtracted
  /// @param[out] J_d_y if not null, \f$ J_r^{-1}(d) \f$
  /// @param[out] J_d_x if not null, \f$ -J_l^{-1}(d) \f$
  [[nodiscard]] Tangent minus(const SO3& x, Jacobian* J_d_y = nullptr,
                              Jacobian* J_d_x = nullptr) const noexcept {
    const Tangent d = x.between(*this).log(J_d_y);
    if (J_d_x) *J_d_x = -left_jacobian_inverse(d);
    return d;
  }

  /// \f$ \mathrm{Ad}_g = R \f$, so that \f$ g\,\mathrm{Exp}(\phi) = \mathrm{Exp}(R\phi)\,g \f$.
  [[nodiscard]] Jacobian adjoint() const noexcept { return matrix(); }

  /// \f$ J_r(\phi) \f$ (Solà eq 143; see the file comment). Above
  /// detail::large_angle, in the axis form
  /// \f$ I - \tfrac{1 - \cos\theta}{\theta}[u]_\times + (1 - \tfrac{\sin\theta}{\theta})[u]_\times^2 \f$,
  /// finite for every finite φ.
  [[nodiscard]] static Jacobian right_jacobian(const Tangent& phi) noexcept {
    const T th = detail::overflow_safe_norm(phi);
    if (th > detail::large_angle<T>()) {
      const Matrix U = hat(Tangent(phi / th));
      const T s = std::sin(th / T(2));
      return Matrix::Identity() - (T(2) * s * s / th) * U + (T(1) - std::sin(th) / th) * (U * U);
    }
    const Matrix W = hat(phi);
    return Matrix::Identity() - detail::one_minus_cos_over_x2(th) * W +
           detail::x_minus_sin_over_x3(th) * (W * W);
  }
  /// \f$ J_r^{-1}(\phi) \f$ (Solà eq 144; finite for |φ| < 2π).
  [[nodiscard]] static Jacobian right_jacobian_inverse(const Tangent& phi) noexcept {
    const Matrix W = hat(phi);
    return Matrix::Identity() + T(0.5) * W + detail::so3_jinv_coeff(phi.norm()) * (W * W);
  }
  /// \f$ J_l(\phi) = J_r(-\phi) \f$ (Solà eq 145).
  [[nodiscard]] static Jacobian left_jacobian(const Tangent& phi) noexcept {
    return right_jacobian(Tangent(-phi));
  }
  /// \f$ J_l^{-1}(\phi) = J_r^{-1}(-\phi) \f$ (Solà eq 146).
  [[nodiscard]] static Jacobian left_jacobian_inverse(const Tangent& phi) noexcept {
    return right_jacobian_inverse(Tangent(-phi));
  }
  /// \f$ [\phi]_\times \f$, with \f$ [\phi]_\times p = \phi \times p \f$.
  [[nodiscard]] static LieAlgebra hat(const Tangent& phi) noexcept {
    LieAlgebra W;
    W << T(0), -phi.z(), phi.y(), phi.z(), T(0), -phi.x(), -phi.y(), phi.x(), T(0);
    return W;
  }
  /// Inverse of hat (antisymmetric part):
  /// \f$ ((W_{21} - W_{12}), (W_{02} - W_{20}), (W_{10} - W_{01})) / 2 \f$.
  [[nodiscard]] static Tangent vee(const LieAlgebra& W) noexcept {
    return Tangent(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)) / T(2);
  }

  /// The unit quaternion (either sign may be stored).
  [[nodiscard]] const Quaternion& quaternion() const noexcept { return q_; }
  /// The rotation matrix R.
  [[nodiscard]] Matrix matrix() const noexcept { return q_.toRotationMatrix(); }

  /// The same rotation in scalar type U (renormalised after rounding).
  template <std::floating_point U>
  [[nodiscard]] SO3<U> cast() const noexcept {
    return SO3<U>(q_.template cast<U>().normalized(), typename SO3<U>::Unchecked{});
  }
  /// True when \f$ |g \ominus o| \le \f$ tol (rad).
  [[nodiscard]] bool is_approx(const SO3& o, T tol) const noexcept {
    return minus(o).norm() <= tol;
  }

 private:
  template <std::floating_point U>
  friend class SO3;
  struct Unchecked {};
  SO3(const Quaternion& q, Unchecked) noexcept : q_(q) {}

  Quaternion q_{Quaternion::Identity()};
};

using SO3d = SO3<double>;  ///< SO(3) in double
using SO3f = SO3<float>;   ///< SO(3) in float

}  // namespace posefuse

#pragma once
/// @file
/// Odometry increments on the plane as a motion model: the state is a
/// PlanarPose (\f$ \mathbb{R}^2 \times S^1 \f$, world frame), the control the
/// body-frame increment \f$ \delta = O_{k-1}^{-1} \oplus O_k \f$ between two
/// odometry poses, as an SE(2) element.
///
/// **Prediction.** \f$ x' = x \oplus \delta \f$ (SE(2) composition:
/// \f$ t' = t + R(\theta)\,t_\delta,\; \theta' = \theta + \theta_\delta \f$).
///
/// **Jacobian with respect to the state.** lie/se2.hpp gives right Jacobians,
/// for perturbations \f$ x\,\mathrm{Exp}(\tau) \f$ in the body frame; the
/// state's `plus` perturbs in the world frame, \f$ e = (\delta t_w,
/// \delta\theta) \f$. To first order \f$ x\,\mathrm{Exp}(\tau) = (t + R\rho,
/// \theta + \phi) \f$, i.e. \f$ e = M(\theta)\,\tau \f$ with \f$ M(\theta) =
/// \mathrm{diag}(R(\theta), 1) \f$, so a right Jacobian \f$ J \f$ of a map
/// between poses becomes \f$ M(\theta_{out})\,J\,M(\theta_{in})^\top \f$ on
/// \f$ \mathbb{R}^2 \times S^1 \f$. For \f$ x \oplus \delta \f$ the position
/// row block is that of the action \f$ t' = x \cdot t_\delta \f$, whose SE(2)
/// Jacobian is \f$ J_{t',x} = [R,\; R [1]_\times t_\delta] \f$
/// (`SE2::act`'s `J_q_g`); times \f$ M(\theta)^\top \f$ it is
/// \f$ [I,\; R [1]_\times t_\delta] \f$, and the heading row is
/// \f$ [0, 0, 1] \f$:
/// \f[ F = \begin{bmatrix} I_2 & R(\theta)[1]_\times t_\delta \\ 0 & 1
///     \end{bmatrix} \f]
/// (the SE(2) Jacobians are Solà, Deray, Atchuthan, arXiv:1812.01537, App. C;
/// the change of perturbation is derived here).
///
/// **Noise.** Additive on the increment's components \f$ (t_{\delta,x},
/// t_{\delta,y}, \theta_\delta) \f$ in the body frame,
/// \f$ Q_\delta = \mathrm{diag}(k_{xy}^2 s,\; k_{xy}^2 s,\; k_{\theta s}^2 s +
/// k_{\theta\theta}^2 |\theta_\delta|) \f$ with \f$ s = \|t_\delta\| \f$
/// (random-walk growth with distance and with the angle turned), mapped to
/// the state by \f$ J_\delta = \mathrm{diag}(R(\theta), 1) \f$ (`SE2::act`'s
/// `J_q_p` and the angle sum): \f$ Q = J_\delta Q_\delta J_\delta^\top \f$, which
/// is \f$ Q_\delta \f$ itself because its position block is isotropic.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// The SE(2) element of a planar pose: body frame in the world, (x, y) m, θ rad.
template <std::floating_point T>
[[nodiscard]] inline SE2<T> as_se2(const PlanarPose<T>& p) noexcept {
  return SE2<T>(p.x, p.y, p.theta);
}

/// The planar pose of an SE(2) element (θ in [-π, π)).
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> as_planar_pose(const SE2<T>& g) noexcept {
  return {g.x(), g.y(), g.angle()};
}

/// SE(2) composition \f$a \oplus b\f$ (b expressed in a's frame).
/// Deprecated: use `SE2` (lie/se2.hpp), `as_se2(a) * as_se2(b)`.
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> se2_compose(const PlanarPose<T>& a, const PlanarPose<T>& b) {
  return as_planar_pose(as_se2(a) * as_se2(b));
}

/// SE(2) inverse \f$a^{-1}\f$.
/// Deprecated: use `SE2` (lie/se2.hpp), `as_se2(a).inverse()`.
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> se2_inverse(const PlanarPose<T>& a) {
  return as_planar_pose(as_se2(a).inverse());
}

/// Noise of Se2Odometry: 1-σ growth per √distance and per √angle turned.
template <std::floating_point T = double>
struct Se2OdometryNoise {
  T xy_sigma_per_sqrt_m = T(0.02);         ///< position noise per √m travelled (m/√m)
  T theta_sigma_per_sqrt_m = T(0.005);     ///< heading noise per √m travelled (rad/√m)
  T theta_sigma_per_sqrt_rad = T(0.03);    ///< heading noise per √rad turned (rad/√rad)
};

/// Motion model \f$ x' = x \oplus \delta \f$ on PlanarPose driven by odometry
/// increments (see the file comment for F and Q).
template <std::floating_point T = double>
class Se2Odometry {
 public:
  using State = PlanarPose<T>;     ///< body pose in the world frame
  using Control = SE2<T>;          ///< body-frame increment δ = O_{k-1}⁻¹ O_k
  using Matrix3 = Eigen::Matrix<T, 3, 3>;
  using Vector3 = Eigen::Matrix<T, 3, 1>;

  /// @param[in] noise growth rates of the increment noise (all >= 0)
  /// @throws posefuse::invalid_argument if a rate is negative or not finite
  explicit Se2Odometry(const Se2OdometryNoise<T>& noise = {}) : n_(noise) {
    for (T v : {n_.xy_sigma_per_sqrt_m, n_.theta_sigma_per_sqrt_m, n_.theta_sigma_per_sqrt_rad})
      if (!std::isfinite(v) || v < T(0))
        throw invalid_argument("Se2Odometry: noise rates must be finite and >= 0");
  }

  /// \f$ x \oplus \delta \f$ (the time step is not used: δ is the motion).
  /// The heading is summed and wrapped, \f$ \mathrm{wrap}(\theta + \theta_\delta) \f$,
  /// rather than read back from the composed rotation (one atan2 fewer).
  [[nodiscard]] State predict(const State& x, const Control& d, T /*dt_s*/) const noexcept {
    const typename SE2<T>::Point t = as_se2(x).act(d.translation());
    return {t.x(), t.y(), wrap_angle(x.theta + d.angle())};
  }

  /// \f$ F = \partial (x \oplus \delta) / \partial x \f$ on \f$ \mathbb{R}^2 \times S^1 \f$.
  [[nodiscard]] Matrix3 jacobian(const State& x, const Control& d, T /*dt_s*/) const noexcept {
    typename SE2<T>::ActJacobianGroup J_t_x;
    (void)as_se2(x).act(d.translation(), &J_t_x);
    // J_t_x * M(θ)^T: the left block R R^T is the identity exactly.
    Matrix3 F = Matrix3::Identity();
    F.template topRightCorner<2, 1>() = J_t_x.col(2);
    return F;
  }

  /// \f$ J_\delta = \partial (x \oplus \delta) / \partial (t_\delta, \theta_\delta) \f$
  /// = diag(R(θ), 1): how increment errors (body frame) enter the state.
  [[nodiscard]] Matrix3 jacobian_increment(const State& x, const Control& d) const noexcept {
    typename SE2<T>::ActJacobianPoint J_t_d;
    (void)as_se2(x).act(d.translation(), nullptr, &J_t_d);
    Matrix3 J = Matrix3::Identity();
    J.template topLeftCorner<2, 2>() = J_t_d;
    return J;
  }

  /// The diagonal of \f$ Q_\delta \f$ for increment δ (m², m², rad²).
  [[nodiscard]] Vector3 increment_variance(const Control& d) const noexcept {
    return variance_of(d, d.angle());
  }

  /// \f$ Q = J_\delta Q_\delta J_\delta^\top \f$ (world frame, m² / rad²). The
  /// position block of \f$ Q_\delta \f$ is isotropic, \f$ q I_2 \f$, so
  /// \f$ R\,(q I_2)\,R^\top = q I_2 \f$: Q equals \f$ Q_\delta \f$ and does not
  /// depend on the state's heading.
  [[nodiscard]] Matrix3 noise(const State& /*x*/, const Control& d, T /*dt_s*/) const noexcept {
    return noise_of(increment_variance(d));
  }

  /// predict(), jacobian() and noise() at once (Ekf uses it, see
  /// HasLinearize): the same values bit for bit, with the sine and
  /// cosine of x.theta computed once instead of twice and the increment's
  /// heading (an atan2) once instead of twice.
  struct Linearization {
    State state;       ///< \f$ x \oplus \delta \f$
    Matrix3 jacobian;  ///< F
    Matrix3 noise;     ///< Q
    /// \f$ F P F^\top \f$ for F = [I, c; 0, 1] (c its top-right column):
    /// rows, then columns, 0 and 1 gain c times row / column 2 (see
    /// HasLinearizePropagate).
    [[nodiscard]] Matrix3 propagate(const Matrix3& P) const noexcept {
      const T c0 = jacobian(0, 2), c1 = jacobian(1, 2);
      Matrix3 B = P;
      B.row(0) += c0 * P.row(2);
      B.row(1) += c1 * P.row(2);
      Matrix3 out = B;
      out.col(0) += c0 * B.col(2);
      out.col(1) += c1 * B.col(2);
      return out;
    }
  };
  [[nodiscard]] Linearization linearize(const State& x, const Control& d, T /*dt_s*/) const noexcept {
    const T dth = d.angle();  // the increment's heading: one atan2, shared
    typename SE2<T>::ActJacobianGroup J_t_x;
    const typename SE2<T>::Point t = as_se2(x).act(d.translation(), &J_t_x);
    Linearization out;
    out.state = {t.x(), t.y(), wrap_angle(x.theta + dth)};
    out.jacobian = Matrix3::Identity();
    out.jacobian.template topRightCorner<2, 1>() = J_t_x.col(2);
    out.noise = noise_of(variance_of(d, dth));
    return out;
  }

  /// The noise rates.
  [[nodiscard]] const Se2OdometryNoise<T>& noise_rates() const noexcept { return n_; }

 private:
  Vector3 variance_of(const Control& d, T dth) const noexcept {
    const T s = std::hypot(d.x(), d.y()), turned = std::abs(dth);
    const T kxy = n_.xy_sigma_per_sqrt_m, kts = n_.theta_sigma_per_sqrt_m,
            ktt = n_.theta_sigma_per_sqrt_rad;
    return {kxy * kxy * s, kxy * kxy * s, kts * kts * s + ktt * ktt * turned};
  }
  static Matrix3 noise_of(const Vector3& v) noexcept {
    Matrix3 Q = Matrix3::Zero();
    Q.diagonal() = v;
    return Q;
  }

  Se2OdometryNoise<T> n_;
};

}  // namespace posefuse

#pragma once
/// @file
/// The IMU factor between two keyframe states \f$ x = [p, v, q, b_a, b_g] \f$:
/// residual with analytic Jacobians with respect to both states, whitening
/// by the pre-integration covariance, and prediction of the second state.
///
/// **Residual** (Forster et al., "On-Manifold Preintegration", IEEE T-RO 2017,
/// eq 45; Qin et al., "VINS-Mono", IEEE T-RO 2018, eq 16), with
/// \f$ \Delta t \f$ the pre-integration time, \f$ g_w \f$ the gravity vector and
/// \f$ \Delta(b_i) \f$ the pre-integration corrected to first order to the
/// biases of state i (inertial/preintegration.hpp):
/// \f[ r_p = R_i^\top(p_j - p_i - v_i\Delta t - \tfrac12 g_w\Delta t^2) - \Delta p(b_i), \quad
///     r_\phi = \mathrm{Log}\big(\Delta R(b_i)^\top R_i^\top R_j\big), \f]
/// \f[ r_v = R_i^\top(v_j - v_i - g_w\Delta t) - \Delta v(b_i), \quad
///     r_{b_a} = b_{a,j} - b_{a,i}, \quad r_{b_g} = b_{g,j} - b_{g,i}, \f]
/// in the order \f$ [r_p, r_\phi, r_v, r_{b_a}, r_{b_g}] \f$ of the pre-integration
/// covariance P. Whitened: \f$ L^{-1} r \f$ with \f$ P = L L^\top \f$, so that
/// \f$ |L^{-1} r|^2 = r^\top P^{-1} r \f$.
///
/// **Jacobians** (right perturbations, lie/lie.hpp; the state's tangent is
/// \f$ [\delta p, \delta\phi, \delta v, \delta b_a, \delta b_g] \f$ with
/// \f$ p \oplus \delta p = p + \delta p \f$ in the world frame and
/// \f$ R \oplus \delta\phi = R\,\mathrm{Exp}(\delta\phi) \f$). With
/// \f$ A = p_j - p_i - v_i\Delta t - \tfrac12 g_w\Delta t^2 \f$,
/// \f$ B = v_j - v_i - g_w\Delta t \f$, \f$ J_r^{-1} = J_r^{-1}(r_\phi) \f$ and
/// \f$ \Delta R(b_i) = \Delta R\,\mathrm{Exp}(J_{\phi b_g}\delta b_g) \f$:
/// \f[ \frac{\partial r_p}{\partial(\delta p_i, \delta\phi_i, \delta v_i, \delta b_{a,i}, \delta b_{g,i})}
///     = (-R_i^\top,\ [R_i^\top A]_\times,\ -R_i^\top\Delta t,\ -J_{p b_a},\ -J_{p b_g}), \f]
/// \f[ \frac{\partial r_\phi}{\partial\delta\phi_i} = -J_r^{-1} R_j^\top R_i, \quad
///     \frac{\partial r_\phi}{\partial\delta b_{g,i}} = -J_r^{-1}\mathrm{Exp}(r_\phi)^\top
///        J_r(J_{\phi b_g}\delta b_g) J_{\phi b_g}, \quad
///     \frac{\partial r_\phi}{\partial\delta\phi_j} = J_r^{-1}, \f]
/// \f[ \frac{\partial r_v}{\partial(\delta\phi_i, \delta v_i, \delta b_{a,i}, \delta b_{g,i})}
///     = ([R_i^\top B]_\times,\ -R_i^\top,\ -J_{v b_a},\ -J_{v b_g}), \quad
///     \frac{\partial r_p}{\partial\delta p_j} = \frac{\partial r_v}{\partial\delta v_j} = R_i^\top, \f]
/// and \f$ \mp I \f$ for the bias rows. VINS-Mono approximates the bias
/// Jacobian of \f$ r_\phi \f$; here it is exact. A bias far from the
/// pre-integration's linearisation bias should be handled by
/// `Preintegration::update_bias` (re-integration) and a new factor.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

#include <posefuse/core/error.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// A keyframe state \f$ [p, v, q, b_a, b_g] \f$ (world frame w, z up; body
/// frame = IMU frame), a posefuse::Manifold of dimension 15 with tangent
/// \f$ [\delta p, \delta\phi, \delta v, \delta b_a, \delta b_g] \f$ (see the file comment).
struct ImuState {
  using Scalar = double;                              ///< scalar type
  static constexpr int Dim = 15;                      ///< tangent dimension
  using Tangent = Eigen::Matrix<double, 15, 1>;       ///< [δp, δφ, δv, δb_a, δb_g]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();        ///< position of the body in w (m)
  SO3d R;                                             ///< attitude, body → w
  Eigen::Vector3d v = Eigen::Vector3d::Zero();        ///< velocity in w (m/s)
  ImuBias bias;                                       ///< IMU biases

  /// \f$ x \oplus d \f$.
  [[nodiscard]] ImuState plus(const Tangent& d) const {
    return ImuState{p + d.segment<3>(0), R.plus(d.segment<3>(3)), v + d.segment<3>(6),
                    ImuBias{bias.accel + d.segment<3>(9), bias.gyro + d.segment<3>(12)}};
  }
  /// \f$ y \ominus x \f$ (this = y).
  [[nodiscard]] Tangent minus(const ImuState& x) const {
    Tangent d;
    d << p - x.p, R.minus(x.R), v - x.v, bias.accel - x.bias.accel, bias.gyro - x.bias.gyro;
    return d;
  }
};

/// The IMU factor of one pre-integrated interval (see the file comment).
class ImuFactor {
 public:
  using Residual = Eigen::Matrix<double, 15, 1>;   ///< [r_p, r_φ, r_v, r_ba, r_bg]
  using Jacobian = Eigen::Matrix<double, 15, 15>;  ///< ∂r / ∂(state tangent)
  using Covariance = Eigen::Matrix<double, 15, 15>;

  /// @param[in] pre a pre-integration of at least one step (its delta, bias
  ///            Jacobians, covariance, linearisation bias and Δt are copied)
  /// @param[in] gravity_w the gravity vector in the world frame, e.g. (0, 0, -9.81) m/s²
  /// @throws posefuse::invalid_argument when pre has no step, gravity is not
  ///         finite, or the covariance is not positive definite (e.g. zero noise)
  template <class Lazy = void>
  ImuFactor(const Preintegration& pre, const Eigen::Vector3d& gravity_w)
      : delta_(pre.delta()),
        J_(pre.bias_jacobian()),
        bias_(pre.bias()),
        dt_s_(pre.dt_s()),
        P_(pre.covariance()),
        g_(gravity_w) {
    if (!(dt_s_ > 0)) throw invalid_argument("ImuFactor: the pre-integration has no step");
    if (!g_.allFinite()) throw invalid_argument("ImuFactor: gravity is not finite");
    const Eigen::LLT<Covariance> llt(P_);
    if (llt.info() != Eigen::Success || !P_.allFinite())
      throw invalid_argument("ImuFactor: the pre-integration covariance is not positive definite");
    W_ = llt.matrixL().solve(Covariance::Identity());
  }

  /// The residual r(x_i, x_j) (not whitened).
  /// @param[in] xi, xj the states at keyframes i and j
  /// @param[out] J_r_i, J_r_j if not null, \f$ \partial r / \partial x_i \f$ and
  ///             \f$ \partial r / \partial x_j \f$ (right perturbations; file comment)
  template <class Lazy = void>
  [[nodiscard]] Residual residual(const ImuState& xi, const ImuState& xj, Jacobian* J_r_i = nullptr,
                                  Jacobian* J_r_j = nullptr) const {
    using M3 = Eigen::Matrix3d;
    const Eigen::Vector3d db_a = xi.bias.accel - bias_.accel;
    const Eigen::Vector3d db_g = xi.bias.gyro - bias_.gyro;
    const M3 Jp_a = J_.block<3, 3>(0, 0), Jp_g = J_.block<3, 3>(0, 3);
    const M3 Jphi_g = J_.block<3, 3>(3, 3);
    const M3 Jv_a = J_.block<3, 3>(6, 0), Jv_g = J_.block<3, 3>(6, 3);
    const Eigen::Vector3d dphi = Jphi_g * db_g;
    SO3d::Jacobian Jr_corr;
    const SO3d dR = delta_.R.plus(dphi, nullptr, &Jr_corr);
    const double T = dt_s_;
    const Eigen::Vector3d A = xj.p - xi.p - xi.v * T - 0.5 * g_ * T * T;
    const Eigen::Vector3d B = xj.v - xi.v - g_ * T;
    const M3 RiT = xi.R.matrix().transpose();
    const Eigen::Vector3d RiTA = RiT * A, RiTB = RiT * B;
    const SO3d E = dR.inverse().compose(xi.R.between(xj.R));
    SO3d::Jacobian Jr_inv;
    Residual r;
    r.segment<3>(0) = RiTA - delta_.p - Jp_a * db_a - Jp_g * db_g;
    r.segment<3>(3) = E.log(&Jr_inv);
    r.segment<3>(6) = RiTB - delta_.v - Jv_a * db_a - Jv_g * db_g;
    r.segment<3>(9) = xj.bias.accel - xi.bias.accel;
    r.segment<3>(12) = xj.bias.gyro - xi.bias.gyro;
    if (J_r_i) {
      Jacobian& J = *J_r_i;
      J.setZero();
      J.block<3, 3>(0, 0) = -RiT;
      J.block<3, 3>(0, 3) = SO3d::hat(RiTA);
      J.block<3, 3>(0, 6) = -RiT * T;
      J.block<3, 3>(0, 9) = -Jp_a;
      J.block<3, 3>(0, 12) = -Jp_g;
      J.block<3, 3>(3, 3) = -Jr_inv * (xj.R.matrix().transpose() * xi.R.matrix());
      J.block<3, 3>(3, 12) = -Jr_inv * E.matrix().transpose() * Jr_corr * Jphi_g;
      J.block<3, 3>(6, 3) = SO3d::hat(RiTB);
      J.block<3, 3>(6, 6) = -RiT;
      J.block<3, 3>(6, 9) = -Jv_a;
      J.block<3, 3>(6, 12) = -Jv_g;
      J.block<3, 3>(9, 9) = -M3::Identity();
      J.block<3, 3>(12, 12) = -M3::Identity();
    }
    if (J_r_j) {
      Jacobian& J = *J_r_j;
      J.setZero();
      J.block<3, 3>(0, 0) = RiT;
      J.block<3, 3>(3, 3) = Jr_inv;
      J.block<3, 3>(6, 6) = RiT;
      J.block<3, 3>(9, 9).setIdentity();
      J.block<3, 3>(12, 12).setIdentity();
    }
    return r;
  }

  /// The whitened residual \f$ L^{-1} r \f$ and, if requested, the whitened
  /// Jacobians \f$ L^{-1} J \f$ (what a least-squares solver needs).
  template <class Lazy = void>
  [[nodiscard]] Residual whitened_residual(const ImuState& xi, const ImuState& xj,
                                           Jacobian* J_r_i = nullptr,
                                           Jacobian* J_r_j = nullptr) const {
    const Residual r = residual(xi, xj, J_r_i, J_r_j);
    if (J_r_i) *J_r_i = (W_ * *J_r_i).eval();
    if (J_r_j) *J_r_j = (W_ * *J_r_j).eval();
    return W_ * r;
  }

  /// The state j predicted from state i (the residual is then zero):
  /// \f$ R_j = R_i\Delta R(b_i) \f$, \f$ v_j = v_i + g_w\Delta t + R_i\Delta v(b_i) \f$,
  /// \f$ p_j = p_i + v_i\Delta t + \tfrac12 g_w\Delta t^2 + R_i\Delta p(b_i) \f$, biases of i.
  template <class Lazy = void>
  [[nodiscard]] ImuState predict(const ImuState& xi) const {
    const Eigen::Matrix<double, 6, 1> db = xi.bias.vector() - bias_.vector();
    const Eigen::Vector3d dp = delta_.p + J_.block<3, 6>(0, 0) * db;
    const Eigen::Vector3d dv = delta_.v + J_.block<3, 6>(6, 0) * db;
    const SO3d dR = delta_.R.plus(J_.block<3, 6>(3, 0) * db);
    const double T = dt_s_;
    return ImuState{xi.p + xi.v * T + 0.5 * g_ * T * T + xi.R.act(dp), xi.R.compose(dR),
                    xi.v + g_ * T + xi.R.act(dv), xi.bias};
  }

  /// The pre-integration covariance P of the residual.
  [[nodiscard]] const Covariance& covariance() const noexcept { return P_; }
  /// The whitening matrix \f$ L^{-1} \f$ (\f$ P = LL^\top \f$; lower triangular).
  [[nodiscard]] const Covariance& whitening() const noexcept { return W_; }
  /// \f$ \Delta t \f$ (s).
  [[nodiscard]] double dt_s() const noexcept { return dt_s_; }

 private:
  ImuDelta delta_;
  Preintegration::BiasJacobian J_;
  ImuBias bias_;
  double dt_s_;
  Covariance P_, W_;
  Eigen::Vector3d g_;
};

}  // namespace posefuse

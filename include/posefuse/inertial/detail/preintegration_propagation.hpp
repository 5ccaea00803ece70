#pragma once
/// @file
/// The structured covariance and bias-Jacobian propagation of IMU
/// pre-integration (inertial/preintegration.hpp, whose file comment states the
/// model, the error state and F, G, Q). Internal: not part of the public API.
///
/// **Internal coordinates.** Two changes of variables make the one-step
/// transition the identity on everything but the biases' inputs:
///  - the rotation error is the left perturbation in frame i,
///    \f$ \Delta R_{true} = \mathrm{Exp}(\theta)\,\Delta R \f$, \f$ \theta = \Delta R\,\delta\phi \f$:
///    its transition is the identity, \f$ \partial\bar u/\partial\theta = -[\bar u]_\times \f$
///    and F has no \f$ E^\top \f$ blocks;
///  - position is carried as \f$ r = \Delta p - \tau\,\Delta v \f$, τ the time since a
///    reference instant: the mid-point step \f$ \Delta p' = \Delta p + \Delta v\,\delta t + h\bar u \f$,
///    \f$ \Delta v' = \Delta v + \delta t\,\bar u \f$ (\f$ h = \delta t^2/2 \f$) becomes
///    \f$ r' = r + \beta\bar u \f$, \f$ \Delta v' = \Delta v + \delta t\,\bar u \f$ with
///    \f$ \beta = -(\tau\delta t + h) \f$, so q = [r; v] moves by \f$ q' = q + Bz \f$,
///    \f$ B = [\beta I; \delta t I] \f$, with no \f$ \Delta v\,\delta t \f$ coupling. Reading
///    \f$ \Delta p = r + \tau v \f$ cancels terms of size \f$ \tau^2\,\mathrm{Cov}(v) \f$, so the
///    reference instant moves to the present (rebase()) once τ exceeds 0.25 s:
///    at 200 Hz one conversion of the blocks every 50 steps; the covariance
///    then agrees with the dense reference to about 1e-14 (tests/inertial).
/// Both are undone when read (covariance(), bias_jacobian()):
/// \f$ \delta\phi = \Delta R^\top\theta \f$, \f$ p = r + \tau v \f$. The integrator keeps Δp itself.
///
/// **Storage.** Only the non-zero 3x3 blocks of the covariance are kept, with
/// r and v stacked as 6x3 blocks where they share a column block (their
/// products then vectorise with SSE2 packets of two; no -march flag is
/// assumed). Cov(θ, b_a) stays 0 (the rotation does not depend on b_a) and
/// the bias-bias blocks are \f$ d_a I \f$, \f$ d_g I \f$.
///
/// **One step.** With z = δū the velocity input and w the rotation input,
/// \f[ z = -[\bar u]_\times\theta + U_a\delta b_a + U_g\delta b_g + n_z, \qquad
///     w = -V\delta b_g + n_w, \f]
/// \f$ V = \Delta R_{k+1} J_r(\bar\omega\delta t)\,\delta t \f$, \f$ U_a = -(\Delta R_k + \Delta R_{k+1})/2 \f$,
/// \f$ U_g = \tfrac12[c_1]_\times V \f$ (\f$ c_1 = \Delta R_{k+1}a'_{k+1} \f$), the covariance
/// moves by the cross-covariances of z and w with the old state. Every
/// product by \f$ U_g \f$ goes through V; \f$ U_aU_a^\top \f$, \f$ VV^\top \f$ and the noise
/// terms have closed forms in \f$ y = \Delta R_{k+1}\bar\omega\delta t \f$ (see propagate()).

#include <Eigen/Core>

#include <posefuse/inertial/detail/small_rotation.hpp>
#include <posefuse/inertial/imu_types.hpp>

namespace posefuse::detail {

/// Covariance blocks and bias Jacobians of a pre-integration, in the internal
/// coordinates of the file comment.
class PreintegrationPropagation {
 public:
  using M3 = Eigen::Matrix3d;
  using M63 = Eigen::Matrix<double, 6, 3>;
  using V3 = Eigen::Vector3d;
  using Covariance = Eigen::Matrix<double, 15, 15>;
  using BiasJacobian = Eigen::Matrix<double, 9, 6>;

  /// One mid-point step's terms, as the integrator computed them.
  struct Step {
    double dt;        ///< \f$ \delta t \f$ (s)
    const M3& R0;     ///< \f$ \Delta R_k \f$
    const M3& R1;     ///< \f$ \Delta R_{k+1} \f$
    const M3& Jr;     ///< \f$ J_r(\bar\omega\delta t) = I - a[\bar\omega\delta t]_\times + b[\bar\omega\delta t]_\times^2 \f$
    double ja, jb;    ///< its coefficients a, b
    const V3& theta;  ///< \f$ \bar\omega\delta t \f$
    const V3& c1;     ///< \f$ \Delta R_{k+1} a'_{k+1} \f$
    const V3& u;      ///< \f$ \bar u \f$
  };

  /// Zero covariance and Jacobians (the start of an interval).
  void clear() noexcept {
    for (M3* m : {&rr_, &rv_, &vv_, &tt_, &tg_, &Jt_g_}) m->setZero();
    for (M63* m : {&qt_, &qa_, &qg_, &Jq_a_, &Jq_g_}) m->setZero();
    da_ = dg_ = tau_ = 0.0;
  }

  /// Propagates the covariance and the bias Jacobians over one step.
  void propagate(const Step& s, const ImuNoise& noise) noexcept {
    const double dt = s.dt, b = -(tau_ * dt + 0.5 * dt * dt);
    const V3& u = s.u;
    const V3 hc = 0.5 * s.c1;
    M3 Ua = s.R0 + s.R1;
    Ua *= -0.5;
    M3 Vn;  // -V
    Vn.noalias() = s.R1 * s.Jr;
    Vn *= -dt;
    const M3 Ug = neg_skew_times(hc, Vn);  // ½[c1]x V

    // Bias Jacobians (J_θa = 0): J_q' = J_q + B U, J_θg' = J_θg - V.
    const M3 Zg = neg_skew_times(u, Jt_g_) + Ug;
    Jq_a_.topRows<3>() += b * Ua;
    Jq_a_.bottomRows<3>() += dt * Ua;
    Jq_g_.topRows<3>() += b * Zg;
    Jq_g_.bottomRows<3>() += dt * Zg;
    Jt_g_ += Vn;

    // Closed forms (J_r J_r^T = I + c[θ]x², c = 2b - a² - b²|θ|², as [θ]x⁴ = -|θ|²[θ]x²):
    // V V^T = d0 I + d1 y y^T; U_a U_a^T = ¼ R0 (2I + E + E^T) R0^T = (1 - ½a|θ|²) I + ½a y y^T;
    // K = [c1]x V V^T = d0 [c1]x + d1 (c1 × y) y^T; K [c1]x = d0 (c1 c1^T - |c1|² I) - d1 (c1 × y)(c1 × y)^T.
    const V3 y = s.R1 * s.theta;
    const double t2 = s.theta.squaredNorm();
    const double cj = 2.0 * s.jb - s.ja * s.ja - s.jb * s.jb * t2;
    const double d0 = dt * dt * (1.0 - cj * t2), d1 = dt * dt * cj;
    const V3 cy = s.c1.cross(y);
    const M3 yy = y * y.transpose();
    // Noise (preintegration.hpp's file comment) in the left form: Σθθ = ½c_g V V^T,
    // Σzθ = -¼c_g K, Σzz = ½c_a I + c_g/8 K [c1]x^T.
    const double two_over_dt = 2.0 / dt;
    const double ca = two_over_dt * noise.accel_noise_density * noise.accel_noise_density;
    const double cg = two_over_dt * noise.gyro_noise_density * noise.gyro_noise_density;
    // Cov(w, w) = d_g V V^T + Σθθ, Cov(z, w) ∋ -½d_g K + Σzθ = -2σ K, Cov(z, z) ∋ σ K [c1]x^T.
    const double sigma = 0.25 * dg_ + 0.125 * cg;

    // Cross-covariances of z and w with the old state.
    M63 Cqw;  // Cov(q, w) = -Cov(q, b_g) V^T
    Cqw.noalias() = qg_ * Vn.transpose();
    M3 Ctw;  // Cov(θ, w)
    Ctw.noalias() = tg_ * Vn.transpose();
    // Cov(q, z) = Cov(q, θ)[u]x + Cov(q, b_a) U_a^T + Cov(q, b_g) U_g^T, the last ½ Cov(q, w)[c1]x.
    M63 Cqz = times_skew<6>(qt_, u) + times_skew<6>(Cqw, hc);
    Cqz.noalias() += qa_ * Ua.transpose();
    // Cov(z, θ) = -[u]x Cov(θ, θ) + U_g Cov(b_g, θ), the last -½[c1]x Cov(w, θ).
    const M3 Czt = neg_skew_times(u, tt_) + neg_skew_times_transposed(hc, Ctw);
    const M3 Czg = neg_skew_times(u, tg_) + dg_ * Ug;
    const M3 N = neg_skew_times(u, Ctw);  // Cov(z, w) = N - 2σ K
    M3 K = (-2.0 * sigma * d1) * (cy * y.transpose());
    const V3 kc = (2.0 * sigma * d0) * s.c1;  // -2σ d0 [c1]x
    K(0, 1) += kc.z();
    K(1, 0) -= kc.z();
    K(0, 2) -= kc.y();
    K(2, 0) += kc.y();
    K(1, 2) += kc.x();
    K(2, 1) -= kc.x();
    // Cov(z, z) = Cov(z, θ)[u]x + d_a U_a U_a^T + ½ Cov(z, w)[c1]x + Σzz.
    M3 Czz = times_skew<3>(Czt, u) + times_skew<3>(N, hc) + (0.5 * da_ * s.ja) * yy +
             sigma * (d1 * (cy * cy.transpose()) - d0 * (s.c1 * s.c1.transpose()));
    Czz.diagonal().array() += da_ * (1.0 - 0.5 * s.ja * t2) + 0.5 * ca + sigma * d0 * s.c1.squaredNorm();
    mirror_upper(Czz);  // symmetric to rounding: make it exact

    // Cov(q', q') = Cov(q, q) + Cov(q, z) B^T + B Cov(z, q) + B Cov(z, z) B^T.
    const M3 Crz = Cqz.topRows<3>(), Cvz = Cqz.bottomRows<3>();
    rv_ += dt * Crz + b * Cvz.transpose() + (b * dt) * Czz;
    rr_ += b * (Crz + Crz.transpose()) + (b * b) * Czz;
    vv_ += dt * (Cvz + Cvz.transpose()) + (dt * dt) * Czz;
    mirror_upper(rr_);
    mirror_upper(vv_);
    // Cov(q', θ') = Cov(q, θ) + Cov(q, w) + B (Cov(z, θ) + Cov(z, w)).
    qt_ += Cqw;
    const M3 Zt = Czt + N + K;
    qt_.topRows<3>() += b * Zt;
    qt_.bottomRows<3>() += dt * Zt;
    // Cov(q', b_a) = Cov(q, b_a) + B d_a U_a; Cov(q', b_g) = Cov(q, b_g) + B Cov(z, b_g).
    qa_.topRows<3>() += (b * da_) * Ua;
    qa_.bottomRows<3>() += (dt * da_) * Ua;
    qg_.topRows<3>() += b * Czg;
    qg_.bottomRows<3>() += dt * Czg;
    // Cov(θ', θ') = Cov(θ, θ) + Cov(θ, w) + Cov(w, θ) + d_g V V^T + Σθθ; Cov(θ', b_g) = Cov(θ, b_g) - d_g V.
    const double sv = dg_ + 0.5 * cg;
    tt_ += Ctw + Ctw.transpose() + (sv * d1) * yy;
    tt_.diagonal().array() += sv * d0;
    mirror_upper(tt_);
    tg_ += dg_ * Vn;
    da_ += noise.accel_random_walk * noise.accel_random_walk * dt;
    dg_ += noise.gyro_random_walk * noise.gyro_random_walk * dt;
    tau_ += dt;
    if (tau_ > kRebaseS) rebase();
  }

  /// The covariance over [δp, δφ, δv, δb_a, δb_g] (δφ the right perturbation),
  /// exactly symmetric, given ΔR (p = r + τ v with the τ held here).
  [[nodiscard]] Covariance covariance(const M3& R) const {
    const double T = tau_;  // p = r + T v
    const M3 Rt = R.transpose();
    const auto p_rows = [T](const M63& X) { return M3(X.topRows<3>() + T * X.bottomRows<3>()); };
    Covariance P = Covariance::Zero();
    P.block<3, 3>(0, 0) = rr_ + T * (rv_ + rv_.transpose()) + (T * T) * vv_;
    P.block<3, 3>(0, 3) = p_rows(qt_) * R;
    P.block<3, 3>(0, 6) = rv_ + T * vv_;
    P.block<3, 3>(3, 3) = Rt * tt_ * R;
    P.block<3, 3>(3, 6) = Rt * qt_.bottomRows<3>().transpose();
    P.block<3, 3>(6, 6) = vv_;
    P.block<3, 3>(0, 9) = p_rows(qa_);
    P.block<3, 3>(0, 12) = p_rows(qg_);
    P.block<3, 3>(3, 12) = Rt * tg_;
    P.block<3, 3>(6, 9) = qa_.bottomRows<3>();
    P.block<3, 3>(6, 12) = qg_.bottomRows<3>();
    P.block<3, 3>(9, 9).diagonal().setConstant(da_);
    P.block<3, 3>(12, 12).diagonal().setConstant(dg_);
    P.triangularView<Eigen::StrictlyLower>() = P.transpose();
    // The rotated diagonal block, symmetric to rounding: make it exact.
    P.block<3, 3>(3, 3).triangularView<Eigen::StrictlyLower>() = P.block<3, 3>(3, 3).transpose();
    return P;
  }

  /// \f$ \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$ (δφ the right
  /// perturbation), given ΔR (p = r + τ v).
  [[nodiscard]] BiasJacobian bias_jacobian(const M3& R) const {
    const double T = tau_;  // p = r + T v
    BiasJacobian J;
    J << Jq_a_.topRows<3>() + T * Jq_a_.bottomRows<3>(), Jq_g_.topRows<3>() + T * Jq_g_.bottomRows<3>(),
        M3::Zero(), R.transpose() * Jt_g_, Jq_a_.bottomRows<3>(), Jq_g_.bottomRows<3>();
    return J;
  }

 private:
  /// Moves the reference time to now (τ = 0): r becomes Δp.
  [[gnu::noinline]] void rebase() noexcept {
    const double T = tau_;  // p = r + T v
    rr_ += T * (rv_ + rv_.transpose()) + (T * T) * vv_;
    mirror_upper(rr_);
    rv_ += T * vv_;
    for (M63* m : {&qt_, &qa_, &qg_, &Jq_a_, &Jq_g_}) m->topRows<3>() += T * m->bottomRows<3>();
    tau_ = 0.0;
  }

  /// \f$ -[u]_\times M^\top \f$.
  static M3 neg_skew_times_transposed(const V3& u, const M3& M) noexcept {
    M3 out;
    for (int j = 0; j < 3; ++j) {
      out(0, j) = M(j, 1) * u.z() - M(j, 2) * u.y();
      out(1, j) = M(j, 2) * u.x() - M(j, 0) * u.z();
      out(2, j) = M(j, 0) * u.y() - M(j, 1) * u.x();
    }
    return out;
  }

  /// Copies the strict upper triangle of a 3x3 block to the lower one.
  static void mirror_upper(M3& S) noexcept {
    S(1, 0) = S(0, 1);
    S(2, 0) = S(0, 2);
    S(2, 1) = S(1, 2);
  }

  M3 rr_, rv_, vv_;      // Cov(q, q), q = [r; v]: upper blocks (rr, vv exactly symmetric)
  M63 qt_, qa_, qg_;     // Cov(q, θ), Cov(q, b_a), Cov(q, b_g)
  M3 tt_, tg_;           // Cov(θ, θ) (exactly symmetric), Cov(θ, b_g)
  double da_ = 0, dg_ = 0;  // bias variances (scalar × I)
  double tau_ = 0;          // τ: r = Δp - τ Δv
  static constexpr double kRebaseS = 0.25;  // largest τ (s) before rebase()
  M63 Jq_a_, Jq_g_;      // bias Jacobians of q
  M3 Jt_g_;              // bias Jacobian of θ (J_θa = 0)
};

}  // namespace posefuse::detail

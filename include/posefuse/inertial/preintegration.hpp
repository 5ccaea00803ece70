#pragma once
/// @file
/// IMU pre-integration between two keyframes i and j, in the body frame of i:
/// mid-point integration, the 15x15 covariance, the bias Jacobians, first-order
/// bias correction and re-integration.
///
/// **Model.** The IMU measures, in its body frame b, the angular rate and the
/// specific force
/// \f[ \tilde\omega = \omega + b_g + n_g, \qquad
///     \tilde a = R_{wb}^\top (a_w - g_w) + b_a + n_a, \f]
/// with \f$ g_w \f$ the gravity vector (e.g. \f$ (0, 0, -9.81) \f$ m/s² in a z-up world).
/// Pre-integration (Lupton & Sukkarieh 2012; Forster, Carlone, Dellaert,
/// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial
/// Odometry", IEEE T-RO 2017, eq 33-35) accumulates the bias-dependent parts
/// only, so that with \f$ \Delta t_{ij} \f$ the time between the keyframes
/// \f[ R_j = R_i\,\Delta R_{ij}, \quad
///     v_j = v_i + g_w \Delta t_{ij} + R_i\,\Delta v_{ij}, \quad
///     p_j = p_i + v_i \Delta t_{ij} + \tfrac12 g_w \Delta t_{ij}^2 + R_i\,\Delta p_{ij}. \f]
///
/// **Mid-point rule** (as VINS-Mono: Qin, Li, Shen, "VINS-Mono", IEEE T-RO 2018,
/// §IV-B and its discrete propagation). Between samples k and k+1, step
/// \f$ \delta t \f$, biases \f$ \bar b_a, \bar b_g \f$ (the linearisation point):
/// \f[ \bar\omega = \tfrac12(\tilde\omega_k + \tilde\omega_{k+1}) - \bar b_g, \quad
///     \Delta R_{k+1} = \Delta R_k\,\mathrm{Exp}(\bar\omega\,\delta t), \f]
/// \f[ \bar u = \tfrac12\big(\Delta R_k(\tilde a_k - \bar b_a) + \Delta R_{k+1}(\tilde a_{k+1} - \bar b_a)\big), \quad
///     \Delta v_{k+1} = \Delta v_k + \bar u\,\delta t, \quad
///     \Delta p_{k+1} = \Delta p_k + \Delta v_k\,\delta t + \tfrac12 \bar u\,\delta t^2. \f]
/// (VINS-Mono approximates Exp by the first-order quaternion; here it is exact.)
///
/// **Error state** \f$ \delta x = [\delta p, \delta\phi, \delta v, \delta b_a, \delta b_g] \f$
/// (15, VINS-Mono's order), \f$ \Delta R_{true} = \Delta R\,\mathrm{Exp}(\delta\phi) \f$
/// (right perturbation, lie/lie.hpp). Its one-step transition F is the exact
/// linearisation of the mid-point step (the same blocks as VINS-Mono's, with
/// \f$ \mathrm{Exp}(\bar\omega\delta t)^\top \f$ for \f$ I - [\bar\omega]_\times\delta t \f$
/// and \f$ J_r(\bar\omega\delta t) \f$ on the gyroscope terms). With
/// \f$ a'_k = \tilde a_k - \bar b_a \f$, \f$ E = \mathrm{Exp}(\bar\omega\delta t) \f$,
/// \f$ R_0 = \Delta R_k \f$, \f$ R_1 = \Delta R_{k+1} \f$:
/// \f[ U_\phi = -\tfrac12\big(R_0[a'_k]_\times + R_1[a'_{k+1}]_\times E^\top\big), \quad
///     U_{b_a} = -\tfrac12(R_0 + R_1), \quad
///     U_{b_g} = \tfrac12 R_1[a'_{k+1}]_\times J_r(\bar\omega\delta t)\,\delta t, \f]
/// \f[ \delta\phi' = E^\top\delta\phi - J_r\,\delta t\,\delta b_g, \quad
///     \delta v' = \delta v + \delta t\,(U_\phi\delta\phi + U_{b_a}\delta b_a + U_{b_g}\delta b_g), \quad
///     \delta p' = \delta p + \delta t\,\delta v + \tfrac12\delta t^2 (U_\phi\delta\phi + \dots). \f]
///
/// **Noise.** Continuous densities (ImuNoise): white noise \f$ \sigma_a, \sigma_g \f$
/// on the readings, random walks \f$ \sigma_{b_a}, \sigma_{b_g} \f$ on the biases.
/// As in VINS-Mono the two end samples of a step carry independent noises
/// \f$ n_{a,k}, n_{g,k}, n_{a,k+1}, n_{g,k+1} \f$; each gets variance
/// \f$ 2\sigma^2/\delta t \f$, so that their mean has the variance
/// \f$ \sigma^2/\delta t \f$ of a continuous white noise averaged over the step
/// (Forster eq 46's discretisation). They enter like the biases, halved; bias
/// random walks add \f$ \sigma_b^2\,\delta t\,I \f$. The covariance is
/// \f$ P' = F P F^\top + G Q G^\top \f$ from \f$ P = 0 \f$ (VINS-Mono eq 11).
///
/// **Cost.** The update exploits the structure: internally the rotation
/// error is the left perturbation in frame i, \f$ \theta = \Delta R\,\delta\phi \f$
/// (so its transition is the identity and \f$ \partial\bar u/\partial\theta = -[\bar u]_\times \f$),
/// only the non-zero 3x3 blocks of P are stored (the bias-bias blocks stay
/// scalar × I, Cov(θ, b_a) stays 0), the noise term has a closed form, and
/// the result is converted to δφ when read (covariance(), bias_jacobian()).
/// Position and velocity rows are stacked as 6x3 blocks so that their
/// products vectorise with SSE2 (no -march flag is assumed), products by
/// \f$ U_{b_g} \f$ go through V, and \f$ U_{b_a}U_{b_a}^\top \f$, \f$ VV^\top \f$ have
/// closed forms. The step carries `[[gnu::flatten]]` (g++ and clang; other
/// compilers ignore it): without it g++ leaves many of Eigen's small
/// assignment kernels out of line and the step costs about 1.8x more.
/// `DensePreintegration` in posefuse/testing/dense_preintegration.hpp forms the
/// 15x15 F and 15x18 G in the δφ form and multiplies them (VINS-Mono's way);
/// a test checks both agree to 1e-12.
///
/// **Bias Jacobians** \f$ J = \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$
/// propagate as \f$ J' = F_x J + F_b \f$ from 0 (the top-right 9x6 block of the
/// product of the F's). First-order correction (Forster eq 44) for a bias
/// \f$ b = \bar b + \delta b \f$:
/// \f[ \Delta R(b) = \Delta R\,\mathrm{Exp}(J_{\phi b_g}\delta b_g), \quad
///     \Delta v(b) = \Delta v + J_{v b_a}\delta b_a + J_{v b_g}\delta b_g, \quad
///     \Delta p(b) = \Delta p + J_{p b_a}\delta b_a + J_{p b_g}\delta b_g. \f]
///
/// **Samples** (core/samples.hpp) have integer-nanosecond stamps; a sample
/// that cannot be integrated is reported (ImuStatus, inertial/imu_types.hpp)
/// and leaves the state untouched.
///
/// **Allocation.** Everything is fixed-size. The samples are kept for
/// re-integration in a std::vector reserved at construction
/// (`PreintegrationOptions::reserve_samples`); adding a sample allocates only
/// when that reserve is exceeded.
///
/// The value types (ImuNoise, ImuBias, ImuStatus, ImuDelta) are in
/// inertial/imu_types.hpp; `preintegrate` over a recorded sample range is in
/// inertial/preintegrate.hpp, included at the end of this header.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/inertial/detail/small_rotation.hpp>
#include <posefuse/inertial/imu_types.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// Configuration of a Preintegration.
struct PreintegrationOptions {
  /// Largest accepted time between consecutive samples (ns); a larger gap is kGap.
  std::int64_t max_gap_ns = 50'000'000;
  /// update_bias() re-integrates when \f$ |\delta b_a| \f$ exceeds this (m/s²) ...
  double reintegrate_accel_threshold = 0.1;
  /// ... or when \f$ |\delta b_g| \f$ exceeds this (rad/s).
  double reintegrate_gyro_threshold = 0.01;
  /// Samples reserved for re-integration (no allocation per sample below this).
  std::size_t reserve_samples = 1024;
};

/// IMU pre-integration between two keyframes (see the file comment).
///
/// Usage: construct with the noise and the bias to linearise about, `add`
/// every sample from the one at keyframe i to the one at keyframe j (the
/// first returns kStarted), then read `delta()`, `covariance()`,
/// `bias_jacobian()`, or `delta(bias)` for another bias.
class Preintegration {
 public:
  using Covariance = Eigen::Matrix<double, 15, 15>;  ///< over [δp, δφ, δv, δb_a, δb_g]
  using BiasJacobian = Eigen::Matrix<double, 9, 6>;  ///< ∂[Δp, Δφ, Δv] / ∂[b_a, b_g]

  /// @param[in] noise continuous-time noise figures
  /// @param[in] bias linearisation bias \f$ \bar b \f$
  /// @param[in] options gap limit, re-integration thresholds, sample reserve
  /// @throws posefuse::invalid_argument for bad noise figures, a non-finite
  ///         bias, a non-positive max_gap_ns or negative/non-finite thresholds
  explicit Preintegration(const ImuNoise& noise = {}, const ImuBias& bias = {},
                          const PreintegrationOptions& options = {})
      : noise_(noise), bias_(bias), options_(options) {
    noise.validate();
    if (!bias.vector().allFinite()) throw invalid_argument("Preintegration: bias is not finite");
    if (options.max_gap_ns <= 0) throw invalid_argument("Preintegration: max_gap_ns must be > 0");
    if (!(options.reintegrate_accel_threshold >= 0 && options.reintegrate_gyro_threshold >= 0 &&
          std::isfinite(options.reintegrate_accel_threshold) &&
          std::isfinite(options.reintegrate_gyro_threshold)))
      throw invalid_argument("Preintegration: re-integration thresholds must be finite and >= 0");
    samples_.reserve(options.reserve_samples);
    clear_state();
  }

  /// Adds the next sample: the first starts the interval (kStarted), every
  /// later one integrates from the previous sample to it (kApplied).
  /// Anything else leaves the pre-integration untouched (see ImuStatus).
  [[nodiscard]] ImuStatus add(const ImuSample& s) {
    if (!s.accel_mps2.allFinite() || !s.gyro_radps.allFinite()) return ImuStatus::kNonFinite;
    if (samples_.empty()) {
      samples_.push_back(s);
      return ImuStatus::kStarted;
    }
    const ImuSample& last = samples_.back();
    if (s.t_ns < last.t_ns) return ImuStatus::kOutOfOrder;
    if (s.t_ns == last.t_ns) return ImuStatus::kRepeated;
    if (s.t_ns - last.t_ns > options_.max_gap_ns) return ImuStatus::kGap;  // no overflow: s > last
    integrate(last, s);
    samples_.push_back(s);
    return ImuStatus::kApplied;
  }

  /// The pre-integrated measurement at the linearisation bias.
  [[nodiscard]] ImuDelta delta() const { return ImuDelta{delta_p_, rotation(), delta_v_}; }

  /// The first-order bias-corrected measurement (Forster eq 44; file comment).
  /// @param[in] bias the bias to correct to; exact at the linearisation bias
  /// @param[out] J_d_b if not null, \f$ \partial\,\Delta(b) \ominus \Delta(\bar b) / \partial b \f$
  ///             (9x6; equal to bias_jacobian() except the rotation rows,
  ///             \f$ J_r(J_{\phi b_g}\delta b_g) J_{\phi b_g} \f$)
  template <class Lazy = void>
  [[nodiscard]] ImuDelta delta(const ImuBias& bias, BiasJacobian* J_d_b = nullptr) const {
    const Eigen::Matrix<double, 6, 1> db = bias.vector() - bias_.vector();
    const BiasJacobian J = bias_jacobian();
    const Eigen::Vector3d dphi = J.block<3, 6>(3, 0) * db;
    SO3d::Jacobian Jr;
    ImuDelta d{delta_p_ + J.block<3, 6>(0, 0) * db, rotation().plus(dphi, nullptr, &Jr),
               delta_v_ + J.block<3, 6>(6, 0) * db};
    if (J_d_b) {
      *J_d_b = J;
      J_d_b->block<3, 6>(3, 0) = Jr * J.block<3, 6>(3, 0);
    }
    return d;
  }

  /// Moves the linearisation point to `bias`: re-integrates every stored
  /// sample when the change exceeds a threshold of PreintegrationOptions,
  /// else keeps the current integration (delta(bias) then corrects to first order).
  /// @return true when it re-integrated
  /// @throws posefuse::invalid_argument when `bias` is not finite
  bool update_bias(const ImuBias& bias) {
    if (!bias.vector().allFinite()) throw invalid_argument("update_bias: bias is not finite");
    const double da = (bias.accel - bias_.accel).norm();
    const double dg = (bias.gyro - bias_.gyro).norm();
    if (da <= options_.reintegrate_accel_threshold && dg <= options_.reintegrate_gyro_threshold)
      return false;
    reintegrate(bias);
    return true;
  }

  /// Starts a new interval (e.g. at the next keyframe) about `bias`; the
  /// sample storage keeps its capacity, so this does not allocate.
  /// @throws posefuse::invalid_argument when `bias` is not finite
  void reset(const ImuBias& bias) {
    if (!bias.vector().allFinite()) throw invalid_argument("reset: bias is not finite");
    bias_ = bias;
    samples_.clear();
    clear_state();
  }

  /// Re-integrates every stored sample about a new linearisation bias.
  /// @throws posefuse::invalid_argument when `bias` is not finite
  void reintegrate(const ImuBias& bias) {
    if (!bias.vector().allFinite()) throw invalid_argument("reintegrate: bias is not finite");
    bias_ = bias;
    clear_state();
    for (std::size_t k = 1; k < samples_.size(); ++k) integrate(samples_[k - 1], samples_[k]);
  }

  /// Covariance of \f$ [\delta p, \delta\phi, \delta v, \delta b_a, \delta b_g] \f$ (SI units,
  /// rad; δφ the right perturbation of ΔR), exactly symmetric. Assembled from
  /// the internal blocks on each call (a few hundred flops).
  template <class Lazy = void>
  [[nodiscard]] Covariance covariance() const {
    const M3 Rt = R_.transpose();  // δφ = ΔR^T θ
    Covariance P = Covariance::Zero();
    P.block<3, 3>(0, 0) = C_.pp;
    P.block<3, 3>(0, 3) = C_.qt.template topRows<3>() * R_;
    P.block<3, 3>(0, 6) = C_.pv;
    P.block<3, 3>(3, 3) = Rt * C_.tt * R_;
    P.block<3, 3>(3, 6) = Rt * C_.qt.template bottomRows<3>().transpose();
    P.block<3, 3>(6, 6) = C_.vv;
    P.block<3, 3>(0, 9) = C_.qa.template topRows<3>();
    P.block<3, 3>(0, 12) = C_.qg.template topRows<3>();
    P.block<3, 3>(3, 12) = Rt * C_.tg;
    P.block<3, 3>(6, 9) = C_.qa.template bottomRows<3>();
    P.block<3, 3>(6, 12) = C_.qg.template bottomRows<3>();
    P.block<3, 3>(9, 9).diagonal().setConstant(C_.da);
    P.block<3, 3>(12, 12).diagonal().setConstant(C_.dg);
    P.template triangularView<Eigen::StrictlyLower>() = P.transpose();
    // The rotated diagonal block, symmetric to rounding: make it exact.
    P.template block<3, 3>(3, 3).template triangularView<Eigen::StrictlyLower>() =
        P.template block<3, 3>(3, 3).transpose();
    return P;
  }
  /// \f$ \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$ at the
  /// linearisation bias (δφ the right perturbation of ΔR).
  template <class Lazy = void>
  [[nodiscard]] BiasJacobian bias_jacobian() const {
    BiasJacobian J;
    J << Jq_a_.template topRows<3>(), Jq_g_.template topRows<3>(), M3::Zero(),
        R_.transpose() * Jt_g_, Jq_a_.template bottomRows<3>(), Jq_g_.template bottomRows<3>();
    return J;
  }
  /// The linearisation bias \f$ \bar b \f$.
  [[nodiscard]] const ImuBias& bias() const noexcept { return bias_; }
  /// The noise figures.
  [[nodiscard]] const ImuNoise& noise() const noexcept { return noise_; }
  /// The options.
  [[nodiscard]] const PreintegrationOptions& options() const noexcept { return options_; }
  /// \f$ \Delta t_{ij} \f$ (s): sum of the integrated steps.
  [[nodiscard]] double dt_s() const noexcept { return dt_s_; }
  /// Number of stored samples (integrated steps + 1, or 0).
  [[nodiscard]] std::size_t sample_count() const noexcept { return samples_.size(); }
  /// The stored samples.
  [[nodiscard]] std::span<const ImuSample> samples() const noexcept { return samples_; }
  /// Stamp of the first sample (keyframe i), 0 before any.
  [[nodiscard]] std::int64_t start_t_ns() const noexcept {
    return samples_.empty() ? 0 : samples_.front().t_ns;
  }
  /// Stamp of the last sample, 0 before any.
  [[nodiscard]] std::int64_t end_t_ns() const noexcept {
    return samples_.empty() ? 0 : samples_.back().t_ns;
  }

 private:
  using M3 = Eigen::Matrix3d;
  using M63 = Eigen::Matrix<double, 6, 3>;
  // Internally the rotation error is the left perturbation in frame i,
  // ΔR_true = Exp(θ) ΔR, θ = ΔR δφ: its transition is the identity, the
  // accelerometer term is a cross product, and F has no E^T blocks. The
  // covariance is kept as its non-zero blocks, with p and v stacked as
  // q = [p; v] where they share a column block (6x3: the products then
  // vectorise with SSE2 packets of two). Cov(θ, b_a) stays 0, the bias-bias
  // blocks are d_a I and d_g I; everything is converted to δφ when read.
  struct Blocks {
    M3 pp, pv, vv;   // Cov(q, q), upper blocks (pp, vv exactly symmetric)
    M63 qt, qa, qg;  // Cov(q, θ), Cov(q, b_a), Cov(q, b_g)
    M3 tt, tg;       // Cov(θ, θ) (exactly symmetric), Cov(θ, b_g)
    double da, dg;   // bias variances (scalar × I)
  };

  void clear_state() {
    delta_p_.setZero();
    delta_v_.setZero();
    delta_q_.setIdentity();
    R_.setIdentity();
    Jq_a_.setZero();
    Jq_g_.setZero();
    Jt_g_.setZero();
    for (M3* m : {&C_.pp, &C_.pv, &C_.vv, &C_.tt, &C_.tg}) m->setZero();
    for (M63* m : {&C_.qt, &C_.qa, &C_.qg}) m->setZero();
    C_.da = C_.dg = 0.0;
    dt_s_ = 0.0;
  }

  [[nodiscard]] SO3d rotation() const { return SO3d(delta_q_); }

  /// Copies the strict upper triangle of a 3x3 block to the lower one.
  static void mirror_upper(M3& S) noexcept {
    S(1, 0) = S(0, 1);
    S(2, 0) = S(0, 2);
    S(2, 1) = S(1, 2);
  }

  /// One mid-point step (file comment) with the structured covariance and
  /// Jacobian update, in the left form described at Blocks.
  ///
  /// With q = [p; v], the step is q' = A q + B z, θ' = θ + w, the biases
  /// unchanged, where A = [I, dt I; 0, I], B = [h I; dt I] (h = dt²/2),
  /// z = δu = -[u]x θ + U_a δb_a + U_g δb_g (+ noise) and w = -V δb_g (+ noise),
  /// V = ΔR_{k+1} J_r(ω̄ dt) dt, U_a = -(ΔR_k + ΔR_{k+1})/2, U_g = [c_1]x V / 2.
  /// P' follows from the cross-covariances of z and w with the old state;
  /// every product by U_g goes through V (U_g M^T = -½ [c_1]x V M^T), and
  /// U_a U_a^T and V V^T have closed forms (both depend only on y = ΔR_{k+1} θ_step).
  [[gnu::flatten]] void integrate(const ImuSample& s0, const ImuSample& s1) {
    const double dt = seconds_between(s1.t_ns, s0.t_ns);
    const double h = 0.5 * dt * dt;
    const Eigen::Vector3d a0 = s0.accel_mps2 - bias_.accel;
    const Eigen::Vector3d a1 = s1.accel_mps2 - bias_.accel;
    const Eigen::Vector3d w = 0.5 * (s0.gyro_radps + s1.gyro_radps) - bias_.gyro;
    Eigen::Quaterniond E;
    M3 Jr;
    double ja, jb;
    const Eigen::Vector3d theta = w * dt;
    detail::small_exp(theta, E, Jr, ja, jb);
    const M3 R0 = R_;
    delta_q_ = delta_q_ * E;
    // Both factors are unit, so |q|² = 1 + ε with ε at rounding level: the
    // first-order renormalisation (3 - |q|²)/2 = 1/|q| + O(ε²) needs no sqrt or division.
    delta_q_.coeffs() *= 0.5 * (3.0 - delta_q_.squaredNorm());
    R_ = delta_q_.toRotationMatrix();
    const Eigen::Vector3d c0 = R0 * a0, c1 = R_ * a1;
    const Eigen::Vector3d u = 0.5 * (c0 + c1);
    delta_p_ += dt * delta_v_ + h * u;
    delta_v_ += dt * u;
    dt_s_ += dt;

    M3 Ua = R0 + R_;
    Ua *= -0.5;
    M3 V;
    V.noalias() = R_ * Jr;
    V *= dt;
    const M3 Ug = -0.5 * detail::neg_skew_times(c1, V);  // ½[c1]x V

    // Bias Jacobians (J_θa = 0): J_q' = A J_q + B U, J_θg' = J_θg - V.
    const M3 Zg = detail::neg_skew_times(u, Jt_g_) + Ug;
    Jq_a_.template topRows<3>() += dt * Jq_a_.template bottomRows<3>() + h * Ua;
    Jq_a_.template bottomRows<3>() += dt * Ua;
    Jq_g_.template topRows<3>() += dt * Jq_g_.template bottomRows<3>() + h * Zg;
    Jq_g_.template bottomRows<3>() += dt * Zg;
    Jt_g_ -= V;

    // Closed forms, y = ΔR_{k+1} θ_step = ΔR_k θ_step:
    // V V^T = dt² R1 J_r J_r^T R1^T = d0 I + d1 y y^T (J_r J_r^T = I + c [θ]x²,
    // c = 2b - a² - b²|θ|², since [θ]x⁴ = -|θ|²[θ]x²);
    // U_a U_a^T = ¼ R0 (2I + E + E^T) R0^T = (1 - ½a|θ|²) I + ½a y y^T;
    // K = [c1]x V V^T = d0 [c1]x + d1 (c1 × y) y^T.
    const Eigen::Vector3d y = R_ * theta;
    const double t2 = theta.squaredNorm();
    const double cj = 2.0 * jb - ja * ja - jb * jb * t2;
    const double d0 = dt * dt * (1.0 - cj * y.squaredNorm()), d1 = dt * dt * cj;
    const Eigen::Vector3d cy = c1.cross(y);
    const M3 yy = y * y.transpose();
    M3 K = d1 * (cy * y.transpose());
    K(0, 1) -= d0 * c1.z();
    K(1, 0) += d0 * c1.z();
    K(0, 2) += d0 * c1.y();
    K(2, 0) -= d0 * c1.y();
    K(1, 2) -= d0 * c1.x();
    K(2, 1) += d0 * c1.x();

    // Cross-covariances of z and w with the old state.
    Blocks& P = C_;
    M63 Cqw;  // Cov(q, w) = -Cov(q, b_g) V^T
    Cqw.noalias() = P.qg * V.transpose();
    Cqw = -Cqw;
    M3 Ctw;  // Cov(θ, w)
    Ctw.noalias() = P.tg * V.transpose();
    Ctw = -Ctw;
    // Cov(q, z) = Cov(q, θ)[u]x + Cov(q, b_a) U_a^T + Cov(q, b_g) U_g^T, the last ½ Cov(q, w)[c1]x.
    M63 Cqz = detail::times_skew<6>(P.qt, u) + 0.5 * detail::times_skew<6>(Cqw, c1);
    Cqz.noalias() += P.qa * Ua.transpose();
    // Cov(z, θ) = -[u]x Cov(θ, θ) + U_g Cov(b_g, θ), the last -½[c1]x Cov(w, θ).
    const M3 Czt = detail::neg_skew_times(u, P.tt) + 0.5 * detail::neg_skew_times(c1, M3(Ctw.transpose()));
    const M3 Cza = P.da * Ua;
    const M3 Czg = detail::neg_skew_times(u, P.tg) + P.dg * Ug;
    const M3 Czw = detail::neg_skew_times(u, Ctw) - (0.5 * P.dg) * K;
    // Cov(z, z) = Cov(z, θ)[u]x + d_a U_a U_a^T + ½ Cov(z, w)[c1]x, plus the
    // measurement noise (file comment), in the left form:
    // Σθθ = ½c_g V V^T, Σuθ = -¼c_g K, Σuu = ½c_a I + c_g/8 K [c1]x^T.
    const double two_over_dt = 2.0 / dt;
    const double ca = two_over_dt * noise_.accel_noise_density * noise_.accel_noise_density;
    const double cg = two_over_dt * noise_.gyro_noise_density * noise_.gyro_noise_density;
    M3 Czz = detail::times_skew<3>(Czt, u) + detail::times_skew<3>(Czw, 0.5 * c1) +
             (0.5 * P.da * ja) * yy + (cg / 8.0) * (d1 * (cy * cy.transpose()) - d0 * (c1 * c1.transpose()));
    Czz.diagonal().array() +=
        P.da * (1.0 - 0.5 * ja * t2) + 0.5 * ca + (cg / 8.0) * d0 * c1.squaredNorm();
    mirror_upper(Czz);  // symmetric to rounding: make it exact
    const M3 Sut = (-0.25 * cg) * K;

    // Cov(q', q') = A Cov(q, q) A^T + M B^T + B M^T + B Czz B^T, M = A Cov(q, z).
    const M3 Mp = Cqz.template topRows<3>() + dt * Cqz.template bottomRows<3>();
    const M3 Mv = Cqz.template bottomRows<3>();
    const M3 pvs = P.pv + P.pv.transpose();
    P.pv += dt * P.vv + dt * Mp + h * Mv.transpose() + (h * dt) * Czz;
    P.pp += dt * pvs + (dt * dt) * P.vv + h * (Mp + Mp.transpose()) + (h * h) * Czz;
    P.vv += dt * (Mv + Mv.transpose()) + (dt * dt) * Czz;
    mirror_upper(P.pp);
    mirror_upper(P.vv);
    // Cov(q', θ') = A (Cov(q, θ) + Cov(q, w)) + B (Cov(z, θ) + Cov(z, w) + Σuθ).
    P.qt += Cqw;
    const M3 Zt = Czt + Czw + Sut;
    P.qt.template topRows<3>() += dt * P.qt.template bottomRows<3>() + h * Zt;
    P.qt.template bottomRows<3>() += dt * Zt;
    // Cov(q', b_a) = A Cov(q, b_a) + B d_a U_a; Cov(q', b_g) = A Cov(q, b_g) + B Cov(z, b_g).
    P.qa.template topRows<3>() += dt * P.qa.template bottomRows<3>() + h * Cza;
    P.qa.template bottomRows<3>() += dt * Cza;
    P.qg.template topRows<3>() += dt * P.qg.template bottomRows<3>() + h * Czg;
    P.qg.template bottomRows<3>() += dt * Czg;
    // Cov(θ', θ') = Cov(θ, θ) + Cov(θ, w) + Cov(w, θ) + d_g V V^T + Σθθ; Cov(θ', b_g) = Cov(θ, b_g) - d_g V.
    const double sv = P.dg + 0.5 * cg;
    P.tt += Ctw + Ctw.transpose() + (sv * d1) * yy;
    P.tt.diagonal().array() += sv * d0;
    mirror_upper(P.tt);
    P.tg -= P.dg * V;
    P.da += noise_.accel_random_walk * noise_.accel_random_walk * dt;
    P.dg += noise_.gyro_random_walk * noise_.gyro_random_walk * dt;
  }

  ImuNoise noise_;
  ImuBias bias_;
  PreintegrationOptions options_;
  std::vector<ImuSample> samples_;
  Eigen::Vector3d delta_p_, delta_v_;
  Eigen::Quaterniond delta_q_;
  M3 R_;                 // ΔR as a matrix
  M63 Jq_a_, Jq_g_;      // bias Jacobians of q = [Δp; Δv]
  M3 Jt_g_;              // bias Jacobian of θ (left form)
  Blocks C_;
  double dt_s_ = 0.0;
};

}  // namespace posefuse

// The free functions over recorded sample ranges (preintegrate,
// interpolate_imu) need the class above; they are included here so that
// this header alone keeps offering them.
#include <posefuse/inertial/preintegrate.hpp>

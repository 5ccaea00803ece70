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
/// **Cost.** The step does not form F and G: the integrator here advances
/// ΔR, Δv, Δp, and detail::PreintegrationPropagation
/// (inertial/detail/preintegration_propagation.hpp) moves the covariance and
/// the bias Jacobians by their structure — only the non-zero 3x3 blocks,
/// in internal coordinates whose transition is the identity, closed forms for
/// the products with the step's rotation Jacobian and for the noise term —
/// and converts them to the δφ form above when read (covariance(),
/// bias_jacobian()). The step carries `[[gnu::flatten]]` (g++ and clang; other
/// compilers ignore it): without it g++ leaves many of Eigen's small
/// assignment kernels out of line and the step costs about 1.5x more.
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
#include <posefuse/inertial/detail/preintegration_propagation.hpp>
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
    return prop_.covariance(R_);
  }
  /// \f$ \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$ at the
  /// linearisation bias (δφ the right perturbation of ΔR).
  template <class Lazy = void>
  [[nodiscard]] BiasJacobian bias_jacobian() const {
    return prop_.bias_jacobian(R_);
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

  void clear_state() {
    delta_p_.setZero();
    delta_v_.setZero();
    delta_q_.setIdentity();
    R_.setIdentity();
    prop_.clear();
    dt_s_ = 0.0;
  }

  [[nodiscard]] SO3d rotation() const { return SO3d(delta_q_); }

  /// One mid-point step (file comment); the covariance and the bias
  /// Jacobians move in detail::PreintegrationPropagation, inlined here.
  [[gnu::flatten]] void integrate(const ImuSample& s0, const ImuSample& s1) {
    const double dt = seconds_between(s1.t_ns, s0.t_ns);
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
    const Eigen::Vector3d c1 = R_ * a1;
    const Eigen::Vector3d u = 0.5 * (R0 * a0 + c1);
    delta_p_ += dt * delta_v_ + (0.5 * dt * dt) * u;
    delta_v_ += dt * u;
    dt_s_ += dt;
    prop_.propagate({dt, R0, R_, Jr, ja, jb, theta, c1, u}, noise_);
  }

  ImuNoise noise_;
  ImuBias bias_;
  PreintegrationOptions options_;
  std::vector<ImuSample> samples_;
  Eigen::Vector3d delta_p_, delta_v_;
  Eigen::Quaterniond delta_q_;
  M3 R_;  // ΔR as a matrix
  detail::PreintegrationPropagation prop_;
  double dt_s_ = 0.0;  // Δt_ij (s)
};

}  // namespace posefuse

// The free functions over recorded sample ranges (preintegrate,
// interpolate_imu) need the class above; they are included here so that
// this header alone keeps offering them.
#include <posefuse/inertial/preintegrate.hpp>

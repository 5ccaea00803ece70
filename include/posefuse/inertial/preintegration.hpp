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
/// **Cost.** The update exploits the structure (most of F is identity or zero,
/// the bias-bias blocks stay scalar × I, the noise term has the closed form
/// below); `DensePreintegration` in examples/apps/dense_preintegration.hpp forms the
/// 15x15 F and 15x18 G and multiplies them (VINS-Mono's way), and a test
/// checks both agree to 1e-12.
///
/// **Bias Jacobians** \f$ J = \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$
/// propagate as \f$ J' = F_x J + F_b \f$ from 0 (the top-right 9x6 block of the
/// product of the F's). First-order correction (Forster eq 44) for a bias
/// \f$ b = \bar b + \delta b \f$:
/// \f[ \Delta R(b) = \Delta R\,\mathrm{Exp}(J_{\phi b_g}\delta b_g), \quad
///     \Delta v(b) = \Delta v + J_{v b_a}\delta b_a + J_{v b_g}\delta b_g, \quad
///     \Delta p(b) = \Delta p + J_{p b_a}\delta b_a + J_{p b_g}\delta b_g. \f]
///
/// **Samples.** Stamps are integer nanoseconds (core/time.hpp). A sample that
/// is older than the last one (kOutOfOrder), has the same stamp (kRepeated),
/// comes after a gap above `max_gap_ns` (kGap) or is not finite (kNonFinite)
/// is reported and not integrated; the state is then untouched.
///
/// **Allocation.** Everything is fixed-size. The samples are kept for
/// re-integration in a std::vector reserved at construction
/// (`PreintegrationOptions::reserve_samples`); adding a sample allocates only
/// when that reserve is exceeded.

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// Continuous-time IMU noise figures (the four numbers of a Kalibr / EuRoC
/// `imu.yaml`).
struct ImuNoise {
  double gyro_noise_density = 1.6968e-4;   ///< \f$ \sigma_g \f$ (rad/s/√Hz)
  double accel_noise_density = 2.0e-3;     ///< \f$ \sigma_a \f$ (m/s²/√Hz)
  double gyro_random_walk = 1.9393e-5;     ///< \f$ \sigma_{b_g} \f$ (rad/s²/√Hz)
  double accel_random_walk = 3.0e-3;       ///< \f$ \sigma_{b_a} \f$ (m/s³/√Hz)

  /// Checks every figure is finite and non-negative.
  /// @throws posefuse::invalid_argument naming the first bad figure
  void validate() const {
    const double v[4] = {gyro_noise_density, accel_noise_density, gyro_random_walk,
                         accel_random_walk};
    const char* names[4] = {"gyro_noise_density", "accel_noise_density", "gyro_random_walk",
                            "accel_random_walk"};
    for (int i = 0; i < 4; ++i)
      if (!(std::isfinite(v[i]) && v[i] >= 0.0))
        throw invalid_argument(std::string("ImuNoise: ") + names[i] +
                               " must be finite and >= 0, got " + std::to_string(v[i]));
  }
};

/// Accelerometer and gyroscope biases in the body frame.
struct ImuBias {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< \f$ b_a \f$ (m/s²)
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   ///< \f$ b_g \f$ (rad/s)
  /// As one vector \f$ [b_a, b_g] \f$.
  [[nodiscard]] Eigen::Matrix<double, 6, 1> vector() const {
    Eigen::Matrix<double, 6, 1> b;
    b << accel, gyro;
    return b;
  }
  /// From one vector \f$ [b_a, b_g] \f$.
  [[nodiscard]] static ImuBias from_vector(const Eigen::Matrix<double, 6, 1>& b) {
    return ImuBias{b.head<3>(), b.tail<3>()};
  }
};

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

/// Outcome of adding one IMU sample.
enum class ImuStatus {
  kApplied,        ///< integrated
  kStarted,        ///< the first sample: it starts the interval, nothing to integrate yet
  kOutOfOrder,     ///< stamp before the last sample's: not integrated
  kRepeated,       ///< stamp equal to the last sample's: not integrated
  kGap,            ///< time since the last sample above max_gap_ns: not integrated
  kNonFinite,      ///< a reading is NaN or infinite: not integrated
  kOutOfRange,     ///< (preintegrate) the samples do not cover the requested interval
};

/// Human-readable name of an ImuStatus.
[[nodiscard]] constexpr const char* to_string(ImuStatus s) noexcept {
  switch (s) {
    case ImuStatus::kApplied: return "applied";
    case ImuStatus::kStarted: return "started";
    case ImuStatus::kOutOfOrder: return "out of order";
    case ImuStatus::kRepeated: return "repeated stamp";
    case ImuStatus::kGap: return "gap above the limit";
    case ImuStatus::kNonFinite: return "non-finite reading";
    case ImuStatus::kOutOfRange: return "samples do not cover the interval";
  }
  return "unknown";
}

/// The pre-integrated measurement \f$ (\Delta p, \Delta R, \Delta v) \f$, a
/// posefuse::Manifold of dimension 9 with tangent \f$ [\delta p, \delta\phi, \delta v] \f$
/// (\f$ \Delta R \oplus \delta\phi = \Delta R\,\mathrm{Exp}(\delta\phi) \f$; p and v Euclidean).
struct ImuDelta {
  using Scalar = double;             ///< scalar type
  static constexpr int Dim = 9;      ///< tangent dimension
  using Tangent = Eigen::Matrix<double, 9, 1>;  ///< [δp, δφ, δv]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< \f$ \Delta p_{ij} \f$ (m, frame i)
  SO3d R;                                       ///< \f$ \Delta R_{ij} = R_i^\top R_j \f$
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  ///< \f$ \Delta v_{ij} \f$ (m/s, frame i)

  /// \f$ x \oplus d \f$.
  [[nodiscard]] ImuDelta plus(const Tangent& d) const {
    return ImuDelta{p + d.segment<3>(0), R.plus(d.segment<3>(3)), v + d.segment<3>(6)};
  }
  /// \f$ y \ominus x \f$ (this = y).
  [[nodiscard]] Tangent minus(const ImuDelta& x) const {
    Tangent d;
    d << p - x.p, R.minus(x.R), v - x.v;
    return d;
  }
};

namespace detail {

/// Blocks of one mid-point step's transition (see the file comment), shared by
/// the structured update, the bias Jacobians and the dense reference.
struct MidpointStep {
  Eigen::Matrix3d E_T;     ///< \f$ \mathrm{Exp}(\bar\omega\delta t)^\top \f$
  Eigen::Matrix3d Jr_dt;   ///< \f$ J_r(\bar\omega\delta t)\,\delta t \f$
  Eigen::Matrix3d U_phi;   ///< \f$ \partial\bar u/\partial\delta\phi \f$
  Eigen::Matrix3d U_ba;    ///< \f$ \partial\bar u/\partial b_a \f$
  Eigen::Matrix3d U_bg;    ///< \f$ \partial\bar u/\partial b_g \f$
  Eigen::Matrix3d R0;      ///< \f$ \Delta R_k \f$
  Eigen::Matrix3d R1;      ///< \f$ \Delta R_{k+1} \f$
  Eigen::Matrix3d K;       ///< \f$ R_1[a'_{k+1}]_\times J_r\,\delta t \f$ (gyro noise into \f$ \bar u \f$, ×1/4)
};

/// Advances (p, R, v) by one mid-point step and returns the step's blocks.
template <class Lazy = void>
MidpointStep midpoint_step(const ImuSample& s0, const ImuSample& s1, const ImuBias& bias, double dt,
                           Eigen::Vector3d& p, SO3d& R, Eigen::Vector3d& v) {
  MidpointStep st;
  const Eigen::Vector3d w = 0.5 * (s0.gyro_radps + s1.gyro_radps) - bias.gyro;
  const Eigen::Vector3d a0 = s0.accel_mps2 - bias.accel;
  const Eigen::Vector3d a1 = s1.accel_mps2 - bias.accel;
  const Eigen::Vector3d theta = w * dt;
  SO3d::Jacobian Jr;
  const SO3d E = SO3d::exp(theta, &Jr);
  const SO3d R_next = R.compose(E);
  st.R0 = R.matrix();
  st.R1 = R_next.matrix();
  st.E_T = E.matrix().transpose();
  st.Jr_dt = Jr * dt;
  const Eigen::Vector3d u = 0.5 * (st.R0 * a0 + st.R1 * a1);
  const Eigen::Matrix3d R1_a1x = st.R1 * SO3d::hat(a1);
  st.U_phi = -0.5 * (st.R0 * SO3d::hat(a0) + R1_a1x * st.E_T);
  st.U_ba = -0.5 * (st.R0 + st.R1);
  st.K = R1_a1x * st.Jr_dt;
  st.U_bg = 0.5 * st.K;
  p += v * dt + (0.5 * dt * dt) * u;
  v += u * dt;
  R = R_next;
  return st;
}

}  // namespace detail

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
  [[nodiscard]] ImuDelta delta() const { return ImuDelta{delta_p_, delta_R_, delta_v_}; }

  /// The first-order bias-corrected measurement (Forster eq 44; file comment).
  /// @param[in] bias the bias to correct to; exact at the linearisation bias
  /// @param[out] J_d_b if not null, \f$ \partial\,\Delta(b) \ominus \Delta(\bar b) / \partial b \f$
  ///             (9x6; equal to bias_jacobian() except the rotation rows,
  ///             \f$ J_r(J_{\phi b_g}\delta b_g) J_{\phi b_g} \f$)
  template <class Lazy = void>
  [[nodiscard]] ImuDelta delta(const ImuBias& bias, BiasJacobian* J_d_b = nullptr) const {
    const Eigen::Matrix<double, 6, 1> db = bias.vector() - bias_.vector();
    const Eigen::Vector3d dphi = J_.block<3, 6>(3, 0) * db;
    SO3d::Jacobian Jr;
    ImuDelta d{delta_p_ + J_.block<3, 6>(0, 0) * db, delta_R_.plus(dphi, nullptr, &Jr),
               delta_v_ + J_.block<3, 6>(6, 0) * db};
    if (J_d_b) {
      *J_d_b = J_;
      J_d_b->block<3, 6>(3, 0) = Jr * J_.block<3, 6>(3, 0);
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

  /// Re-integrates every stored sample about a new linearisation bias.
  /// @throws posefuse::invalid_argument when `bias` is not finite
  void reintegrate(const ImuBias& bias) {
    if (!bias.vector().allFinite()) throw invalid_argument("reintegrate: bias is not finite");
    bias_ = bias;
    clear_state();
    for (std::size_t k = 1; k < samples_.size(); ++k) integrate(samples_[k - 1], samples_[k]);
  }

  /// Covariance of \f$ [\delta p, \delta\phi, \delta v, \delta b_a, \delta b_g] \f$ (SI units, rad).
  [[nodiscard]] const Covariance& covariance() const noexcept { return P_; }
  /// \f$ \partial[\Delta p, \Delta\phi, \Delta v] / \partial[b_a, b_g] \f$ at the linearisation bias.
  [[nodiscard]] const BiasJacobian& bias_jacobian() const noexcept { return J_; }
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
  void clear_state() {
    delta_p_.setZero();
    delta_v_.setZero();
    delta_R_ = SO3d();
    J_.setZero();
    P_.setZero();
    dt_s_ = 0.0;
  }

  /// One mid-point step with the structured covariance and Jacobian update.
  void integrate(const ImuSample& s0, const ImuSample& s1) {
    const double dt = seconds_between(s1.t_ns, s0.t_ns);
    const detail::MidpointStep st =
        detail::midpoint_step(s0, s1, bias_, dt, delta_p_, delta_R_, delta_v_);
    dt_s_ += dt;
    propagate_jacobian(st, dt);
    propagate_covariance(st, dt);
  }

  // J' = F_x J + F_b with F_x = [[I, ½dt²U_φ, dt I], [0, E^T, 0], [0, dt U_φ, I]].
  void propagate_jacobian(const detail::MidpointStep& st, double dt) {
    const double h = 0.5 * dt * dt;
    const Eigen::Matrix<double, 3, 6> Jp = J_.block<3, 6>(0, 0);
    const Eigen::Matrix<double, 3, 6> Jphi = J_.block<3, 6>(3, 0);
    const Eigen::Matrix<double, 3, 6> Jv = J_.block<3, 6>(6, 0);
    Eigen::Matrix<double, 3, 6> Ub;  // ∂ū/∂[b_a, b_g] + U_φ J_φ
    Ub << st.U_ba, st.U_bg;
    Ub.noalias() += st.U_phi * Jphi;
    J_.block<3, 6>(0, 0) = Jp + dt * Jv + h * Ub;
    J_.block<3, 6>(6, 0) = Jv + dt * Ub;
    J_.block<3, 6>(3, 0).noalias() = st.E_T * Jphi;
    J_.block<3, 3>(3, 3) -= st.Jr_dt;
  }

  // P' = F P F^T + G Q G^T by blocks (file comment). Index blocks 0..4 =
  // p, φ, v, b_a, b_g; the b_a/b_g blocks of P are d_a I and d_g I.
  void propagate_covariance(const detail::MidpointStep& st, double dt) {
    using M3 = Eigen::Matrix3d;
    const double h = 0.5 * dt * dt;
    const double da = P_(9, 9), dg = P_(12, 12);
    const auto B = [this](int i, int j) { return P_.block<3, 3>(3 * i, 3 * j); };
    // Rows of X = F P for p, φ, v; columns p, φ, v, b_a, b_g. With
    // u_j = U_φ P_φj + U_ba P_aj + U_bg P_gj:  X_p = P_p + dt P_v + h u,
    // X_φ = E^T P_φ - Jr dt P_g, X_v = P_v + dt u.
    Eigen::Matrix<double, 9, 15> X;
    for (int j = 0; j < 5; ++j) {
      M3 u = st.U_phi * B(1, j);
      M3 Pg_term;  // Jr dt P_gj
      if (j < 3) {
        u.noalias() += st.U_ba * B(3, j) + st.U_bg * B(4, j);
        Pg_term.noalias() = st.Jr_dt * B(4, j);
      } else if (j == 3) {
        u += da * st.U_ba;
        Pg_term.setZero();
      } else {
        u += dg * st.U_bg;
        Pg_term = dg * st.Jr_dt;
      }
      X.block<3, 3>(0, 3 * j) = B(0, j) + dt * B(2, j) + h * u;
      X.block<3, 3>(3, 3 * j).noalias() = st.E_T * B(1, j);
      X.block<3, 3>(3, 3 * j) -= Pg_term;
      X.block<3, 3>(6, 3 * j) = B(2, j) + dt * u;
    }
    // P' = X F^T for the p, φ, v rows: P'_ip = X_ip + dt X_iv + h w_i,
    // P'_iφ = X_iφ E - X_ig (Jr dt)^T, P'_iv = X_iv + dt w_i, with
    // w_i = X_iφ U_φ^T + X_ia U_ba^T + X_ig U_bg^T; P'_ia = X_ia, P'_ig = X_ig.
    Eigen::Matrix<double, 9, 9> A;
    {
      const Eigen::Matrix<double, 9, 3> Xp = X.block<9, 3>(0, 0), Xphi = X.block<9, 3>(0, 3),
                                        Xv = X.block<9, 3>(0, 6), Xa = X.block<9, 3>(0, 9),
                                        Xg = X.block<9, 3>(0, 12);
      Eigen::Matrix<double, 9, 3> w;
      w.noalias() = Xphi * st.U_phi.transpose();
      w.noalias() += Xa * st.U_ba.transpose();
      w.noalias() += Xg * st.U_bg.transpose();
      A.block<9, 3>(0, 0) = Xp + dt * Xv + h * w;
      A.block<9, 3>(0, 3).noalias() = Xphi * st.E_T.transpose();
      A.block<9, 3>(0, 3).noalias() -= Xg * st.Jr_dt.transpose();
      A.block<9, 3>(0, 6) = Xv + dt * w;
    }
    // Noise, closed form: ū gets −½R0 n_a0 − ½R1 n_a1 + ¼K(n_g0 + n_g1), δφ gets
    // −½Jr dt (n_g0 + n_g1); each n with variance 2σ²/dt.
    const double ca = 2.0 * noise_.accel_noise_density * noise_.accel_noise_density / dt;
    const double cg = 2.0 * noise_.gyro_noise_density * noise_.gyro_noise_density / dt;
    M3 S_uu = (cg / 8.0) * (st.K * st.K.transpose());
    S_uu.diagonal().array() += 0.5 * ca;  // ¼ca (R0 R0^T + R1 R1^T) = ½ca I
    const M3 S_phiphi = (0.5 * cg) * (st.Jr_dt * st.Jr_dt.transpose());
    const M3 S_uphi = (-0.25 * cg) * (st.K * st.Jr_dt.transpose());
    A.block<3, 3>(0, 0) += (h * h) * S_uu;
    A.block<3, 3>(0, 3) += h * S_uphi;
    A.block<3, 3>(0, 6) += (h * dt) * S_uu;
    A.block<3, 3>(3, 3) += S_phiphi;
    A.block<3, 3>(3, 6) += dt * S_uphi.transpose();
    A.block<3, 3>(6, 6) += (dt * dt) * S_uu;
    // Lower blocks of the noise term mirror the upper ones.
    A.block<3, 3>(3, 0) += h * S_uphi.transpose();
    A.block<3, 3>(6, 0) += (h * dt) * S_uu;
    A.block<3, 3>(6, 3) += dt * S_uphi;
    // Exactly symmetric: the upper triangle, mirrored.
    P_.block<9, 9>(0, 0).triangularView<Eigen::Upper>() = A;
    P_.block<9, 9>(0, 0).triangularView<Eigen::StrictlyLower>() = A.transpose();
    P_.block<9, 6>(0, 9) = X.block<9, 6>(0, 9);
    P_.block<6, 9>(9, 0) = X.block<9, 6>(0, 9).transpose();
    const double qa = noise_.accel_random_walk * noise_.accel_random_walk * dt;
    const double qg = noise_.gyro_random_walk * noise_.gyro_random_walk * dt;
    for (int k = 0; k < 3; ++k) {
      P_(9 + k, 9 + k) = da + qa;
      P_(12 + k, 12 + k) = dg + qg;
    }
  }

  ImuNoise noise_;
  ImuBias bias_;
  PreintegrationOptions options_;
  std::vector<ImuSample> samples_;
  Eigen::Vector3d delta_p_, delta_v_;
  SO3d delta_R_;
  BiasJacobian J_;
  Covariance P_;
  double dt_s_ = 0.0;
};

/// The sample at `t_ns` linearly interpolated between `a` and `b` (readings
/// only; the magnetometer is interpolated too).
/// @pre a.t_ns < b.t_ns and a.t_ns <= t_ns <= b.t_ns
[[nodiscard]] inline ImuSample interpolate_imu(const ImuSample& a, const ImuSample& b,
                                               std::int64_t t_ns) noexcept {
  const double s = seconds_between(t_ns, a.t_ns) / seconds_between(b.t_ns, a.t_ns);
  ImuSample out;
  out.t_ns = t_ns;
  out.accel_mps2 = a.accel_mps2 + s * (b.accel_mps2 - a.accel_mps2);
  out.gyro_radps = a.gyro_radps + s * (b.gyro_radps - a.gyro_radps);
  out.mag_uT = a.mag_uT + s * (b.mag_uT - a.mag_uT);
  return out;
}

/// Pre-integrates a time-ordered sample stream between two arbitrary stamps:
/// the boundary samples at `t0_ns` and `t1_ns` are linearly interpolated
/// from the samples around them (used as they are when a stamp matches).
/// @param[in] samples time-ordered samples covering [t0_ns, t1_ns]
/// @param[in] t0_ns, t1_ns the keyframe stamps, t0_ns < t1_ns
/// @param[out] out a fresh Preintegration (its noise, bias and options are kept)
/// @return kApplied, kOutOfRange when the samples do not cover the interval
///         (or t1_ns <= t0_ns), or the first non-applied status of a sample
///         inside it (out is then partial: do not use it)
template <class Lazy = void>
[[nodiscard]] ImuStatus preintegrate(std::span<const ImuSample> samples, std::int64_t t0_ns,
                                     std::int64_t t1_ns, Preintegration& out) {
  out = Preintegration(out.noise(), out.bias(), out.options());
  if (!(t0_ns < t1_ns) || samples.empty() || samples.front().t_ns > t0_ns ||
      samples.back().t_ns < t1_ns)
    return ImuStatus::kOutOfRange;
  // First sample with t > t0 (binary search; the stream must be ordered, which add() checks).
  std::size_t lo = 0, hi = samples.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (samples[mid].t_ns <= t0_ns) lo = mid + 1; else hi = mid;
  }
  const std::size_t k0 = lo;  // samples[k0 - 1].t_ns <= t0 < samples[k0].t_ns
  const ImuSample& before = samples[k0 - 1];
  const ImuSample first =
      before.t_ns == t0_ns ? before : interpolate_imu(before, samples[k0], t0_ns);
  ImuStatus st = out.add(first);
  if (st != ImuStatus::kStarted) return st;
  for (std::size_t k = k0; k < samples.size(); ++k) {
    const ImuSample& s = samples[k];
    if (s.t_ns >= t1_ns) {
      const ImuSample last = s.t_ns == t1_ns ? s : interpolate_imu(samples[k - 1], s, t1_ns);
      st = out.add(last);
      return st;
    }
    st = out.add(s);
    if (st != ImuStatus::kApplied) return st;
  }
  return ImuStatus::kOutOfRange;  // unreachable: samples.back().t_ns >= t1_ns
}

}  // namespace posefuse

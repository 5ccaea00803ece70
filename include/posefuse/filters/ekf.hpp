#pragma once
/// @file
/// Extended Kalman filter over one motion model and any number of measurement
/// models, all sizes fixed at compile time.
///
/// Step (Thrun et al., *Probabilistic Robotics*, Table 3.3; seed 000 Fig. 3),
/// written with boxplus so that wrapped states work:
/// \f[ \bar x = f(x, u, \Delta t),\quad \bar P = F P F^\top + Q_f \f]
/// \f[ r = z \boxminus h(\bar x),\quad S = H \bar P H^\top + R_h,\quad
///     K = \bar P H^\top S^{-1} \f]
/// \f[ x = \bar x \boxplus K r,\quad
///     P = (I - K H) \bar P (I - K H)^\top + K R_h K^\top \f]
/// The covariance update is Joseph's form, then symmetrised, so P stays
/// symmetric positive semi-definite under round-off.
///
/// Naming: posefuse calls a model's noise `noise()`. Seed 000 follows Thrun
/// and calls process noise R and measurement noise Q; the models that
/// reproduce it (planar_displacement.hpp, position.hpp) keep that naming in
/// their parameters.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <tuple>
#include <type_traits>

namespace posefuse {

/// Outcome of a filter step. Anything but kApplied leaves the filter untouched.
enum class FilterStatus {
  kApplied,              ///< the step changed the state and covariance
  kNonFinite,            ///< input or result had NaN/Inf
  kInvalidInput,         ///< e.g. a negative time step
  kNotPositiveDefinite,  ///< the innovation covariance S was not positive definite
  kGated,                ///< the normalised innovation squared exceeded the gate
};

/// Human-readable name of a status.
[[nodiscard]] constexpr const char* to_string(FilterStatus s) noexcept {
  switch (s) {
    case FilterStatus::kApplied: return "applied";
    case FilterStatus::kNonFinite: return "non-finite";
    case FilterStatus::kInvalidInput: return "invalid input";
    case FilterStatus::kNotPositiveDefinite: return "innovation covariance not positive definite";
    case FilterStatus::kGated: return "rejected by gate";
  }
  return "unknown";
}

/// What an update did, with its innovation statistics (valid whenever S could
/// be formed, also for gated updates).
template <MeasurementModel H>
struct UpdateResult {
  using Innovation = TangentOf<typename H::Measurement>;
  using InnovationCovariance = CovarianceOf<typename H::Measurement>;

  FilterStatus status = FilterStatus::kNonFinite;
  Innovation innovation = Innovation::Zero();  ///< \f$ r = z \boxminus h(\bar x) \f$
  InnovationCovariance S = InnovationCovariance::Zero();  ///< \f$ H P H^\top + R \f$
  ScalarOf<typename H::State> nis = std::numeric_limits<ScalarOf<typename H::State>>::quiet_NaN();

  /// True when the update was applied.
  [[nodiscard]] explicit operator bool() const noexcept { return status == FilterStatus::kApplied; }
};

namespace detail {
template <class T, class... Ts>
inline constexpr std::size_t index_of_v = [] {
  constexpr std::array<bool, sizeof...(Ts)> same{std::is_same_v<T, Ts>...};
  std::size_t found = sizeof...(Ts);
  std::size_t count = 0;
  for (std::size_t i = 0; i < same.size(); ++i) {
    if (same[i]) {
      found = i;
      ++count;
    }
  }
  return count == 1 ? found : sizeof...(Ts);
}();

/// A zero-initialised state (Eigen vectors are not zeroed by default).
template <class S>
S zero_state() {
  if constexpr (requires { S::Zero(); }) {
    return S::Zero();
  } else {
    return S{};
  }
}

/// Inverts a symmetric matrix if it is positive definite. Sizes 1 and 2 use
/// Sylvester's criterion and the closed-form inverse (a few flops, no
/// branches on the data beyond the test); larger sizes use Cholesky.
/// @return false (and leaves `inv` unspecified) unless S is positive definite
template <class Mat>
[[nodiscard]] inline bool spd_inverse(const Mat& S, Mat& inv) {
  using T = typename Mat::Scalar;
  constexpr int N = Mat::RowsAtCompileTime;
  if constexpr (N == 1) {
    if (!(S(0, 0) > T(0))) return false;
    inv(0, 0) = T(1) / S(0, 0);
    return true;
  } else if constexpr (N == 2) {
    const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
    if (!(S(0, 0) > T(0) && det > T(0))) return false;
    const T r = T(1) / det;
    inv(0, 0) = S(1, 1) * r;
    inv(1, 1) = S(0, 0) * r;
    inv(0, 1) = -S(0, 1) * r;
    inv(1, 0) = -S(1, 0) * r;
    return true;
  } else {
    const Eigen::LLT<Mat> llt(S);
    if (llt.info() != Eigen::Success) return false;
    inv = llt.solve(Mat::Identity());
    return true;
  }
}
}  // namespace detail

/// An EKF over `Motion` with measurement models `Sensors...`.
/// @tparam Motion  a posefuse::MotionModel
/// @tparam Sensors posefuse::MeasurementModel's with the same State
template <class Motion, class... Sensors>
class Ekf {
  static_assert(check_motion_model<Motion>(), "posefuse::Ekf: see the message above");
  static_assert((check_measurement_model<Sensors>() && ...),
                "posefuse::Ekf: see the message above");
  static_assert((std::is_same_v<typename Sensors::State, typename Motion::State> && ...),
                "posefuse::Ekf: every measurement model must have the motion model's State type");

 public:
  using MotionType = Motion;
  using StateType = typename Motion::State;
  using Control = typename Motion::Control;
  using Scalar = ScalarOf<StateType>;
  static constexpr int Dim = DimOf<StateType>;
  using Covariance = CovarianceOf<StateType>;
  using Belief = Gaussian<StateType>;
  template <std::size_t I>
  using SensorType = std::tuple_element_t<I, std::tuple<Sensors...>>;

  /// A filter with models but no belief yet: call reset() before the first step.
  explicit Ekf(Motion motion, Sensors... sensors)
      : motion_(std::move(motion)), sensors_(std::move(sensors)...) {
    gates_.fill(std::numeric_limits<Scalar>::infinity());
  }

  /// Sets the belief.
  /// @throws posefuse::invalid_argument if P0 is not a finite symmetric PSD
  ///         matrix or x0 is not finite
  void reset(const StateType& x0, const Covariance& P0) {
    if (!minus(x0, x0).allFinite()) throw invalid_argument("Ekf::reset: state has NaN or Inf");
    require_covariance(P0, "Ekf::reset");
    x_ = x0;
    P_ = P0;
  }
  /// Sets the belief from a Gaussian (already validated by its constructor).
  void reset(const Belief& b) { reset(b.mean, b.cov); }

  /// Prediction \f$ \bar x = f(x, u, \Delta t) \f$, \f$ \bar P = F P F^\top + Q \f$.
  /// @param[in] u  control input
  /// @param[in] dt time step (s), finite and >= 0
  /// @return kApplied, kInvalidInput (dt < 0) or kNonFinite; the filter is
  ///         unchanged unless kApplied
  [[nodiscard]] FilterStatus predict(const Control& u, Scalar dt) {
    if (!std::isfinite(dt)) return FilterStatus::kNonFinite;
    if (dt < Scalar(0)) return FilterStatus::kInvalidInput;
    const StateType x_new = motion_.predict(x_, u, dt);
    Covariance P_new;
    if constexpr (has_identity_jacobian_v<Motion>) {
      P_new = P_ + Covariance(motion_.noise(x_, u, dt));
      if (!minus(x_new, x_).allFinite() || !P_new.allFinite()) return FilterStatus::kNonFinite;
      // F_ stays the identity it was initialised to.
    } else {
      const Covariance F = motion_.jacobian(x_, u, dt);
      P_new = F * P_ * F.transpose() + Covariance(motion_.noise(x_, u, dt));
      if (!minus(x_new, x_).allFinite() || !P_new.allFinite()) return FilterStatus::kNonFinite;
      F_ = F;
    }
    x_ = x_new;
    P_ = symmetrised(P_new);
    return FilterStatus::kApplied;
  }

  /// Update with the I-th measurement model of the filter.
  template <std::size_t I>
  [[nodiscard]] UpdateResult<SensorType<I>> update(const typename SensorType<I>::Measurement& z) {
    using H = SensorType<I>;
    const H& sensor = std::get<I>(sensors_);
    if constexpr (is_time_invariant_v<H>) {
      // The covariance part depends on P alone: reuse it while P repeats
      // (a converged, steady-state filter), bit for bit what it would compute.
      GainMemo<H>& memo = std::get<I>(memos_);
      if (!memo.valid || memo.P_in != P_) {
        memo.valid = false;
        const FilterStatus s = covariance_update(sensor, memo.gain);
        if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
        memo.P_in = P_;
        memo.valid = true;
      }
      return apply_update(sensor, z, gates_[I], memo.gain);
    } else {
      return update_with(sensor, z, gates_[I]);
    }
  }

  /// Update with the filter's measurement model of type H (which must occur
  /// exactly once in Sensors...).
  template <class H>
    requires(detail::index_of_v<H, Sensors...> < sizeof...(Sensors))
  [[nodiscard]] UpdateResult<H> update(const typename H::Measurement& z) {
    return update<detail::index_of_v<H, Sensors...>>(z);
  }

  /// Update with any measurement model of this state type, not held by the
  /// filter (no gate unless `gate` is given).
  /// @param[in] gate reject when the NIS exceeds this (see chi_square_quantile)
  template <MeasurementModelFor<StateType> H>
  [[nodiscard]] UpdateResult<H> update_with(const H& sensor, const typename H::Measurement& z,
                                            Scalar gate = std::numeric_limits<Scalar>::infinity()) {
    Gain<H> g;
    const FilterStatus s = covariance_update(sensor, g);
    if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
    return apply_update(sensor, z, gate, g);
  }

  /// Sets the NIS gate of the I-th measurement model; +infinity disables it.
  /// @throws posefuse::invalid_argument if the threshold is not positive
  template <std::size_t I>
  void set_gate(Scalar nis_threshold) {
    if (!(nis_threshold > Scalar(0))) throw invalid_argument("Ekf::set_gate: threshold must be > 0");
    gates_[I] = nis_threshold;
  }
  /// The NIS gate of the I-th measurement model.
  template <std::size_t I>
  [[nodiscard]] Scalar gate() const noexcept {
    return gates_[I];
  }

  [[nodiscard]] const StateType& state() const noexcept { return x_; }
  [[nodiscard]] const Covariance& covariance() const noexcept { return P_; }
  [[nodiscard]] Belief belief() const { return Belief(x_, P_); }
  /// The state Jacobian F of the last applied prediction (for smoothing).
  [[nodiscard]] const Covariance& last_jacobian() const noexcept { return F_; }
  [[nodiscard]] const Motion& motion() const noexcept { return motion_; }
  template <std::size_t I>
  [[nodiscard]] const SensorType<I>& sensor() const noexcept {
    return std::get<I>(sensors_);
  }

 private:
  /// The data-independent part of an update: S, S^-1, K and the Joseph-form
  /// posterior covariance at the current P.
  template <class H>
  struct Gain {
    using SMat = CovarianceOf<typename H::Measurement>;
    SMat S = SMat::Zero();
    SMat S_inv = SMat::Zero();
    Eigen::Matrix<Scalar, Dim, DimOf<typename H::Measurement>> K =
        Eigen::Matrix<Scalar, Dim, DimOf<typename H::Measurement>>::Zero();
    Covariance P_post = Covariance::Zero();
  };
  template <class H>
  struct GainMemo {
    bool valid = false;
    Covariance P_in = Covariance::Zero();
    Gain<H> gain;
  };

  template <class H>
  FilterStatus covariance_update(const H& sensor, Gain<H>& g) const {
    using SMat = typename Gain<H>::SMat;
    const SMat R = sensor.noise();
    if constexpr (has_identity_jacobian_v<H> && DimOf<typename H::Measurement> == Dim) {
      g.S = P_ + R;
      if (!detail::spd_inverse(g.S, g.S_inv)) return FilterStatus::kNotPositiveDefinite;
      g.K = P_ * g.S_inv;
      const Covariance I_K = Covariance::Identity() - g.K;
      g.P_post = I_K * P_ * I_K.transpose() + g.K * R * g.K.transpose();
    } else {
      const MeasurementJacobianOf<H> J = sensor.jacobian(x_);
      const Eigen::Matrix<Scalar, DimOf<typename H::Measurement>, Dim> JP = J * P_;
      g.S = JP * J.transpose() + R;
      if (!detail::spd_inverse(g.S, g.S_inv)) return FilterStatus::kNotPositiveDefinite;
      g.K = JP.transpose() * g.S_inv;  // K = P J^T S^-1
      const Covariance I_KH = Covariance::Identity() - g.K * J;
      g.P_post = I_KH * P_ * I_KH.transpose() + g.K * R * g.K.transpose();
    }
    if (!g.P_post.allFinite()) return FilterStatus::kNonFinite;
    g.P_post = symmetrised(g.P_post);
    return FilterStatus::kApplied;
  }

  template <class H>
  UpdateResult<H> apply_update(const H& sensor, const typename H::Measurement& z, Scalar gate,
                               const Gain<H>& g) {
    using Z = typename H::Measurement;
    UpdateResult<H> out;
    out.S = g.S;
    out.innovation = minus(z, static_cast<Z>(sensor.predict(x_)));
    if (!out.innovation.allFinite()) return out;  // kNonFinite
    out.nis = out.innovation.dot(g.S_inv * out.innovation);
    if (!(out.nis <= gate)) return fail(out, FilterStatus::kGated);
    const StateType x_new = plus(x_, TangentOf<StateType>(g.K * out.innovation));
    if (!minus(x_new, x_).allFinite()) return fail(out, FilterStatus::kNonFinite);
    x_ = x_new;
    P_ = g.P_post;
    out.status = FilterStatus::kApplied;
    return out;
  }

  template <class R>
  static R fail(R r, FilterStatus s) {
    r.status = s;
    return r;
  }
  static Covariance symmetrised(const Covariance& P) {
    return Scalar(0.5) * (P + P.transpose());
  }

  Motion motion_;
  std::tuple<Sensors...> sensors_;
  std::tuple<GainMemo<Sensors>...> memos_;
  std::array<Scalar, sizeof...(Sensors) == 0 ? 1 : sizeof...(Sensors)> gates_{};
  StateType x_ = detail::zero_state<StateType>();
  Covariance P_ = Covariance::Identity();
  Covariance F_ = Covariance::Identity();
};

}  // namespace posefuse

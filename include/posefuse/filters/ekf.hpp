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
/// symmetric positive semi-definite under round-off. \f$ R_h \f$ is the
/// model's `noise()`, or `noise(x)` at the prior state when the model has it
/// (state-dependent noise, core/concepts.hpp).
///
/// **Solving with S.** For 1x1 and 2x2 innovations S is tested by
/// Sylvester's criterion and inverted in closed form (a few flops). Larger
/// ones are factorised, \f$ S = L L^\top \f$, and K and the NIS
/// \f$ r^\top S^{-1} r \f$ are computed by solving with L; no inverse is
/// formed. Either way S counts as positive definite only when every pivot is
/// above round-off: \f$ L_{ii}^2 > n\,\epsilon\,S_{ii} \f$ (2x2:
/// \f$ \det S > 2 \epsilon S_{00} S_{11} \f$), which is invariant to the units
/// of each component, so an indefinite or (numerically) singular S is
/// reported as kNotPositiveDefinite instead of producing a huge gain.
///
/// **Gates.** An update can be rejected by a NIS threshold (per filter-held
/// model, set_gate(), or per call) and/or by a gate functor
/// `bool(const Innovation& r, const InnovationCovariance& S[, Scalar nis])`
/// given to the call, so a caller can gate parts of a measurement separately
/// (e.g. position and heading of a pose); the returned UpdateResult keeps r,
/// S and the NIS, from which the caller can tell which part failed.
///
/// **Before reset().** A filter constructed without a belief has none:
/// predict() and every update return FilterStatus::kNotInitialised and change
/// nothing until reset() is called (initialised()).
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
#include <posefuse/core/status.hpp>
#include <tuple>
#include <type_traits>

namespace posefuse {

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

/// A gate for updates with measurement model H: a NIS threshold (any
/// arithmetic type), or a functor `bool(const Innovation& r, const
/// InnovationCovariance& S)` or `bool(r, S, Scalar nis)` returning true to
/// accept the measurement.
template <class G, class H>
concept InnovationGate =
    MeasurementModel<H> &&
    ((std::is_arithmetic_v<G> && !std::is_same_v<G, bool>) ||
     std::is_invocable_r_v<bool, const G&, const typename UpdateResult<H>::Innovation&,
                           const typename UpdateResult<H>::InnovationCovariance&> ||
     std::is_invocable_r_v<bool, const G&, const typename UpdateResult<H>::Innovation&,
                           const typename UpdateResult<H>::InnovationCovariance&,
                           ScalarOf<typename H::State>>);

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

/// True unless H names a State that differs from S (a missing State is
/// reported by check_measurement_model).
template <class H, class S>
consteval bool state_matches() {
  if constexpr (requires { typename H::State; }) {
    return std::is_same_v<typename H::State, S>;
  } else {
    return true;
  }
}

/// The positive-definiteness test and the solves with an innovation
/// covariance S (see the file comment). Sizes 1 and 2 keep S⁻¹ in closed
/// form; larger sizes keep the Cholesky factor and never form S⁻¹.
template <class Mat, int N = Mat::RowsAtCompileTime>
class SpdSolver {
  using T = typename Mat::Scalar;
  using Vec = Eigen::Matrix<T, N, 1>;

 public:
  /// Factorises S. @return false (solver unusable) unless S is positive definite
  [[nodiscard]] bool compute(const Mat& S) {
    if constexpr (N == 1) {
      if (!(S(0, 0) > T(0))) return false;
      inv_(0, 0) = T(1) / S(0, 0);
      return true;
    } else if constexpr (N == 2) {
      const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
      if (!(S(0, 0) > T(0) && det > T(2) * std::numeric_limits<T>::epsilon() * S(0, 0) * S(1, 1)))
        return false;
      const T r = T(1) / det;
      inv_(0, 0) = S(1, 1) * r;
      inv_(1, 1) = S(0, 0) * r;
      inv_(0, 1) = -S(0, 1) * r;
      inv_(1, 0) = -S(1, 0) * r;
      return true;
    } else {
      llt_.compute(S);
      if (llt_.info() != Eigen::Success) return false;
      const T tol = T(N) * std::numeric_limits<T>::epsilon();
      const auto& L = llt_.matrixLLT();
      for (int i = 0; i < N; ++i)
        if (!(L(i, i) * L(i, i) > tol * S(i, i))) return false;
      return true;
    }
  }
  /// \f$ r^\top S^{-1} r \f$.
  [[nodiscard]] T nis(const Vec& r) const {
    if constexpr (N <= 2) {
      return r.dot(inv_ * r);
    } else {
      return r.dot(llt_.solve(r));
    }
  }
  /// \f$ A S^{-1} \f$ for an M x N matrix A.
  template <int M>
  [[nodiscard]] Eigen::Matrix<T, M, N> right_solve(const Eigen::Matrix<T, M, N>& A) const {
    if constexpr (N <= 2) {
      return A * inv_;
    } else {
      // A S^-1 = (S^-1 A^T)^T, S symmetric.
      return llt_.solve(A.transpose()).transpose();
    }
  }

 private:
  struct Empty {};
  using Inverse = std::conditional_t<(N <= 2), Mat, Empty>;
  static Inverse zero_inverse() {
    if constexpr (N <= 2) {
      return Mat::Zero();
    } else {
      return Empty{};
    }
  }
  [[no_unique_address]] Inverse inv_ = zero_inverse();
  [[no_unique_address]] std::conditional_t<(N <= 2), Empty, Eigen::LLT<Mat>> llt_{};
};

/// Placeholder measurement type for update_with() with a type that names none.
struct NotAMeasurementModel {};
template <class H>
struct measurement_of {
  using type = NotAMeasurementModel;
};
template <class H>
  requires requires { typename H::Measurement; }
struct measurement_of<H> {
  using type = typename H::Measurement;
};
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

  /// A filter with models but no belief yet: call reset() before the first
  /// step (until then every step returns kNotInitialised).
  explicit Ekf(Motion motion, Sensors... sensors)
      : motion_(std::move(motion)), sensors_(std::move(sensors)...) {
    gates_.fill(std::numeric_limits<Scalar>::infinity());
  }

  /// Sets the belief (and marks the filter initialised).
  /// @throws posefuse::invalid_argument if P0 is not a finite symmetric PSD
  ///         matrix or x0 is not finite
  void reset(const StateType& x0, const Covariance& P0) {
    if (!minus(x0, x0).allFinite()) throw invalid_argument("Ekf::reset: state has NaN or Inf");
    require_covariance(P0, "Ekf::reset");
    x_ = x0;
    P_ = P0;
    initialised_ = true;
  }
  /// Sets the belief from a Gaussian (already validated by its constructor).
  void reset(const Belief& b) { reset(b.mean, b.cov); }

  /// True once reset() has given the filter a belief.
  [[nodiscard]] bool initialised() const noexcept { return initialised_; }

  /// Prediction \f$ \bar x = f(x, u, \Delta t) \f$, \f$ \bar P = F P F^\top + Q \f$.
  /// @param[in] u  control input
  /// @param[in] dt time step (s), finite and >= 0
  /// @return kApplied, kNotInitialised (no reset() yet), kInvalidInput (dt < 0)
  ///         or kNonFinite; the filter is unchanged unless kApplied
  [[nodiscard]] FilterStatus predict(const Control& u, Scalar dt) {
    if (!initialised_) return FilterStatus::kNotInitialised;
    if (!std::isfinite(dt)) return FilterStatus::kNonFinite;
    if (dt < Scalar(0)) return FilterStatus::kInvalidInput;
    StateType x_new = detail::zero_state<StateType>();
    Covariance P_new;
    if constexpr (has_identity_jacobian_v<Motion>) {
      x_new = motion_.predict(x_, u, dt);
      P_new = P_ + Covariance(motion_.noise(x_, u, dt));
      if (!minus(x_new, x_).allFinite() || !P_new.allFinite()) return FilterStatus::kNonFinite;
      P_new = symmetrised(P_new);
      if (!is_positive_semidefinite(P_new)) return FilterStatus::kNotPositiveDefinite;
      // F_ stays the identity it was initialised to.
    } else if constexpr (HasLinearize<Motion>) {
      // One model call (see HasLinearize, core/concepts.hpp); the same values as below.
      const auto lin = motion_.linearize(x_, u, dt);
      x_new = lin.state;
      const Covariance F = lin.jacobian;
      P_new = F * P_ * F.transpose() + Covariance(lin.noise);
      if (!minus(x_new, x_).allFinite() || !P_new.allFinite()) return FilterStatus::kNonFinite;
      P_new = symmetrised(P_new);
      if (!is_positive_semidefinite(P_new)) return FilterStatus::kNotPositiveDefinite;
      F_ = F;  // recorded for the smoother only when the step is applied
    } else {
      x_new = motion_.predict(x_, u, dt);
      const Covariance F = motion_.jacobian(x_, u, dt);
      P_new = F * P_ * F.transpose() + Covariance(motion_.noise(x_, u, dt));
      if (!minus(x_new, x_).allFinite() || !P_new.allFinite()) return FilterStatus::kNonFinite;
      P_new = symmetrised(P_new);
      if (!is_positive_semidefinite(P_new)) return FilterStatus::kNotPositiveDefinite;
      F_ = F;  // recorded for the smoother only when the step is applied
    }
    x_ = x_new;
    P_ = P_new;
    return FilterStatus::kApplied;
  }

  /// Update with the I-th measurement model of the filter, gated by its NIS
  /// gate (set_gate()).
  /// @param[in] z the measurement
  /// @return the status (kApplied, kGated, kNonFinite, kNotPositiveDefinite,
  ///         kNotInitialised) and innovation statistics; the filter is
  ///         unchanged unless kApplied
  template <std::size_t I>
  [[nodiscard]] UpdateResult<SensorType<I>> update(const typename SensorType<I>::Measurement& z) {
    return update_held<I>(z, NoGate{});
  }

  /// Update with the I-th measurement model, gated by its NIS gate *and* by
  /// `gate` (see InnovationGate; a number is a further NIS threshold).
  template <std::size_t I, InnovationGate<SensorType<I>> Gate>
  [[nodiscard]] UpdateResult<SensorType<I>> update(const typename SensorType<I>::Measurement& z,
                                                   const Gate& gate) {
    return update_held<I>(z, gate);
  }

  /// Update with the filter's measurement model of type H (which must occur
  /// exactly once in Sensors...).
  template <class H>
    requires(detail::index_of_v<H, Sensors...> < sizeof...(Sensors))
  [[nodiscard]] UpdateResult<H> update(const typename H::Measurement& z) {
    return update<detail::index_of_v<H, Sensors...>>(z);
  }

  /// Update with any measurement model of this state type, not held by the
  /// filter — e.g. one built per measurement (its noise given with the
  /// reading). Any type is accepted here and checked inside, so a sensor that
  /// is not a posefuse::MeasurementModel is reported by
  /// check_measurement_model()'s sentence naming what it misses.
  /// @param[in] sensor a MeasurementModel whose State is this filter's
  /// @param[in] z      the measurement
  /// @param[in] gate   no gate by default; a number rejects when the NIS
  ///                   exceeds it (see chi_square_quantile); a functor
  ///                   `bool(r, S)` or `bool(r, S, nis)` rejects when it
  ///                   returns false (see InnovationGate)
  /// @return UpdateResult<H>: the status (kApplied, kGated, kNonFinite,
  ///         kNotPositiveDefinite, kNotInitialised) and innovation statistics;
  ///         the filter is unchanged unless kApplied
  template <class H, class Gate = Scalar>
  [[nodiscard]] auto update_with(const H& sensor, const typename detail::measurement_of<H>::type& z,
                                 const Gate& gate = std::numeric_limits<Scalar>::infinity()) {
    constexpr bool is_model = check_measurement_model<H>();
    static_assert(is_model,
                  "posefuse::Ekf::update_with: the sensor is not a posefuse::MeasurementModel "
                  "(see the message above)");
    static_assert(detail::state_matches<H, StateType>(),
                  "posefuse::Ekf::update_with: the sensor's State must be the filter's State "
                  "type (the motion model's State)");
    if constexpr (is_model && detail::state_matches<H, StateType>()) {
      static_assert(InnovationGate<Gate, H>,
                    "posefuse::Ekf::update_with: the gate must be a number (NIS threshold) or "
                    "a functor bool(const Innovation&, const InnovationCovariance&[, Scalar nis])");
      if (!initialised_) return fail(UpdateResult<H>{}, FilterStatus::kNotInitialised);
      Gain<H> g;
      const FilterStatus s = covariance_update(sensor, g);
      if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
      if constexpr (std::is_arithmetic_v<Gate>) {
        return apply_update(sensor, z, static_cast<Scalar>(gate), NoGate{}, g);
      } else {
        return apply_update(sensor, z, std::numeric_limits<Scalar>::infinity(), gate, g);
      }
    } else {
      return FilterStatus::kInvalidInput;  // not reached: a static_assert above failed
    }
  }

  /// update_with() for a sensor type that names no `Measurement`: only
  /// reports (at compile time) what the type misses.
  template <class H, class Z, class Gate = Scalar>
    requires(!requires { typename H::Measurement; })
  auto update_with(const H&, const Z&, const Gate& = std::numeric_limits<Scalar>::infinity()) {
    static_assert(check_measurement_model<H>(),
                  "posefuse::Ekf::update_with: the sensor is not a posefuse::MeasurementModel "
                  "(see the message above)");
    return FilterStatus::kInvalidInput;
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

  /// The state estimate (meaningful once initialised()).
  [[nodiscard]] const StateType& state() const noexcept { return x_; }
  /// Its covariance on the state's tangent space.
  [[nodiscard]] const Covariance& covariance() const noexcept { return P_; }
  /// State and covariance as a Gaussian.
  [[nodiscard]] Belief belief() const { return Belief(x_, P_); }
  /// The state Jacobian F of the last applied prediction (for smoothing).
  [[nodiscard]] const Covariance& last_jacobian() const noexcept { return F_; }
  /// The motion model.
  [[nodiscard]] const Motion& motion() const noexcept { return motion_; }
  /// The I-th measurement model.
  template <std::size_t I>
  [[nodiscard]] const SensorType<I>& sensor() const noexcept {
    return std::get<I>(sensors_);
  }

 private:
  struct NoGate {};

  /// update<I>() with a gate (NoGate, a number or a functor) on top of gates_[I].
  template <std::size_t I, class Gate>
  UpdateResult<SensorType<I>> update_held(const typename SensorType<I>::Measurement& z,
                                          const Gate& gate) {
    using H = SensorType<I>;
    if (!initialised_) return fail(UpdateResult<H>{}, FilterStatus::kNotInitialised);
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
      return apply_update(sensor, z, gates_[I], gate, memo.gain);
    } else {
      Gain<H> g;
      const FilterStatus s = covariance_update(sensor, g);
      if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
      return apply_update(sensor, z, gates_[I], gate, g);
    }
  }

  /// The data-independent part of an update: S, its factorisation, K and the
  /// Joseph-form posterior covariance at the current P.
  template <class H>
  struct Gain {
    using SMat = CovarianceOf<typename H::Measurement>;
    SMat S = SMat::Zero();
    detail::SpdSolver<SMat> S_solver;
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
    const SMat R = measurement_noise(sensor, x_);
    if constexpr (has_identity_jacobian_v<H> && DimOf<typename H::Measurement> == Dim) {
      g.S = P_ + R;
      if (!g.S_solver.compute(g.S)) return FilterStatus::kNotPositiveDefinite;
      g.K = g.S_solver.right_solve(P_);  // K = P S^-1
      const Covariance I_K = Covariance::Identity() - g.K;
      g.P_post = I_K * P_ * I_K.transpose() + g.K * R * g.K.transpose();
    } else {
      const MeasurementJacobianOf<H> J = sensor.jacobian(x_);
      const Eigen::Matrix<Scalar, DimOf<typename H::Measurement>, Dim> JP = J * P_;
      g.S = JP * J.transpose() + R;
      if (!g.S_solver.compute(g.S)) return FilterStatus::kNotPositiveDefinite;
      g.K = g.S_solver.right_solve(
          Eigen::Matrix<Scalar, Dim, DimOf<typename H::Measurement>>(JP.transpose()));  // P J^T S^-1
      const Covariance I_KH = Covariance::Identity() - g.K * J;
      g.P_post = I_KH * P_ * I_KH.transpose() + g.K * R * g.K.transpose();
    }
    if (!g.P_post.allFinite()) return FilterStatus::kNonFinite;
    g.P_post = symmetrised(g.P_post);
    // The Joseph form is PSD in exact arithmetic; with a singular or badly
    // scaled prior, rounding can still give a negative variance. Such a
    // result is refused (core/gaussian.hpp's criterion), never stored.
    if (!is_positive_semidefinite(g.P_post)) return FilterStatus::kNotPositiveDefinite;
    return FilterStatus::kApplied;
  }

  template <class H, class Gate>
  static bool gate_accepts(const Gate& gate, const UpdateResult<H>& r) {
    using Innov = typename UpdateResult<H>::Innovation;
    using InnovCov = typename UpdateResult<H>::InnovationCovariance;
    if constexpr (std::is_same_v<Gate, NoGate>) {
      return true;
    } else if constexpr (std::is_arithmetic_v<Gate>) {
      return r.nis <= static_cast<Scalar>(gate);
    } else if constexpr (std::is_invocable_r_v<bool, const Gate&, const Innov&, const InnovCov&,
                                               Scalar>) {
      return static_cast<bool>(gate(r.innovation, r.S, r.nis));
    } else {
      return static_cast<bool>(gate(r.innovation, r.S));
    }
  }

  template <class H, class Gate>
  UpdateResult<H> apply_update(const H& sensor, const typename H::Measurement& z, Scalar nis_gate,
                               const Gate& gate, const Gain<H>& g) {
    using Z = typename H::Measurement;
    UpdateResult<H> out;
    out.S = g.S;
    out.innovation = minus(z, static_cast<Z>(sensor.predict(x_)));
    if (!out.innovation.allFinite()) return out;  // kNonFinite
    out.nis = g.S_solver.nis(out.innovation);
    if (!(out.nis <= nis_gate)) return fail(out, FilterStatus::kGated);
    if (!gate_accepts<H>(gate, out)) return fail(out, FilterStatus::kGated);
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
  /// (P + P^T) / 2, as P/2 + P^T/2 so that it cannot overflow where P is
  /// finite (halving is exact, so the result is bit-identical otherwise).
  static Covariance symmetrised(const Covariance& P) {
    return Scalar(0.5) * P + Scalar(0.5) * P.transpose();
  }

  Motion motion_;
  std::tuple<Sensors...> sensors_;
  std::tuple<GainMemo<Sensors>...> memos_;
  std::array<Scalar, sizeof...(Sensors) == 0 ? 1 : sizeof...(Sensors)> gates_{};
  StateType x_ = detail::zero_state<StateType>();
  Covariance P_ = Covariance::Identity();
  Covariance F_ = Covariance::Identity();
  bool initialised_ = false;
};

}  // namespace posefuse

#pragma once
/// @file
/// Extended Kalman filter over one motion model and any number of measurement
/// models, all sizes fixed at compile time: BasicEkf, and Ekf, BasicEkf with
/// the default options. This header also provides what a user of the filter
/// names: the options (filters/ekf_options.hpp) and the update's result and
/// gates (filters/ekf_update_result.hpp). The update itself is written once,
/// in filters/detail/ekf_update.hpp.
///
/// Step (Thrun et al., *Probabilistic Robotics*, Table 3.3; seed 000 Fig. 3),
/// written with boxplus so that wrapped states work:
/// \f[ \bar x = f(x, u, \Delta t),\quad \bar P = F P F^\top + Q_f \f]
/// \f[ r = z \boxminus h(\bar x),\quad S = H \bar P H^\top + R_h,\quad
///     K = \bar P H^\top S^{-1} \f]
/// \f[ x = \bar x \boxplus K r,\quad
///     P = (I - K H) \bar P (I - K H)^\top + K R_h K^\top \f]
/// The covariance update is Joseph's form by default (or the standard
/// \f$ (I - K H) \bar P \f$, EkfOptions), computed as one triangle and
/// mirrored, so P stays exactly symmetric, and positive semi-definite under
/// round-off (each result is checked, below). \f$ R_h \f$ is the
/// model's `noise()`, or `noise(x)` at the prior state when the model has it
/// (state-dependent noise, core/concepts.hpp).
///
/// **Solving with S** (core/spd_solver.hpp). For 1x1, 2x2 and 3x3
/// innovations S is tested by Sylvester's criterion and inverted in closed
/// form. Larger
/// ones are factorised, \f$ S = L D L^\top \f$, and K and the NIS
/// \f$ r^\top S^{-1} r \f$ are computed by solving with L; no inverse is
/// formed. Either way S counts as positive definite only when every pivot is
/// above round-off, relative to its own variance, so an indefinite or
/// (numerically) singular S is reported as kNotPositiveDefinite instead of
/// producing a huge gain.
///
/// **Gates.** An update can be rejected by a NIS threshold (per filter-held
/// model, set_gate(), or per call) and/or by a gate functor
/// `bool(const Innovation& r, const InnovationCovariance& S[, Scalar nis])`
/// given to the call, so a caller can gate parts of a measurement separately
/// (e.g. position and heading of a pose); the returned UpdateResult keeps r,
/// S and the NIS, from which the caller can tell which part failed.
///
/// **Compile-time options and structure.** BasicEkf<Options, Motion,
/// Sensors...> takes EkfOptions (covariance form, NIS policy, Jacobian
/// recording for smoothers, steady-state gain memo); Ekf<Motion, Sensors...>
/// uses the defaults. Selection Jacobians (a model's `kSelection`), identity
/// Jacobians and model-supplied covariance propagation (`propagate`) are
/// used at compile time; see BasicEkf.
///
/// **Before reset().** A filter constructed without a belief has none:
/// predict() and every update return FilterStatus::kNotInitialised and change
/// nothing until reset() is called (initialised()).
///
/// Naming: posefuse calls a model's noise `noise()`. Seed 000 follows Thrun
/// and calls process noise R and measurement noise Q; the models that
/// reproduce it (planar_displacement.hpp, position.hpp) keep that naming in
/// their parameters.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/detail/ekf_update.hpp>
#include <posefuse/filters/ekf_options.hpp>
#include <posefuse/filters/ekf_update_result.hpp>
#include <tuple>
#include <type_traits>
#include <utility>

namespace posefuse {

namespace detail {
/// The index of T in Ts..., or sizeof...(Ts) unless T occurs exactly once.
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

/// An EKF over `Motion` with measurement models `Sensors...` and
/// compile-time options `Options` (EkfOptions or a type derived from it);
/// `Ekf<Motion, Sensors...>` is the usual spelling with the default options.
///
/// **Structure used at compile time** (each declared by the model, each
/// checked against the model's own Jacobian by testing/conformance.hpp):
/// `kIdentityJacobian` skips products with F or H; a measurement model's
/// `kSelection` (has_selection_v) makes the update read rows and columns of
/// P instead of multiplying by H (also inside the Joseph form); a motion
/// model's `propagate(P, x, u, dt)` (HasPropagate) or its linearisation's
/// `propagate(P)` (HasLinearizePropagate) replaces \f$ F P F^\top \f$.
/// Symmetric results are computed as one triangle and mirrored, so P is
/// exactly symmetric after every applied step.
///
/// **Safety at one check per result**: every applied step's covariance
/// passed is_positive_semidefinite() (core/definiteness.hpp), which also
/// refuses NaN and Inf; the state and the innovation are checked for
/// finiteness. A refused step returns its status and leaves the filter
/// bit-identical.
/// @tparam Options an EkfOptionSet
/// @tparam Motion  a posefuse::MotionModel
/// @tparam Sensors posefuse::MeasurementModel's with the same State
template <class Options, class Motion, class... Sensors>
class BasicEkf {
  static_assert(EkfOptionSet<Options>,
                "posefuse::BasicEkf: Options must name kCovarianceUpdate, kNis, "
                "kRecordJacobian and kGainMemo (derive it from posefuse::EkfOptions)");
  static_assert(check_motion_model<Motion>(), "posefuse::Ekf: see the message above");
  static_assert((check_measurement_model<Sensors>() && ...),
                "posefuse::Ekf: see the message above");
  static_assert((std::is_same_v<typename Sensors::State, typename Motion::State> && ...),
                "posefuse::Ekf: every measurement model must have the motion model's State type");

 public:
  using OptionsType = Options;
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
  explicit BasicEkf(Motion motion, Sensors... sensors)
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
    StateType x_new = detail::zero_state<StateType>();
    Covariance P_new;
    [[maybe_unused]] Covariance F_new;  // recorded for the smoother (kRecordJacobian)
    const FilterStatus s = predict_unchecked(u, dt, x_new, P_new, F_new);
    if (s != FilterStatus::kApplied) return s;
    // Refuses NaN and Inf too; the finiteness pass runs only to name the failure.
    if (!detail::psd_accepts(P_new)) return detail::refused_covariance_status(P_new);
    commit(x_new, P_new, F_new);
    return FilterStatus::kApplied;
  }

  /// One whole step: predict(u, dt), then update<0>(z_0), ...,
  /// update<N-1>(z_{N-1}) with the N held measurement models in order, with
  /// the same statuses and, bit for bit, the same belief as those calls
  /// (checked by tests/filters/test_ekf_step.cpp), but at one covariance
  /// check less: the belief is carried between them in locals, and the
  /// predicted covariance \f$ \bar P \f$ is not checked on its own when
  /// the first update applies, because that update's checked posterior
  /// certifies it:
  ///
  /// **Why the check of \f$ \bar P \f$ is implied.** An applied update has
  /// S = H P̄ Hᵀ + R positive definite (SpdSolver) and R PSD (every model's
  /// noise is validated), and forms, with the gain computed from P̄, the
  /// posterior \f$ P^+ = \bar P - \bar P H^\top S^{-1} H \bar P \f$ (the
  /// Joseph form equals it for that gain). (1) The congruence
  /// \f$ \begin{bmatrix} I & -H \\ 0 & I \end{bmatrix}
  /// \begin{bmatrix} S & H\bar P \\ \bar P H^\top & \bar P \end{bmatrix}
  /// \begin{bmatrix} I & 0 \\ -H^\top & I \end{bmatrix} =
  /// \begin{bmatrix} R & 0 \\ 0 & \bar P \end{bmatrix} \f$ and Haynsworth's
  /// inertia additivity for the Schur complement of S give
  /// \f$ \mathrm{In}(P^+) = \mathrm{In}(R) + \mathrm{In}(\bar P) -
  /// \mathrm{In}(S) \f$: \f$ P^+ \f$ has exactly as many negative eigenvalues as
  /// \f$ \bar P \f$. (2) Quantitatively, \f$ P^+ \preceq \bar P \f$ (the
  /// subtracted term is PSD) and every variance shrinks, so for any w with
  /// \f$ w^\top \bar P w < 0 \f$, \f$ w^\top P^+ w / w^\top D^+ w \le
  /// w^\top \bar P w / w^\top \bar D w \f$ (D the diagonal): P̄'s most negative
  /// direction is at least as negative in the scale-free form of \f$ P^+ \f$,
  /// the form is_positive_semidefinite() judges. Hence a P̄ that the check
  /// would refuse yields a posterior the check refuses, and an accepted
  /// posterior stands for both checks. (In floating point, only a P̄ refused
  /// by less than the update's own round-off, relative to the posterior's
  /// variances, could pass; predict()'s decision there is itself a round-off
  /// decision.) When the first update does not apply (gated, refused), P̄ is
  /// checked on its own; if it is refused the step continues as the separate
  /// calls do: the prediction is refused and the updates run on the belief
  /// before the step.
  /// @param[in] u  control input
  /// @param[in] dt time step (s), finite and >= 0
  /// @param[in] z  one measurement per held measurement model, in order
  /// @return the prediction's status and every update's UpdateResult
  [[nodiscard]] EkfStepResult<Sensors...> step(const Control& u, Scalar dt,
                                               const typename Sensors::Measurement&... z)
    requires(sizeof...(Sensors) > 0)
  {
    return step_impl(std::index_sequence_for<Sensors...>{}, u, dt, z...);
  }

  /// Update with the I-th measurement model of the filter, gated by its NIS
  /// gate (set_gate()).
  /// @param[in] z the measurement
  /// @return the status (kApplied, kGated, kNonFinite, kNotPositiveDefinite,
  ///         kNotInitialised) and innovation statistics; the filter is
  ///         unchanged unless kApplied
  template <std::size_t I>
  [[nodiscard, gnu::always_inline]] UpdateResult<SensorType<I>> update(
      const typename SensorType<I>::Measurement& z) {
    return update_held<I>(z, NoGate{});
  }

  /// Update with the I-th measurement model, gated by its NIS gate *and* by
  /// `gate` (see InnovationGate; a number is a further NIS threshold).
  template <std::size_t I, InnovationGate<SensorType<I>> Gate>
  [[nodiscard, gnu::always_inline]] UpdateResult<SensorType<I>> update(const typename SensorType<I>::Measurement& z,
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
  [[nodiscard, gnu::always_inline]] auto update_with(const H& sensor, const typename detail::measurement_of<H>::type& z,
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
      if (!initialised_) return detail::with_status(UpdateResult<H>{}, FilterStatus::kNotInitialised);
      if constexpr (std::is_arithmetic_v<Gate>) {
        return detail::update_afresh<Options>(sensor, z, static_cast<Scalar>(gate), NoGate{}, x_, P_);
      } else {
        return detail::update_afresh<Options>(sensor, z, std::numeric_limits<Scalar>::infinity(), gate,
                                              x_, P_);
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
  /// The state Jacobian F of the last applied prediction (for smoothing;
  /// only with Options::kRecordJacobian).
  [[nodiscard]] const Covariance& last_jacobian() const noexcept
    requires(Options::kRecordJacobian)
  {
    return F_;
  }
  /// The motion model.
  [[nodiscard]] const Motion& motion() const noexcept { return motion_; }
  /// The I-th measurement model.
  template <std::size_t I>
  [[nodiscard]] const SensorType<I>& sensor() const noexcept {
    return std::get<I>(sensors_);
  }

 private:
  template <class H>
  using GainMemo = detail::EkfGainMemo<H>;
  using NoGate = detail::NoGate;

  /// The prediction of predict() into x_new, P_new (both triangles) and,
  /// with kRecordJacobian, F_new, checked for everything but P_new's
  /// definiteness. @return kApplied, kInvalidInput or kNonFinite
  [[gnu::always_inline]] FilterStatus predict_unchecked(const Control& u, Scalar dt, StateType& x_new,
                                                        Covariance& P_new,
                                                        [[maybe_unused]] Covariance& F_new) const {
    if (!std::isfinite(dt)) return FilterStatus::kNonFinite;
    if (dt < Scalar(0)) return FilterStatus::kInvalidInput;
    if constexpr (has_identity_jacobian_v<Motion>) {
      x_new = motion_.predict(x_, u, dt);
      // P is exactly symmetric, so P + Q is unless Q is not: mirror only then
      // (the whole sum stays in vector registers otherwise).
      P_new = P_ + Covariance(motion_.noise(x_, u, dt));
      if (!exactly_symmetric(P_new)) [[unlikely]]
        detail::mirror_lower(P_new);
    } else if constexpr (HasLinearize<Motion>) {
      // One model call (see HasLinearize, core/concepts.hpp).
      const auto lin = motion_.linearize(x_, u, dt);
      x_new = lin.state;
      if constexpr (HasLinearizePropagate<Motion>) {
        P_new = Covariance(lin.propagate(P_)) + Covariance(lin.noise);
      } else {
        P_new = sandwich(Covariance(lin.jacobian), Covariance(lin.noise));
      }
      if constexpr (Options::kRecordJacobian) F_new = lin.jacobian;
    } else if constexpr (HasPropagate<Motion>) {
      x_new = motion_.predict(x_, u, dt);
      P_new = Covariance(motion_.propagate(P_, x_, u, dt)) + Covariance(motion_.noise(x_, u, dt));
      if constexpr (Options::kRecordJacobian) F_new = motion_.jacobian(x_, u, dt);
    } else {
      x_new = motion_.predict(x_, u, dt);
      const Covariance F = motion_.jacobian(x_, u, dt);
      P_new = sandwich(F, Covariance(motion_.noise(x_, u, dt)));
      if constexpr (Options::kRecordJacobian) F_new = F;
    }
    if (!detail::all_entries_finite(minus(x_new, x_))) return FilterStatus::kNonFinite;
    if constexpr (!has_identity_jacobian_v<Motion>) detail::mirror_lower(P_new);
    return FilterStatus::kApplied;
  }
  /// Stores an applied prediction (or a whole applied step).
  [[gnu::always_inline]] void commit(const StateType& x, const Covariance& P,
                                     [[maybe_unused]] const Covariance& F) {
    if constexpr (Options::kRecordJacobian && !has_identity_jacobian_v<Motion>) F_ = F;
    x_ = x;
    P_ = P;
  }

  /// step() with the sensors' indices.
  template <std::size_t... I>
  [[gnu::always_inline]] EkfStepResult<Sensors...> step_impl(std::index_sequence<I...>, const Control& u,
                                                             Scalar dt,
                                                             const typename Sensors::Measurement&... z) {
    EkfStepResult<Sensors...> out;
    if (!initialised_) {
      out.predict = FilterStatus::kNotInitialised;
      ((std::get<I>(out.updates).status = FilterStatus::kNotInitialised), ...);
      return out;
    }
    StateType x = detail::zero_state<StateType>();
    Covariance P;
    [[maybe_unused]] Covariance F;
    out.predict = predict_unchecked(u, dt, x, P, F);
    if (out.predict == FilterStatus::kApplied) {
      bool unchecked = true;  // P still the predicted covariance, not checked
      (step_update<I>(z, x, P, unchecked, out), ...);
      if (out.predict == FilterStatus::kApplied) {
        commit(x, P, F);
        return out;
      }
    }
    // The prediction was refused: the updates act on the belief before the step.
    ((std::get<I>(out.updates) = update_held<I>(z, NoGate{})), ...);
    return out;
  }
  /// The I-th update of step() on the carried belief (x, P); checks the
  /// predicted covariance when the first update does not apply (step()).
  template <std::size_t I>
  [[gnu::always_inline]] void step_update(const typename SensorType<I>::Measurement& z, StateType& x,
                                          Covariance& P, bool& unchecked, EkfStepResult<Sensors...>& out) {
    if (out.predict != FilterStatus::kApplied) return;
    auto& r = std::get<I>(out.updates);
    r = update_held_on<I>(z, NoGate{}, x, P);
    if (unchecked) {
      unchecked = false;
      if (r.status != FilterStatus::kApplied && !detail::psd_accepts(P))
        out.predict = detail::refused_covariance_status(P);
    }
  }

  /// update<I>() with a gate (NoGate, a number or a functor) on top of gates_[I].
  template <std::size_t I, class Gate>
  [[gnu::always_inline]] UpdateResult<SensorType<I>> update_held(
      const typename SensorType<I>::Measurement& z, const Gate& gate) {
    using H = SensorType<I>;
    if (!initialised_) return detail::with_status(UpdateResult<H>{}, FilterStatus::kNotInitialised);
    return update_held_on<I>(z, gate, x_, P_);
  }
  /// update_held() on the belief (x, P), changed only when the update applies.
  template <std::size_t I, class Gate>
  [[gnu::always_inline]] UpdateResult<SensorType<I>> update_held_on(
      const typename SensorType<I>::Measurement& z, const Gate& gate, StateType& x, Covariance& P) {
    using H = SensorType<I>;
    const H& sensor = std::get<I>(sensors_);
    if constexpr (Options::kGainMemo && is_time_invariant_v<H>) {
      // The gain half depends on P alone: reuse it while P repeats (a
      // converged, steady-state filter), bit for bit what it would compute.
      GainMemo<H>& memo = std::get<I>(memos_);
      if (!memo.recorded || !detail::same_values(memo.P_in, P)) {
        // A new prior. Record it whole only when its first and last
        // variances repeat those of the prior before (a candidate steady
        // state), else just those two numbers: a filter whose P keeps
        // changing pays two comparisons and two stores per update.
        memo.valid = false;
        memo.recorded = memo.first == P(0, 0) && memo.last == P(Dim - 1, Dim - 1);
        if (memo.recorded) memo.P_in = P;
        memo.first = P(0, 0);
        memo.last = P(Dim - 1, Dim - 1);
        return detail::update_afresh<Options>(sensor, z, gates_[I], gate, x, P);
      }
      if (!memo.valid) {
        const FilterStatus s = detail::compute_gain<Options>(sensor, x, P, memo.gain);
        if (s != FilterStatus::kApplied) return detail::with_status(UpdateResult<H>{}, s);
        memo.valid = true;
      }
      return detail::apply_gain<Options>(sensor, z, gates_[I], gate, memo.gain, x, P);
    } else {
      return detail::update_afresh<Options>(sensor, z, gates_[I], gate, x, P);
    }
  }

  /// \f$ F P F^\top + Q \f$, lower triangle only (mirror_lower() completes it).
  [[gnu::always_inline]] Covariance sandwich(const Covariance& F, const Covariance& Q) const {
    const Covariance FP = F.lazyProduct(P_);
    Covariance out;
    for (int j = 0; j < Dim; ++j)
      for (int i = j; i < Dim; ++i) out(i, j) = Q(i, j) + FP.row(i).dot(F.row(j));
    return out;
  }
  /// True when every entry equals (==) its mirror image.
  [[gnu::always_inline]] static bool exactly_symmetric(const Covariance& P) noexcept {
    bool same = true;
    for (int j = 0; j < Dim; ++j)
      for (int i = j + 1; i < Dim; ++i) same &= P(i, j) == P(j, i);
    return same;
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

/// The EKF with the default options (EkfOptions): Joseph form, NIS always,
/// Jacobians recorded, gain memo on. See BasicEkf.
template <class Motion, class... Sensors>
using Ekf = BasicEkf<EkfOptions, Motion, Sensors...>;

/// The EKF with the lean options (LeanEkfOptions): standard form, NIS only
/// when gated, no Jacobian record; the checks of every stored result kept.
template <class Motion, class... Sensors>
using LeanEkf = BasicEkf<LeanEkfOptions, Motion, Sensors...>;

}  // namespace posefuse

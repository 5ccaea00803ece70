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
/// The covariance update is Joseph's form by default (or the standard
/// \f$ (I - K H) \bar P \f$, EkfOptions), computed as one triangle and
/// mirrored, so P stays exactly symmetric, and positive semi-definite under
/// round-off (each result is checked, below). \f$ R_h \f$ is the
/// model's `noise()`, or `noise(x)` at the prior state when the model has it
/// (state-dependent noise, core/concepts.hpp).
///
/// **Solving with S** (core/spd_solver.hpp). For 1x1 and 2x2 innovations S is tested by
/// Sylvester's criterion and inverted in closed form (a few flops). Larger
/// ones are factorised, \f$ S = L D L^\top \f$ (no square roots), and K and the NIS
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
/// **Compile-time options and structure.** BasicEkf<Options, Motion,
/// Sensors...> takes EkfOptions (covariance form, NIS policy, Jacobian
/// recording for smoothers, steady-state gain memo); Ekf<Motion, Sensors...>
/// uses the defaults. Selection Jacobians (`kSelection`), identity
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
#include <cstdint>
#include <limits>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/core/spd_solver.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/ekf_options.hpp>
#include <posefuse/filters/ekf_update_result.hpp>
#include <tuple>
#include <type_traits>

namespace posefuse {


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
/// passed is_positive_semidefinite() (core/gaussian.hpp), which also
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
    if (!std::isfinite(dt)) return FilterStatus::kNonFinite;
    if (dt < Scalar(0)) return FilterStatus::kInvalidInput;
    StateType x_new = detail::zero_state<StateType>();
    Covariance P_new;
    [[maybe_unused]] Covariance F_new;  // recorded for the smoother (kRecordJacobian)
    if constexpr (has_identity_jacobian_v<Motion>) {
      x_new = motion_.predict(x_, u, dt);
      // P is exactly symmetric, so P + Q is unless Q is not: mirror only then
      // (the whole sum stays in vector registers otherwise).
      P_new = P_ + Covariance(motion_.noise(x_, u, dt));
      if (!exactly_symmetric(P_new)) [[unlikely]]
        mirror_lower(P_new);
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
    if (!finite(minus(x_new, x_))) return FilterStatus::kNonFinite;
    if constexpr (!has_identity_jacobian_v<Motion>) mirror_lower(P_new);
    // Refuses NaN and Inf too; the finiteness pass runs only to name the failure.
    if (!psd_accepts(P_new))
      return P_new.allFinite() ? FilterStatus::kNotPositiveDefinite : FilterStatus::kNonFinite;
    if constexpr (Options::kRecordJacobian && !has_identity_jacobian_v<Motion>) F_ = F_new;
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
  struct NoGate {};

  /// update<I>() with a gate (NoGate, a number or a functor) on top of gates_[I].
  template <std::size_t I, class Gate>
  [[gnu::always_inline]] UpdateResult<SensorType<I>> update_held(const typename SensorType<I>::Measurement& z,
                                          const Gate& gate) {
    using H = SensorType<I>;
    if (!initialised_) return fail(UpdateResult<H>{}, FilterStatus::kNotInitialised);
    const H& sensor = std::get<I>(sensors_);
    if constexpr (kSmallSelection<H>) {
      if constexpr (Options::kGainMemo && is_time_invariant_v<H>) {
        GainMemo<H>& memo = std::get<I>(memos_);
        if (same_values(memo.P_in, P_)) {
          if (memo.valid) return apply_update(sensor, z, gates_[I], gate, memo.gain);
          return small_selection_step(sensor, z, gates_[I], gate, &memo);
        }
        remember_prior(memo);
        return small_selection_step(sensor, z, gates_[I], gate, static_cast<GainMemo<H>*>(nullptr));
      } else {
        return small_selection_step(sensor, z, gates_[I], gate, static_cast<GainMemo<H>*>(nullptr));
      }
    } else if constexpr (Options::kGainMemo && is_time_invariant_v<H>) {
      // The covariance part depends on P alone: reuse it while P repeats
      // (a converged, steady-state filter), bit for bit what it would compute.
      GainMemo<H>& memo = std::get<I>(memos_);
      if (!same_values(memo.P_in, P_)) {
        remember_prior(memo);
        Gain<H> g;
        const FilterStatus s = covariance_update(sensor, g);
        if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
        return apply_update(sensor, z, gates_[I], gate, g);
      }
      if (!memo.valid) {
        const FilterStatus s = covariance_update(sensor, memo.gain);
        if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
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
  /// The steady-state memo of one measurement model. A gain is kept only for
  /// a prior P seen twice in a row: an update whose P differs from P_in just
  /// records it (no gain copied, so a filter whose P keeps changing pays one
  /// comparison and one copy of P per update); the next update with the same
  /// P computes the gain into the memo; later ones with that P reuse it.
  template <class H>
  struct GainMemo {
    bool valid = false;  ///< gain holds the update for P_in
    Covariance P_in = Covariance::Constant(std::numeric_limits<Scalar>::quiet_NaN());
    Gain<H> gain;
  };
  /// Records P as the memo's prior, with no gain yet.
  template <class H>
  [[gnu::always_inline]] void remember_prior(GainMemo<H>& memo) const noexcept {
    memo.valid = false;
    memo.P_in = P_;
  }

  /// The state components a measurement model selects, when its Jacobian is
  /// a selection: H = I (kIdentityJacobian with Measurement::Dim == Dim) or
  /// its declared kSelection.
  template <class H>
  static constexpr bool kSelects =
      (has_identity_jacobian_v<H> && DimOf<typename H::Measurement> == Dim) || has_selection_v<H>;
  template <class H>
  static constexpr std::array<int, std::size_t(DimOf<typename H::Measurement>)> selection() {
    if constexpr (has_selection_v<H>) {
      return H::kSelection;
    } else {
      std::array<int, std::size_t(DimOf<typename H::Measurement>)> s{};
      for (std::size_t i = 0; i < s.size(); ++i) s[i] = int(i);
      return s;
    }
  }

  /// The covariance half of an update for a selection H with one or two
  /// rows, on scalars (kept in registers): S, then \f$ U = P H^\top
  /// \mathrm{adj}(S) \f$ and \f$ W = U S U^\top \f$ while \f$ g = 1 / \det S \f$ is
  /// still being divided, so that the division is the only step between S
  /// and the posterior. \f$ K = g U \f$ (= P Hᵀ S⁻¹), and Joseph's form
  /// expanded for a symmetric P, \f$ (I - K H) P (I - K H)^\top + K R K^\top =
  /// P - K H P - P H^\top K^\top + K S K^\top \f$ (each term a function of the
  /// computed K, so an error in K still enters only to second order), one
  /// triangle: \f$ P^+_{ij} = P_{ij} - g\,(U_i \cdot B_j + B_i \cdot U_j) + g^2
  /// W_{ij} \f$, B = P Hᵀ. kStandard: \f$ P_{ij} - g\, U_i \cdot B_j \f$. The
  /// positive-definiteness criterion of S and its closed-form inverse are
  /// detail::SpdSolver's for sizes 1 and 2.
  template <class H>
  struct SmallSelection {
    static constexpr int M = DimOf<typename H::Measurement>;
    Scalar S[M][M];    ///< innovation covariance
    Scalar inv[M][M];  ///< S⁻¹ = adj(S) / det S
    Scalar rd;         ///< 1 / det S
    Scalar K[Dim][M];  ///< gain
    Covariance P_post;
  };
  template <class H>
  [[gnu::always_inline]] FilterStatus small_selection_covariance(const H& sensor,
                                                                 SmallSelection<H>& o) const {
    constexpr int M = SmallSelection<H>::M;
    constexpr std::array<int, std::size_t(M)> sel = selection<H>();
    const auto R = measurement_noise(sensor, x_);
    Scalar B[Dim][M];  // P H^T: the selected columns of P
    for (int i = 0; i < Dim; ++i)
      for (int a = 0; a < M; ++a) B[i][a] = P_(i, sel[std::size_t(a)]);
    auto& S = o.S;
    for (int a = 0; a < M; ++a)
      for (int b = 0; b < M; ++b) S[a][b] = B[sel[std::size_t(a)]][b] + R(a, b);
    Scalar U[Dim][M];  // P H^T adj(S)
    if constexpr (M == 1) {
      for (int i = 0; i < Dim; ++i) U[i][0] = B[i][0];
      if (!(S[0][0] > Scalar(0))) return FilterStatus::kNotPositiveDefinite;
      o.rd = Scalar(1) / S[0][0];
      o.inv[0][0] = o.rd;
    } else {
      for (int i = 0; i < Dim; ++i) {
        U[i][0] = B[i][0] * S[1][1] - B[i][1] * S[1][0];
        U[i][1] = B[i][1] * S[0][0] - B[i][0] * S[0][1];
      }
      const Scalar det = S[0][0] * S[1][1] - S[0][1] * S[1][0];
      if (!(S[0][0] > Scalar(0) &&
            det > Scalar(2) * std::numeric_limits<Scalar>::epsilon() * S[0][0] * S[1][1]))
        return FilterStatus::kNotPositiveDefinite;
      o.rd = Scalar(1) / det;
      o.inv[0][0] = S[1][1] * o.rd;
      o.inv[1][1] = S[0][0] * o.rd;
      o.inv[0][1] = -S[0][1] * o.rd;
      o.inv[1][0] = -S[1][0] * o.rd;
    }
    const Scalar rd = o.rd;
    for (int i = 0; i < Dim; ++i)
      for (int a = 0; a < M; ++a) o.K[i][a] = rd * U[i][a];
    Covariance& P_post = o.P_post;
    if constexpr (Options::kCovarianceUpdate == CovarianceUpdate::kStandard) {
      for (int j = 0; j < Dim; ++j)
        for (int i = j; i < Dim; ++i) {
          Scalar c = U[i][0] * B[j][0];
          for (int a = 1; a < M; ++a) c += U[i][a] * B[j][a];
          const Scalar v = P_(i, j) - rd * c;
          P_post(i, j) = v;
          P_post(j, i) = v;
        }
    } else {
      Scalar V[Dim][M];  // U S
      for (int i = 0; i < Dim; ++i)
        for (int b = 0; b < M; ++b) {
          Scalar v = U[i][0] * S[0][b];
          for (int a = 1; a < M; ++a) v += U[i][a] * S[a][b];
          V[i][b] = v;
        }
      const Scalar rd2 = rd * rd;
      for (int j = 0; j < Dim; ++j)
        for (int i = j; i < Dim; ++i) {
          Scalar c = U[i][0] * B[j][0] + B[i][0] * U[j][0];
          Scalar w = V[i][0] * U[j][0];
          for (int a = 1; a < M; ++a) {
            c += U[i][a] * B[j][a] + B[i][a] * U[j][a];
            w += V[i][a] * U[j][a];
          }
          const Scalar v = (P_(i, j) - rd * c) + rd2 * w;
          P_post(i, j) = v;
          P_post(j, i) = v;
        }
    }
    if (!psd_accepts(P_post))
      return P_post.allFinite() ? FilterStatus::kNotPositiveDefinite : FilterStatus::kNonFinite;
    return FilterStatus::kApplied;
  }

  /// covariance_update() for a selection H with one or two rows:
  /// small_selection_covariance() into a Gain.
  template <class H>
  [[gnu::always_inline]] FilterStatus small_selection_update(const H& sensor, Gain<H>& g) const {
    SmallSelection<H> o;
    const FilterStatus s = small_selection_covariance(sensor, o);
    if (s != FilterStatus::kApplied) return s;
    store_gain(o, g);
    return FilterStatus::kApplied;
  }
  template <class H>
  [[gnu::always_inline]] static void store_gain(const SmallSelection<H>& o, Gain<H>& g) noexcept {
    constexpr int M = SmallSelection<H>::M;
    for (int a = 0; a < M; ++a)
      for (int b = 0; b < M; ++b) g.S(a, b) = o.S[a][b];
    g.S_solver.set_closed_form(o.inv, o.rd);
    for (int i = 0; i < Dim; ++i)
      for (int a = 0; a < M; ++a) g.K(i, a) = o.K[i][a];
    g.P_post = o.P_post;
  }

  /// Measurement models whose update takes small_selection_step().
  template <class H>
  static constexpr bool kSmallSelection = kSelects<H> && DimOf<typename H::Measurement> <= 2;

  /// The whole update (covariance_update() + apply_update()) for a selection
  /// H with one or two rows, on local scalars: small_selection_covariance()
  /// and apply_update()'s formulas, the same results and diagnostics, without
  /// the intermediate Gain object. With a memo, fills it as
  /// covariance_update() would.
  template <class H, class Gate>
  [[gnu::always_inline]] UpdateResult<H> small_selection_step(const H& sensor,
                                                              const typename H::Measurement& z,
                                                              Scalar nis_gate, const Gate& gate,
                                                              GainMemo<H>* memo) {
    using Z = typename H::Measurement;
    constexpr int M = DimOf<Z>;
    SmallSelection<H> o;
    const FilterStatus s = small_selection_covariance(sensor, o);
    if (s != FilterStatus::kApplied) return fail(UpdateResult<H>{}, s);
    const auto& inv = o.inv;
    const auto& K = o.K;
    UpdateResult<H> out;
    for (int a = 0; a < M; ++a)
      for (int b = 0; b < M; ++b) out.S(a, b) = o.S[a][b];
    if (memo) {  // P_ is memo->P_in
      store_gain(o, memo->gain);
      memo->valid = true;
    }
    out.innovation = minus(z, static_cast<Z>(sensor.predict(x_)));
    if (!finite(out.innovation)) return out;  // kNonFinite
    if (needs_nis<H, Gate>(nis_gate)) {
      // detail::SpdSolver::nis() for sizes 1 and 2, term for term.
      const auto& r = out.innovation;
      if constexpr (M == 1) {
        out.nis = r(0) * (inv[0][0] * r(0));
      } else {
        out.nis = r(0) * (inv[0][0] * r(0) + inv[0][1] * r(1)) +
                  r(1) * (inv[1][0] * r(0) + inv[1][1] * r(1));
      }
      if (!(out.nis <= nis_gate)) return fail(out, FilterStatus::kGated);
    }
    if (!gate_accepts<H>(gate, out)) return fail(out, FilterStatus::kGated);
    TangentOf<StateType> dx;
    for (int i = 0; i < Dim; ++i) {
      Scalar v = K[i][0] * out.innovation(0);
      for (int a = 1; a < M; ++a) v += K[i][a] * out.innovation(a);
      dx(i) = v;
    }
    const StateType x_new = plus(x_, dx);
    if (!finite(minus(x_new, x_))) return fail(out, FilterStatus::kNonFinite);
    x_ = x_new;
    P_ = o.P_post;
    out.status = FilterStatus::kApplied;
    return out;
  }

  /// is_positive_semidefinite(), with its fast path inlined for small sizes
  /// and the reference out of line (same decisions).
  [[gnu::always_inline]] static bool psd_accepts(const Covariance& P) {
    if constexpr (Dim <= 4) {
      if (detail::psd_fast_accepts(P)) [[likely]]
        return true;
      return psd_reference_cold(P);
    } else {
      return is_positive_semidefinite(P);
    }
  }
  [[gnu::noinline, gnu::cold]] static bool psd_reference_cold(const Covariance& P) {
    return detail::psd_reference(P, false);
  }

  template <class H>
  [[gnu::always_inline]] FilterStatus covariance_update(const H& sensor, Gain<H>& g) const {
    constexpr int M = DimOf<typename H::Measurement>;
    if constexpr (kSelects<H> && M <= 2) {
      return small_selection_update(sensor, g);
    }
    using SMat = typename Gain<H>::SMat;
    using HP = Eigen::Matrix<Scalar, M, Dim>;
    using Nm = Eigen::Matrix<Scalar, Dim, M>;
    const SMat R = measurement_noise(sensor, x_);
    HP JP;  // H P, which is (P H^T)^T for the symmetric P
    [[maybe_unused]] MeasurementJacobianOf<H> J;
    if constexpr (kSelects<H>) {
      constexpr std::array<int, std::size_t(M)> sel = selection<H>();
      for (int a = 0; a < M; ++a) {
        JP.row(a) = P_.row(sel[std::size_t(a)]);
        for (int b = 0; b < M; ++b)
          g.S(a, b) = P_(sel[std::size_t(a)], sel[std::size_t(b)]) + R(a, b);
      }
    } else {
      J = sensor.jacobian(x_);
      JP = J * P_;
      g.S = JP * J.transpose() + R;
    }
    if (!g.S_solver.compute(g.S)) return FilterStatus::kNotPositiveDefinite;
    g.K = g.S_solver.right_solve(Nm(JP.transpose()));  // P H^T S^-1
    const Covariance A = P_ - g.K.lazyProduct(JP);      // (I - K H) P
    if constexpr (Options::kCovarianceUpdate == CovarianceUpdate::kStandard) {
      g.P_post = A;
      mirror_lower(g.P_post);
    } else {
      // Joseph: A (I - K H)^T + K R K^T = A + (K R - A H^T) K^T, one triangle.
      Nm AHt;
      if constexpr (kSelects<H>) {
        constexpr std::array<int, std::size_t(M)> sel = selection<H>();
        for (int a = 0; a < M; ++a) AHt.col(a) = A.col(sel[std::size_t(a)]);
      } else {
        AHt = A * J.transpose();
      }
      const Nm C = g.K.lazyProduct(R) - AHt;
      for (int j = 0; j < Dim; ++j) {
        for (int i = j; i < Dim; ++i) {
          Scalar v = A(i, j);
          for (int k = 0; k < M; ++k) v += C(i, k) * g.K(j, k);
          g.P_post(i, j) = v;
          g.P_post(j, i) = v;
        }
      }
    }
    // The Joseph form is PSD in exact arithmetic; with a singular or badly
    // scaled prior, rounding can still give a negative variance. Such a
    // result is refused (core/gaussian.hpp's criterion, which also refuses
    // NaN and Inf), never stored.
    if (!psd_accepts(g.P_post))
      return g.P_post.allFinite() ? FilterStatus::kNotPositiveDefinite : FilterStatus::kNonFinite;
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
  [[gnu::always_inline, gnu::flatten]] UpdateResult<H> apply_update(const H& sensor, const typename H::Measurement& z, Scalar nis_gate,
                               const Gate& gate, const Gain<H>& g) {
    using Z = typename H::Measurement;
    UpdateResult<H> out;
    out.S = g.S;
    out.innovation = minus(z, static_cast<Z>(sensor.predict(x_)));
    if (!finite(out.innovation)) return out;  // kNonFinite
    if (needs_nis<H, Gate>(nis_gate)) {
      out.nis = g.S_solver.nis(out.innovation);
      if (!(out.nis <= nis_gate)) return fail(out, FilterStatus::kGated);
    }
    if (!gate_accepts<H>(gate, out)) return fail(out, FilterStatus::kGated);
    const StateType x_new = plus(x_, TangentOf<StateType>(g.K * out.innovation));
    if (!finite(minus(x_new, x_))) return fail(out, FilterStatus::kNonFinite);
    x_ = x_new;
    P_ = g.P_post;
    out.status = FilterStatus::kApplied;
    return out;
  }

  /// Whether an update computes its NIS (Options::kNis).
  template <class H, class Gate>
  static bool needs_nis(Scalar nis_gate) noexcept {
    if constexpr (Options::kNis == NisPolicy::kAlways) {
      return true;
    } else {
      using Innov = typename UpdateResult<H>::Innovation;
      using InnovCov = typename UpdateResult<H>::InnovationCovariance;
      if constexpr (std::is_arithmetic_v<Gate> ||
                    std::is_invocable_r_v<bool, const Gate&, const Innov&, const InnovCov&, Scalar>) {
        return true;
      } else {
        return nis_gate < std::numeric_limits<Scalar>::infinity();
      }
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
  /// Every entry equal (==) to the other's.
  [[gnu::always_inline]] static bool same_values(const Covariance& a, const Covariance& b) noexcept {
    for (int i = 0; i < Dim * Dim; ++i)
      if (a.data()[i] != b.data()[i]) return false;
    return true;
  }
  /// True when every entry is finite, in one branch-free pass: v - v is 0
  /// for a finite entry and NaN for NaN or Inf.
  template <int N>
  [[gnu::always_inline]] static bool finite(const Eigen::Matrix<Scalar, N, 1>& v) noexcept {
    Scalar s = Scalar(0);
    for (int i = 0; i < N; ++i) s += v(i) - v(i);
    return s == Scalar(0);
  }
  /// True when every entry equals (==) its mirror image.
  [[gnu::always_inline]] static bool exactly_symmetric(const Covariance& P) noexcept {
    bool same = true;
    for (int j = 0; j < Dim; ++j)
      for (int i = j + 1; i < Dim; ++i) same &= P(i, j) == P(j, i);
    return same;
  }
  /// Copies the lower triangle onto the upper one (exactly symmetric; no arithmetic).
  [[gnu::always_inline]] static void mirror_lower(Covariance& P) noexcept {
    for (int j = 0; j < Dim; ++j)
      for (int i = j + 1; i < Dim; ++i) P(j, i) = P(i, j);
  }

  template <class R>
  static R fail(R r, FilterStatus s) {
    r.status = s;
    return r;
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

}  // namespace posefuse

#pragma once
/// @file
/// The concepts every posefuse model and estimator is written against.
///
/// * A **manifold** type (states and measurements) has a scalar type, a
///   compile-time tangent dimension `Dim`, and `plus` / `minus`
///   (\f$ x \boxplus \delta \f$ and \f$ y \boxminus x \f$). Filters never use
///   raw `+` / `-` on states, so angles wrap where a type says they do.
///   Fixed-size Eigen column vectors are manifolds out of the box; other types
///   provide member `plus(dx)` / `minus(y)` or specialise ManifoldTraits.
/// * A **motion model** names its `State` and `Control` and gives
///   \f$ f(x, u, \Delta t) \f$, its Jacobian \f$ J_{f,x} \f$ and the process noise.
/// * A **measurement model** names its `State` and `Measurement` and gives
///   \f$ h(x) \f$, its Jacobian \f$ J_{h,x} \f$ and the measurement noise,
///   `noise()` or, when it depends on the state, `noise(const State&)`.
///
/// Every header that defines a model ends with a `static_assert` of the
/// matching concept. For readable diagnostics, `check_motion_model<M>()` and
/// `check_measurement_model<H>()` assert one requirement at a time with a
/// sentence saying which one a type misses.

#include <Eigen/Core>
#include <concepts>
#include <cstddef>
#include <type_traits>

namespace posefuse {

/// How a type behaves as a manifold. The primary template is empty (not a
/// manifold); the specialisations below cover types with members `Scalar`,
/// `Dim`, `plus(dx)` and `minus(y)`, and fixed-size Eigen column vectors.
/// Specialise it for a third-party type you cannot change.
template <class S>
struct ManifoldTraits {};

/// Types that say what they are through their members.
template <class S>
  requires requires {
    typename S::Scalar;
    { S::Dim } -> std::convertible_to<int>;
  }
struct ManifoldTraits<S> {
  using Scalar = typename S::Scalar;
  static constexpr int Dim = S::Dim;
  using Tangent = Eigen::Matrix<Scalar, Dim, 1>;
  static S plus(const S& x, const Tangent& dx) { return x.plus(dx); }
  static Tangent minus(const S& y, const S& x) { return y.minus(x); }
};

/// Fixed-size Eigen column vectors are Euclidean: plus is `+`, minus is `-`.
template <class T, int N, int Options, int MaxRows, int MaxCols>
  requires(N != Eigen::Dynamic)
struct ManifoldTraits<Eigen::Matrix<T, N, 1, Options, MaxRows, MaxCols>> {
  using Scalar = T;
  static constexpr int Dim = N;
  using Type = Eigen::Matrix<T, N, 1, Options, MaxRows, MaxCols>;
  using Tangent = Eigen::Matrix<T, N, 1>;
  static Type plus(const Type& x, const Tangent& dx) { return x + dx; }
  static Tangent minus(const Type& y, const Type& x) { return y - x; }
};

namespace detail {
template <class T>
inline constexpr bool is_eigen_v = std::is_base_of_v<Eigen::EigenBase<std::remove_cvref_t<T>>,
                                                     std::remove_cvref_t<T>>;
template <class From, class To>
consteval bool returns_fit() {
  if constexpr (is_eigen_v<To>) {
    // Eigen converts between any sizes at compile time and asserts at run
    // time; a model must return exactly the size it promises.
    if constexpr (is_eigen_v<From>) {
      using F = std::remove_cvref_t<From>;
      using T = std::remove_cvref_t<To>;
      return int(F::RowsAtCompileTime) == int(T::RowsAtCompileTime) &&
             int(F::ColsAtCompileTime) == int(T::ColsAtCompileTime) &&
             std::is_same_v<typename F::Scalar, typename T::Scalar>;
    } else {
      return false;
    }
  } else {
    return std::is_convertible_v<From, To>;
  }
}
}  // namespace detail

/// `From` is usable where `To` is expected, with equal compile-time sizes and
/// scalar when `To` is an Eigen matrix.
template <class From, class To>
concept ReturnsExactly = detail::returns_fit<From, To>();

/// Scalar type of a manifold.
template <class S>
using ScalarOf = typename ManifoldTraits<S>::Scalar;
/// Tangent dimension of a manifold.
template <class S>
inline constexpr int DimOf = ManifoldTraits<S>::Dim;
/// Tangent vector of a manifold (a fixed-size column vector).
template <class S>
using TangentOf = Eigen::Matrix<ScalarOf<S>, DimOf<S>, 1>;
/// Covariance on a manifold's tangent space.
template <class S>
using CovarianceOf = Eigen::Matrix<ScalarOf<S>, DimOf<S>, DimOf<S>>;

/// A type with a fixed tangent dimension and boxplus / boxminus.
template <class S>
concept Manifold = requires {
  typename ManifoldTraits<S>::Scalar;
  { ManifoldTraits<S>::Dim } -> std::convertible_to<int>;
} && std::floating_point<ScalarOf<S>> && (DimOf<S> > 0) &&
  requires(const S& x, const S& y, const TangentOf<S>& dx) {
    { ManifoldTraits<S>::plus(x, dx) } -> std::convertible_to<S>;
    { ManifoldTraits<S>::minus(y, x) } -> std::convertible_to<TangentOf<S>>;
  };

/// The estimated quantity of a filter.
template <class S>
concept State = Manifold<S>;

/// A sensor reading; its `minus` is the residual (it wraps angles).
template <class Z>
concept Measurement = Manifold<Z>;

/// \f$ x \boxplus \delta \f$.
template <Manifold S>
[[nodiscard]] inline S plus(const S& x, const TangentOf<S>& dx) {
  return ManifoldTraits<S>::plus(x, dx);
}
/// \f$ y \boxminus x \f$: the tangent vector that takes x to y.
template <Manifold S>
[[nodiscard]] inline TangentOf<S> minus(const S& y, const S& x) {
  return ManifoldTraits<S>::minus(y, x);
}

/// A motion model \f$ x_t = f(x_{t-1}, u_t, \Delta t) + w,\; w \sim N(0, Q) \f$.
template <class M>
concept MotionModel =
    requires { typename M::State; typename M::Control; } && State<typename M::State> &&
    requires(const M& m, const typename M::State& x, const typename M::Control& u,
             ScalarOf<typename M::State> dt) {
      { m.predict(x, u, dt) } -> ReturnsExactly<typename M::State>;
      { m.jacobian(x, u, dt) } -> ReturnsExactly<CovarianceOf<typename M::State>>;
      { m.noise(x, u, dt) } -> ReturnsExactly<CovarianceOf<typename M::State>>;
    };

/// A MotionModel that also offers `linearize(x, u, dt)`, returning a struct
/// with members `state`, `jacobian` and `noise` equal to `predict(x, u, dt)`,
/// `jacobian(x, u, dt)` and `noise(x, u, dt)`, computed in one call that
/// shares their work (e.g. the sine and cosine of a heading). Optional:
/// Ekf::predict uses it when present and the three calls otherwise;
/// testing::check_motion_model checks that the two agree and checks the
/// returned Jacobian against central differences.
template <class M>
concept HasLinearize =
    MotionModel<M> && requires(const M& m, const typename M::State& x,
                               const typename M::Control& u, ScalarOf<typename M::State> dt) {
      { m.linearize(x, u, dt).state } -> ReturnsExactly<typename M::State>;
      { m.linearize(x, u, dt).jacobian } -> ReturnsExactly<CovarianceOf<typename M::State>>;
      { m.linearize(x, u, dt).noise } -> ReturnsExactly<CovarianceOf<typename M::State>>;
    };

/// Jacobian of a measurement model, \f$ J_{h,x} \f$.
template <class H>
using MeasurementJacobianOf = Eigen::Matrix<ScalarOf<typename H::State>,
                                            DimOf<typename H::Measurement>,
                                            DimOf<typename H::State>>;

namespace detail {
/// `h.noise()` returns the measurement covariance (noise independent of the state).
template <class H>
concept HasConstantNoise = requires(const H& h) {
  { h.noise() } -> ReturnsExactly<CovarianceOf<typename H::Measurement>>;
};
/// `h.noise(x)` returns the measurement covariance at state x.
template <class H>
concept HasStateNoise = requires(const H& h, const typename H::State& x) {
  { h.noise(x) } -> ReturnsExactly<CovarianceOf<typename H::Measurement>>;
};
}  // namespace detail

/// A measurement model \f$ z = h(x) + v,\; v \sim N(0, R) \f$, or
/// \f$ v \sim N(0, R(x)) \f$ when the noise depends on the state (e.g. a range
/// sensor whose error grows with distance): the model then provides
/// `noise(const State&)` instead of (or besides) `noise()`.
template <class H>
concept MeasurementModel =
    requires { typename H::State; typename H::Measurement; } && State<typename H::State> &&
    Measurement<typename H::Measurement> &&
    std::same_as<ScalarOf<typename H::State>, ScalarOf<typename H::Measurement>> &&
    requires(const H& h, const typename H::State& x) {
      { h.predict(x) } -> ReturnsExactly<typename H::Measurement>;
      { h.jacobian(x) } -> ReturnsExactly<MeasurementJacobianOf<H>>;
    } && (detail::HasConstantNoise<H> || detail::HasStateNoise<H>);

/// True when a measurement model's noise depends on the state, i.e. it has
/// `noise(const State&)`. Estimators then call `noise(x)` at the prior state.
template <MeasurementModel H>
inline constexpr bool has_state_dependent_noise_v = detail::HasStateNoise<H>;

/// The measurement noise \f$ R \f$ (or \f$ R(x) \f$) of a model at state x:
/// `h.noise(x)` when the model has it, else `h.noise()`.
/// @param[in] h a measurement model
/// @param[in] x the state at which the measurement is predicted
/// @return the covariance of the measurement (Measurement::Dim square)
template <MeasurementModel H>
[[nodiscard]] CovarianceOf<typename H::Measurement> measurement_noise(
    const H& h, const typename H::State& x) {
  if constexpr (detail::HasStateNoise<H>) {
    return h.noise(x);
  } else {
    (void)x;
    return h.noise();
  }
}

/// A measurement model of the state type S.
template <class H, class S>
concept MeasurementModelFor = MeasurementModel<H> && std::same_as<typename H::State, S>;

/// Models whose state Jacobian is the identity at compile time may say so with
/// `static constexpr bool kIdentityJacobian = true;`; estimators then skip
/// the matrix products with it (seed 000's G = H = I).
template <class M>
inline constexpr bool has_identity_jacobian_v = [] {
  if constexpr (requires { M::kIdentityJacobian; }) {
    return bool(M::kIdentityJacobian);
  } else {
    return false;
  }
}();

/// Measurement models whose Jacobian and noise depend neither on the state
/// nor on time may say so with `static constexpr bool kTimeInvariant = true;`.
/// The covariance part of their update is then a function of P alone, and
/// estimators may reuse it while P repeats (a converged filter). A model with
/// state-dependent noise (`noise(const State&)`) is never treated as
/// time-invariant, whatever its flag says.
template <class H>
inline constexpr bool is_time_invariant_v = [] {
  if constexpr (requires { H::kTimeInvariant; }) {
    if constexpr (requires { typename H::State; typename H::Measurement; }) {
      if constexpr (detail::HasStateNoise<H>) return false;
    }
    return bool(H::kTimeInvariant);
  } else {
    return false;
  }
}();

/// A MotionModel that propagates a covariance through its own Jacobian
/// itself: `propagate(P, x, u, dt)` returns \f$ F P F^\top \f$ (without the
/// process noise), \f$ F \f$ = `jacobian(x, u, dt)`, computed from F's known
/// structure (constant velocity: a few additions instead of two dense
/// products). Optional: Ekf::predict uses it when present;
/// testing::check_motion_model checks it against \f$ F P F^\top \f$.
template <class M>
concept HasPropagate =
    MotionModel<M> &&
    requires(const M& m, const CovarianceOf<typename M::State>& P, const typename M::State& x,
             const typename M::Control& u, ScalarOf<typename M::State> dt) {
      { m.propagate(P, x, u, dt) } -> ReturnsExactly<CovarianceOf<typename M::State>>;
    };

/// A HasLinearize model whose `linearize()` result also propagates a
/// covariance: `lin.propagate(P)` returns \f$ F P F^\top \f$ with F =
/// `lin.jacobian` (so the work shared with the Jacobian, e.g. a heading's
/// sine and cosine, is not repeated). Optional, checked like HasPropagate.
template <class M>
concept HasLinearizePropagate =
    HasLinearize<M> &&
    requires(const M& m, const typename M::State& x, const typename M::Control& u,
             ScalarOf<typename M::State> dt, const CovarianceOf<typename M::State>& P) {
      { m.linearize(x, u, dt).propagate(P) } -> ReturnsExactly<CovarianceOf<typename M::State>>;
    };

namespace detail {
/// True when `H::kSelection` exists.
template <class H>
concept DeclaresSelection = requires { H::kSelection; };

/// Whether a declared selection is well formed: one index per measurement
/// component, each in [0, state Dim), no index twice.
template <class H>
consteval bool selection_well_formed() {
  if constexpr (!DeclaresSelection<H>) {
    return false;
  } else {
    constexpr auto sel = H::kSelection;
    if (int(sel.size()) != DimOf<typename H::Measurement>) return false;
    for (std::size_t i = 0; i < sel.size(); ++i) {
      if (sel[i] < 0 || sel[i] >= DimOf<typename H::State>) return false;
      for (std::size_t j = 0; j < i; ++j)
        if (sel[i] == sel[j]) return false;
    }
    return true;
  }
}
}  // namespace detail

/// Measurement models whose Jacobian is a *selection* of state components,
/// \f$ H_{k,j} = 1 \f$ if \f$ j = s_k \f$ and 0 otherwise (a position fix
/// \f$ [I\;0] \f$, a heading fix \f$ [0\;0\;1] \f$, a GNSS position of a
/// larger state), may declare it with
/// `static constexpr std::array<int, Measurement::Dim> kSelection = {s_0, ...};`.
/// Estimators then read rows and columns of P instead of multiplying by H.
/// The declaration must match `jacobian(x)` at every x;
/// testing::check_measurement_model checks that it does. A declaration of
/// the wrong length, an index outside the state or one given twice fails to
/// compile in the estimator (check_measurement_model()).
template <class H>
inline constexpr bool has_selection_v = [] {
  if constexpr (requires { typename H::State; typename H::Measurement; }) {
    return detail::DeclaresSelection<H>;
  } else {
    return false;
  }
}();

/// Asserts each requirement of MotionModel separately, so that the compiler's
/// message names the one that is missing. Use in a `static_assert` or call
/// from a template that takes a motion model.
template <class M>
consteval bool check_motion_model() {
  static_assert(requires { typename M::State; },
                "posefuse: a motion model must name its state type: `using State = ...;`");
  static_assert(requires { typename M::Control; },
                "posefuse: a motion model must name its control type: `using Control = ...;`");
  if constexpr (requires { typename M::State; typename M::Control; }) {
    static_assert(State<typename M::State>,
                  "posefuse: the motion model's State is not a posefuse::State (a fixed-size "
                  "Eigen vector, or a type with Scalar, Dim, plus(dx) and minus(y))");
    if constexpr (State<typename M::State>) {
      using S = typename M::State;
      using U = typename M::Control;
      using T = ScalarOf<S>;
      static_assert(requires(const M& m, const S& x, const U& u, T dt) {
                      { m.predict(x, u, dt) } -> ReturnsExactly<S>;
                    },
                    "posefuse: a motion model needs `State predict(const State&, const Control&, "
                    "Scalar dt) const`");
      static_assert(requires(const M& m, const S& x, const U& u, T dt) {
                      { m.jacobian(x, u, dt) } -> ReturnsExactly<CovarianceOf<S>>;
                    },
                    "posefuse: a motion model needs `Matrix<Scalar, Dim, Dim> jacobian(const "
                    "State&, const Control&, Scalar dt) const` (J_f_x)");
      static_assert(requires(const M& m, const S& x, const U& u, T dt) {
                      { m.noise(x, u, dt) } -> ReturnsExactly<CovarianceOf<S>>;
                    },
                    "posefuse: a motion model needs `Matrix<Scalar, Dim, Dim> noise(const State&, "
                    "const Control&, Scalar dt) const` (process noise)");
    }
  }
  return MotionModel<M>;
}

/// Asserts each requirement of MeasurementModel separately (see
/// check_motion_model).
template <class H>
consteval bool check_measurement_model() {
  static_assert(requires { typename H::State; },
                "posefuse: a measurement model must name its state type: `using State = ...;`");
  static_assert(requires { typename H::Measurement; },
                "posefuse: a measurement model must name its measurement type: "
                "`using Measurement = ...;`");
  if constexpr (requires { typename H::State; typename H::Measurement; }) {
    static_assert(State<typename H::State>,
                  "posefuse: the measurement model's State is not a posefuse::State");
    static_assert(Measurement<typename H::Measurement>,
                  "posefuse: the measurement model's Measurement is not a posefuse::Measurement "
                  "(a fixed-size Eigen vector, or a type with Scalar, Dim, plus and minus)");
    if constexpr (State<typename H::State> && Measurement<typename H::Measurement>) {
      using S = typename H::State;
      using Z = typename H::Measurement;
      static_assert(std::same_as<ScalarOf<S>, ScalarOf<Z>>,
                    "posefuse: State and Measurement of a measurement model must share a Scalar");
      static_assert(requires(const H& h, const S& x) {
                      { h.predict(x) } -> ReturnsExactly<Z>;
                    },
                    "posefuse: a measurement model needs `Measurement predict(const State&) const` "
                    "(h(x))");
      static_assert(requires(const H& h, const S& x) {
                      { h.jacobian(x) } -> ReturnsExactly<MeasurementJacobianOf<H>>;
                    },
                    "posefuse: a measurement model needs `Matrix<Scalar, Measurement::Dim, "
                    "State::Dim> jacobian(const State&) const` (J_h_x)");
      static_assert(detail::HasConstantNoise<H> || detail::HasStateNoise<H>,
                    "posefuse: a measurement model needs `Matrix<Scalar, Measurement::Dim, "
                    "Measurement::Dim> noise() const` or, for noise that depends on the state, "
                    "`noise(const State&) const`");
      if constexpr (detail::DeclaresSelection<H>) {
        static_assert(detail::selection_well_formed<H>(),
                      "posefuse: a measurement model's kSelection must list Measurement::Dim "
                      "distinct state indices, each in [0, State::Dim)");
      }
    }
  }
  return MeasurementModel<H>;
}

}  // namespace posefuse

#pragma once
/// @file
/// Compile-time pipelines: chains of stages fixed by the type system.
///
/// A **stage** is a value type that names its `Input` and `Output` types and
/// has a call operator `Output operator()(const Input&)` (it may keep state
/// between calls, e.g. the previous sample). `make_pipeline(a, b, c)` (or
/// `a | b | c`) composes stages into a new stage; the composition is checked
/// when the pipeline type is formed, and a stage whose `Output` does not
/// convert to the next stage's `Input` is a compile error that reads
///
///     error: static assertion failed: posefuse pipeline: a stage's Output
///     type does not convert to the next stage's Input type ...
///     note: in instantiation of 'StageMismatch<Position2, DeadReckoning, ...>'
///
/// naming both stages. Calls are inlined: a pipeline costs what its stages
/// cost, with no virtual dispatch and no allocation.

#include <concepts>
#include <tuple>
#include <type_traits>
#include <utility>

namespace posefuse {

/// A value type with `Input`, `Output` and `Output operator()(const Input&)`.
template <class S>
concept Stage = requires { typename S::Input; typename S::Output; } &&
                requires(S& s, const typename S::Input& in) {
                  { s(in) } -> std::convertible_to<typename S::Output>;
                };

namespace detail {

/// Instantiated only when two neighbouring stages do not fit; its template
/// arguments in the compiler's message name the two stages.
template <class Producer, class Consumer, class ProducedType, class ExpectedType>
struct StageMismatch {
  static constexpr bool fits = std::is_convertible_v<ProducedType, ExpectedType>;
  static_assert(fits,
                "posefuse pipeline: a stage's Output type does not convert to the next stage's "
                "Input type; see StageMismatch<Producer, Consumer, Producer::Output, "
                "Consumer::Input> in this message");
};

template <class Producer, class Consumer>
struct StageMismatch<Producer, Consumer, void, void> {};

template <class S>
struct StageCheck {
  static_assert(Stage<S>,
                "posefuse pipeline: every stage needs `using Input = ...; using Output = ...;` and "
                "`Output operator()(const Input&)`");
  static constexpr bool value = Stage<S>;
};

template <class... S>
struct ChainFits : std::true_type {};

template <class A, class B, class... Rest>
struct ChainFits<A, B, Rest...> {
  static constexpr bool value =
      StageMismatch<A, B, typename A::Output, typename B::Input>::fits &&
      ChainFits<B, Rest...>::value;
};

template <class... S>
struct First;
template <class A, class... Rest>
struct First<A, Rest...> {
  using type = A;
};

template <class... S>
struct Last;
template <class A>
struct Last<A> {
  using type = A;
};
template <class A, class B, class... Rest>
struct Last<A, B, Rest...> : Last<B, Rest...> {};

}  // namespace detail

/// A fixed chain of stages; itself a Stage.
template <class... Stages>
class Pipeline {
  static_assert(sizeof...(Stages) > 0, "posefuse pipeline: a pipeline needs at least one stage");
  static_assert((detail::StageCheck<Stages>::value && ...));
  static_assert(detail::ChainFits<Stages...>::value);

 public:
  using Input = typename detail::First<Stages...>::type::Input;
  using Output = typename detail::Last<Stages...>::type::Output;
  static constexpr std::size_t size = sizeof...(Stages);

  constexpr Pipeline() = default;
  constexpr explicit Pipeline(Stages... stages) : stages_(std::move(stages)...) {}

  /// Runs the sample through every stage in order.
  Output operator()(const Input& in) { return run<0>(in); }

  /// The I-th stage (for its parameters or its state).
  template <std::size_t I>
  [[nodiscard]] auto& stage() noexcept {
    return std::get<I>(stages_);
  }
  template <std::size_t I>
  [[nodiscard]] const auto& stage() const noexcept {
    return std::get<I>(stages_);
  }
  /// All stages, for structured bindings or std::apply.
  [[nodiscard]] std::tuple<Stages...>& stages() noexcept { return stages_; }

 private:
  template <std::size_t I, class T>
  decltype(auto) run(const T& x) {
    if constexpr (I + 1 == sizeof...(Stages)) {
      return static_cast<Output>(std::get<I>(stages_)(x));
    } else {
      using Next = std::tuple_element_t<I + 1, std::tuple<Stages...>>;
      const typename Next::Input y = std::get<I>(stages_)(x);
      return run<I + 1>(y);
    }
  }

  std::tuple<Stages...> stages_;
};

namespace detail {
template <class S>
struct Flatten {
  static auto apply(S s) { return std::tuple<S>(std::move(s)); }
};
template <class... S>
struct Flatten<Pipeline<S...>> {
  static auto apply(Pipeline<S...> p) { return std::move(p.stages()); }
};
}  // namespace detail

/// Composes stages into a Pipeline (nested pipelines are flattened).
template <class... Stages>
[[nodiscard]] auto make_pipeline(Stages... stages) {
  return std::apply([](auto... s) { return Pipeline<decltype(s)...>(std::move(s)...); },
                    std::tuple_cat(detail::Flatten<Stages>::apply(std::move(stages))...));
}

}  // namespace posefuse

/// `a | b` is `posefuse::make_pipeline(a, b)` for any two stages.
///
/// It is declared in the global namespace, constrained to posefuse::Stage
/// operands, so that it is found for stages defined in *any* namespace:
/// ordinary lookup reaches the global namespace from everywhere, whereas a
/// function in namespace posefuse would only be found for posefuse's own
/// types (argument-dependent lookup). One C++ rule still applies: a
/// namespace that declares an `operator|` of its own (e.g. for flag enums)
/// hides this one inside that namespace; write `using ::operator|;` there, or
/// call posefuse::make_pipeline.
template <posefuse::Stage A, posefuse::Stage B>
[[nodiscard]] auto operator|(A a, B b) {
  return posefuse::make_pipeline(std::move(a), std::move(b));
}

namespace posefuse {
/// The same operator under posefuse's name, so existing
/// `using posefuse::operator|;` lines keep working (it is one function).
using ::operator|;
}  // namespace posefuse

#pragma once
/// @file
/// Time-ordered merge of several sample streams: visit every sample of any
/// number of streams exactly once, in order of `t_ns`, without copying them
/// into one container and without a std::variant.
///
///     for_each_in_time_order(Overloaded{
///         [&](const ImuSample& s) { attitude(s); },
///         [&](const WheelSample& s) { odometry(s); },
///         [&](const SlamSample& s) { pending.push_back(&s); }},
///       log.imu, log.wheels, log.slam);
///
/// **Order.** Samples are visited by increasing `t_ns`. Ties are stable: of
/// samples with equal stamps, those of a stream given earlier in the
/// argument list come first, and within one stream the stream's own order is
/// kept. Each stream must be in time order already (`t_ns` non-decreasing);
/// this is checked for every stream before the first sample is visited.
///
/// **Visitor.** Any callable (typically an overload set) that accepts a
/// `const Sample&` of every stream's sample type. When two streams share a
/// sample type, the visitor may instead accept `(const Sample&,
/// std::integral_constant<std::size_t, I>)` and is then told the stream's
/// position I in the argument list.
///
/// Cost: one pass over every stream to check its order, then per sample a
/// comparison of the N stream heads (N is known at compile time).

#include <array>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <ranges>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// A sample with an integer time stamp `t_ns` (core/samples.hpp).
template <class S>
concept TimeStamped = requires(const S& s) {
  { s.t_ns } -> std::convertible_to<std::int64_t>;
};

/// A random-access, sized range of TimeStamped samples (std::vector,
/// std::span, std::array, ...).
template <class R>
concept SampleStream = std::ranges::random_access_range<const R> &&
                       std::ranges::sized_range<const R> &&
                       TimeStamped<std::ranges::range_value_t<const R>>;

/// Builds an overload set from lambdas: `Overloaded{[](const A&) {...}, [](const B&) {...}}`.
template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
/// Deduction guide for Overloaded.
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

namespace detail {

template <class V, class S, std::size_t I>
concept VisitsWithIndex = std::invocable<V&, const S&, std::integral_constant<std::size_t, I>>;

template <class V, class S, std::size_t I>
concept VisitsSample = VisitsWithIndex<V, S, I> || std::invocable<V&, const S&>;

template <std::size_t I, class V, class S>
void visit_sample(V& visit, const S& s) {
  static_assert(VisitsSample<V, S, I>,
                "posefuse::for_each_in_time_order: the visitor cannot be called with the sample "
                "type of one stream; give it an overload `(const Sample&)` or `(const Sample&, "
                "std::integral_constant<std::size_t, I>)` for every stream");
  if constexpr (VisitsWithIndex<V, S, I>) {
    visit(s, std::integral_constant<std::size_t, I>{});
  } else {
    visit(s);
  }
}

template <class R>
void require_time_order(const R& stream, std::size_t which) {
  const auto n = std::ranges::size(stream);
  const auto first = std::ranges::begin(stream);
  for (std::size_t k = 1; k < n; ++k) {
    const std::int64_t a = first[std::ptrdiff_t(k - 1)].t_ns, b = first[std::ptrdiff_t(k)].t_ns;
    if (b < a)
      throw invalid_argument("for_each_in_time_order: stream " + std::to_string(which) +
                             " is not in time order: sample " + std::to_string(k) + " has t_ns " +
                             std::to_string(b) + " after " + std::to_string(a));
  }
}

}  // namespace detail

/// Visits every sample of every stream exactly once, by increasing `t_ns`
/// (ties: earlier stream first, then the stream's own order; see the file
/// comment).
/// @param[in] visit    called once per sample, see the file comment
/// @param[in] streams  the streams, each in time order (`t_ns` non-decreasing)
/// @return the number of samples visited (the sum of the streams' sizes)
/// @throws posefuse::invalid_argument, before any sample is visited, when a
///         stream's `t_ns` decreases (naming the stream's position and the index);
///         whatever `visit` throws
template <class Visitor, SampleStream... Streams>
std::size_t for_each_in_time_order(Visitor&& visit, const Streams&... streams) {
  constexpr std::size_t N = sizeof...(Streams);
  static_assert(N > 0, "posefuse::for_each_in_time_order needs at least one stream");
  const std::tuple<const Streams&...> all(streams...);
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (detail::require_time_order(std::get<I>(all), I), ...);
  }(std::make_index_sequence<N>{});

  std::array<std::size_t, N> next{};  // position of each stream's head
  std::size_t visited = 0;
  for (;;) {
    std::size_t best = N;
    std::int64_t best_t = 0;
    // The earliest head; strict `<` keeps ties with the earlier stream.
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (
          [&] {
            const auto& s = std::get<I>(all);
            if (next[I] >= std::size_t(std::ranges::size(s))) return;
            const std::int64_t t = std::ranges::begin(s)[std::ptrdiff_t(next[I])].t_ns;
            if (best == N || t < best_t) {
              best = I;
              best_t = t;
            }
          }(),
          ...);
    }(std::make_index_sequence<N>{});
    if (best == N) break;
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (
          [&] {
            if (best != I) return;
            const auto& sample = std::ranges::begin(std::get<I>(all))[std::ptrdiff_t(next[I]++)];
            detail::visit_sample<I>(visit, sample);
          }(),
          ...);
    }(std::make_index_sequence<N>{});
    ++visited;
  }
  return visited;
}

}  // namespace posefuse

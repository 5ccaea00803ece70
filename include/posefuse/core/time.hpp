#pragma once
/// @file
/// The library's time convention and the conversions it needs.
///
/// A raw sensor sample carries its stamp as `std::int64_t t_ns` (integer
/// nanoseconds: exact, totally ordered, the unit of recorded logs such as
/// EuRoC and the robot-log folders). Everything that does arithmetic with
/// time — trajectories, filter steps, interpolation, metrics — uses `double`
/// seconds, spelled `t_s` for a time and `dt_s` for a step.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// Nanoseconds in one second.
inline constexpr std::int64_t kNanosecondsPerSecond = 1'000'000'000;

/// `t_ns` as seconds (exact to about 0.1 µs at Unix-epoch magnitudes, where a
/// double keeps 53 bits).
[[nodiscard]] constexpr double seconds_from_ns(std::int64_t t_ns) noexcept {
  return double(t_ns) * 1e-9;
}

/// The difference `a_ns - b_ns` in seconds, computed without overflow for any
/// two int64 stamps (the difference itself may exceed int64).
[[nodiscard]] constexpr double seconds_between(std::int64_t a_ns, std::int64_t b_ns) noexcept {
  // Split into whole seconds and remainders so that each part is exact.
  const std::int64_t sa = a_ns / kNanosecondsPerSecond, ra = a_ns % kNanosecondsPerSecond;
  const std::int64_t sb = b_ns / kNanosecondsPerSecond, rb = b_ns % kNanosecondsPerSecond;
  return (double(sa) - double(sb)) + double(ra - rb) * 1e-9;
}

/// Seconds as the nearest `t_ns`.
/// @throws posefuse::invalid_argument when `t_s` is not finite or its
///         nanosecond count does not fit in an int64 (|t_s| > 9.2e9 s)
[[nodiscard]] inline std::int64_t ns_from_seconds(double t_s) {
  const double ns = std::round(t_s * 1e9);
  // 2^63 is exactly representable; every double below it converts safely.
  if (!std::isfinite(ns) || !(ns < 9223372036854775808.0) || !(ns >= -9223372036854775808.0))
    throw invalid_argument("ns_from_seconds: " + std::to_string(t_s) +
                           " s does not fit in int64 nanoseconds");
  return std::int64_t(ns);
}

}  // namespace posefuse

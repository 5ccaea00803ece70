#pragma once
/// @file
/// Angles on the circle: wrapping, differences and circular means.
///
/// Every function works in radians. Wrapped angles lie in [-pi, pi).

#include <cmath>
#include <concepts>
#include <limits>
#include <numbers>
#include <span>

namespace posefuse {

/// Wraps an angle to [-pi, pi).
/// @param[in] a angle in radians (any finite value)
/// @return the equivalent angle in [-pi, pi); NaN stays NaN
template <std::floating_point T>
[[nodiscard]] inline T wrap_angle(T a) noexcept {
  constexpr T pi = std::numbers::pi_v<T>;
  constexpr T two_pi = T(2) * pi;
  if (a >= -pi && a < pi) return a;  // fast path: already wrapped
  T r = std::fmod(a + pi, two_pi);
  if (r < T(0)) r += two_pi;
  return r - pi;
}

/// The signed shortest rotation from b to a, \f$ \mathrm{wrap}(a - b) \f$.
template <std::floating_point T>
[[nodiscard]] inline T angle_diff(T a, T b) noexcept {
  return wrap_angle(a - b);
}

/// Degrees to radians.
template <std::floating_point T>
[[nodiscard]] constexpr T deg2rad(T deg) noexcept {
  return deg * std::numbers::pi_v<T> / T(180);
}

/// Radians to degrees.
template <std::floating_point T>
[[nodiscard]] constexpr T rad2deg(T rad) noexcept {
  return rad * T(180) / std::numbers::pi_v<T>;
}

namespace detail {
/// Direction of the resultant (s, c); NaN when its length is round-off
/// compared with the total weight (the mean direction is undefined).
template <std::floating_point T>
[[nodiscard]] inline T mean_direction(T s, T c, T total_weight) noexcept {
  if (!(std::hypot(s, c) > T(64) * std::numeric_limits<T>::epsilon() * total_weight))
    return std::numeric_limits<T>::quiet_NaN();
  return wrap_angle(std::atan2(s, c));
}
}  // namespace detail

/// Weighted circular mean \f$ \mathrm{atan2}(\sum w_i \sin a_i, \sum w_i \cos a_i) \f$.
/// Averaging 179° and -179° gives 180°, not 0°.
/// @param[in] a angles in radians
/// @param[in] w non-negative weights, same length as `a`
/// @return the mean in [-pi, pi); NaN when the resultant vector is zero
///         (e.g. two opposite angles with equal weight) or the input is empty
template <std::floating_point T>
[[nodiscard]] inline T circular_mean(std::span<const T> a, std::span<const T> w) noexcept {
  T s = 0, c = 0, total = 0;
  const std::size_t n = a.size() < w.size() ? a.size() : w.size();
  for (std::size_t i = 0; i < n; ++i) {
    s += w[i] * std::sin(a[i]);
    c += w[i] * std::cos(a[i]);
    total += std::abs(w[i]);
  }
  return detail::mean_direction(s, c, total);
}

/// Unweighted circular mean of a set of angles (see the weighted overload).
template <std::floating_point T>
[[nodiscard]] inline T circular_mean(std::span<const T> a) noexcept {
  T s = 0, c = 0;
  for (T x : a) {
    s += std::sin(x);
    c += std::cos(x);
  }
  return detail::mean_direction(s, c, static_cast<T>(a.size()));
}

/// Weighted mean of two angles on the circle: \f$ a + \frac{w_b}{w_a+w_b}\,\mathrm{wrap}(b-a) \f$,
/// i.e. interpolation along the shorter arc. For equal weights this equals
/// the circular mean of {a, b}.
template <std::floating_point T>
[[nodiscard]] inline T angle_interpolate(T a, T b, T fraction_of_b) noexcept {
  return wrap_angle(a + fraction_of_b * angle_diff(b, a));
}

}  // namespace posefuse

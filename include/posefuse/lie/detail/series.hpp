#pragma once
/// @file
/// Scalar helpers shared by the Lie-group headers (namespace posefuse::detail,
/// not API): Taylor-series evaluation and the coefficient functions of
/// SO(2), SE(2), SO(3) and SE(3) with their small-angle branches.
///
/// Every coefficient \f$ c(\theta) \f$ below is an even or odd power series in
/// \f$ \theta \f$. Where the closed form cancels (e.g. \f$ \theta - \sin\theta \f$),
/// its absolute rounding error grows like \f$ \epsilon / \theta^k \f$ as
/// \f$ \theta \to 0 \f$; below `kSeriesAngle` the series is used instead,
/// truncated where its first omitted term is below double precision there.
/// Coefficients whose closed form does not cancel use the series only to avoid
/// 0 / 0, below `tiny_angle<T>()`.

#include <cmath>
#include <concepts>
#include <limits>

namespace posefuse::detail {

/// Angle (rad) below which cancelling closed forms are replaced by their
/// Taylor series; the series below are truncated so that their first omitted
/// term is below 1e-17 (relative) at this angle.
template <std::floating_point T>
inline constexpr T kSeriesAngle = T(0.5);

/// Angle (rad) below which non-cancelling closed forms (sin x / x, ...) use
/// their series to avoid 0 / 0: \f$ \epsilon^{1/4} \f$, where the series'
/// \f$ \theta^4 \f$ term is already below rounding.
template <std::floating_point T>
[[nodiscard]] inline T tiny_angle() noexcept {
  return std::sqrt(std::sqrt(std::numeric_limits<T>::epsilon()));
}

/// Angle (rad) above which SO(3) and SE(3) evaluate Exp and their Jacobians
/// through the unit axis \f$ u = \phi / \theta \f$ and the angle's sine
/// and cosine alone: \f$ 1/\sqrt{\epsilon} \f$ (6.7e7 rad in double). The
/// closed forms in \f$ \phi \f$ multiply powers of θ up to \f$ \theta^5 \f$,
/// which overflow for large finite angles (0 · ∞ = NaN); the axis forms are
/// the same functions without them. Below this angle nothing changes.
template <std::floating_point T>
[[nodiscard]] inline T large_angle() noexcept {
  return T(1) / std::sqrt(std::numeric_limits<T>::epsilon());
}

/// \f$ \sum_k c_k x^k \f$ by Horner's rule.
template <std::floating_point T, std::size_t N>
[[nodiscard]] constexpr T horner(T x, const T (&c)[N]) noexcept {
  T r = c[N - 1];
  for (std::size_t k = N - 1; k-- > 0;) r = r * x + c[k];
  return r;
}

/// \f$ n! \f$ as a floating-point constant.
template <std::floating_point T>
[[nodiscard]] constexpr T factorial(int n) noexcept {
  T r = T(1);
  for (int k = 2; k <= n; ++k) r *= T(k);
  return r;
}

/// \f$ \sin\theta / \theta \f$ (series \f$ 1 - \theta^2/6 + \theta^4/120 \f$).
template <std::floating_point T>
[[nodiscard]] inline T sin_over_x(T th) noexcept {
  if (std::abs(th) < tiny_angle<T>()) {
    const T t2 = th * th;
    return T(1) - t2 / T(6) + t2 * t2 / T(120);
  }
  return std::sin(th) / th;
}

/// \f$ (1 - \cos\theta) / \theta^2 = 2\sin^2(\theta/2) / \theta^2 \f$ (no
/// cancellation in the half-angle form; series \f$ 1/2 - \theta^2/24 + \theta^4/720 \f$).
template <std::floating_point T>
[[nodiscard]] inline T one_minus_cos_over_x2(T th) noexcept {
  if (std::abs(th) < tiny_angle<T>()) {
    const T t2 = th * th;
    return T(0.5) - t2 / T(24) + t2 * t2 / T(720);
  }
  const T s = std::sin(th / T(2));
  return T(2) * s * s / (th * th);
}

/// \f$ (\theta - \sin\theta) / \theta^3 = \sum_{k \ge 1} (-1)^{k+1} \theta^{2k-2} / (2k+1)! \f$.
template <std::floating_point T>
[[nodiscard]] inline T x_minus_sin_over_x3(T th) noexcept {
  const T t2 = th * th;
  if (std::abs(th) < kSeriesAngle<T>) {
    constexpr T c[] = {T(1) / factorial<T>(3),  -T(1) / factorial<T>(5), T(1) / factorial<T>(7),
                       -T(1) / factorial<T>(9), T(1) / factorial<T>(11), -T(1) / factorial<T>(13),
                       T(1) / factorial<T>(15)};
    return horner(t2, c);
  }
  return (th - std::sin(th)) / (t2 * th);
}

/// \f$ (\theta^2 + 2\cos\theta - 2) / (2\theta^4) = \sum_{k \ge 2} (-1)^k \theta^{2k-4} / (2k)! \f$
/// (Barfoot, *State Estimation for Robotics*, 2017, eq 7.86, second coefficient).
template <std::floating_point T>
[[nodiscard]] inline T se3_q_c2(T th) noexcept {
  const T t2 = th * th;
  if (std::abs(th) < kSeriesAngle<T>) {
    constexpr T c[] = {T(1) / factorial<T>(4),   -T(1) / factorial<T>(6), T(1) / factorial<T>(8),
                       -T(1) / factorial<T>(10), T(1) / factorial<T>(12), -T(1) / factorial<T>(14),
                       T(1) / factorial<T>(16),  -T(1) / factorial<T>(18)};
    return horner(t2, c);
  }
  return (t2 + T(2) * std::cos(th) - T(2)) / (T(2) * t2 * t2);
}

/// \f$ (2\theta - 3\sin\theta + \theta\cos\theta) / (2\theta^5)
/// = \sum_{k \ge 2} (-1)^k (k - 1)\, \theta^{2k-4} / (2k+1)! \f$
/// (Barfoot 2017, eq 7.86, third coefficient).
template <std::floating_point T>
[[nodiscard]] inline T se3_q_c3(T th) noexcept {
  const T t2 = th * th;
  if (std::abs(th) < kSeriesAngle<T>) {
    constexpr T c[] = {T(1) / factorial<T>(5),   -T(2) / factorial<T>(7), T(3) / factorial<T>(9),
                       -T(4) / factorial<T>(11), T(5) / factorial<T>(13), -T(6) / factorial<T>(15),
                       T(7) / factorial<T>(17)};
    return horner(t2, c);
  }
  return (T(2) * th - T(3) * std::sin(th) + th * std::cos(th)) / (T(2) * t2 * t2 * th);
}

/// \f$ \left(1 - \tfrac{\theta}{2}\cot\tfrac{\theta}{2}\right) / \theta^2
/// = \frac{1}{\theta^2} - \frac{1 + \cos\theta}{2\theta\sin\theta}
/// = \sum_{n \ge 1} (-1)^{n+1} B_{2n}\, \theta^{2n-2} / (2n)! \f$
/// (\f$ B_{2n} \f$ Bernoulli numbers: 1/12 + θ²/720 + θ⁴/30240 + ...), the
/// coefficient of \f$ [\phi]_\times^2 \f$ in \f$ J_r^{-1} \f$ (Solà et al. 2018,
/// eq 144). The cotangent form stays finite at \f$ \theta = \pi \f$ (it is
/// singular only at \f$ 2\pi \f$).
template <std::floating_point T>
[[nodiscard]] inline T so3_jinv_coeff(T th) noexcept {
  const T t2 = th * th;
  if (std::abs(th) < kSeriesAngle<T>) {
    constexpr T c[] = {T(1) / T(12),
                       T(1) / T(720),
                       T(1) / T(30240),
                       T(1) / T(1209600),
                       T(1) / T(47900160),
                       T(691) / T(1307674368000),
                       T(1) / T(74724249600),
                       T(3617) / T(10670622842880000.0L),
                       T(43867) / T(5109094217170944000.0L)};
    return horner(t2, c);
  }
  const T h = th / T(2);
  return (T(1) - h * std::cos(h) / std::sin(h)) / t2;
}

}  // namespace posefuse::detail

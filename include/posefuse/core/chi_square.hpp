#pragma once
/// @file
/// Chi-square distribution quantiles, for innovation (NIS) gates.
///
/// The CDF is the regularised lower incomplete gamma function
/// \f$ F(x; k) = P(k/2, x/2) \f$ (series for \f$ x < a + 1 \f$, Lentz's continued
/// fraction otherwise; Press et al., *Numerical Recipes*, 3rd ed., §6.2); the
/// quantile inverts it by bisection to full double precision.

#include <cmath>
#include <limits>
#include <posefuse/core/error.hpp>

namespace posefuse {

namespace detail {
/// Regularised lower incomplete gamma P(a, x), a > 0, x >= 0.
inline double regularised_gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(log_prefix);
  }
  // Continued fraction for Q(a, x) (modified Lentz).
  constexpr double tiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / tiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}
}  // namespace detail

/// CDF of the chi-square distribution with `dof` degrees of freedom.
[[nodiscard]] inline double chi_square_cdf(double x, int dof) {
  if (dof <= 0) throw invalid_argument("chi_square_cdf: degrees of freedom must be > 0");
  return detail::regularised_gamma_p(0.5 * dof, 0.5 * x);
}

/// The value below which a chi-square variable with `dof` degrees of freedom
/// falls with the given probability, e.g. `chi_square_quantile(0.99, 2)` =
/// 9.2103: a 99 % gate on a 2-D innovation's NIS.
/// @throws posefuse::invalid_argument unless 0 < probability < 1 and dof > 0
[[nodiscard]] inline double chi_square_quantile(double probability, int dof) {
  if (!(probability > 0.0 && probability < 1.0))
    throw invalid_argument("chi_square_quantile: probability must be in (0, 1)");
  if (dof <= 0) throw invalid_argument("chi_square_quantile: degrees of freedom must be > 0");
  double lo = 0.0;
  double hi = dof + 10.0 * std::sqrt(2.0 * dof) + 50.0;
  while (chi_square_cdf(hi, dof) < probability) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi_square_cdf(mid, dof) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace posefuse

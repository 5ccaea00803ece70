#pragma once
/// @file
/// Summary statistics of an error series, defined as evo's
/// `PE.get_all_statistics()` (evo/core/metrics.py, numpy defaults).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// Statistics of errors \f$ e_1..e_n \f$ (same unit as the errors; `sse` in unit²).
struct Statistics {
  double rmse = 0.0;    ///< \f$ \sqrt{\frac1n \sum e_i^2} \f$
  double mean = 0.0;    ///< \f$ \bar e = \frac1n \sum e_i \f$
  double median = 0.0;  ///< middle value; mean of the two middle values for even n (np.median)
  double std = 0.0;  ///< population standard deviation \f$ \sqrt{\frac1n \sum (e_i-\bar e)^2} \f$
                     ///< (np.std, ddof = 0)
  double min = 0.0;  ///< smallest error
  double max = 0.0;  ///< largest error
  double sse = 0.0;  ///< sum of squared errors \f$ \sum e_i^2 \f$
  std::size_t count = 0;  ///< n
};

/// Computes the statistics of an error series exactly as evo does.
/// @param[in] errors the errors (any finite values)
/// @return rmse, mean, median, std (ddof = 0), min, max, sse and count
/// @throws posefuse::invalid_argument when `errors` is empty or holds a
///         non-finite value
template <class Lazy = void>
[[nodiscard]] Statistics compute_statistics(std::span<const double> errors) {
  if (errors.empty()) throw invalid_argument("compute_statistics: no errors to summarise");
  Statistics s;
  s.count = errors.size();
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const double e = errors[i];
    if (!std::isfinite(e)) {
      throw invalid_argument("compute_statistics: error " + std::to_string(i) + " is not finite");
    }
    sum += e;
    s.sse += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (const double e : errors) var += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(var / n);
  const auto [lo, hi] = std::minmax_element(errors.begin(), errors.end());
  s.min = *lo;
  s.max = *hi;
  // The middle value(s) by selection, O(n) as np.median's partition; the
  // same elements a full sort would put there.
  std::vector<double> v(errors.begin(), errors.end());
  const std::size_t mid = v.size() / 2;
  const auto middle = v.begin() + static_cast<std::ptrdiff_t>(mid);
  std::nth_element(v.begin(), middle, v.end());
  s.median = v.size() % 2 == 1 ? *middle : 0.5 * (*std::max_element(v.begin(), middle) + *middle);
  return s;
}

}  // namespace posefuse

#pragma once
/// @file
/// The simulators' random numbers (not API): mt19937_64 with its own uniform
/// and Box-Muller normal instead of the std distributions, whose algorithms
/// the standard leaves to each library, so that a seed draws the same
/// numbers with libstdc++, libc++ and MSVC's library alike.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

namespace posefuse::sim::detail {

class SeededRng {
 public:
  explicit SeededRng(std::uint64_t seed) : g_(seed) {}
  /// Uniform in [0, 1) from the top 53 bits of one draw.
  double uniform() { return double(g_() >> 11) * 0x1.0p-53; }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Uniform integer in [0, n), n > 0.
  std::size_t below(std::size_t n) { return std::min(n - 1, std::size_t(uniform() * double(n))); }
  /// Normal with standard deviation sigma; the two values of one Box-Muller
  /// pair are returned by consecutive calls.
  double normal(double sigma = 1.0) {
    if (has_spare_) {
      has_spare_ = false;
      return sigma * spare_;
    }
    const double u1 = 1.0 - uniform(), u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1)), a = 2.0 * std::numbers::pi * u2;
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return sigma * r * std::cos(a);
  }
  /// Fisher-Yates shuffle.
  template <class T>
  void shuffle(std::vector<T>& v) {
    for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[below(i)]);
  }

 private:
  std::mt19937_64 g_;
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace posefuse::sim::detail

// Error statistics as evo/numpy define them (population std, numpy median).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <posefuse/eval/statistics.hpp>

TEST_CASE("Statistics: odd count, hand-computed", "[eval][statistics]") {
  const std::vector<double> e{3.0, 1.0, 2.0};
  const posefuse::Statistics s = posefuse::compute_statistics(e);
  CHECK(s.count == 3);
  CHECK(s.median == 2.0);
  CHECK(s.mean == 2.0);
  CHECK(s.sse == 14.0);
  CHECK(s.rmse == Approx(std::sqrt(14.0 / 3.0)).epsilon(1e-15));
  CHECK(s.std == Approx(std::sqrt(2.0 / 3.0)).epsilon(1e-15));  // ddof = 0, not sqrt(1)
  CHECK(s.min == 1.0);
  CHECK(s.max == 3.0);
}

TEST_CASE("Statistics: even count takes the mean of the two middle values", "[eval][statistics]") {
  const std::vector<double> e{4.0, 1.0, 3.0, 2.0};
  const posefuse::Statistics s = posefuse::compute_statistics(e);
  CHECK(s.count == 4);
  CHECK(s.median == 2.5);
  CHECK(s.mean == 2.5);
  CHECK(s.sse == 30.0);
  CHECK(s.rmse == Approx(std::sqrt(7.5)).epsilon(1e-15));
  CHECK(s.std == Approx(std::sqrt(1.25)).epsilon(1e-15));
}

TEST_CASE("Statistics: a single error has zero spread", "[eval][statistics]") {
  const std::vector<double> e{0.75};
  const posefuse::Statistics s = posefuse::compute_statistics(e);
  CHECK(s.median == 0.75);
  CHECK(s.rmse == 0.75);
  CHECK(s.std == 0.0);
}

TEST_CASE("Statistics: empty or non-finite input is rejected", "[eval][statistics]") {
  CHECK_THROWS_AS(posefuse::compute_statistics(std::vector<double>{}), posefuse::invalid_argument);
  const std::vector<double> bad{1.0, std::numeric_limits<double>::quiet_NaN()};
  CHECK_THROWS_WITH(posefuse::compute_statistics(bad), Catch::Contains("error 1 is not finite"));
}

TEST_CASE("Statistics: median, min and max equal a full sort's on random series", "[eval][statistics]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (const std::size_t n : {1u, 2u, 3u, 10u, 11u, 1000u, 1001u}) {
    std::vector<double> e(n);
    for (double& x : e) x = u(rng);
    if (n >= 10) e[3] = e[7];  // a repeated value
    std::vector<double> sorted = e;
    std::sort(sorted.begin(), sorted.end());
    const posefuse::Statistics s = posefuse::compute_statistics(e);
    const std::size_t mid = n / 2;
    CHECK(s.median == (n % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid])));
    CHECK(s.min == sorted.front());
    CHECK(s.max == sorted.back());
  }
}

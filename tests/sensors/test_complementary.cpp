// Tests for filters/complementary.hpp (seed 001 eq 3-4).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/filters/complementary.hpp>

using posefuse::ComplementaryStatus;

TEMPLATE_TEST_CASE("ComplementaryFilter: eq 3-4 hand-worked step", "[sensors][complementary]", float,
                   double) {
  using T = TestType;
  using F = posefuse::ComplementaryFilter<T, 2>;
  using V = typename F::Vector;
  // alpha 0.98, dt 0.01 s:
  //  roll:  0.98 (0.1 + 0.5 * 0.01) + 0.02 * 0.2 = 0.98 * 0.105 + 0.004 = 0.1069
  //  pitch: 0.98 (-0.05 - 1.0 * 0.01) + 0.02 * 0 = 0.98 * -0.06 = -0.0588
  const V out = F::blend(V(T(0.1), T(-0.05)), V(T(0.5), T(-1.0)), T(0.01), V(T(0.2), T(0)), T(0.98));
  CHECK(out(0) == Approx(0.1069).epsilon(1e-5));
  CHECK(out(1) == Approx(-0.0588).epsilon(1e-5));

  // The same through update(): the first sample initialises, dt comes from the stamps.
  F f(T(0.98));
  CHECK(f.update(T(1.0), V(T(9), T(9)), V(T(0.1), T(-0.05))) == ComplementaryStatus::kInitialised);
  CHECK(f.estimate()(0) == Approx(0.1).epsilon(1e-6));
  CHECK(f.update(T(1.01), V(T(0.5), T(-1.0)), V(T(0.2), T(0))) == ComplementaryStatus::kUpdated);
  CHECK(f.estimate()(0) == Approx(0.1069).epsilon(1e-4));
  CHECK(f.estimate()(1) == Approx(-0.0588).epsilon(1e-4));
}

TEST_CASE("ComplementaryFilter: alpha 1 integrates the gyro, alpha 0 follows the accelerometer",
          "[sensors][complementary]") {
  using F = posefuse::ComplementaryFilter<double, 1>;
  using V = F::Vector;
  F gyro(1.0), accel(0.0);
  (void)gyro.update(0.0, V(0.0), V(0.0));
  (void)accel.update(0.0, V(0.0), V(0.0));
  for (int i = 1; i <= 100; ++i) {
    (void)gyro.update(0.01 * i, V(0.2), V(0.7));
    (void)accel.update(0.01 * i, V(0.2), V(0.7));
  }
  CHECK(gyro.estimate()(0) == Approx(0.2).epsilon(1e-9));  // 0.2 rad/s for 1 s
  CHECK(accel.estimate()(0) == Approx(0.7).epsilon(1e-12));
}

TEST_CASE("ComplementaryFilter: gyro bias leaves the predicted steady-state error",
          "[sensors][complementary]") {
  // Fixed point of e = alpha (e + b dt): e = alpha b dt / (1 - alpha) = 0.98 * 0.01 * 0.01 / 0.02
  //                                      = 0.0049 rad.
  using F = posefuse::ComplementaryFilter<double, 1>;
  F f(0.98);
  (void)f.update(0.0, F::Vector(0.0), F::Vector(0.3));
  for (int i = 1; i <= 2000; ++i) (void)f.update(0.01 * i, F::Vector(0.01), F::Vector(0.3));
  CHECK(f.estimate()(0) - 0.3 == Approx(0.0049).epsilon(1e-6));
  CHECK(posefuse::complementary_alpha(0.49, 0.01) == Approx(0.98));
}

TEST_CASE("ComplementaryFilter: blends along the short arc across +-180 deg",
          "[sensors][complementary]") {
  using F = posefuse::ComplementaryFilter<double, 1>;
  // prev 3.1, absolute -3.1 (0.083 rad apart across the seam), alpha 0.5:
  // 3.1 + 0.5 * wrap(-3.1 - 3.1) = 3.1 + 0.5 * 0.0831853 = 3.1415927 = pi -> wraps to -pi.
  const double out = F::blend(F::Vector(3.1), F::Vector(0.0), 0.01, F::Vector(-3.1), 0.5)(0);
  CHECK(std::abs(posefuse::angle_diff(out, std::numbers::pi)) < 1e-7);
  CHECK(out >= -std::numbers::pi);
  CHECK(out < std::numbers::pi);
}

TEST_CASE("ComplementaryFilter: bad configuration and bad samples are reported",
          "[sensors][complementary]") {
  using F = posefuse::ComplementaryFilter<double, 2>;
  using V = F::Vector;
  CHECK_THROWS_AS(F(-0.01), posefuse::invalid_argument);
  CHECK_THROWS_AS(F(1.01), posefuse::invalid_argument);
  CHECK_THROWS_AS(F(std::nan("")), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::complementary_alpha(0.0, 0.01), posefuse::invalid_argument);
  CHECK_NOTHROW(F(0.0));
  CHECK_NOTHROW(F(1.0));

  F f(0.9);
  (void)f.update(1.0, V::Zero(), V(0.1, 0.2));
  CHECK_THROWS_AS(f.update(1.0, V::Zero(), V::Zero()), posefuse::invalid_argument);   // equal stamp
  CHECK_THROWS_AS(f.update(0.5, V::Zero(), V::Zero()), posefuse::invalid_argument);   // going back
  CHECK_THROWS_AS(f.update(std::nan(""), V::Zero(), V::Zero()), posefuse::invalid_argument);
  CHECK(f.estimate() == V(0.1, 0.2));  // untouched by the throws

  // A non-finite sample is skipped; the next good one integrates over both intervals.
  CHECK(f.update(1.1, V(1.0, 0.0), V(std::nan(""), 0.0)) == ComplementaryStatus::kNonFinite);
  CHECK(f.last_time_s() == 1.0);
  CHECK(f.update(1.2, V(1.0, 0.0), V(0.1, 0.2)) == ComplementaryStatus::kUpdated);
  // roll: 0.9 (0.1 + 1.0 * 0.2) + 0.1 * 0.1 = 0.27 + 0.01 = 0.28
  CHECK(f.estimate()(0) == Approx(0.28).epsilon(1e-12));
  f.reset();
  CHECK_FALSE(f.initialised());
}

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <random>

using namespace posefuse;

TEMPLATE_TEST_CASE("Angles: wrap_angle maps into the half-open interval -pi to pi", "[core][angles]", float, double) {
  using T = TestType;
  constexpr T pi = std::numbers::pi_v<T>;
  CHECK(wrap_angle(T(0)) == T(0));
  CHECK(wrap_angle(pi) == Approx(-pi));
  CHECK(wrap_angle(-pi) == Approx(-pi));
  CHECK(wrap_angle(T(3) * pi) == Approx(-pi));
  CHECK(wrap_angle(T(2.5) * pi) == Approx(T(0.5) * pi));
  CHECK(wrap_angle(T(-2.5) * pi) == Approx(T(-0.5) * pi));
  std::mt19937 rng(7);
  std::uniform_real_distribution<T> u(T(-100), T(100));
  for (int i = 0; i < 1000; ++i) {
    const T a = u(rng);
    const T w = wrap_angle(a);
    REQUIRE(w >= -pi);
    REQUIRE(w < pi);
    REQUIRE(std::cos(w) == Approx(std::cos(a)).margin(1e-4));
    REQUIRE(std::sin(w) == Approx(std::sin(a)).margin(1e-4));
  }
  CHECK(std::isnan(wrap_angle(std::numeric_limits<T>::quiet_NaN())));
}

TEST_CASE("Angles: differences and means across +-180 degrees", "[core][angles]") {
  CHECK(rad2deg(angle_diff(deg2rad(-179.0), deg2rad(179.0))) == Approx(2.0));
  CHECK(rad2deg(angle_diff(deg2rad(179.0), deg2rad(-179.0))) == Approx(-2.0));
  const std::array<double, 2> a{deg2rad(179.0), deg2rad(-179.0)};
  // The plain average is 0 degrees -- the wrong side of the circle.
  CHECK((a[0] + a[1]) / 2 == Approx(0.0).margin(1e-12));
  CHECK(std::abs(rad2deg(circular_mean<double>(a))) == Approx(180.0));
  const std::array<double, 2> w{3.0, 1.0};
  CHECK(rad2deg(circular_mean<double>(a, w)) == Approx(179.5).epsilon(1e-3));
  CHECK(rad2deg(angle_interpolate(deg2rad(179.0), deg2rad(-179.0), 0.5)) == Approx(-180.0));
  const std::array<double, 2> opposite{0.0, std::numbers::pi};
  CHECK(std::isnan(circular_mean<double>(opposite)));
}

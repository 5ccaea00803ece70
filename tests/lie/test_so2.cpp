// Tests for lie/so2.hpp: the conformance harness on SO2<float> and SO2<double>,
// hand-worked rotations, wrapping at +-pi, small angles, (cos, sin) input checks.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/lie/so2.hpp>
#include <posefuse/testing/conformance.hpp>
#include <type_traits>

using posefuse::SO2;

namespace {
template <class T>
constexpr T pi = std::numbers::pi_v<T>;
template <class T>
T eps() {
  return std::numeric_limits<T>::epsilon();
}
}  // namespace

TEMPLATE_TEST_CASE("SO2: passes the Lie-group conformance checks", "[lie][so2]", float, double) {
  using T = TestType;
  // double: every Jacobian within 1e-10 of a long-double central difference;
  // float: within 2e-5 (about 170 float ulps; the largest error seen is ~1e-7).
  const bool is_double = std::is_same_v<T, double>;
  const auto r = posefuse::testing::check_lie_group<SO2<T>>(20240601u, is_double ? 400 : 100,
                                                            is_double ? 1e-10 : 2e-5);
  INFO(r.message);
  CHECK(r);
}

TEMPLATE_TEST_CASE("SO2: hand-worked rotations", "[lie][so2]", float, double) {
  using T = TestType;
  using P = Eigen::Matrix<T, 2, 1>;
  const T tol = T(8) * eps<T>();
  const SO2<T> q(pi<T> / 2);
  // A quarter turn maps x to y and y to -x.
  CHECK((q.act(P(1, 0)) - P(0, 1)).norm() < tol);
  CHECK((q.act(P(0, 1)) - P(-1, 0)).norm() < tol);
  Eigen::Matrix<T, 2, 2> M;
  M << 0, -1, 1, 0;
  CHECK((q.matrix() - M).norm() < tol);
  // Angles add and wrap: 3 + 1 = 4 rad = 4 - 2 pi.
  CHECK((SO2<T>(3) * SO2<T>(1)).angle() == Approx(4 - 2 * pi<T>).margin(tol * 4));
  // between(a, b) = b - a: from 3 rad to -3 rad is +0.283 rad (through pi).
  CHECK(SO2<T>(3).between(SO2<T>(-3)).angle() == Approx(2 * pi<T> - 6).margin(tol * 4));
  CHECK(SO2<T>(-3).minus(SO2<T>(3))(0) == Approx(2 * pi<T> - 6).margin(tol * 4));
  // plus wraps: 3 + 0.5 rad = 3.5 - 2 pi.
  CHECK(SO2<T>(3).plus(Eigen::Matrix<T, 1, 1>(T(0.5))).angle() ==
        Approx(3.5 - 2 * pi<T>).margin(tol * 4));
  CHECK(q.inverse().angle() == Approx(-pi<T> / 2).margin(tol));
  // hat / vee.
  CHECK(SO2<T>::hat(Eigen::Matrix<T, 1, 1>(T(0.7))) ==
        (Eigen::Matrix<T, 2, 2>() << 0, T(-0.7), T(0.7), 0).finished());
  CHECK(SO2<T>::vee(SO2<T>::hat(Eigen::Matrix<T, 1, 1>(T(0.7))))(0) == T(0.7));
}

TEMPLATE_TEST_CASE("SO2: angle() lies in [-pi, pi)", "[lie][so2]", float, double) {
  using T = TestType;
  // cos = -1, sin = +-0: the half-open interval sends the half turn to -pi.
  CHECK(SO2<T>::from_cos_sin(-1, 0).angle() == -pi<T>);
  CHECK(SO2<T>::from_cos_sin(-1, T(-0.0)).angle() == -pi<T>);
  // pi rounded to T is a little past or short of the true pi: SO2 of it lies
  // within an ulp of -pi or of pi.
  CHECK(std::abs(std::abs(SO2<T>(pi<T>).angle()) - pi<T>) <= T(2) * pi<T> * eps<T>());
  CHECK(SO2<T>(pi<T>).log()(0) == SO2<T>(pi<T>).angle());
  for (int k = -40; k <= 40; ++k) {
    const T a = T(k) * T(0.4);
    const T w = SO2<T>(a).angle();
    CHECK(w >= -pi<T>);
    CHECK(w < pi<T>);
    CHECK(std::cos(w) == Approx(std::cos(a)).margin(T(32) * eps<T>()));
    CHECK(std::sin(w) == Approx(std::sin(a)).margin(T(32) * eps<T>()));
  }
}

TEST_CASE("SO2: small angles and angles near pi are exact to rounding", "[lie][so2]") {
  // 1e-12 rad: cos = 1 - 5e-25 (rounds to 1), sin = 1e-12 exactly to 1 ulp.
  const SO2<double> s(1e-12);
  CHECK(s.cos() == 1.0);
  CHECK(s.sin() == Approx(1e-12).epsilon(1e-15));
  CHECK(s.log()(0) == Approx(1e-12).epsilon(1e-15));
  CHECK(s.act(Eigen::Vector2d(0, 1)).x() == Approx(-1e-12).epsilon(1e-15));
  // pi - 1e-7 and -(pi - 1e-7): log returns them to within about 2 ulps of pi.
  for (const double a : {std::numbers::pi - 1e-7, -std::numbers::pi + 1e-7}) {
    CHECK(std::abs(SO2<double>(a).log()(0) - a) < 1e-15);
    CHECK(std::abs(SO2<double>(a).angle() - a) < 1e-15);
  }
  // The difference of two angles on either side of pi is small, not ~2 pi.
  const SO2<double> y(std::numbers::pi - 1e-7), x(-std::numbers::pi + 1e-7);
  CHECK(y.minus(x)(0) == Approx(-2e-7).epsilon(1e-8));
  CHECK(x.minus(y)(0) == Approx(2e-7).epsilon(1e-8));
}

TEMPLATE_TEST_CASE("SO2: from_cos_sin normalises and rejects bad input", "[lie][so2]", float,
                   double) {
  using T = TestType;
  const SO2<T> r = SO2<T>::from_cos_sin(3, 4);
  CHECK(r.cos() == Approx(0.6).epsilon(4 * eps<T>()));
  CHECK(r.sin() == Approx(0.8).epsilon(4 * eps<T>()));
  CHECK(r.angle() == Approx(std::atan2(T(4), T(3))).epsilon(4 * eps<T>()));
  CHECK_THROWS_AS(SO2<T>::from_cos_sin(0, 0), posefuse::invalid_argument);
  CHECK_THROWS_AS(SO2<T>::from_cos_sin(T(1e-30), 0), posefuse::invalid_argument);
  CHECK_THROWS_AS(SO2<T>::from_cos_sin(std::numeric_limits<T>::quiet_NaN(), 1),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(SO2<T>::from_cos_sin(1, std::numeric_limits<T>::infinity()),
                  posefuse::invalid_argument);
  CHECK_THROWS_WITH(SO2<T>::from_cos_sin(0, 0), Catch::Contains("zero length"));
}

TEST_CASE("SO2: cast, is_approx and long chains of compositions", "[lie][so2]") {
  const SO2<double> a(0.3);
  const SO2<float> f = a.cast<float>();
  CHECK(f.angle() == Approx(0.3f).epsilon(1e-6));
  CHECK(f.cos() * f.cos() + f.sin() * f.sin() == Approx(1.0f).epsilon(2e-7));
  CHECK(a.is_approx(SO2<double>(0.3 + 1e-9), 2e-9));
  CHECK_FALSE(a.is_approx(SO2<double>(0.3 + 1e-3), 1e-4));
  // A million steps of 0.001 rad stay on the unit circle and add up.
  SO2<double> g;
  const SO2<double> step(1e-3);
  for (int i = 0; i < 1000000; ++i) g = g * step;
  CHECK(g.cos() * g.cos() + g.sin() * g.sin() == Approx(1.0).epsilon(4e-16));
  CHECK(g.angle() == Approx(posefuse::wrap_angle(1000.0)).margin(1e-9));
}

TEST_CASE("SO2: is a posefuse::Manifold", "[lie][so2]") {
  STATIC_REQUIRE(posefuse::Manifold<SO2<double>>);
  STATIC_REQUIRE(posefuse::Manifold<SO2<float>>);
  STATIC_REQUIRE(SO2<double>::Dim == 1);
  const SO2<double> x(3.1);
  Eigen::Matrix<double, 1, 1> d(0.2);  // crosses pi
  const auto r = posefuse::testing::check_manifold(x, d, 1e-15);
  INFO(r.message);
  CHECK(r);
}

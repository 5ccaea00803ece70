// Tests for lie/se2.hpp: the conformance harness on SE2<float> and SE2<double>,
// hand-worked poses, Exp of an arc, small-angle and near-pi branches.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/lie/se2.hpp>
#include <posefuse/testing/conformance.hpp>
#include <type_traits>

using posefuse::SE2;
using posefuse::SO2;

namespace {
template <class T>
constexpr T pi = std::numbers::pi_v<T>;
template <class T>
T eps() {
  return std::numeric_limits<T>::epsilon();
}
}  // namespace

TEMPLATE_TEST_CASE("SE2: passes the Lie-group conformance checks", "[lie][se2]", float, double) {
  using T = TestType;
  // double: Jacobians within 1e-10 of long-double central differences; float: 2e-5
  // (the largest error seen is ~1e-6, from translations of a few metres).
  const bool is_double = std::is_same_v<T, double>;
  const auto r = posefuse::testing::check_lie_group<SE2<T>>(7u, is_double ? 400 : 100,
                                                            is_double ? 1e-10 : 2e-5);
  INFO(r.message);
  CHECK(r);
}

TEMPLATE_TEST_CASE("SE2: compose, inverse, between and act of known poses", "[lie][se2]", float,
                   double) {
  using T = TestType;
  using P = Eigen::Matrix<T, 2, 1>;
  const T tol = T(16) * eps<T>();
  // a: at (1, 2) facing +y. b: 3 m ahead. a b: 3 m ahead of a along +y = (1, 5), still facing +y.
  const SE2<T> a(1, 2, pi<T> / 2), b(3, 0, 0);
  const SE2<T> ab = a * b;
  CHECK(ab.x() == Approx(1).margin(tol));
  CHECK(ab.y() == Approx(5).epsilon(tol));
  CHECK(ab.angle() == Approx(pi<T> / 2).epsilon(tol));
  // b a: a's offset (1, 2) taken in b's (unrotated) frame: (4, 2).
  const SE2<T> ba = b * a;
  CHECK(ba.x() == Approx(4).epsilon(tol));
  CHECK(ba.y() == Approx(2).epsilon(tol));
  // a^-1 = (-R^T t, -90 deg) with R^T (1, 2) = (2, -1): (-2, 1, -pi/2).
  const SE2<T> ai = a.inverse();
  CHECK(ai.x() == Approx(-2).epsilon(tol));
  CHECK(ai.y() == Approx(1).epsilon(tol));
  CHECK(ai.angle() == Approx(-pi<T> / 2).epsilon(tol));
  // between: ab seen from a is b.
  CHECK(a.between(ab).is_approx(b, tol * 4));
  // act: the body point (1, 0) of a is 1 m along +y from (1, 2).
  CHECK((a.act(P(1, 0)) - P(1, 3)).norm() < tol * 4);
  // Homogeneous matrix.
  Eigen::Matrix<T, 3, 3> M;
  M << 0, -1, 1, 1, 0, 2, 0, 0, 1;
  CHECK((a.matrix() - M).norm() < tol);
  CHECK(a.translation() == P(1, 2));
  CHECK(a.so2().angle() == a.angle());
  CHECK(SE2<T>(P(1, 2), SO2<T>(pi<T> / 2)).is_approx(a, tol));
}

TEMPLATE_TEST_CASE("SE2: Exp of a quarter arc and its Jacobian structure", "[lie][se2]", float,
                   double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  const T tol = T(16) * eps<T>();
  // Driving an arc of length pi/2 while turning pi/2 left (radius 1) from the
  // origin along +x ends at (1, 1) facing +y: V rho = (A, B) pi/2 with A = B = 2/pi.
  const SE2<T> g = SE2<T>::exp(V(pi<T> / 2, 0, pi<T> / 2));
  CHECK(g.x() == Approx(1).epsilon(tol));
  CHECK(g.y() == Approx(1).epsilon(tol));
  CHECK(g.angle() == Approx(pi<T> / 2).epsilon(tol));
  CHECK((g.log() - V(pi<T> / 2, 0, pi<T> / 2)).norm() < tol * 4);
  // Pure translation: Exp is the translation itself; J_r = I except the
  // rotation column, (-rho_y / 2, rho_x / 2) at theta = 0.
  const V tr(3, -4, 0);
  CHECK((SE2<T>::exp(tr).translation() - tr.template head<2>()).norm() == 0);
  Eigen::Matrix<T, 3, 3> Jr_expected;
  Jr_expected << 1, 0, 2, 0, 1, T(1.5), 0, 0, 1;
  CHECK((SE2<T>::right_jacobian(tr) - Jr_expected).norm() < tol);
  // Left Jacobian: the same with the opposite sign of the coupling column.
  Jr_expected(0, 2) = -2;
  Jr_expected(1, 2) = T(-1.5);
  CHECK((SE2<T>::left_jacobian(tr) - Jr_expected).norm() < tol);
  // Adjoint of a pose: [R, (t_y, -t_x); 0, 1].
  Eigen::Matrix<T, 3, 3> Ad;
  Ad << 0, -1, 2, 1, 0, -1, 0, 0, 1;
  CHECK((SE2<T>(1, 2, pi<T> / 2).adjoint() - Ad).norm() < tol);
}

TEST_CASE("SE2: the small-angle branch is exact at theta = 1e-12", "[lie][se2]") {
  using V = Eigen::Vector3d;
  // A = 1 - theta^2/6 = 1, B = theta/2 = 5e-13 (to 1e-37):
  // t = (A rho_x - B rho_y, B rho_x + A rho_y) = (1 - 1e-12, 2 + 5e-13).
  const V tau(1, 2, 1e-12);
  const SE2<double> g = SE2<double>::exp(tau);
  CHECK(g.x() == Approx(1 - 1e-12).epsilon(1e-16));
  CHECK(g.y() == Approx(2 + 5e-13).epsilon(1e-16));
  CHECK(g.angle() == Approx(1e-12).epsilon(1e-15));
  CHECK((g.log() - tau).cwiseAbs().maxCoeff() < 1e-16 * 4);
  // J_r: [A, B, C rho_x - D rho_y; -B, A, D rho_x + C rho_y; 0, 0, 1] with C = theta/6, D = 1/2.
  Eigen::Matrix3d J;
  J << 1, 5e-13, 1e-12 / 6 - 1, -5e-13, 1, 0.5 + 2e-12 / 6, 0, 0, 1;
  CHECK((SE2<double>::right_jacobian(tau) - J).cwiseAbs().maxCoeff() < 1e-16 * 4);
  CHECK((SE2<double>::right_jacobian_inverse(tau) * J - Eigen::Matrix3d::Identity())
            .cwiseAbs()
            .maxCoeff() < 1e-15);
}

TEST_CASE("SE2: near pi and at pi", "[lie][se2]") {
  using V = Eigen::Vector3d;
  using L = long double;
  for (const double th : {std::numbers::pi - 1e-7, -(std::numbers::pi - 1e-7)}) {
    const V tau(1, 0.5, th);
    const SE2<double> g = SE2<double>::exp(tau);
    // Reference in long double: A = sin th / th, B = (1 - cos th) / th (no cancellation near pi).
    const L t = L(th), A = std::sin(t) / t, B = (1 - std::cos(t)) / t;
    CHECK(double(std::abs(L(g.x()) - (A * 1 - B * 0.5L))) < 2e-16);
    CHECK(double(std::abs(L(g.y()) - (B * 1 + A * 0.5L))) < 2e-16);
    CHECK((g.log() - tau).cwiseAbs().maxCoeff() < 2e-15);
  }
  // Exactly pi: Log returns theta = -pi (the half-open interval) and Exp(Log(g)) = g.
  const SE2<double> g(Eigen::Vector2d(1, 2), SO2<double>::from_cos_sin(-1, 0));
  const V l = g.log();
  CHECK(l(2) == -std::numbers::pi);
  CHECK(SE2<double>::exp(l).is_approx(g, 1e-15));
  CHECK((SE2<double>::exp(l).translation() - g.translation()).norm() < 1e-15);
}

TEST_CASE("SE2: cast and Manifold", "[lie][se2]") {
  STATIC_REQUIRE(posefuse::Manifold<SE2<double>>);
  STATIC_REQUIRE(posefuse::Manifold<SE2<float>>);
  const SE2<double> a(1.5, -2.0, 3.0);
  const SE2<float> f = a.cast<float>();
  CHECK(f.x() == 1.5f);
  CHECK(f.y() == -2.0f);
  CHECK(f.angle() == Approx(3.0f).epsilon(1e-6));
  CHECK(f.cast<double>().is_approx(a, 1e-6));
  // plus / minus through the heading wrap at pi.
  const auto r = posefuse::testing::check_manifold(a, Eigen::Vector3d(0.3, -0.2, 0.5), 1e-15);
  INFO(r.message);
  CHECK(r);
}

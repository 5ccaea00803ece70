// Tests for lie/so3.hpp: the conformance harness on SO3<float> and SO3<double>,
// hand-worked rotations, the small-angle and near-pi branches of Exp / Log /
// Jacobians against analytic or long-double values, and conversions.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/lie/so3.hpp>
#include <posefuse/testing/conformance.hpp>
#include <random>
#include <type_traits>

using posefuse::SO3;

namespace {
template <class T>
constexpr T pi = std::numbers::pi_v<T>;
template <class T>
T eps() {
  return std::numeric_limits<T>::epsilon();
}
template <class T>
Eigen::Matrix<T, 3, 3> angle_axis(T a, const Eigen::Matrix<T, 3, 1>& axis) {
  return Eigen::AngleAxis<T>(a, axis.normalized()).toRotationMatrix();
}
}  // namespace

TEMPLATE_TEST_CASE("SO3: passes the Lie-group conformance checks", "[lie][so3]", float, double) {
  using T = TestType;
  // double: Jacobians within 1e-10 of long-double central differences; float: 2e-5.
  const bool is_double = std::is_same_v<T, double>;
  const auto r = posefuse::testing::check_lie_group<SO3<T>>(31337u, is_double ? 400 : 100,
                                                            is_double ? 1e-10 : 2e-5);
  INFO(r.message);
  CHECK(r);
}

TEMPLATE_TEST_CASE("SO3: Exp of pi/2 about z and other hand-worked rotations", "[lie][so3]", float,
                   double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  using M = Eigen::Matrix<T, 3, 3>;
  const T tol = T(8) * eps<T>();
  const SO3<T> Rz = SO3<T>::exp(V(0, 0, pi<T> / 2));
  M expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  CHECK((Rz.matrix() - expected).norm() < tol);
  // Quaternion (cos 45 deg, 0, 0, sin 45 deg).
  CHECK(Rz.quaternion().w() == Approx(std::sqrt(T(0.5))).epsilon(tol));
  CHECK(Rz.quaternion().z() == Approx(std::sqrt(T(0.5))).epsilon(tol));
  CHECK((Rz.act(V(1, 0, 0)) - V(0, 1, 0)).norm() < tol);
  CHECK((Rz.log() - V(0, 0, pi<T> / 2)).norm() < tol * 2);
  // Rz(90) Rx(90) = [[0,0,1],[1,0,0],[0,1,0]]: x -> y, y -> z, z -> x.
  const SO3<T> Rx = SO3<T>::exp(V(pi<T> / 2, 0, 0));
  expected << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  CHECK(((Rz * Rx).matrix() - expected).norm() < tol * 2);
  // That is a rotation by 120 deg about (1, 1, 1)/sqrt(3).
  const V l = (Rz * Rx).log();
  CHECK((l - V(1, 1, 1).normalized() * (T(2) * pi<T> / T(3))).norm() < tol * 8);
  // between, inverse, adjoint = R, hat = skew.
  CHECK(Rz.between(Rz * Rx).is_approx(Rx, tol * 4));
  CHECK((Rz.inverse().matrix() - Rz.matrix().transpose()).norm() < tol);
  CHECK(Rz.adjoint() == Rz.matrix());
  CHECK(SO3<T>::hat(V(1, 2, 3)) * V(4, 5, 6) == V(1, 2, 3).cross(V(4, 5, 6)));
  CHECK(SO3<T>::vee(SO3<T>::hat(V(1, 2, 3))) == V(1, 2, 3));
  // The legacy helpers of lie/rotation.hpp are the same implementation.
  CHECK(posefuse::so3_exp(V(0.1f, -0.2f, 0.3f)) == SO3<T>::exp(V(0.1f, -0.2f, 0.3f)).matrix());
  CHECK(posefuse::skew(V(1, 2, 3)) == SO3<T>::hat(V(1, 2, 3)));
}

TEST_CASE("SO3: small-angle branches are exact at |phi| = 1e-12", "[lie][so3]") {
  using V = Eigen::Vector3d;
  using M = Eigen::Matrix3d;
  const V phi = V(1, -2, 3).normalized() * 1e-12;
  const M W = SO3<double>::hat(phi);
  // R = I + W + W^2 / 2 + O(1e-36).
  const M R = SO3<double>::exp(phi).matrix();
  CHECK((R - (M::Identity() + W + 0.5 * W * W)).cwiseAbs().maxCoeff() < 2e-16);
  // Log returns phi to relative 1e-15.
  CHECK((SO3<double>::exp(phi).log() - phi).norm() < 1e-15 * 1e-12);
  // J_r = I - W / 2 + W^2 / 6, J_r^-1 = I + W / 2 + W^2 / 12 (to 1e-36).
  CHECK((SO3<double>::right_jacobian(phi) - (M::Identity() - 0.5 * W + W * W / 6.0))
            .cwiseAbs()
            .maxCoeff() < 1e-28);
  CHECK((SO3<double>::right_jacobian_inverse(phi) - (M::Identity() + 0.5 * W + W * W / 12.0))
            .cwiseAbs()
            .maxCoeff() < 1e-28);
  CHECK((SO3<double>::left_jacobian(phi) - SO3<double>::right_jacobian(phi).transpose())
            .cwiseAbs()
            .maxCoeff() == 0);
  // phi = 0 exactly: identity, Jacobians I.
  CHECK(SO3<double>::exp(V::Zero()).matrix() == M::Identity());
  CHECK(SO3<double>().log() == V::Zero());
  CHECK(SO3<double>::right_jacobian(V::Zero()) == M::Identity());
  CHECK(SO3<double>::right_jacobian_inverse(V::Zero()) == M::Identity());
}

TEST_CASE("SO3: Jacobian coefficients are accurate on both sides of the series switch",
          "[lie][so3]") {
  // Just below and above 0.5 rad (lie/detail/series.hpp's switch) and at
  // smaller angles, each coefficient times the norm of the matrix it
  // multiplies (theta^2 for both) matches the long-double closed form to a few ulps.
  using L = long double;
  for (const double th : {0.5 - 1e-12, 0.5, 0.5 + 1e-12, 0.8, 0.1, 1e-3, 1e-6}) {
    const L t = th;
    const L c1 = (t - std::sin(t)) / (t * t * t);
    const L e = 1 / (t * t) - (1 + std::cos(t)) / (2 * t * std::sin(t));
    INFO("theta " << th);
    CHECK(double(std::abs(L(posefuse::detail::x_minus_sin_over_x3(th)) - c1) * t * t) < 1e-15);
    CHECK(double(std::abs(L(posefuse::detail::so3_jinv_coeff(th)) - e) * t * t) < 1e-15);
    const L sh = std::sin(t / 2);  // (1 - cos t) / t^2 without cancellation
    CHECK(double(std::abs(L(posefuse::detail::one_minus_cos_over_x2(th)) - 2 * sh * sh / (t * t)) *
                 t) < 1e-15);
  }
}

TEST_CASE("SO3: near pi and at pi", "[lie][so3]") {
  using V = Eigen::Vector3d;
  using L = long double;
  std::mt19937 rng(99);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 50; ++i) {
    const V axis = V(n(rng), n(rng), n(rng)).normalized();
    const V phi = (std::numbers::pi - 1e-7) * axis;
    // Exp against a long-double Rodrigues matrix (a few ulps of the entries).
    const Eigen::Matrix<L, 3, 3> ref = angle_axis<L>(L(phi.norm()), phi.cast<L>());
    CHECK(double((SO3<double>::exp(phi).matrix().cast<L>() - ref).cwiseAbs().maxCoeff()) < 1e-15);
    // Log from the quaternion, and from the rounded matrix, both give phi back.
    CHECK((SO3<double>::exp(phi).log() - phi).norm() < 2e-15);
    const SO3<double> from_matrix(Eigen::Matrix3d(ref.cast<double>()));
    CHECK((from_matrix.log() - phi).norm() < 4e-15);
    // J_r^-1 at pi - 1e-7 is finite: coefficient 1/th^2 - (1 + cos th)/(2 th sin th) ~ 1/pi^2.
    const Eigen::Matrix3d Ji = SO3<double>::right_jacobian_inverse(phi);
    CHECK(Ji.allFinite());
    CHECK((Ji * SO3<double>::right_jacobian(phi) - Eigen::Matrix3d::Identity()).norm() < 1e-14);
  }
  // Exactly pi about x: R = diag(1, -1, -1); Log = +-(pi, 0, 0); the quaternion w = 0.
  Eigen::Matrix3d R = Eigen::Vector3d(1, -1, -1).asDiagonal();
  const SO3<double> g(R);
  CHECK(g.quaternion().w() == 0);
  const V l = g.log();
  CHECK(std::abs(l.x()) == Approx(std::numbers::pi).epsilon(1e-16));
  CHECK(l.y() == 0);
  CHECK(l.z() == 0);
  CHECK((SO3<double>::exp(l).matrix() - R).cwiseAbs().maxCoeff() < 1e-15);
  // Exp of exactly pi about an arbitrary axis and back.
  const V phi = V(0.3, -0.5, 0.8).normalized() * std::numbers::pi;
  const SO3<double> h = SO3<double>::exp(phi);
  const V back = h.log();
  CHECK(back.norm() == Approx(std::numbers::pi).epsilon(1e-15));
  CHECK(std::abs(back.normalized().dot(phi.normalized())) == Approx(1).epsilon(1e-15));
  CHECK(SO3<double>::exp(back).is_approx(h, 1e-15));
  CHECK(SO3<double>::right_jacobian_inverse(back).allFinite());
}

TEST_CASE("SO3: Exp and J_r of large finite angles: long double below 3e9 rad, finite up to the largest double",
          "[lie][so3]") {
  using V = Eigen::Vector3d;
  using L = long double;
  // Axis (1, 2, 2) / 3 scaled by 2^k: |phi| = 3 * 2^k exactly, also where
  // |phi|^2 overflows (the norm is then scaled by the largest entry, 2^(k+1)).
  const V u = V(1, 2, 2) / 3.0;
  // Above detail::large_angle (6.7e7 rad) double takes the axis form; the
  // long-double closed form is still the ordinary one below 3e9 rad (x87).
  if constexpr (std::numeric_limits<L>::digits > 53) {
    for (const int k : {25, 27, 29}) {
      const V phi = std::ldexp(1.0, k) * V(1, 2, 2);
      INFO("|phi| = 3 * 2^" << k);
      REQUIRE(phi.norm() > posefuse::detail::large_angle<double>());
      REQUIRE(L(phi.norm()) < posefuse::detail::large_angle<L>());
      Eigen::Matrix3d J;
      Eigen::Matrix<L, 3, 3> J_ref;
      const SO3<double> g = SO3<double>::exp(phi, &J);
      const SO3<L> ref = SO3<L>::exp(phi.cast<L>(), &J_ref);
      CHECK(double((g.matrix().cast<L>() - ref.matrix()).cwiseAbs().maxCoeff()) < 4e-16);
      CHECK(double((J.cast<L>() - J_ref).cwiseAbs().maxCoeff()) < 4e-16);
    }
  }
  for (const int k : {60, 500, 996, 1022}) {  // 3 * 2^1022 is above DBL_MAX / 2: |phi|^2 and 2 |phi| overflow
    const V phi = std::ldexp(1.0, k) * V(1, 2, 2);
    const double th = 3.0 * std::ldexp(1.0, k);
    INFO("|phi| = 3 * 2^" << k);
    REQUIRE(std::isfinite(th));
    Eigen::Matrix3d J;
    const SO3<double> g = SO3<double>::exp(phi, &J);
    const Eigen::Matrix3d R = g.matrix();
    REQUIRE(R.allFinite());
    CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15);
    // A rotation about u (R u = u) by th: trace R = 1 + 2 cos th (cos reduces th exactly).
    CHECK((R * u - u).cwiseAbs().maxCoeff() < 1e-15);
    CHECK(std::abs(R.trace() - (1.0 + 2.0 * std::cos(th))) < 4e-15);
    // J_r(phi) phi = phi; away from 0 the rest of J_r is 1/th small: J_r = u u^T + O(1/th).
    REQUIRE(J.allFinite());
    CHECK((J * u - u).cwiseAbs().maxCoeff() < 1e-15);
    CHECK((J - u * u.transpose()).cwiseAbs().maxCoeff() < 1e-15);
  }
  // Non-finite stays non-finite.
  CHECK_FALSE(SO3<double>::exp(V(std::numeric_limits<double>::infinity(), 0, 0)).matrix().allFinite());
  CHECK_FALSE(SO3<double>::exp(V(std::numeric_limits<double>::quiet_NaN(), 0, 0)).matrix().allFinite());
}

TEMPLATE_TEST_CASE("SO3: quaternion and matrix constructors normalise and validate", "[lie][so3]",
                   float, double) {
  using T = TestType;
  using Q = Eigen::Quaternion<T>;
  using M = Eigen::Matrix<T, 3, 3>;
  using V = Eigen::Matrix<T, 3, 1>;
  const T tol = T(8) * eps<T>();
  // Any non-zero quaternion is normalised: (2, 0, 0, 0) is the identity.
  CHECK(SO3<T>(Q(2, 0, 0, 0)).matrix() == M::Identity());
  const SO3<T> r(Q(1, 1, 0, 0));  // 90 deg about x
  CHECK(r.quaternion().norm() == Approx(1).epsilon(tol));
  CHECK((r.log() - V(pi<T> / 2, 0, 0)).norm() < tol * 2);
  // q and -q are the same rotation; Log picks the representative with w >= 0.
  const Q q = Q(T(0.2), T(-0.4), T(0.5), T(0.7)).normalized();
  CHECK((SO3<T>(q).log() - SO3<T>(Q(-q.coeffs())).log()).norm() < tol);
  // Rotation matrix -> SO3 -> matrix round trip.
  const M R = angle_axis<T>(T(2.2), V(1, 2, -1));
  CHECK((SO3<T>(R).matrix() - R).norm() < tol * 4);
  // A matrix with rounding-level noise (1e-7) is accepted and projected onto SO(3).
  M noisy = R;
  noisy(0, 1) += T(1e-7);
  const M P = SO3<T>(noisy).matrix();
  CHECK((P.transpose() * P - M::Identity()).norm() < tol * 4);
  CHECK((P - R).norm() < T(1e-6));

  const T nan = std::numeric_limits<T>::quiet_NaN();
  CHECK_THROWS_AS(SO3<T>(Q(0, 0, 0, 0)), posefuse::invalid_argument);
  CHECK_THROWS_AS(SO3<T>(Q(nan, 0, 0, 1)), posefuse::invalid_argument);
  CHECK_THROWS_AS(SO3<T>(Q(1, std::numeric_limits<T>::infinity(), 0, 0)),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(SO3<T>(M(T(1.01) * R)), posefuse::invalid_argument);  // not orthonormal
  CHECK_THROWS_WITH(SO3<T>(M(T(1.01) * R)), Catch::Contains("not orthonormal"));
  M reflection = M::Identity();
  reflection(2, 2) = -1;
  CHECK_THROWS_WITH(SO3<T>(reflection), Catch::Contains("reflection"));
  M bad = R;
  bad(1, 1) = nan;
  CHECK_THROWS_WITH(SO3<T>(bad), Catch::Contains("non-finite"));
  CHECK_THROWS_AS(SO3<T>(M::Zero()), posefuse::invalid_argument);
  // A looser tolerance can be asked for explicitly.
  CHECK_NOTHROW(SO3<T>(M(T(1.001) * R), T(0.01)));
  // so3_log (lie/rotation.hpp) validates through the same constructor.
  CHECK_THROWS_AS(posefuse::so3_log(M(T(1.01) * R)), posefuse::invalid_argument);
}

TEST_CASE("SO3: cast, is_approx, long chains and Manifold", "[lie][so3]") {
  STATIC_REQUIRE(posefuse::Manifold<SO3<double>>);
  STATIC_REQUIRE(posefuse::Manifold<SO3<float>>);
  const SO3<double> a = SO3<double>::exp(Eigen::Vector3d(0.3, -1.2, 2.0));
  const SO3<float> f = a.cast<float>();
  CHECK(f.quaternion().norm() == Approx(1.0f).epsilon(2e-7));
  CHECK(f.cast<double>().is_approx(a, 1e-6));
  CHECK_FALSE(f.cast<double>().is_approx(a.plus(Eigen::Vector3d(1e-3, 0, 0)), 1e-4));
  // 100000 compositions of a small rotation stay a unit quaternion and add up.
  const Eigen::Vector3d w = Eigen::Vector3d(1, 2, 2) / 3.0;  // unit axis
  SO3<double> g;
  const SO3<double> step = SO3<double>::exp(w * 1e-4);
  for (int i = 0; i < 100000; ++i) g = g * step;
  CHECK(g.quaternion().norm() == Approx(1.0).epsilon(4e-16));
  CHECK((g.log() - w * posefuse::wrap_angle(10.0)).norm() < 1e-10);
  const auto r = posefuse::testing::check_manifold(a, Eigen::Vector3d(0.4, 2.0, -1.5), 1e-14);
  INFO(r.message);
  CHECK(r);
}

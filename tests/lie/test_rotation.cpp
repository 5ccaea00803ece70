// Tests for lie/rotation.hpp: ZYX Euler <-> rotation matrix with the
// gimbal-lock cases of seed 001 eq 11-13, pose matrix -> position + Euler,
// and SO(3) exp / log / right Jacobian.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/lie/rotation.hpp>
#include <random>

using posefuse::EulerZYX;

namespace {
template <class T>
T tol() {
  return std::is_same_v<T, float> ? T(2e-5) : T(1e-12);
}
template <class T>
Eigen::Matrix<T, 3, 3> Rx(T a) {
  return Eigen::AngleAxis<T>(a, Eigen::Matrix<T, 3, 1>::UnitX()).toRotationMatrix();
}
template <class T>
Eigen::Matrix<T, 3, 3> Ry(T a) {
  return Eigen::AngleAxis<T>(a, Eigen::Matrix<T, 3, 1>::UnitY()).toRotationMatrix();
}
template <class T>
Eigen::Matrix<T, 3, 3> Rz(T a) {
  return Eigen::AngleAxis<T>(a, Eigen::Matrix<T, 3, 1>::UnitZ()).toRotationMatrix();
}
}  // namespace

TEMPLATE_TEST_CASE("Rotation: euler -> R matches hand-worked matrices", "[lie][rotation]", float,
                   double) {
  using T = TestType;
  constexpr T h = std::numbers::pi_v<T> / 2;
  // yaw = 90 deg only: x_body -> y_world.  R = [[0,-1,0],[1,0,0],[0,0,1]].
  Eigen::Matrix<T, 3, 3> expected;
  expected << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  CHECK((posefuse::rotation_from_euler_zyx(EulerZYX<T>{0, 0, h}) - expected).norm() < tol<T>());
  // roll = 90, yaw = 90: Rz(90) Rx(90) = [[0,-1,0],[1,0,0],[0,0,1]] * [[1,0,0],[0,0,-1],[0,1,0]]
  //                                     = [[0,0,1],[1,0,0],[0,1,0]].
  expected << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  const Eigen::Matrix<T, 3, 3> R = posefuse::rotation_from_euler_zyx(EulerZYX<T>{h, 0, h});
  CHECK((R - expected).norm() < tol<T>());
  // Back (eq 12, 13-c): pitch = atan2(-p31, sqrt(p11^2 + p21^2)) = atan2(0, 1) = 0,
  // yaw = atan2(p21, p11) = atan2(1, 0) = 90 deg, roll = atan2(p32, p33) = atan2(1, 0) = 90 deg.
  const EulerZYX<T> e = posefuse::euler_zyx_from_rotation(R);
  CHECK(e.pitch == Approx(0).margin(tol<T>()));
  CHECK(e.yaw == Approx(h).epsilon(tol<T>()));
  CHECK(e.roll == Approx(h).epsilon(tol<T>()));
  // Same as Eigen's composition of elementary rotations.
  const EulerZYX<T> g{T(0.3), T(-0.4), T(2.5)};
  CHECK((posefuse::rotation_from_euler_zyx(g) - Rz(g.yaw) * Ry(g.pitch) * Rx(g.roll)).norm() <
        tol<T>() * 4);
}

TEMPLATE_TEST_CASE("Rotation: round trip euler -> R -> euler away from gimbal lock",
                   "[lie][rotation]", float, double) {
  using T = TestType;
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> ang(-3.1, 3.1);
  std::uniform_real_distribution<double> pit(-1.45, 1.45);  // |pitch| <= 83 deg
  for (int i = 0; i < 500; ++i) {
    const EulerZYX<T> e{T(ang(rng)), T(pit(rng)), T(ang(rng))};
    const EulerZYX<T> b = posefuse::euler_zyx_from_rotation(posefuse::rotation_from_euler_zyx(e));
    const T t = std::is_same_v<T, float> ? T(5e-5) : T(1e-11);
    REQUIRE(posefuse::angle_diff(b.roll, e.roll) == Approx(0).margin(t));
    REQUIRE(b.pitch == Approx(e.pitch).margin(t));
    REQUIRE(posefuse::angle_diff(b.yaw, e.yaw) == Approx(0).margin(t));
  }
}

TEMPLATE_TEST_CASE("Rotation: gimbal lock at exactly +-90 deg pitch (eq 13-a, 13-b)",
                   "[lie][rotation]", float, double) {
  using T = TestType;
  constexpr T h = std::numbers::pi_v<T> / 2;
  // Hand-built: yaw 0.3, pitch +90, roll 0: Rz(0.3) Ry(90) with Ry(90) = [[0,0,1],[0,1,0],[-1,0,0]]
  // gives [[0,-s,c],[0,c,s],[-1,0,0]] (c, s = cos, sin 0.3): p31 = -1 -> pitch = atan2(1, 0) = +90;
  // eq 13-b: yaw = atan2(p23, p13) = atan2(s, c) = 0.3, roll = 0.
  const T c = std::cos(T(0.3)), s = std::sin(T(0.3));
  Eigen::Matrix<T, 3, 3> R;
  R << 0, -s, c, 0, c, s, -1, 0, 0;
  EulerZYX<T> e = posefuse::euler_zyx_from_rotation(R);
  CHECK(e.pitch == h);
  CHECK(e.roll == 0);
  CHECK(e.yaw == Approx(0.3).epsilon(tol<T>()));
  // pitch -90: Rz(0.3) Ry(-90) = [[0,-s,-c],[0,c,-s],[1,0,0]]; eq 13-a: yaw = atan2(-p23, -p13) = 0.3.
  R << 0, -s, -c, 0, c, -s, 1, 0, 0;
  e = posefuse::euler_zyx_from_rotation(R);
  CHECK(e.pitch == -h);
  CHECK(e.roll == 0);
  CHECK(e.yaw == Approx(0.3).epsilon(tol<T>()));

  // With roll: at pitch +90 only yaw - roll is observable, at -90 only yaw + roll.
  const T yaw = T(0.5), roll = T(0.2);
  e = posefuse::euler_zyx_from_rotation(posefuse::rotation_from_euler_zyx(EulerZYX<T>{roll, h, yaw}));
  CHECK(e.roll == 0);
  CHECK(e.pitch == Approx(h).epsilon(tol<T>()));
  CHECK(e.yaw == Approx(yaw - roll).epsilon(tol<T>() * 10));
  e = posefuse::euler_zyx_from_rotation(posefuse::rotation_from_euler_zyx(EulerZYX<T>{roll, -h, yaw}));
  CHECK(e.roll == 0);
  CHECK(e.pitch == Approx(-h).epsilon(tol<T>()));
  CHECK(e.yaw == Approx(yaw + roll).epsilon(tol<T>() * 10));
  // Either way the angles reproduce the rotation.
  for (const T p : {h, -h}) {
    const Eigen::Matrix<T, 3, 3> R0 = posefuse::rotation_from_euler_zyx(EulerZYX<T>{roll, p, yaw});
    const Eigen::Matrix<T, 3, 3> R1 =
        posefuse::rotation_from_euler_zyx(posefuse::euler_zyx_from_rotation(R0));
    CHECK((R1 - R0).norm() < tol<T>() * 10);
  }
}

TEMPLATE_TEST_CASE("Rotation: near gimbal lock the result still reproduces R", "[lie][rotation]",
                   float, double) {
  using T = TestType;
  constexpr T h = std::numbers::pi_v<T> / 2;
  const T lock = posefuse::gimbal_lock_tolerance<T>();
  // Offsets well inside the generic branch, at its edge, and inside the lock branch.
  const T offsets[] = {T(100) * lock, T(2) * lock, lock / T(2), lock / T(100)};
  for (const T sign : {T(1), T(-1)}) {
    for (const T off : offsets) {
      const EulerZYX<T> e{T(0.4), sign * (h - off), T(-1.1)};
      const Eigen::Matrix<T, 3, 3> R = posefuse::rotation_from_euler_zyx(e);
      const EulerZYX<T> b = posefuse::euler_zyx_from_rotation(R);
      INFO("sign " << sign << " offset " << off);
      CHECK(std::isfinite(b.roll));
      CHECK(std::isfinite(b.yaw));
      CHECK(std::abs(b.pitch) <= h);
      // Error bounded by ~max(eps / cos pitch, cos pitch) ~ a few times lock.
      CHECK((posefuse::rotation_from_euler_zyx(b) - R).norm() < T(8) * lock);
    }
  }
  // Well away from the lock the angles themselves come back.
  const EulerZYX<T> e{T(0.4), h - T(1000) * lock, T(-1.1)};
  const EulerZYX<T> b = posefuse::euler_zyx_from_rotation(posefuse::rotation_from_euler_zyx(e));
  CHECK(b.roll == Approx(e.roll).margin((std::is_same_v<T, float> ? T(1e-4) : T(1e-8))));
  CHECK(b.yaw == Approx(e.yaw).margin((std::is_same_v<T, float> ? T(1e-4) : T(1e-8))));
}

TEMPLATE_TEST_CASE("Rotation: position_and_euler reads a pose matrix (eq 11)", "[lie][rotation]",
                   float, double) {
  using T = TestType;
  const EulerZYX<T> e{T(0.1), T(-0.2), T(2.0)};
  Eigen::Matrix<T, 4, 4> P = Eigen::Matrix<T, 4, 4>::Identity();
  P.template block<3, 3>(0, 0) = posefuse::rotation_from_euler_zyx(e);
  P.template block<3, 1>(0, 3) << T(1.5), T(-2), T(0.25);  // p14, p24, p34
  const posefuse::PositionEuler<T> pe = posefuse::position_and_euler(P);
  CHECK(pe.position.x() == T(1.5));
  CHECK(pe.position.y() == T(-2));
  CHECK(pe.position.z() == T(0.25));
  CHECK(pe.euler.roll == Approx(e.roll).margin(tol<T>() * 10));
  CHECK(pe.euler.pitch == Approx(e.pitch).margin(tol<T>() * 10));
  CHECK(pe.euler.yaw == Approx(e.yaw).margin(tol<T>() * 10));

  Eigen::Transform<T, 3, Eigen::Isometry> iso(P);
  const posefuse::PositionEuler<T> pi = posefuse::position_and_euler(iso);
  CHECK(pi.position == pe.position);
  CHECK(pi.euler.yaw == pe.euler.yaw);
}

TEMPLATE_TEST_CASE("Rotation: SO(3) exp and log are inverse, also near 0 and pi",
                   "[lie][rotation]", float, double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  const T t = std::is_same_v<T, float> ? T(2e-5) : T(1e-12);
  // Hand: exp of (0, 0, pi/2) is Rz(90).
  CHECK((posefuse::so3_exp(V(0, 0, std::numbers::pi_v<T> / 2)) - Rz(std::numbers::pi_v<T> / 2)).norm() < t);
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    V axis = V(T(n(rng)), T(n(rng)), T(n(rng))).normalized();
    const T mags[] = {T(0), T(1e-9), T(1e-4), T(0.005), T(0.3), T(2.0), std::numbers::pi_v<T> - T(1e-3),
                      std::numbers::pi_v<T> - T(1e-6)};
    const T mag = mags[i % 8];
    const V phi = mag * axis;
    const Eigen::Matrix<T, 3, 3> R = posefuse::so3_exp(phi);
    REQUIRE((R.transpose() * R - Eigen::Matrix<T, 3, 3>::Identity()).norm() < T(10) * t);
    const V back = posefuse::so3_log(R);
    // log returns |phi| <= pi, so compare rotations, and vectors away from pi.
    REQUIRE((posefuse::so3_exp(back) - R).norm() < T(50) * t);
    if (mag < T(3)) REQUIRE((back - phi).norm() < T(50) * t);
  }
}

TEST_CASE("Rotation: SO(3) right Jacobian matches central differences", "[lie][rotation]") {
  using V = Eigen::Vector3d;
  for (const V& phi : {V(0.3, -0.2, 0.5), V(1e-4, 2e-4, -1e-4), V(0, 0, 0), V(2.0, 1.0, -0.5)}) {
    const Eigen::Matrix3d Jr = posefuse::so3_right_jacobian(phi);
    const Eigen::Matrix3d R = posefuse::so3_exp(phi);
    Eigen::Matrix3d Jn;
    const double e = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const V d = V::Unit(k) * e;
      // exp(phi + d) = exp(phi) exp(Jr d)  =>  Jr d = log(exp(phi)^T exp(phi + d))
      Jn.col(k) = (posefuse::so3_log(R.transpose() * posefuse::so3_exp(V(phi + d))) -
                   posefuse::so3_log(R.transpose() * posefuse::so3_exp(V(phi - d)))) /
                  (2 * e);
    }
    CHECK((Jr - Jn).norm() < 1e-8);
  }
}

// Tests for sensors/accelerometer_tilt.hpp (seed 001 eq 1-2 in the REP-103 form) and
// seed/accelerometer_tilt.hpp (eq 1-2 as printed).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/seed/accelerometer_tilt.hpp>
#include <posefuse/sensors/accelerometer_tilt.hpp>
#include <random>

namespace {
template <class T>
T tol() {
  return std::is_same_v<T, float> ? T(1e-5) : T(1e-13);
}
/// Specific force at rest, REP-103: a = R^T (0, 0, g).
template <class T>
Eigen::Matrix<T, 3, 1> at_rest(T roll, T pitch, T yaw, T g = T(9.81)) {
  const Eigen::Matrix<T, 3, 3> R = posefuse::rotation_from_euler_zyx(posefuse::EulerZYX<T>{roll, pitch, yaw});
  return R.transpose() * Eigen::Matrix<T, 3, 1>(0, 0, g);
}
}  // namespace

TEMPLATE_TEST_CASE("AccelerometerTilt: eq 1-2 as printed, hand-worked", "[sensors][tilt]", float,
                   double) {
  using T = TestType;
  // a = (1, 2, 2): rho_a = atan(1 / sqrt(4 + 4)) = atan(0.353553) = 0.339837 rad (eq 1),
  //                phi_a = atan(2 / sqrt(1 + 4)) = atan(0.894427) = 0.729728 rad (eq 2).
  const posefuse::Tilt<T> t = posefuse::seed::accelerometer_tilt(Eigen::Matrix<T, 3, 1>(1, 2, 2));
  CHECK(t.roll == Approx(0.3398369094541219).epsilon(tol<T>()));
  CHECK(t.pitch == Approx(0.7297276562269663).epsilon(tol<T>()));
  // atan keeps both in [-90, 90] deg even with the sensor upside down (az < 0).
  const posefuse::Tilt<T> u = posefuse::seed::accelerometer_tilt(Eigen::Matrix<T, 3, 1>(1, 2, -2));
  CHECK(u.roll == Approx(t.roll).epsilon(tol<T>()));
  CHECK(u.pitch == Approx(t.pitch).epsilon(tol<T>()));
}

TEMPLATE_TEST_CASE("AccelerometerTilt: REP-103 form, hand-worked", "[sensors][tilt]", float, double) {
  using T = TestType;
  // Level: a = (0, 0, 9.81) -> roll = atan2(0, 9.81) = 0, pitch = atan2(-0, 9.81) = 0.
  posefuse::Tilt<T> t = posefuse::accelerometer_tilt_rep103(Eigen::Matrix<T, 3, 1>(0, 0, T(9.81)));
  CHECK(t.roll == 0);
  CHECK(t.pitch == 0);
  // Rolled 30 deg left side up about x: a = g (0, sin 30, cos 30) = (0, 4.905, 8.49571)
  //   roll = atan2(4.905, 8.49571) = 30 deg.
  t = posefuse::accelerometer_tilt_rep103(Eigen::Matrix<T, 3, 1>(0, T(4.905), T(8.495709211)));
  CHECK(t.roll == Approx(std::numbers::pi / 6).epsilon(T(1e-5)));
  CHECK(t.pitch == Approx(0).margin(tol<T>()));
  // Nose down 20 deg (pitch +20 about y, REP-103): a = g (-sin 20, 0, cos 20) = (-3.35520, 0, 9.21840)
  //   pitch = atan2(3.35520, 9.21840) = 20 deg.
  t = posefuse::accelerometer_tilt_rep103(Eigen::Matrix<T, 3, 1>(T(-3.355203), 0, T(9.218398)));
  CHECK(t.pitch == Approx(posefuse::deg2rad(20.0)).epsilon(T(1e-5)));
  CHECK(t.roll == Approx(0).margin(tol<T>()));
}

TEMPLATE_TEST_CASE("AccelerometerTilt: REP-103 form inverts gravity at any attitude",
                   "[sensors][tilt]", float, double) {
  using T = TestType;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> roll(-3.1, 3.1), pitch(-1.5, 1.5), yaw(-3.1, 3.1);
  for (int i = 0; i < 1000; ++i) {
    const T r = T(roll(rng)), p = T(pitch(rng)), y = T(yaw(rng));
    const posefuse::Tilt<T> t = posefuse::accelerometer_tilt_rep103(at_rest(r, p, y));
    const T m = std::is_same_v<T, float> ? T(2e-4) : T(1e-10);
    REQUIRE(posefuse::angle_diff(t.roll, r) == Approx(0).margin(m));
    REQUIRE(t.pitch == Approx(p).margin(m));
  }
}

TEMPLATE_TEST_CASE("AccelerometerTilt: the seed's angles in REP-103 axes", "[sensors][tilt]", float,
                   double) {
  using T = TestType;
  // Documented relation: rho_a = -pitch, phi_a = asin(cos(pitch) sin(roll)).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ang(-1.2, 1.2);
  for (int i = 0; i < 200; ++i) {
    const T r = T(ang(rng)), p = T(ang(rng));
    const posefuse::Tilt<T> s = posefuse::seed::accelerometer_tilt(at_rest(r, p, T(0.3)));
    const T m = std::is_same_v<T, float> ? T(1e-5) : T(1e-12);
    REQUIRE(s.roll == Approx(-p).margin(m));
    REQUIRE(s.pitch == Approx(std::asin(std::cos(p) * std::sin(r))).margin(m));
  }
}

TEST_CASE("AccelerometerTilt: the stage flags unusable readings", "[sensors][tilt]") {
  posefuse::AccelerometerTiltStage stage;
  posefuse::ImuSample s;
  s.t_ns = 1'000'000'000;
  s.accel_mps2 << 0, 0, 9.81;
  posefuse::TiltedImu out = stage(s);
  CHECK(out.status == posefuse::SampleStatus::kOk);
  CHECK(out.tilt.roll == 0);
  CHECK(out.imu.t_ns == 1'000'000'000);
  s.accel_mps2.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK(stage(s).status == posefuse::SampleStatus::kNonFinite);
  s.accel_mps2.setZero();
  CHECK(stage(s).status == posefuse::SampleStatus::kNonFinite);
}

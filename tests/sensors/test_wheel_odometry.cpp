// Tests for sensors/wheel_odometry.hpp (seed 001 eq 8-9).
#include <catch2/catch.hpp>

#include <cstdint>
#include <limits>

#include <cmath>
#include <numbers>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/sensors/wheel_odometry.hpp>

using posefuse::DiffDriveParams;
using posefuse::WheelTicks;

namespace {
// 1000 ticks/rev, r = 5 cm, d = 40 cm: m_tick = 2 pi 0.05 / 1000 = 3.14159e-4 m.
const DiffDriveParams kParams{1000.0, 0.05, 0.40};
}  // namespace

TEMPLATE_TEST_CASE("WheelOdometry: eq 8 averages front and back wheels", "[sensors][odometry]",
                   float, double) {
  using T = TestType;
  // E_L = (100 + 102) / 2 = 101, E_R = (204 + 200) / 2 = 202.
  const posefuse::SideTicks<T> s = posefuse::average_sides<T>(WheelTicks{100, 204, 102, 200});
  CHECK(s.left == T(101));
  CHECK(s.right == T(202));
  // Half ticks survive.
  CHECK(posefuse::average_sides<T>(WheelTicks{1, 0, 0, 0}).left == T(0.5));
}

TEMPLATE_TEST_CASE("WheelOdometry: eq 9 hand-worked with explicit units", "[sensors][odometry]",
                   float, double) {
  using T = TestType;
  const posefuse::SideTicks<T> d{T(101), T(202)};
  // ds = m_tick (202 + 101) / 2 = 3.14159e-4 * 151.5 = 0.0475951 m
  // dtheta = m_tick (202 - 101) / 0.4 = 3.14159e-4 * 252.5 = 0.0793252 rad
  const posefuse::BodyDisplacement<T> b = posefuse::body_displacement(d, kParams);
  CHECK(b.ds_m == Approx(0.04759512870188536).epsilon(1e-6));
  CHECK(b.dtheta_rad == Approx(0.07932521450314228).epsilon(1e-6));
  // over dt = 0.1 s: v = 0.475951 m/s, w = 0.793252 rad/s
  const posefuse::BodyVelocity<T> v = posefuse::body_velocity(d, T(0.1), kParams);
  CHECK(v.v_mps == Approx(0.4759512870188536).epsilon(1e-6));
  CHECK(v.w_radps == Approx(0.7932521450314228).epsilon(1e-6));
  // Straight: equal sides -> w = 0. Spin on the spot: opposite sides -> v = 0, turning left.
  CHECK(posefuse::body_displacement(posefuse::SideTicks<T>{T(50), T(50)}, kParams).dtheta_rad == 0);
  const auto spin = posefuse::body_displacement(posefuse::SideTicks<T>{T(-50), T(50)}, kParams);
  CHECK(spin.ds_m == 0);
  CHECK(spin.dtheta_rad > 0);
  CHECK_THROWS_AS(posefuse::body_velocity(d, T(0), kParams), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::body_velocity(d, T(-0.1), kParams), posefuse::invalid_argument);
}

TEST_CASE("WheelOdometry: parameters are validated", "[sensors][odometry]") {
  CHECK_NOTHROW(kParams.validate());
  CHECK_THROWS_AS((DiffDriveParams{1000, 0.05, 0.0}.validate()), posefuse::invalid_argument);
  CHECK_THROWS_AS((DiffDriveParams{1000, -0.05, 0.4}.validate()), posefuse::invalid_argument);
  CHECK_THROWS_AS((DiffDriveParams{0, 0.05, 0.4}.validate()), posefuse::invalid_argument);
  CHECK_THROWS_AS((DiffDriveParams{std::nan(""), 0.05, 0.4}.validate()), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::WheelOdometry(DiffDriveParams{1000, 0.05, 0.0}), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::WheelOdometry(kParams, posefuse::WheelNoiseParams{-1.0, 0.0}),
                  posefuse::invalid_argument);
  CHECK(kParams.metres_per_tick() == Approx(3.141592653589793e-4));
}

TEST_CASE("WheelOdometry: covariance of (ds, dtheta) from per-wheel noise", "[sensors][odometry]") {
  // Quantisation only, sigma_q^2 = 1/12 tick^2: per side 1/24 (two wheels averaged).
  //  var(ds) = m^2 (1/24 + 1/24) / 4 = m^2 / 48 = 2.05617e-9 m^2
  //  var(dtheta) = m^2 (1/12) / d^2 = 5.14042e-8 rad^2, cov = m^2 (1/24 - 1/24) / (2 d) = 0
  const posefuse::WheelNoiseParams q{};
  Eigen::Matrix2d C = posefuse::body_displacement_covariance(posefuse::SideTicks<double>{101, 202}, kParams, q);
  CHECK(C(0, 0) == Approx(2.056167583560283e-09).epsilon(1e-9));
  CHECK(C(1, 1) == Approx(5.140418958900707e-08).epsilon(1e-9));
  CHECK(C(0, 1) == 0.0);
  // With 1 % slip the faster (right) side is noisier: positive ds-dtheta correlation.
  C = posefuse::body_displacement_covariance(posefuse::SideTicks<double>{101, 202}, kParams,
                                             posefuse::WheelNoiseParams{q.tick_sigma, 0.01});
  CHECK(C(0, 1) > 0.0);
  CHECK(C(0, 1) == C(1, 0));
  CHECK(posefuse::is_positive_definite(C));
}

TEST_CASE("WheelOdometry: stage turns cumulative ticks into body motion", "[sensors][odometry]") {
  using posefuse::WheelSample;
  constexpr std::int64_t t0 = 10'000'000'000;  // 10 s
  posefuse::WheelOdometry odo(kParams);
  posefuse::BodyMotion m = odo(WheelSample{t0, WheelTicks{1000, 1000, 1000, 1000}});
  CHECK(m.status == posefuse::SampleStatus::kFirst);
  CHECK(m.dt_s == 0.0);
  CHECK(m.ds_m == 0.0);
  CHECK(m.v_mps == 0.0);
  CHECK(m.t_ns == t0);
  CHECK(m.cov.isZero());
  // +100/+204/+102/+200 ticks over 0.1 s: the hand-worked step above.
  m = odo(WheelSample{t0 + 100'000'000, WheelTicks{1100, 1204, 1102, 1200}});
  CHECK(m.status == posefuse::SampleStatus::kOk);
  CHECK(m.dt_s == Approx(0.1).epsilon(1e-15));
  CHECK(m.t_ns == t0 + 100'000'000);
  CHECK(m.ds_m == Approx(0.04759512870188536).epsilon(1e-12));
  CHECK(m.dtheta_rad == Approx(0.07932521450314228).epsilon(1e-12));
  CHECK(m.v_mps == Approx(0.4759512870188536).epsilon(1e-9));
  CHECK(m.w_radps == Approx(0.7932521450314228).epsilon(1e-9));
  CHECK(m.cov(0, 0) == Approx(2.056167583560283e-09).epsilon(1e-9));
  // Non-increasing stamps are configuration errors; the state is kept.
  CHECK_THROWS_AS(odo(WheelSample{t0 + 100'000'000, WheelTicks{}}), posefuse::invalid_argument);
  CHECK_THROWS_AS(odo(WheelSample{t0 - 1'000'000'000, WheelTicks{}}), posefuse::invalid_argument);
  m = odo(WheelSample{t0 + 200'000'000, WheelTicks{1200, 1408, 1204, 1400}});
  CHECK(m.ds_m == Approx(0.04759512870188536).epsilon(1e-12));
  odo.reset();
  CHECK(odo(WheelSample{0, WheelTicks{}}).status == posefuse::SampleStatus::kFirst);
}

TEST_CASE("WheelOdometry: a non-finite side count is rejected", "[sensors][odometry]") {
  posefuse::DiffDriveOdometry odo(kParams);
  (void)odo(posefuse::StampedSideTicks{0, {0.0, 0.0}});
  CHECK_THROWS_AS(odo(posefuse::StampedSideTicks{1, {std::nan(""), 0.0}}), posefuse::invalid_argument);
  CHECK(odo(posefuse::StampedSideTicks{2, {10.0, 10.0}}).status == posefuse::SampleStatus::kOk);
}

TEST_CASE("WheelOdometry: stamps and counts at the ends of the int64 range do not overflow",
          "[sensors][odometry][overflow]") {
  constexpr std::int64_t lo = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int64_t>::max();
  // Regression: t_ns - previous t_ns overflowed for stamps this far apart.
  posefuse::WheelOdometry odo(kParams);
  (void)odo(posefuse::WheelSample{lo + 1, WheelTicks{}});
  const posefuse::BodyMotion m = odo(posefuse::WheelSample{hi, WheelTicks{10, 10, 10, 10}});
  CHECK(m.dt_s == Approx(2.0 * 9.223372036854775807e9).epsilon(1e-15));
  CHECK(m.ds_m == Approx(10 * kParams.metres_per_tick()).epsilon(1e-12));
  // tick_increment saturates instead of overflowing, and is exact when the difference fits.
  const WheelTicks d = posefuse::tick_increment(WheelTicks{hi, lo, hi - 5, 7}, WheelTicks{lo, hi, hi, -3});
  CHECK(d.fl == hi);
  CHECK(d.fr == lo);
  CHECK(d.bl == -5);
  CHECK(d.br == 10);
  CHECK(posefuse::saturating_difference(lo, 1) == lo);
  CHECK(posefuse::saturating_difference(hi, -1) == hi);
  CHECK(posefuse::saturating_difference(-1, lo) == hi);  // 2^63 - 1 exactly
  CHECK(posefuse::saturating_difference(0, hi) == lo + 1);
}

// Tests for sensors/pipelines.hpp: the attitude chain (eq 1-7) and the
// odometry chain (eq 8-10) compose, run, and equal their stages called by hand.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/sensors/pipelines.hpp>
#include <type_traits>

using namespace posefuse;

static_assert(std::is_same_v<AttitudePipeline::Input, ImuSample>);
static_assert(std::is_same_v<AttitudePipeline::Output, Attitude>);
static_assert(std::is_same_v<OdometryPipeline::Input, WheelSample>);
static_assert(std::is_same_v<OdometryPipeline::Output, PlanarPoseEstimate>);
static_assert(Stage<WheelOdometry> && Stage<DeadReckoning> && Stage<CompassStage>);
// WheelOdometry -> DeadReckoning is also a valid two-stage chain.
static_assert(std::is_same_v<decltype(make_pipeline(WheelOdometry(DiffDriveParams{1, 1, 1}),
                                                    DeadReckoning{}))::Output,
                             PlanarPoseEstimate>);

namespace {
const Eigen::Vector3d kFieldWorld(50 * std::cos(0.925), 0.0, -50 * std::sin(0.925));  // dip 53 deg

/// IMU sample of a body at (roll, pitch, yaw) turning about world z at yaw_rate, without linear
/// acceleration: accel = R^T (0,0,g), gyro = R^T (0,0,yaw_rate), mag = R^T m_w.
ImuSample imu_at(double t, double roll, double pitch, double yaw, double yaw_rate) {
  const Eigen::Matrix3d R = rotation_from_euler_zyx(EulerZYX<double>{roll, pitch, yaw});
  ImuSample s;
  s.t_ns = ns_from_seconds(t);
  s.accel_mps2 = R.transpose() * Eigen::Vector3d(0, 0, 9.81);
  s.gyro_radps = R.transpose() * Eigen::Vector3d(0, 0, yaw_rate);
  s.mag_uT = R.transpose() * kFieldWorld;
  return s;
}
}  // namespace

TEST_CASE("Pipelines: attitude chain recovers a constant attitude", "[sensors][pipelines]") {
  AttitudePipeline att = make_attitude_pipeline();
  Attitude a = att(imu_at(0.0, 0.1, -0.05, 0.7, 0.0));
  CHECK(a.status == SampleStatus::kFirst);
  for (int k = 1; k <= 100; ++k) a = att(imu_at(0.01 * k, 0.1, -0.05, 0.7, 0.0));
  CHECK(a.status == SampleStatus::kOk);
  CHECK(a.t_ns == 1'000'000'000);
  CHECK(a.roll == Approx(0.1).epsilon(1e-12));
  CHECK(a.pitch == Approx(-0.05).epsilon(1e-12));
  CHECK(a.yaw == Approx(0.7).epsilon(1e-12));
  CHECK_THROWS_AS(att(imu_at(0.5, 0, 0, 0, 0)), posefuse::invalid_argument);  // stamp goes back
  CHECK_THROWS_AS(make_attitude_pipeline(AttitudeConfig{1.5}), posefuse::invalid_argument);
}

TEST_CASE("Pipelines: attitude chain equals its stages called by hand", "[sensors][pipelines]") {
  AttitudePipeline att = make_attitude_pipeline(AttitudeConfig{0.95, GyroToTiltRate::kEulerKinematics});
  AccelerometerTiltStage s1;
  ComplementaryTiltStage s2(0.95, GyroToTiltRate::kEulerKinematics);
  CompassStage s3;
  for (int k = 0; k < 300; ++k) {
    const double t = 0.01 * k;
    ImuSample s = imu_at(t, 0.2 * std::sin(t), 0.1 * std::cos(2 * t), 0.3 * t, 0.3);
    s.accel_mps2.x() += 0.5 * std::sin(7 * t);  // linear acceleration the filter must ride out
    const Attitude a = att(s);
    const Attitude b = s3(s2(s1(s)));
    REQUIRE(a.roll == b.roll);
    REQUIRE(a.pitch == b.pitch);
    REQUIRE(a.yaw == b.yaw);
    REQUIRE(a.status == b.status);
  }
}

TEST_CASE("Pipelines: Euler-kinematics gyro mapping tracks tilt while turning, eq 3-4 lags",
          "[sensors][pipelines]") {
  // Constant roll 0.2, pitch 0.1, turning at 0.5 rad/s about world z. The body rates have
  // x = -0.5 sin(0.1) = -0.05 and y = 0.5 cos(0.1) sin(0.2) = 0.099 rad/s, which eq 3-4 takes
  // for roll/pitch rates: steady-state roll error alpha * 0.05 * dt / (1 - alpha)
  // = 0.98 * 0.05 * 0.01 / 0.02 = 0.0245 rad.
  AttitudePipeline seed = make_attitude_pipeline(AttitudeConfig{0.98, GyroToTiltRate::kSeed});
  AttitudePipeline kin = make_attitude_pipeline(AttitudeConfig{0.98, GyroToTiltRate::kEulerKinematics});
  Attitude a, b;
  for (int k = 0; k <= 1000; ++k) {
    const double t = 0.01 * k;
    const ImuSample s = imu_at(t, 0.2, 0.1, wrap_angle(0.5 * t), 0.5);
    a = seed(s);
    b = kin(s);
  }
  CHECK(b.roll == Approx(0.2).margin(1e-9));
  CHECK(b.pitch == Approx(0.1).margin(1e-9));
  CHECK(angle_diff(b.yaw, wrap_angle(5.0)) == Approx(0).margin(1e-9));
  CHECK(std::abs(a.roll - 0.2) > 0.01);
  CHECK(std::abs(a.roll - 0.2) < 0.03);
}

TEST_CASE("Pipelines: the defaults are the sound variants; the seed's printed forms are options",
          "[sensors][pipelines]") {
  CHECK(AttitudeConfig{}.gyro_mapping == GyroToTiltRate::kEulerKinematics);
  CHECK(DeadReckoning{}.method() == Integration::kExactArc);
  CHECK(make_odometry_pipeline(DiffDriveParams{1000.0, 0.05, 0.40}).stage<2>().method() ==
        Integration::kExactArc);
  // A stage built without a mapping follows the Euler kinematics, not eq 3-4 as printed:
  // tilted and turning, the two mappings differ.
  AccelerometerTiltStage tilt;
  ComplementaryTiltStage plain(0.98), kin(0.98, GyroToTiltRate::kEulerKinematics),
      seed(0.98, GyroToTiltRate::kSeed);
  TiltedImu a, b, c;
  for (int k = 0; k <= 200; ++k) {
    const TiltedImu in = tilt(imu_at(0.01 * k, 0.2, 0.1, wrap_angle(0.5 * 0.01 * k), 0.5));
    a = plain(in);
    b = kin(in);
    c = seed(in);
  }
  CHECK(a.tilt.roll == b.tilt.roll);
  CHECK(a.tilt.pitch == b.tilt.pitch);
  CHECK(std::abs(a.tilt.roll - c.tilt.roll) > 0.01);
}

TEST_CASE("Pipelines: odometry chain drives the closed-form circle", "[sensors][pipelines]") {
  const DiffDriveParams p{1000.0, 0.05, 0.40};
  OdometryPipeline odo = make_odometry_pipeline(p, WheelNoiseParams{0.3, 0.01});
  FourWheelAverage s1;
  DiffDriveOdometry s2(p, WheelNoiseParams{0.3, 0.01});
  DeadReckoning s3;
  // Every 0.02 s the left wheels advance 100 ticks and the right wheels 120:
  // ds = m (220 / 2), dtheta = m (20 / 0.4), a circle of radius ds / dtheta = 110 / 50 = 2.2 m.
  const double m = p.metres_per_tick();
  const double ds = m * 110.0, dth = m * 20.0 / 0.4, rho = ds / dth;
  WheelTicks ticks{};
  PlanarPoseEstimate out, hand;
  const int n = 2000;
  constexpr std::int64_t kStep = 20'000'000;  // 0.02 s
  for (int k = 0; k <= n; ++k) {
    const WheelSample in{kStep * k, ticks};
    out = odo(in);
    hand = s3(s2(s1(in)));
    REQUIRE(out.pose.mean.x == hand.pose.mean.x);
    REQUIRE(out.pose.mean.theta == hand.pose.mean.theta);
    REQUIRE(out.pose.cov == hand.pose.cov);
    ticks.fl += 100;
    ticks.bl += 100;
    ticks.fr += 120;
    ticks.br += 120;
  }
  CHECK(rho == Approx(2.2));
  CHECK(out.pose.mean.x == Approx(rho * std::sin(n * dth)).margin(1e-9));
  CHECK(out.pose.mean.y == Approx(rho * (1 - std::cos(n * dth))).margin(1e-9));
  CHECK(angle_diff(out.pose.mean.theta, n * dth) == Approx(0).margin(1e-9));
  CHECK(out.t_ns == 40'000'000'000);
  CHECK(is_positive_semidefinite(out.pose.cov));
  CHECK(out.pose.cov(2, 2) > 0.0);

  // Re-anchor the dead reckoning through the pipeline (what the fuser does on re-initialisation).
  odo.stage<2>().reset(PlanarPose<double>{1, 1, 0}, Eigen::Matrix3d::Identity() * 1e-4);
  out = odo(WheelSample{kStep * (n + 1), ticks});
  CHECK(out.pose.mean.x == Approx(1 + rho * std::sin(dth)).epsilon(1e-12));
  CHECK(out.pose.cov(0, 0) > 1e-4);
}

// Tests for sensors/compass.hpp and sensors/magnetometer_calibration.hpp
// (seed 001 eq 5-7 and hard/soft-iron calibration).
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/rotation.hpp>
#include <posefuse/sensors/compass.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <random>
#include <vector>

namespace {
/// Earth field in the world frame (x magnetic north, y west, z up): 50 uT, dip 53 deg (Korea).
template <class T>
Eigen::Matrix<T, 3, 1> field_world() {
  const double dip = posefuse::deg2rad(53.0);
  return Eigen::Matrix<T, 3, 1>(T(50 * std::cos(dip)), T(0), T(-50 * std::sin(dip)));
}
/// Body-frame reading for a REP-103 attitude: m = R^T m_w.
template <class T>
Eigen::Matrix<T, 3, 1> reading(T roll, T pitch, T yaw) {
  return posefuse::rotation_from_euler_zyx(posefuse::EulerZYX<T>{roll, pitch, yaw}).transpose() *
         field_world<T>();
}
}  // namespace

TEMPLATE_TEST_CASE("Compass: heading hand-worked at zero tilt", "[sensors][compass]", float, double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  // Facing north: m = (20, 0, -40): Xh = 20, Yh = 0 -> yaw = atan2(0, 20) = 0.
  CHECK(posefuse::tilt_compensated_heading(V(20, 0, -40), T(0), T(0)) == Approx(0).margin(1e-7));
  // Facing west (turned left 90 deg, yaw +pi/2): m = Rz(90)^T (20, 0, -40) = (0, -20, -40):
  // Xh = 0, Yh = -20 -> yaw = atan2(20, 0) = +pi/2 (counter-clockwise positive).
  CHECK(posefuse::tilt_compensated_heading(V(0, -20, -40), T(0), T(0)) ==
        Approx(std::numbers::pi / 2).epsilon(1e-6));
  // Facing east: m = (0, 20, -40) -> yaw = -pi/2.
  CHECK(posefuse::tilt_compensated_heading(V(0, 20, -40), T(0), T(0)) ==
        Approx(-std::numbers::pi / 2).epsilon(1e-6));
  // The printed eq 5-7 at zero tilt: theta = atan(My / Mx) = atan(-20 / 20) = -pi/4 for a
  // robot at yaw +pi/4, i.e. the printed form measures clockwise.
  CHECK(posefuse::tilt_compensated_heading_seed(reading(T(0), T(0), T(std::numbers::pi / 4)), T(0),
                                                T(0)) == Approx(-std::numbers::pi / 4).epsilon(1e-5));
}

TEMPLATE_TEST_CASE("Compass: corrected yaw is invariant to roll and pitch (property)",
                   "[sensors][compass]", float, double) {
  using T = TestType;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> tilt(-1.3, 1.3), yaw(-3.14, 3.14);
  const T m = std::is_same_v<T, float> ? T(5e-5) : T(1e-12);
  for (int i = 0; i < 2000; ++i) {
    const T y = T(yaw(rng)), r = T(tilt(rng)), p = T(tilt(rng));
    const T est = posefuse::tilt_compensated_heading(reading(r, p, y), r, p);
    REQUIRE(posefuse::angle_diff(est, y) == Approx(0).margin(m));
  }
}

TEST_CASE("Compass: the printed eq 5-7 are not invariant to tilt (SPEC B check)",
          "[sensors][compass]") {
  // SPEC B: with roll 0.2 rad a true yaw of 0.70 rad reads 0.98 rad. Here: REP-103 axes, field
  // 50 uT with 53 deg dip, robot at yaw 0.70 rolled 0.2 rad; the printed form measures clockwise
  // (-0.70 at zero tilt) and reads -0.981 once rolled.
  const Eigen::Vector3d level = reading(0.0, 0.0, 0.70);
  const Eigen::Vector3d rolled = reading(0.2, 0.0, 0.70);
  CHECK(posefuse::tilt_compensated_heading_seed(level, 0.0, 0.0) == Approx(-0.70).epsilon(1e-12));
  CHECK(posefuse::tilt_compensated_heading_seed(rolled, 0.2, 0.0) == Approx(-0.981).margin(5e-4));
  CHECK(posefuse::tilt_compensated_heading(rolled, 0.2, 0.0) == Approx(0.70).epsilon(1e-12));

  // The same invariance property fails for the printed form: its reading with tilt differs from
  // its own reading level, by more than 0.05 rad for most attitudes.
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> tilt(-0.6, 0.6), yaw(-1.2, 1.2);
  int violations = 0;
  double worst = 0.0;
  const int n = 500;
  for (int i = 0; i < n; ++i) {
    const double y = yaw(rng), r = tilt(rng), p = tilt(rng);
    const double seed_tilted = posefuse::tilt_compensated_heading_seed(reading(r, p, y), r, p);
    const double seed_level = posefuse::tilt_compensated_heading_seed(reading(0.0, 0.0, y), 0.0, 0.0);
    const double err = std::abs(posefuse::angle_diff(seed_tilted, seed_level));
    worst = std::max(worst, err);
    if (err > 0.05) ++violations;
  }
  CHECK(violations > n / 2);
  CHECK(worst > 0.5);
}

TEST_CASE("Compass: ellipsoid fit recovers a known hard/soft-iron distortion",
          "[sensors][compass][calibration]") {
  // Raw = D b + h with symmetric D and offset h, plus 0.3 uT noise, over 400 random attitudes.
  Eigen::Matrix3d D;
  D << 1.20, 0.10, -0.05,  //
      0.10, 0.90, 0.08,    //
      -0.05, 0.08, 1.05;
  const Eigen::Vector3d h(12.0, -7.0, 25.0);
  std::mt19937 rng(99);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> raw, truth;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    const Eigen::Vector3d b = q.toRotationMatrix().transpose() * field_world<double>();
    truth.push_back(b);
    raw.push_back(D * b + h + 0.3 * Eigen::Vector3d(n(rng), n(rng), n(rng)));
  }
  const posefuse::MagnetometerCalibration cal = posefuse::fit_ellipsoid(raw, 50.0);
  CHECK((cal.hard_iron - h).norm() < 0.2);
  CHECK((cal.soft_iron - D.inverse()).norm() < 0.01);
  CHECK((cal.soft_iron - cal.soft_iron.transpose()).norm() < 1e-12);
  double worst = 0.0;
  for (std::size_t i = 0; i < raw.size(); ++i)
    worst = std::max(worst, (cal.apply(raw[i]) - truth[i]).norm());
  CHECK(worst < 1.5);  // ~ 3 sigma of the 0.3 uT noise, times |D^-1|

  // Without a field magnitude the fit keeps the geometric mean radius; the shape is the same.
  const posefuse::MagnetometerCalibration cal0 = posefuse::fit_ellipsoid(raw);
  const double k = cal0.soft_iron.norm() / cal.soft_iron.norm();
  CHECK((cal0.soft_iron / k - cal.soft_iron).norm() < 1e-9);
  CHECK((cal0.hard_iron - cal.hard_iron).norm() < 1e-9);
  CHECK(k == Approx(std::cbrt(D.determinant())).epsilon(0.01));

  // Calibrated and tilt-compensated, the heading is right again.
  const double yaw = 1.1, roll = 0.3, pitch = -0.2;
  const Eigen::Vector3d m = D * reading(roll, pitch, yaw) + h;
  CHECK(std::abs(posefuse::angle_diff(posefuse::tilt_compensated_heading(cal.apply(m), roll, pitch),
                                      yaw)) < posefuse::deg2rad(0.5));
  // Uncalibrated, the same reading is off by ~1.9 deg.
  CHECK(std::abs(posefuse::angle_diff(posefuse::tilt_compensated_heading(m, roll, pitch), yaw)) >
        posefuse::deg2rad(1.5));
}

TEST_CASE("Compass: ellipsoid fit rejects too few or degenerate samples",
          "[sensors][compass][calibration]") {
  std::vector<Eigen::Vector3d> few(8, Eigen::Vector3d(1, 2, 3));
  CHECK_THROWS_AS(posefuse::fit_ellipsoid(few), posefuse::invalid_argument);
  // A robot that only turns about z: readings on one circle, not an ellipsoid.
  std::vector<Eigen::Vector3d> flat;
  for (int i = 0; i < 100; ++i) flat.push_back(reading(0.0, 0.0, 0.0628 * i));
  CHECK_THROWS_AS(posefuse::fit_ellipsoid(flat), posefuse::invalid_argument);
  std::vector<Eigen::Vector3d> same(20, Eigen::Vector3d(1, 2, 3));
  CHECK_THROWS_AS(posefuse::fit_ellipsoid(same), posefuse::invalid_argument);
  std::vector<Eigen::Vector3d> nan(20, Eigen::Vector3d(1, 2, std::nan("")));
  CHECK_THROWS_AS(posefuse::fit_ellipsoid(nan), posefuse::invalid_argument);
  std::vector<Eigen::Vector3d> ok;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 50; ++i) ok.push_back(Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized());
  CHECK_THROWS_AS(posefuse::fit_ellipsoid(ok, -1.0), posefuse::invalid_argument);
  CHECK_NOTHROW(posefuse::fit_ellipsoid(ok, 1.0));
}

TEST_CASE("Compass: stage applies calibration and holds yaw on bad readings", "[sensors][compass]") {
  posefuse::MagnetometerCalibration cal;
  cal.hard_iron << 5, -3, 2;
  posefuse::CompassStage stage(cal);
  posefuse::TiltedImu in;
  in.imu.t_s = 2.0;
  in.tilt = {0.1, -0.05};
  in.imu.mag_uT = reading(0.1, -0.05, 0.4) + cal.hard_iron;
  posefuse::Attitude a = stage(in);
  CHECK(a.status == posefuse::SampleStatus::kOk);
  CHECK(a.t_s == 2.0);
  CHECK(a.roll == 0.1);
  CHECK(a.pitch == -0.05);
  CHECK(a.yaw == Approx(0.4).epsilon(1e-12));
  in.imu.mag_uT.x() = std::numeric_limits<double>::infinity();
  a = stage(in);
  CHECK(a.status == posefuse::SampleStatus::kNonFinite);
  CHECK(a.yaw == Approx(0.4).epsilon(1e-12));
  CHECK_THROWS_AS(posefuse::CompassStage(cal, std::nan("")), posefuse::invalid_argument);
}

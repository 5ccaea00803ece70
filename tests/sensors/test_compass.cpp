// Tests for sensors/compass.hpp, sensors/magnetometer_calibration.hpp and
// seed/tilt_compensated_heading.hpp (seed 001 eq 5-7 corrected and as printed, and
// hard/soft-iron calibration).
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/seed/tilt_compensated_heading.hpp>
#include <posefuse/sensors/compass.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <random>
#include <ranges>
#include <span>
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

/// A lazy forward range applying `f` to each element of a vector, returning
/// by value: what `v | std::views::transform(f)` is, written out because
/// clang 14 cannot compile libstdc++ 12's views (std::ranges::view_interface).
template <class Src, class Out>
class MappedRange {
 public:
  using Fn = Out (*)(const Src&);
  class iterator {
   public:
    using iterator_concept = std::forward_iterator_tag;
    using iterator_category = std::forward_iterator_tag;
    using value_type = Out;
    using difference_type = std::ptrdiff_t;
    iterator() = default;
    iterator(const Src* p, Fn f) : p_(p), f_(f) {}
    Out operator*() const { return f_(*p_); }
    iterator& operator++() {
      ++p_;
      return *this;
    }
    iterator operator++(int) {
      iterator old = *this;
      ++p_;
      return old;
    }
    bool operator==(const iterator& o) const { return p_ == o.p_; }

   private:
    const Src* p_ = nullptr;
    Fn f_ = nullptr;
  };
  MappedRange(const std::vector<Src>& v, Fn f) : v_(&v), f_(f) {}
  iterator begin() const { return {v_->data(), f_}; }
  iterator end() const { return {v_->data() + v_->size(), f_}; }

 private:
  const std::vector<Src>* v_;
  Fn f_;
};
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
  CHECK(posefuse::seed::tilt_compensated_heading_seed(reading(T(0), T(0), T(std::numbers::pi / 4)),
                                                      T(0), T(0)) ==
        Approx(-std::numbers::pi / 4).epsilon(1e-5));
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

TEST_CASE("Compass: the printed eq 5-7 are not invariant to tilt",
          "[sensors][compass]") {
  // With roll 0.2 rad a true yaw of 0.70 rad reads 0.98 rad. Here: REP-103 axes, field
  // 50 uT with 53 deg dip, robot at yaw 0.70 rolled 0.2 rad; the printed form measures clockwise
  // (-0.70 at zero tilt) and reads -0.981 once rolled.
  const Eigen::Vector3d level = reading(0.0, 0.0, 0.70);
  const Eigen::Vector3d rolled = reading(0.2, 0.0, 0.70);
  CHECK(posefuse::seed::tilt_compensated_heading_seed(level, 0.0, 0.0) ==
        Approx(-0.70).epsilon(1e-12));
  CHECK(posefuse::seed::tilt_compensated_heading_seed(rolled, 0.2, 0.0) ==
        Approx(-0.981).margin(5e-4));
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
    const double seed_tilted =
        posefuse::seed::tilt_compensated_heading_seed(reading(r, p, y), r, p);
    const double seed_level =
        posefuse::seed::tilt_compensated_heading_seed(reading(0.0, 0.0, y), 0.0, 0.0);
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
  in.imu.t_ns = 2'000'000'000;
  in.tilt = {0.1, -0.05};
  in.imu.mag_uT = reading(0.1, -0.05, 0.4) + cal.hard_iron;
  posefuse::Attitude a = stage(in);
  CHECK(a.status == posefuse::SampleStatus::kOk);
  CHECK(a.t_ns == 2'000'000'000);
  CHECK(a.roll == 0.1);
  CHECK(a.pitch == -0.05);
  CHECK(a.yaw == Approx(0.4).epsilon(1e-12));
  in.imu.mag_uT.x() = std::numeric_limits<double>::infinity();
  a = stage(in);
  CHECK(a.status == posefuse::SampleStatus::kNonFinite);
  CHECK(a.yaw == Approx(0.4).epsilon(1e-12));
  CHECK_THROWS_AS(posefuse::CompassStage(cal, std::nan("")), posefuse::invalid_argument);
}

namespace {
/// Raw horizontal readings of a robot turning about z through `turn_rad` in
/// `n` steps: level body, so m = D (R_z(yaw)^T b_w) + h, with 0.2 uT noise.
std::vector<Eigen::Vector2d> turning_readings(const Eigen::Matrix2d& D, const Eigen::Vector2d& h,
                                              double turn_rad, int n, std::vector<double>* yaws = nullptr) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < n; ++i) {
    const double yaw = turn_rad * i / n;
    const Eigen::Vector3d b = reading(0.0, 0.0, yaw);
    out.push_back(D * b.head<2>() + h + Eigen::Vector2d(noise(rng), noise(rng)));
    if (yaws != nullptr) yaws->push_back(yaw);
  }
  return out;
}
}  // namespace

TEST_CASE("Compass: horizontal ellipse fit recovers hard and soft iron of a turning robot",
          "[sensors][compass][calibration]") {
  Eigen::Matrix2d D;
  D << 1.15, 0.08,  //
      0.08, 0.90;
  const Eigen::Vector2d h(9.0, -14.0);
  std::vector<double> yaws;
  const auto raw = turning_readings(D, h, 2 * std::numbers::pi, 720, &yaws);
  const posefuse::HorizontalEllipseFit fit = posefuse::fit_horizontal_ellipse(raw);
  REQUIRE(fit.ok());
  CHECK(fit.readings == 720);
  CHECK(fit.coverage_deg == 360.0);
  const posefuse::MagnetometerCalibration& cal = fit.calibration;
  CHECK((cal.hard_iron.head<2>() - h).norm() < 0.1);
  CHECK(cal.hard_iron.z() == 0.0);
  CHECK(cal.soft_iron(2, 2) == 1.0);
  CHECK(cal.soft_iron(0, 2) == 0.0);
  CHECK(cal.soft_iron(2, 1) == 0.0);
  // S keeps the geometric-mean radius: det S = 1, so S = D^-1 sqrt(det D) for a symmetric D.
  const Eigen::Matrix2d S = cal.soft_iron.topLeftCorner<2, 2>();
  CHECK(S.determinant() == Approx(1.0).epsilon(1e-12));
  CHECK((S - D.inverse() * std::sqrt(D.determinant())).norm() < 5e-3);
  CHECK((S - S.transpose()).norm() < 1e-12);
  // Calibrated, the level heading is right to a fraction of a degree; raw, it is degrees off.
  double worst = 0, worst_raw = 0;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Eigen::Vector3d m(raw[i].x(), raw[i].y(), -40.0);
    worst = std::max(worst, std::abs(posefuse::angle_diff(
                                posefuse::tilt_compensated_heading(cal.apply(m), 0.0, 0.0), yaws[i])));
    worst_raw = std::max(worst_raw, std::abs(posefuse::angle_diff(
                                        posefuse::tilt_compensated_heading(m, 0.0, 0.0), yaws[i])));
  }
  CHECK(worst < posefuse::deg2rad(1.5));
  CHECK(worst_raw > posefuse::deg2rad(20.0));
}

TEST_CASE("Compass: horizontal ellipse fit takes any range of 2-vectors, e.g. a view of IMU samples",
          "[sensors][compass][calibration]") {
  const auto raw = turning_readings(Eigen::Matrix2d::Identity(), Eigen::Vector2d(3, 4), 2 * std::numbers::pi, 100);
  std::vector<posefuse::ImuSample> imu(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) imu[i].mag_uT << raw[i], -40.0;
  const MappedRange<posefuse::ImuSample, Eigen::Vector2d> view(imu, [](const posefuse::ImuSample& s) {
    return Eigen::Vector2d(s.mag_uT.head<2>());
  });
  static_assert(std::ranges::forward_range<decltype(view)>);
  const auto a = posefuse::fit_horizontal_ellipse(view);
  const auto b = posefuse::fit_horizontal_ellipse(raw);
  REQUIRE(a.ok());
  CHECK(a.calibration.hard_iron == b.calibration.hard_iron);
  CHECK(a.calibration.soft_iron == b.calibration.soft_iron);
  CHECK((a.calibration.hard_iron.head<2>() - Eigen::Vector2d(3, 4)).norm() < 0.1);
}

TEST_CASE("Compass: horizontal ellipse fit reports why it cannot calibrate",
          "[sensors][compass][calibration]") {
  using posefuse::EllipseFitStatus;
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  const Eigen::Vector2d h(2, -3);
  const auto check_fails = [](const std::vector<Eigen::Vector2d>& r, EllipseFitStatus want) {
    const auto fit = posefuse::fit_horizontal_ellipse(r);
    CHECK(fit.status == want);
    CHECK_FALSE(fit.ok());
    CHECK(fit.calibration.hard_iron.isZero());  // identity calibration on failure
    CHECK(fit.calibration.soft_iron.isIdentity());
  };
  check_fails({}, EllipseFitStatus::kTooFewReadings);
  check_fails(turning_readings(I, h, 2 * std::numbers::pi, 19), EllipseFitStatus::kTooFewReadings);
  check_fails(std::vector<Eigen::Vector2d>(50, Eigen::Vector2d(1, 2)), EllipseFitStatus::kConstantReadings);
  auto with_nan = turning_readings(I, h, 2 * std::numbers::pi, 50);
  with_nan[10].x() = std::nan("");
  check_fails(with_nan, EllipseFitStatus::kNonFinite);
  // Half a turn fits an ellipse but does not determine it: too little turning.
  const auto half = posefuse::fit_horizontal_ellipse(turning_readings(I, h, std::numbers::pi, 200));
  CHECK(half.status == EllipseFitStatus::kTooLittleTurning);
  CHECK(half.coverage_deg < 270.0);
  // A soft iron squeezing one axis 3:1 (eigenvalue ratio 9 > 4) is not plausible.
  Eigen::Matrix2d squeeze = I;
  squeeze(1, 1) = 1.0 / 3.0;
  check_fails(turning_readings(squeeze, h, 2 * std::numbers::pi, 200), EllipseFitStatus::kNotAnEllipse);
  // ... unless the limit allows it.
  posefuse::HorizontalEllipseFitOptions loose;
  loose.max_eigenvalue_ratio = 10.0;
  CHECK(posefuse::fit_horizontal_ellipse(turning_readings(squeeze, h, 2 * std::numbers::pi, 200), loose).ok());
  // Readings on a line are no ellipse.
  std::vector<Eigen::Vector2d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(0.1 * i, 0.2 * i);
  check_fails(line, EllipseFitStatus::kNotAnEllipse);
  // The reasons as the runner prints them.
  CHECK(posefuse::to_string(EllipseFitStatus::kTooFewReadings) == "fewer than 20 readings");
  CHECK(posefuse::to_string(EllipseFitStatus::kTooLittleTurning) ==
        "the robot turned through less than 270 deg");
  CHECK(posefuse::to_string(EllipseFitStatus::kNotAnEllipse) == "readings are not on a plausible ellipse");
}

TEST_CASE("Compass: ellipsoid fit takes a std::span and a view as well as a vector",
          "[sensors][compass][calibration]") {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> raw;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    raw.push_back(q.toRotationMatrix().transpose() * field_world<double>() + Eigen::Vector3d(4, -2, 7));
  }
  const auto a = posefuse::fit_ellipsoid(raw);
  const auto b = posefuse::fit_ellipsoid(std::span<const Eigen::Vector3d>(raw));
  const auto c = posefuse::fit_ellipsoid(MappedRange<Eigen::Vector3d, Eigen::Vector3d>(
      raw, [](const Eigen::Vector3d& v) -> Eigen::Vector3d { return v; }));
  CHECK(a.hard_iron == b.hard_iron);
  CHECK(a.soft_iron == c.soft_iron);
  CHECK((a.hard_iron - Eigen::Vector3d(4, -2, 7)).norm() < 1e-6);
}

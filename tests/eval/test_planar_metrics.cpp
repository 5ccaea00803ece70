// Tests for eval/planar_metrics.hpp: RMSE and heading error after
// association by time, loop closure, time without a pose; bad input.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/planar_metrics.hpp>

using posefuse::PlanarTrajectory;

namespace {
/// A reference driving a circle of radius 5 m at 1 rad/10 s, sampled at 100 Hz over [0, 20] s.
PlanarTrajectory circle() {
  PlanarTrajectory ref;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 0.01 * k, a = 0.1 * t;
    ref.push_back(t, Eigen::Vector3d(5 * std::sin(a), 5 * (1 - std::cos(a)), posefuse::wrap_angle(a)));
  }
  return ref;
}
}  // namespace

TEST_CASE("PlanarMetrics: a track equal to the reference has zero error", "[eval][planar]") {
  const PlanarTrajectory ref = circle();
  const posefuse::PlanarErrors e = posefuse::planar_errors(ref, ref);
  CHECK(e.matched == ref.size());
  CHECK(e.rmse_m == 0.0);
  CHECK(e.max_heading_error_rad == 0.0);
}

TEST_CASE("PlanarMetrics: RMSE and heading error against a hand-computed offset", "[eval][planar]") {
  const PlanarTrajectory ref = circle();
  // Poses at 3 Hz between the reference samples, off by (0.3, -0.4) m (0.5 m) and a heading
  // error alternating +-2 deg; two poses before and after the reference span are not matched.
  PlanarTrajectory est;
  est.push_back(-1.0, Eigen::Vector3d(100, 100, 0));
  int n = 0;
  for (double t = 0.005; t < 20.0; t += 1.0 / 3.0, ++n) {
    const double a = 0.1 * t;
    const double dh = (n % 2 ? 2.0 : -2.0) * std::numbers::pi / 180.0;
    est.push_back(t, Eigen::Vector3d(5 * std::sin(a) + 0.3, 5 * (1 - std::cos(a)) - 0.4, a + dh));
  }
  est.push_back(25.0, Eigen::Vector3d(-100, 0, 0));
  const posefuse::PlanarErrors e = posefuse::planar_errors(est, ref);
  CHECK(e.matched == std::size_t(n));
  // Linear interpolation of the circle between 10 ms samples is off by < 5 * (0.001)^2 / 8 m.
  CHECK(e.rmse_m == Approx(0.5).margin(1e-5));
  CHECK(e.max_heading_error_rad == Approx(2.0 * std::numbers::pi / 180.0).margin(1e-9));
}

TEST_CASE("PlanarMetrics: headings are compared on the circle", "[eval][planar]") {
  PlanarTrajectory ref, est;
  ref.push_back(0.0, Eigen::Vector3d(0, 0, std::numbers::pi - 0.01));
  ref.push_back(1.0, Eigen::Vector3d(1, 0, -std::numbers::pi + 0.01));
  est.push_back(0.5, Eigen::Vector3d(0.5, 0, std::numbers::pi - 0.02));  // ref is at pi there
  const auto e = posefuse::planar_errors(est, ref);
  CHECK(e.matched == 1);
  CHECK(e.rmse_m == Approx(0).margin(1e-12));
  CHECK(e.max_heading_error_rad == Approx(0.02).epsilon(1e-9));  // not 2 pi - 0.02
}

TEST_CASE("PlanarMetrics: no overlap or no poses give matched = 0 and NaN", "[eval][planar]") {
  const PlanarTrajectory ref = circle();
  PlanarTrajectory late;
  late.push_back(30.0, Eigen::Vector3d(0, 0, 0));
  for (const PlanarTrajectory& est : {late, PlanarTrajectory{}}) {
    const auto e = posefuse::planar_errors(est, ref);
    CHECK(e.matched == 0);
    CHECK(std::isnan(e.rmse_m));
    CHECK(std::isnan(e.max_heading_error_rad));
  }
  CHECK(posefuse::planar_errors(ref, PlanarTrajectory{}).matched == 0);
}

TEST_CASE("PlanarMetrics: tracks may repeat a stamp but not go back or hold NaN", "[eval][planar]") {
  const PlanarTrajectory ref = circle();
  PlanarTrajectory est;
  est.push_back(1.0, Eigen::Vector3d(0, 0, 0));
  est.push_back(1.0, Eigen::Vector3d(0, 0, 0));  // two poses reported at one time: fine
  CHECK(posefuse::planar_errors(est, ref).matched == 2);
  est.push_back(0.5, Eigen::Vector3d(0, 0, 0));
  CHECK_THROWS_WITH(posefuse::planar_errors(est, ref), Catch::Contains("not in time order at index 2"));
  CHECK_THROWS_AS(posefuse::time_without_pose(est, 0, 2, 0.5), posefuse::invalid_argument);
  est.t_s[2] = 2.0;
  est.poses[1](0) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(posefuse::planar_errors(est, ref), Catch::Contains("pose 1 is not finite"));
  CHECK_THROWS_AS(posefuse::planar_errors(ref, est), posefuse::invalid_argument);
}

TEST_CASE("PlanarMetrics: loop-closure error", "[eval][planar]") {
  PlanarTrajectory est;
  CHECK_THROWS_AS(posefuse::loop_closure_error(est, Eigen::Vector2d::Zero()), posefuse::invalid_argument);
  est.push_back(0.0, Eigen::Vector3d(0, 0, 0));
  est.push_back(9.0, Eigen::Vector3d(3.5, -1.0, 2.0));
  CHECK(posefuse::loop_closure_error(est, Eigen::Vector2d(0.5, 3.0)) == Approx(5.0));
  CHECK_THROWS_AS(posefuse::loop_closure_error(est, Eigen::Vector2d(std::nan(""), 0)),
                  posefuse::invalid_argument);
}

TEST_CASE("PlanarMetrics: time without a pose counts gaps longer than the limit", "[eval][planar]") {
  PlanarTrajectory est;
  // From t = 0: a 1 s gap to the first pose, poses every 0.2 s to t = 3, a 4 s gap, poses to
  // t = 9, then nothing until t_end = 10.
  for (double t = 1.0; t <= 3.0 + 1e-9; t += 0.2) est.push_back(t, Eigen::Vector3d::Zero());
  for (double t = 7.0; t <= 9.0 + 1e-9; t += 0.2) est.push_back(t, Eigen::Vector3d::Zero());
  CHECK(posefuse::time_without_pose(est, 0.0, 10.0, 0.5) == Approx(1.0 + 4.0 + 1.0).epsilon(1e-9));
  // A limit above every gap: nothing counts; the gaps of 0.2 s count with a 0.1 s limit.
  CHECK(posefuse::time_without_pose(est, 0.0, 10.0, 5.0) == 0.0);
  CHECK(posefuse::time_without_pose(est, 0.0, 10.0, 0.1) == Approx(10.0).epsilon(1e-9));
  // No pose at all: the whole span.
  CHECK(posefuse::time_without_pose(PlanarTrajectory{}, 2.0, 5.0, 0.5) == 3.0);
  CHECK(posefuse::time_without_pose(PlanarTrajectory{}, 2.0, 2.4, 0.5) == 0.0);
  // Poses before t_begin do not open a gap there.
  PlanarTrajectory early;
  early.push_back(-5.0, Eigen::Vector3d::Zero());
  early.push_back(0.3, Eigen::Vector3d::Zero());
  CHECK(posefuse::time_without_pose(early, 0.0, 0.5, 0.5) == 0.0);
  // Bad spans and limits.
  CHECK_THROWS_AS(posefuse::time_without_pose(est, 3.0, 1.0, 0.5), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::time_without_pose(est, 0.0, 10.0, -0.5), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::time_without_pose(est, std::nan(""), 10.0, 0.5), posefuse::invalid_argument);
}

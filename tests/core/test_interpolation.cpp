// Tests for core/interpolation.hpp: vectors, planar poses (shorter arc),
// SE(3) poses (slerp), trajectories at a time, and bad input.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/trajectory.hpp>

using posefuse::deg2rad;

namespace {
Eigen::Isometry3d pose(double x, double y, double z, const Eigen::Vector3d& axis, double angle) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}
}  // namespace

TEMPLATE_TEST_CASE("Interpolation: time fraction and vectors", "[core][interpolation]", float, double) {
  using T = TestType;
  CHECK(posefuse::time_fraction(T(2), T(6), T(3)) == Approx(0.25));
  CHECK(posefuse::time_fraction(T(2), T(6), T(2)) == T(0));
  CHECK(posefuse::time_fraction(T(2), T(6), T(8)) == Approx(1.5));  // outside: extrapolation
  CHECK_THROWS_AS(posefuse::time_fraction(T(6), T(2), T(3)), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::time_fraction(T(2), T(2), T(2)), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::time_fraction(T(2), T(6), std::numeric_limits<T>::quiet_NaN()),
                  posefuse::invalid_argument);
  using V = Eigen::Matrix<T, 4, 1>;
  const V a(1, 2, 3, 4), b(3, 2, -1, 8);
  const V m = posefuse::lerp(a, b, T(0.25));
  CHECK(m(0) == Approx(1.5));
  CHECK(m(1) == T(2));
  CHECK(m(2) == Approx(2));
  CHECK(m(3) == Approx(5));
  CHECK(posefuse::lerp(a, b, T(0)) == a);
  CHECK(posefuse::lerp(a, b, T(1)) == b);
}

TEMPLATE_TEST_CASE("Interpolation: planar pose heading takes the shorter arc", "[core][interpolation]",
                   float, double) {
  using T = TestType;
  using P = Eigen::Matrix<T, 3, 1>;
  const P a(0, 0, T(deg2rad(170.0))), b(2, -4, T(deg2rad(-170.0)));
  const P m = posefuse::interpolate_planar_pose(a, b, T(0.5));
  CHECK(m(0) == Approx(1));
  CHECK(m(1) == Approx(-2));
  // Through 180 deg, not through 0.
  CHECK(std::abs(posefuse::angle_diff(m(2), std::numbers::pi_v<T>)) < T(1e-5));
  const P q = posefuse::interpolate_planar_pose(a, b, T(0.25));
  CHECK(posefuse::angle_diff(q(2), T(deg2rad(175.0))) == Approx(0).margin(1e-5));
  // The result is wrapped.
  CHECK(q(2) >= -std::numbers::pi_v<T>);
  CHECK(q(2) < std::numbers::pi_v<T>);
}

TEST_CASE("Interpolation: SE(3) pose: linear translation, slerp rotation", "[core][interpolation]") {
  const Eigen::Vector3d axis(1, -2, 0.5);
  const Eigen::Isometry3d a = pose(0, 0, 0, axis, 0.2), b = pose(2, 4, -6, axis, 1.4);
  const Eigen::Isometry3d m = posefuse::interpolate_pose(a, b, 0.25);
  CHECK((m.translation() - Eigen::Vector3d(0.5, 1, -1.5)).norm() < 1e-12);
  // About a fixed axis, slerp is linear in the angle: 0.2 + 0.25 (1.4 - 0.2) = 0.5.
  const Eigen::AngleAxisd aa(m.linear());
  CHECK(aa.angle() == Approx(0.5).epsilon(1e-12));
  CHECK((aa.axis() - axis.normalized()).norm() < 1e-12);
  CHECK((m.linear() * m.linear().transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
  // Ends are reproduced.
  CHECK(posefuse::interpolate_pose(a, b, 0.0).isApprox(a, 1e-12));
  CHECK(posefuse::interpolate_pose(a, b, 1.0).isApprox(b, 1e-12));
  // Shorter arc: from +170 deg to -170 deg about z passes through 180 deg.
  const Eigen::Isometry3d c = pose(0, 0, 0, Eigen::Vector3d::UnitZ(), deg2rad(170.0));
  const Eigen::Isometry3d d = pose(0, 0, 0, Eigen::Vector3d::UnitZ(), deg2rad(-170.0));
  const Eigen::Matrix3d half = posefuse::interpolate_pose(c, d, 0.5).linear();
  CHECK(std::abs(std::atan2(half(1, 0), half(0, 0))) == Approx(std::numbers::pi).epsilon(1e-12));
}

TEST_CASE("Interpolation: a planar trajectory at a time", "[core][interpolation]") {
  posefuse::PlanarTrajectory traj;
  traj.push_back(1.0, Eigen::Vector3d(0, 0, deg2rad(170.0)));
  traj.push_back(2.0, Eigen::Vector3d(1, 2, deg2rad(-170.0)));
  traj.push_back(4.0, Eigen::Vector3d(3, 2, 0.0));
  const auto m = posefuse::interpolate_at(traj, 1.5);
  REQUIRE(m);
  CHECK((*m)(0) == Approx(0.5));
  CHECK((*m)(1) == Approx(1.0));
  CHECK(std::abs(posefuse::angle_diff((*m)(2), std::numbers::pi)) < 1e-12);
  // On a sample: returned as stored (headings are not re-wrapped).
  traj.poses[0](2) = 7.0;
  CHECK(posefuse::interpolate_at(traj, 1.0)->z() == 7.0);
  CHECK(posefuse::interpolate_at(traj, 4.0)->x() == 3.0);
  const auto q = posefuse::interpolate_at(traj, 3.0);
  REQUIRE(q);
  CHECK(q->x() == Approx(2.0));
  // Outside the span, or no pose: nothing.
  CHECK_FALSE(posefuse::interpolate_at(traj, 0.999));
  CHECK_FALSE(posefuse::interpolate_at(traj, 4.001));
  CHECK_FALSE(posefuse::interpolate_at(posefuse::PlanarTrajectory{}, 1.0));
  // Bad input is an error.
  CHECK_THROWS_AS(posefuse::interpolate_at(traj, std::nan("")), posefuse::invalid_argument);
  posefuse::PlanarTrajectory back = traj;
  back.t_s = {1.0, 3.5, 2.0};  // out of time order
  CHECK_THROWS_WITH(posefuse::interpolate_at(back, 1.5), Catch::Contains("not in time order at index 2"));
  back = traj;
  back.t_s.pop_back();
  CHECK_THROWS_AS(posefuse::interpolate_at(back, 1.5), posefuse::invalid_argument);
  back = traj;
  back.poses[2](0) = std::nan("");
  CHECK_THROWS_WITH(posefuse::interpolate_at(back, 1.5), Catch::Contains("pose 2 is not finite"));
  // Equal stamps (a reported track) are in time order; the later pose applies after them.
  posefuse::PlanarTrajectory twice;
  twice.push_back(0.0, Eigen::Vector3d(0, 0, 0));
  twice.push_back(1.0, Eigen::Vector3d(1, 0, 0));
  twice.push_back(1.0, Eigen::Vector3d(5, 0, 0));
  twice.push_back(2.0, Eigen::Vector3d(7, 0, 0));
  CHECK(posefuse::interpolate_at(twice, 0.5)->x() == Approx(0.5));
  CHECK(posefuse::interpolate_at(twice, 1.5)->x() == Approx(6.0));
}

TEST_CASE("Interpolation: an SE(3) trajectory at a time", "[core][interpolation]") {
  posefuse::Trajectory traj;
  traj.push_back(10.0, pose(0, 0, 0, Eigen::Vector3d::UnitZ(), 0.0));
  traj.push_back(12.0, pose(4, 0, 2, Eigen::Vector3d::UnitZ(), 1.0));
  const auto m = posefuse::interpolate_at(traj, 11.5);
  REQUIRE(m);
  CHECK((m->translation() - Eigen::Vector3d(3, 0, 1.5)).norm() < 1e-12);
  CHECK(Eigen::AngleAxisd(m->linear()).angle() == Approx(0.75).epsilon(1e-12));
  CHECK(posefuse::interpolate_at(traj, 12.0)->isApprox(traj.poses[1]));
  CHECK_FALSE(posefuse::interpolate_at(traj, 9.0));
  CHECK_FALSE(posefuse::interpolate_at(posefuse::Trajectory{}, 9.0));
  CHECK_THROWS_AS(posefuse::interpolate_at(traj, std::numeric_limits<double>::infinity()),
                  posefuse::invalid_argument);
  posefuse::Trajectory back = traj;
  std::swap(back.t_s[0], back.t_s[1]);
  CHECK_THROWS_WITH(posefuse::interpolate_at(back, 11.0), Catch::Contains("not in time order at index 1"));
  back = traj;
  back.poses[0](0, 3) = std::nan("");
  CHECK_THROWS_WITH(posefuse::interpolate_at(back, 11.0), Catch::Contains("entry 0 is not finite"));
}

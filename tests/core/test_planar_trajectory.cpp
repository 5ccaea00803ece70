// Tests for PlanarTrajectory (core/trajectory.hpp) and the raw sample types
// (core/samples.hpp).
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/trajectory.hpp>

TEST_CASE("PlanarTrajectory: stores (x, y, heading) poses with stamps", "[core][trajectory]") {
  posefuse::PlanarTrajectory traj;
  CHECK(traj.empty());
  traj.push_back(0.5, Eigen::Vector3d(1, 2, 0.3));
  traj.push_back(0.7, Eigen::Vector3d(-1, 4, 7.0));  // headings are stored as given
  CHECK(traj.size() == 2);
  CHECK(traj.position(1) == Eigen::Vector2d(-1, 4));
  CHECK(traj.heading(1) == 7.0);
  const auto p = traj.positions();
  REQUIRE(p.size() == 2);
  CHECK(p[0] == Eigen::Vector2d(1, 2));
  CHECK_NOTHROW(traj.validate());
  CHECK_NOTHROW(posefuse::PlanarTrajectory{}.validate());
}

TEST_CASE("PlanarTrajectory: validate rejects every broken invariant", "[core][trajectory]") {
  posefuse::PlanarTrajectory traj;
  traj.push_back(0.0, Eigen::Vector3d(0, 0, 0));
  traj.push_back(0.1, Eigen::Vector3d(1, 0, 0));
  SECTION("mismatched lengths") {
    traj.t_s.push_back(0.2);
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("3 stamps but 2 poses"));
    CHECK_THROWS_AS(traj.validate_time_order(), posefuse::invalid_argument);
  }
  SECTION("NaN stamp") {
    traj.t_s[1] = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("stamp 1 is not finite"));
  }
  SECTION("Inf heading") {
    traj.poses[0](2) = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(traj.validate_time_order(), Catch::Contains("pose 0 is not finite"));
  }
  SECTION("equal stamps: not strictly increasing, but in time order") {
    traj.t_s[1] = 0.0;
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("not strictly increasing at index 1"));
    CHECK_NOTHROW(traj.validate_time_order());
  }
  SECTION("decreasing stamps") {
    traj.t_s[1] = -0.1;
    CHECK_THROWS_WITH(traj.validate_time_order(), Catch::Contains("not in time order at index 1"));
  }
}

TEST_CASE("Samples: defaults, equality and the SLAM quaternion's coefficient order", "[core][samples]") {
  posefuse::ImuSample a, b;
  CHECK(a == b);
  CHECK(a.accel_mps2.isZero());
  b.mag_uT.z() = -40;
  CHECK_FALSE(a == b);
  posefuse::SlamSample s;
  CHECK(s.state == posefuse::SlamState::kLost);
  CHECK(s.orientation.coeffs() == Eigen::Vector4d(0, 0, 0, 1));  // identity, stored x, y, z, w
  posefuse::SlamSample t = s;
  CHECK(s == t);
  t.orientation.coeffs()(3) = -1;  // the same rotation, another quaternion: not equal
  CHECK_FALSE(s == t);
  t = s;
  t.position_m.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(t == t);  // NaN compares unequal
  const posefuse::WheelSample w{5, {1, 2, 3, 4}};
  CHECK(w == posefuse::WheelSample{5, {1, 2, 3, 4}});
  CHECK_FALSE(w == posefuse::WheelSample{5, {1, 2, 3, 5}});
  const posefuse::PlanarPoseSample g{7, Eigen::Vector3d(1, 2, 3)};
  CHECK(g == posefuse::PlanarPoseSample{7, Eigen::Vector3d(1, 2, 3)});
}

TEST_CASE("Samples: saturating_difference is exact when it fits, saturates otherwise", "[core][samples]") {
  constexpr std::int64_t lo = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int64_t>::max();
  static_assert(posefuse::saturating_difference(5, 7) == -2);
  static_assert(posefuse::saturating_difference(hi, 0) == hi);
  static_assert(posefuse::saturating_difference(lo, 0) == lo);
  static_assert(posefuse::saturating_difference(hi, lo) == hi);   // 2^64 - 1 does not fit
  static_assert(posefuse::saturating_difference(lo, hi) == lo);   // -(2^64 - 1)
  static_assert(posefuse::saturating_difference(lo + 1, 1) == lo);
  static_assert(posefuse::saturating_difference(lo + 1, 2) == lo);  // would be lo - 1
  static_assert(posefuse::saturating_difference(hi - 1, -1) == hi);
  static_assert(posefuse::saturating_difference(hi - 1, -2) == hi);  // would be hi + 1
  static_assert(posefuse::saturating_difference(-1, lo) == hi);     // exactly 2^63 - 1
  CHECK(posefuse::saturating_difference(1'600'000'000'000'000'000, 1'599'999'999'990'000'000) ==
        10'000'000);
}

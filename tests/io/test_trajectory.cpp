// Trajectory invariants, selection, path length and road-plane projection.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <limits>
#include <vector>

#include <posefuse/core/plane.hpp>
#include <posefuse/core/trajectory.hpp>

namespace {

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

}  // namespace

TEST_CASE("Trajectory: validate accepts a good trajectory", "[io][trajectory]") {
  posefuse::Trajectory traj;
  traj.push_back(0.0, at(0, 0, 0));
  traj.push_back(0.1, at(1, 0, 0));
  CHECK(traj.size() == 2);
  CHECK_FALSE(traj.empty());
  CHECK_NOTHROW(traj.validate());
  CHECK_NOTHROW(posefuse::Trajectory{}.validate());
}

TEST_CASE("Trajectory: validate rejects every broken invariant", "[io][trajectory]") {
  posefuse::Trajectory traj;
  traj.push_back(0.0, at(0, 0, 0));
  traj.push_back(0.1, at(1, 0, 0));
  SECTION("mismatched lengths") {
    traj.t_s.push_back(0.2);
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("3 stamps but 2 poses"));
  }
  SECTION("NaN stamp") {
    traj.t_s[1] = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("stamp 1 is not finite"));
  }
  SECTION("Inf in a pose") {
    traj.poses[0].translation().y() = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("pose 0 is not finite"));
  }
  SECTION("equal stamps") {
    traj.t_s[1] = 0.0;
    CHECK_THROWS_AS(traj.validate(), posefuse::invalid_argument);
  }
  SECTION("decreasing stamps") {
    traj.t_s[1] = -1.0;
    CHECK_THROWS_WITH(traj.validate(), Catch::Contains("not strictly increasing at index 1"));
  }
}

TEST_CASE("Trajectory: positions, select and path_length", "[io][trajectory]") {
  posefuse::Trajectory traj;
  traj.push_back(0.0, at(0, 0, 0));
  traj.push_back(1.0, at(3, 4, 0));   // 5 m
  traj.push_back(2.0, at(3, 4, 12));  // 12 m
  const std::vector<Eigen::Vector3d> p = traj.positions();
  REQUIRE(p.size() == 3);
  CHECK(p[1] == Eigen::Vector3d(3, 4, 0));
  CHECK(posefuse::path_length(traj) == 17.0);
  const std::vector<std::size_t> ids{2, 0, 2};
  const posefuse::Trajectory sub = posefuse::select(traj, ids);
  CHECK(sub.t_s == std::vector<double>{2.0, 0.0, 2.0});
  CHECK(sub.poses[0].translation() == Eigen::Vector3d(3, 4, 12));
  const std::vector<std::size_t> bad{3};
  CHECK_THROWS_AS(posefuse::select(traj, bad), posefuse::invalid_argument);
}

TEST_CASE("Plane: parsing and projection keep the named axes", "[io][plane]") {
  using posefuse::Plane;
  CHECK(posefuse::parse_plane("xz") == Plane::kXZ);
  CHECK(posefuse::parse_plane("xy") == Plane::kXY);
  CHECK(posefuse::parse_plane("yz") == Plane::kYZ);
  CHECK(posefuse::to_string(Plane::kYZ) == "yz");
  CHECK_THROWS_AS(posefuse::parse_plane("XZ"), posefuse::invalid_argument);
  CHECK_THROWS_WITH(posefuse::parse_plane("zx"), Catch::Contains("unknown plane 'zx'"));

  const Eigen::Isometry3d T = at(1, 2, 3);
  // KITTI camera frame: x right, y down, z forward -> the road plane is (x, z).
  CHECK(posefuse::project_to_plane(T, Plane::kXZ) == Eigen::Vector2d(1, 3));
  CHECK(posefuse::project_to_plane(T, Plane::kXY) == Eigen::Vector2d(1, 2));
  CHECK(posefuse::project_to_plane(T, Plane::kYZ) == Eigen::Vector2d(2, 3));

  posefuse::Trajectory traj;
  traj.push_back(0.0, at(1, 2, 3));
  traj.push_back(1.0, at(-4, 5, -6));
  const std::vector<Eigen::Vector2d> xz = posefuse::project_to_plane(traj, Plane::kXZ);
  REQUIRE(xz.size() == 2);
  CHECK(xz[1] == Eigen::Vector2d(-4, -6));
}

// Umeyama alignment: exact recovery of known SE(3) / Sim(3) transforms, the
// reflection fix, degenerate inputs, and evo's way of applying the result.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include <posefuse/eval/alignment.hpp>

#include "support/synthetic_trajectory.hpp"

namespace {

std::vector<Eigen::Vector3d> random_points(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> d(0.0, 20.0);
  std::vector<Eigen::Vector3d> p(n);
  for (Eigen::Vector3d& x : p) x = Eigen::Vector3d(d(rng), d(rng), d(rng));
  return p;
}

}  // namespace

TEST_CASE("Alignment: Umeyama recovers a known SE(3)", "[eval][alignment]") {
  std::mt19937_64 rng(42);
  const Eigen::Isometry3d T = posefuse::test::random_pose(rng, 50.0);
  const std::vector<Eigen::Vector3d> x = random_points(100, 1);
  std::vector<Eigen::Vector3d> y;
  for (const Eigen::Vector3d& p : x) y.push_back(T * p);
  const posefuse::AlignmentResult a = posefuse::umeyama_alignment(x, y, false);
  CHECK((a.rotation - T.linear()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((a.translation - T.translation()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(a.scale == 1.0);
}

TEST_CASE("Alignment: Umeyama recovers a known Sim(3)", "[eval][alignment]") {
  std::mt19937_64 rng(43);
  const Eigen::Isometry3d T = posefuse::test::random_pose(rng, 50.0);
  const double s = 24.8;  // like monocular ORB-SLAM on KITTI 06
  const std::vector<Eigen::Vector3d> x = random_points(100, 2);
  std::vector<Eigen::Vector3d> y;
  for (const Eigen::Vector3d& p : x) y.push_back(s * (T.linear() * p) + T.translation());
  const posefuse::AlignmentResult a = posefuse::umeyama_alignment(x, y, true);
  CHECK((a.rotation - T.linear()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((a.translation - T.translation()).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(a.scale == Approx(s).epsilon(1e-12));
  for (std::size_t i = 0; i < x.size(); ++i) CHECK((a.apply(x[i]) - y[i]).norm() < 1e-9);
}

TEST_CASE("Alignment: a mirrored point set gives a proper rotation (reflection fix)",
          "[eval][alignment]") {
  // x: +-3 e1, +-2 e2, +-1 e3 (zero mean, diagonal covariance (3, 4/3, 1/3)).
  // y = diag(1, 1, -1) x is a mirror image. The best *rotation* is I (flipping
  // the least spread axis costs least), so S = diag(1, 1, -1) must be used,
  // and c = tr(D S) / sigma_x^2 = (3 + 4/3 - 1/3) / (14/3) = 6/7.
  std::vector<Eigen::Vector3d> x;
  for (const double sign : {1.0, -1.0}) {
    x.emplace_back(3.0 * sign, 0.0, 0.0);
    x.emplace_back(0.0, 2.0 * sign, 0.0);
    x.emplace_back(0.0, 0.0, 1.0 * sign);
  }
  std::vector<Eigen::Vector3d> y;
  for (const Eigen::Vector3d& p : x) y.emplace_back(p.x(), p.y(), -p.z());
  const posefuse::AlignmentResult se3 = posefuse::umeyama_alignment(x, y, false);
  CHECK(se3.rotation.determinant() == Approx(1.0).epsilon(1e-12));
  CHECK((se3.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(se3.translation.norm() < 1e-12);
  const posefuse::AlignmentResult sim3 = posefuse::umeyama_alignment(x, y, true);
  CHECK(sim3.scale == Approx(6.0 / 7.0).epsilon(1e-12));
}

TEST_CASE("Alignment: degenerate inputs are rejected with a reason", "[eval][alignment]") {
  const std::vector<Eigen::Vector3d> two{{0, 0, 0}, {1, 0, 0}};
  CHECK_THROWS_WITH(posefuse::umeyama_alignment(two, two, false),
                    Catch::Contains("at least 3 point pairs"));
  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  CHECK_THROWS_WITH(posefuse::umeyama_alignment(same, same, true),
                    Catch::Contains("degenerate covariance rank 0"));
  const std::vector<Eigen::Vector3d> line{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {4, 0, 0}};
  CHECK_THROWS_WITH(posefuse::umeyama_alignment(line, line, false),
                    Catch::Contains("degenerate covariance rank 1"));
  const std::vector<Eigen::Vector3d> three{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  CHECK_THROWS_WITH(posefuse::umeyama_alignment(three, two, false),
                    Catch::Contains("3 source but 2 target"));
  CHECK_THROWS_AS(posefuse::parse_alignment("SE3"), posefuse::invalid_argument);
  CHECK(posefuse::parse_alignment("sim3") == posefuse::Alignment::kSim3);
  CHECK(posefuse::to_string(posefuse::Alignment::kSE3) == "se3");
}

TEST_CASE("Alignment: applied as evo does, scale positions then left-multiply",
          "[eval][alignment]") {
  posefuse::Trajectory traj;
  Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
  P.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix();
  P.translation() = Eigen::Vector3d(1, 2, 3);
  traj.push_back(0.0, P);
  posefuse::AlignmentResult a;
  a.rotation = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  a.translation = Eigen::Vector3d(10, 0, -1);
  a.scale = 2.0;
  const posefuse::Trajectory moved = posefuse::apply_alignment(traj, a);
  CHECK(moved.poses[0].linear().isApprox(a.rotation * P.linear(), 1e-15));
  CHECK(moved.poses[0].translation().isApprox(a.rotation * (2.0 * P.translation()) + a.translation,
                                              1e-15));
  CHECK(moved.t_s == traj.t_s);
}

TEST_CASE("Alignment: align_trajectory undoes a Sim(3) on a synthetic drive", "[eval][alignment]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(300, 5);
  // est = ref seen through an arbitrary world frame with a 1/24.8 scale.
  std::mt19937_64 rng(9);
  const Eigen::Isometry3d G = posefuse::test::random_pose(rng, 100.0);
  posefuse::Trajectory est = ref;
  for (Eigen::Isometry3d& T : est.poses) {
    T.translation() /= 24.8;
    T = G * T;
  }
  const posefuse::AlignedTrajectory se3 =
      posefuse::align_trajectory(est, ref, posefuse::Alignment::kSE3);
  const posefuse::AlignedTrajectory sim3 =
      posefuse::align_trajectory(est, ref, posefuse::Alignment::kSim3);
  CHECK(sim3.transform.scale == Approx(24.8).epsilon(1e-10));
  for (std::size_t k = 0; k < ref.size(); ++k) {
    REQUIRE((sim3.trajectory.poses[k].matrix() - ref.poses[k].matrix()).cwiseAbs().maxCoeff() <
            1e-8);
  }
  CHECK(se3.transform.scale == 1.0);
  const posefuse::AlignedTrajectory none =
      posefuse::align_trajectory(est, ref, posefuse::Alignment::kNone);
  CHECK(none.trajectory.poses[7].matrix() == est.poses[7].matrix());
  posefuse::Trajectory shorter = est;
  shorter.poses.pop_back();
  shorter.t_s.pop_back();
  CHECK_THROWS_WITH(posefuse::align_trajectory(shorter, ref, posefuse::Alignment::kSE3),
                    Catch::Contains("call associate() first"));
}

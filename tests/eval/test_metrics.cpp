// APE / RPE / planar RMSE on hand-computed cases, and on KITTI 06 against
// values re-derived independently (tests/eval/evo_crosscheck.py).
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

#include "support/data_path.hpp"
#include "support/synthetic_trajectory.hpp"

namespace {

using posefuse::PoseRelation;
using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

Eigen::Isometry3d pose(const Eigen::Vector3d& t, double yaw_rad = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// Reference: poses at x = 0, 1, ..., n-1 m (identity rotation), 1 s apart.
posefuse::Trajectory straight_line(std::size_t n, double step_m = 1.0) {
  posefuse::Trajectory traj;
  for (std::size_t k = 0; k < n; ++k) {
    traj.push_back(static_cast<double>(k), pose({step_m * static_cast<double>(k), 0, 0}));
  }
  return traj;
}

}  // namespace

TEST_CASE("Metrics: rmse_2d of seed 000, by hand", "[eval][metrics]") {
  const std::vector<Eigen::Vector2d> gt{{0, 0}, {1, 1}};
  const std::vector<Eigen::Vector2d> est{{3, 4}, {1, 1}};
  CHECK(posefuse::rmse_2d(gt, est) == Approx(std::sqrt(12.5)).epsilon(1e-15));
  const std::vector<Eigen::Vector2d> one{{0, 0}};
  CHECK_THROWS_WITH(posefuse::rmse_2d(gt, one), Catch::Contains("2 ground-truth but 1"));
  CHECK_THROWS_AS(posefuse::rmse_2d({}, {}), posefuse::invalid_argument);
}

TEST_CASE("Metrics: rotation_angle is accurate from 0 to pi", "[eval][metrics]") {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
  for (const double theta :
       {0.0, 1e-9, 1e-4, 0.5, 2.0, std::numbers::pi - 1e-7, std::numbers::pi}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(theta, axis).toRotationMatrix();
    CHECK(posefuse::rotation_angle(R) == Approx(theta).epsilon(1e-9).margin(1e-15));
  }
}

TEST_CASE("Metrics: APE on a 4-pose trajectory, by hand", "[eval][metrics][ape]") {
  const posefuse::Trajectory ref = straight_line(4);
  posefuse::Trajectory est = ref;
  // Translation errors 0, 1, 2, 3 m and rotation errors 0, 10, 20, 30 deg.
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const double kd = static_cast<double>(k);
    est.poses[k] = pose(ref.poses[k].translation() + Eigen::Vector3d(0, kd, 0), 10.0 * kd * deg);
  }
  const posefuse::MetricResult t = posefuse::ape(ref, est, PoseRelation::kTranslation);
  CHECK(t.errors == std::vector<double>{0, 1, 2, 3});
  CHECK(t.stats.rmse == Approx(std::sqrt(3.5)));
  CHECK(t.stats.mean == 1.5);
  CHECK(t.stats.median == 1.5);
  CHECK(t.stats.std == Approx(std::sqrt(1.25)));
  CHECK(t.stats.sse == 14.0);
  CHECK(t.pairs.empty());

  const posefuse::MetricResult a = posefuse::ape(ref, est, PoseRelation::kRotationAngleDeg);
  for (std::size_t k = 0; k < 4; ++k) CHECK(a.errors[k] == Approx(10.0 * double(k)).margin(1e-12));
  CHECK(a.stats.median == Approx(15.0));
  const posefuse::MetricResult r = posefuse::ape(ref, est, PoseRelation::kRotationAngleRad);
  CHECK(r.errors[3] == Approx(30.0 * deg));

  // Full: ||E - I||_F with E = P^-1 Q; here ||R - I||_F^2 = 8 sin^2(theta/2)
  // and the translation block has the norm of the position error.
  const posefuse::MetricResult f = posefuse::ape(ref, est, PoseRelation::kFull);
  for (std::size_t k = 0; k < 4; ++k) {
    const double th = 10.0 * double(k) * deg, s = std::sin(th / 2);
    CHECK(f.errors[k] == Approx(std::sqrt(8.0 * s * s + double(k * k))).margin(1e-12));
  }
}

TEST_CASE("Metrics: APE with alignment removes a rigid / similarity offset",
          "[eval][metrics][ape]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(200, 3);
  const Eigen::Isometry3d G = pose({5, -1, 7}, 0.7);
  posefuse::Trajectory est = ref;
  for (Eigen::Isometry3d& T : est.poses) T = G * T;
  CHECK(posefuse::ape(ref, est).stats.rmse > 1.0);
  const auto se3 = posefuse::ape(ref, est, PoseRelation::kTranslation, posefuse::Alignment::kSE3);
  CHECK(se3.stats.rmse < 1e-9);
  CHECK(se3.alignment.rotation.isApprox(G.linear().transpose(), 1e-12));
  const auto ang =
      posefuse::ape(ref, est, PoseRelation::kRotationAngleDeg, posefuse::Alignment::kSE3);
  CHECK(ang.stats.max < 1e-9);
  CHECK_THROWS_WITH(posefuse::ape(ref, straight_line(3)), Catch::Contains("associate them first"));
}

TEST_CASE("Metrics: RPE by frames, by hand", "[eval][metrics][rpe]") {
  const posefuse::Trajectory ref = straight_line(5);
  posefuse::Trajectory est = ref;
  est.poses[2].translation().y() = 0.5;  // one displaced pose
  SECTION("delta 1: four pairs, two see the displacement") {
    const posefuse::MetricResult r = posefuse::rpe(ref, est, {});
    CHECK(r.pairs == Pairs{{0, 1}, {1, 2}, {2, 3}, {3, 4}});
    CHECK(r.errors == std::vector<double>{0.0, 0.5, 0.5, 0.0});
    CHECK(r.stats.median == 0.25);  // even count
    CHECK(r.stats.rmse == Approx(std::sqrt(0.125)));
  }
  SECTION("delta 2: ids 0, 2, 4") {
    posefuse::RpeOptions o;
    o.delta = 2;
    const posefuse::MetricResult r = posefuse::rpe(ref, est, o);
    CHECK(r.pairs == Pairs{{0, 2}, {2, 4}});
    CHECK(r.errors == std::vector<double>{0.5, 0.5});
  }
  SECTION("delta 3: ids 0, 3 only (4 is not a multiple of 3)") {
    posefuse::RpeOptions o;
    o.delta = 3;
    const posefuse::MetricResult r = posefuse::rpe(ref, est, o);
    CHECK(r.pairs == Pairs{{0, 3}});
    CHECK(r.stats.count == 1);
    CHECK(r.errors[0] == 0.0);
  }
  SECTION("bad deltas") {
    posefuse::RpeOptions o;
    o.delta = 0;
    CHECK_THROWS_AS(posefuse::rpe(ref, est, o), posefuse::invalid_argument);
    o.delta = 1.5;
    CHECK_THROWS_WITH(posefuse::rpe(ref, est, o), Catch::Contains("integer"));
    o.delta = 5;
    CHECK_THROWS_WITH(posefuse::rpe(ref, est, o), Catch::Contains("empty index list"));
  }
}

TEST_CASE("Metrics: RPE with a delta in frames beyond any size_t says the list is empty",
          "[eval][metrics][rpe]") {
  // Regression: the delta was cast to size_t unchecked, undefined behaviour
  // for 1e300 or 2^64 (x86 turned both into 0: "must be at least 1").
  const posefuse::Trajectory ref = straight_line(5);
  posefuse::RpeOptions o;
  for (const double delta : {1e300, 1.8446744073709552e19, 9.223372036854775808e18, 1e19, 5.0}) {
    INFO("delta " << delta);
    o.delta = delta;
    CHECK_THROWS_WITH(posefuse::rpe(ref, ref, o), Catch::Contains("produced an empty index list") &&
                                                      Catch::Contains("(frames)"));
  }
  o.delta = 1e300;
  CHECK_THROWS_WITH(posefuse::rpe(ref, ref, o), Catch::StartsWith("rpe: delta = 1e+300 (frames)"));
  o.delta = 4;  // n - 1: one pair
  CHECK(posefuse::rpe(ref, ref, o).pairs == Pairs{{0, 4}});
  // The index pairs themselves do not wrap around for a step near SIZE_MAX.
  CHECK(posefuse::rpe_pairs_by_index(5, std::numeric_limits<std::size_t>::max()).empty());
}

TEST_CASE("Metrics: RPE rotation angle per pair", "[eval][metrics][rpe]") {
  // Reference turns 10 deg per step, estimate 12 deg: every pair errs by 2 deg.
  posefuse::Trajectory ref, est;
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t k = 0; k < 6; ++k) {
    const double kd = static_cast<double>(k);
    ref.push_back(kd, pose({kd, 0, 0}, 10.0 * kd * deg));
    est.push_back(kd, pose({kd, 0, 0}, 12.0 * kd * deg));
  }
  posefuse::RpeOptions o;
  o.relation = PoseRelation::kRotationAngleDeg;
  const posefuse::MetricResult r = posefuse::rpe(ref, est, o);
  REQUIRE(r.errors.size() == 5);
  for (const double e : r.errors) CHECK(e == Approx(2.0).epsilon(1e-12));
}

TEST_CASE("Metrics: RPE by metres picks pairs on the estimate unless told otherwise",
          "[eval][metrics][rpe]") {
  // Reference advances 1 m per pose, the estimate 2 m (twice too fast).
  const posefuse::Trajectory ref = straight_line(11, 1.0);
  const posefuse::Trajectory est = straight_line(11, 2.0);
  // evo's rule on the estimate, delta 3 m: path 2 (k=1) < 3, 4 (k=2) >= 3 ->
  // id 2, reset; 4 at k=4 -> id 4; ... Index 0 is never an id.
  CHECK(posefuse::rpe_pairs_by_path(est.poses, 3.0) == Pairs{{2, 4}, {4, 6}, {6, 8}, {8, 10}});
  CHECK(posefuse::rpe_pairs_by_path(ref.poses, 3.0) == Pairs{{3, 6}, {6, 9}});

  posefuse::RpeOptions o;
  o.delta = 3.0;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  const posefuse::MetricResult on_est = posefuse::rpe(ref, est, o);
  CHECK(on_est.errors == std::vector<double>{2, 2, 2, 2});  // 4 m travelled vs 2 m true
  o.pairs_from_reference = true;
  const posefuse::MetricResult on_ref = posefuse::rpe(ref, est, o);
  CHECK(on_ref.errors == std::vector<double>{3, 3});  // 6 m vs 3 m
  o.delta = -1.0;
  CHECK_THROWS_AS(posefuse::rpe(ref, est, o), posefuse::invalid_argument);
  o.delta = 100.0;
  CHECK_THROWS_WITH(posefuse::rpe(ref, est, o), Catch::Contains("empty index list"));
}

TEST_CASE("Metrics: RPE ignores SE(3) alignment but not Sim(3) scale", "[eval][metrics][rpe]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(200, 8);
  posefuse::Trajectory est = posefuse::test::perturb(ref, 0.05, 0.002, 4);
  const Eigen::Isometry3d G = pose({3, 1, -2}, 1.1);
  for (Eigen::Isometry3d& T : est.poses) {
    T.translation() *= 0.5;  // monocular-like scale
    T = G * T;
  }
  posefuse::RpeOptions o;
  const double none = posefuse::rpe(ref, est, o).stats.rmse;
  o.alignment = posefuse::Alignment::kSE3;
  CHECK(posefuse::rpe(ref, est, o).stats.rmse == Approx(none).epsilon(1e-9));
  o.alignment = posefuse::Alignment::kSim3;
  const posefuse::MetricResult sim3 = posefuse::rpe(ref, est, o);
  CHECK(sim3.alignment.scale == Approx(2.0).epsilon(0.01));
  CHECK(sim3.stats.rmse < 0.5 * none);
}

TEST_CASE("Metrics: parsers", "[eval][metrics]") {
  CHECK(posefuse::parse_pose_relation("trans") == PoseRelation::kTranslation);
  CHECK(posefuse::parse_pose_relation("angle_deg") == PoseRelation::kRotationAngleDeg);
  CHECK(posefuse::parse_pose_relation("full") == PoseRelation::kFull);
  CHECK_THROWS_AS(posefuse::parse_pose_relation("rot"), posefuse::invalid_argument);
  CHECK(posefuse::parse_delta_unit("m") == posefuse::DeltaUnit::kMeters);
  CHECK(posefuse::parse_delta_unit("frames") == posefuse::DeltaUnit::kFrames);
  CHECK_THROWS_AS(posefuse::parse_delta_unit("s"), posefuse::invalid_argument);
  CHECK(posefuse::unit_of(PoseRelation::kRotationAngleDeg) == "deg");
}

// Reference values: tests/eval/evo_crosscheck.py, an independent pure-Python
// implementation of evo's definitions (Horn's quaternion alignment instead
// of the SVD). They agree with posefuse to better than 1e-5.
TEST_CASE("Metrics: KITTI 06 ORB-SLAM2 stereo APE and RPE match evo's definitions",
          "[eval][metrics][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "kitti/06");
  const posefuse::Trajectory gt = posefuse::read_kitti(dir / "groundtruth.txt", dir / "times.txt");
  const posefuse::Trajectory est =
      posefuse::read_kitti(dir / "orbslam2_stereo.txt", dir / "times.txt");

  // evo_ape kitti groundtruth.txt orbslam2_stereo.txt -a
  const auto se3 = posefuse::ape(gt, est, PoseRelation::kTranslation, posefuse::Alignment::kSE3);
  REQUIRE(se3.stats.rmse == Approx(0.7504).margin(1e-3));
  CHECK(se3.stats.rmse == Approx(0.750409).margin(1e-5));
  CHECK(se3.stats.mean == Approx(0.682740).margin(1e-5));
  CHECK(se3.stats.median == Approx(0.668036).margin(1e-5));
  CHECK(se3.stats.std == Approx(0.311416).margin(1e-5));
  CHECK(se3.stats.min == Approx(0.219585).margin(1e-5));
  CHECK(se3.stats.max == Approx(1.524709).margin(1e-5));
  CHECK(se3.stats.sse == Approx(619.987665).margin(1e-4));
  CHECK(se3.stats.count == 1101);

  // evo_ape kitti ... -as
  const auto sim3 = posefuse::ape(gt, est, PoseRelation::kTranslation, posefuse::Alignment::kSim3);
  CHECK(sim3.stats.rmse == Approx(0.563501).margin(1e-5));
  CHECK(sim3.alignment.scale == Approx(0.996415).margin(1e-6));

  // evo_rpe kitti ... (delta 1 frame), and -r angle_deg
  posefuse::RpeOptions o;
  CHECK(posefuse::rpe(gt, est, o).stats.rmse == Approx(0.018583).margin(1e-5));
  o.relation = PoseRelation::kRotationAngleDeg;
  CHECK(posefuse::rpe(gt, est, o).stats.rmse == Approx(0.043171).margin(1e-5));
  // evo_rpe kitti ... --delta 10 --delta_unit f
  o.relation = PoseRelation::kTranslation;
  o.delta = 10;
  CHECK(posefuse::rpe(gt, est, o).stats.rmse == Approx(0.104459).margin(1e-5));
  // evo_rpe kitti ... --delta 100 --delta_unit m (-r angle_deg)
  o.delta = 100;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  const auto rpe100 = posefuse::rpe(gt, est, o);
  CHECK(rpe100.stats.count == 11);
  CHECK(rpe100.stats.rmse == Approx(0.662570).margin(1e-5));
  o.relation = PoseRelation::kRotationAngleDeg;
  CHECK(posefuse::rpe(gt, est, o).stats.rmse == Approx(0.438944).margin(1e-5));

  // Seed 000's metric on the raw output (no alignment), road plane x-z.
  const double raw = posefuse::rmse_2d(posefuse::project_to_plane(gt, posefuse::Plane::kXZ),
                                       posefuse::project_to_plane(est, posefuse::Plane::kXZ));
  CHECK(raw == Approx(0.874250).margin(1e-5));
}

TEST_CASE("Metrics: KITTI 06 ORB-SLAM2 mono needs Sim(3), scale about 24.8",
          "[eval][metrics][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "kitti/06");
  // Ground truth as TUM: KITTI poses with times.txt stamps.
  const posefuse::Trajectory gt = posefuse::read_kitti(dir / "groundtruth.txt", dir / "times.txt");
  const posefuse::Trajectory mono = posefuse::read_tum(dir / "orbslam2_mono.tum");
  // evo_ape tum gt.tum orbslam2_mono.tum -as   (t_max_diff 0.01 s)
  const posefuse::AssociatedTrajectories sync = posefuse::associate(gt, mono);
  REQUIRE(sync.ref.size() == 1101);
  const auto sim3 =
      posefuse::ape(sync.ref, sync.est, PoseRelation::kTranslation, posefuse::Alignment::kSim3);
  CHECK(sim3.alignment.scale == Approx(24.841695).margin(1e-5));
  CHECK(sim3.alignment.scale > 24.0);
  CHECK(sim3.alignment.scale < 26.0);
  CHECK(sim3.stats.rmse == Approx(12.978526).margin(1e-4));
  CHECK(sim3.stats.median == Approx(11.687740).margin(1e-4));
  // Without scale the error is of the size of the trajectory itself.
  const auto se3 =
      posefuse::ape(sync.ref, sync.est, PoseRelation::kTranslation, posefuse::Alignment::kSE3);
  CHECK(se3.stats.rmse > 5.0 * sim3.stats.rmse);
  // evo_rpe tum ... --delta 100 --delta_unit m -as
  posefuse::RpeOptions o;
  o.delta = 100;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  o.alignment = posefuse::Alignment::kSim3;
  CHECK(posefuse::rpe(sync.ref, sync.est, o).stats.rmse == Approx(9.460708).margin(1e-4));
  WARN("KITTI 06 mono: Sim(3) scale " << sim3.alignment.scale << ", APE RMSE " << sim3.stats.rmse
                                      << " m, SE(3) APE RMSE " << se3.stats.rmse << " m");
}

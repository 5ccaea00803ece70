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
#include <posefuse/eval/trajectory_filters.hpp>
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
  CHECK_THROWS_WITH(posefuse::ape(ref, straight_line(3)), Catch::Contains("call associate() first"));
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

// ---------------------------------------------------------------------------
// evo_ape / evo_rpe options (evaluation issue), each on a hand-worked case.

namespace {

posefuse::Trajectory line_along_x(const std::vector<double>& xs) {
  posefuse::Trajectory traj;
  for (std::size_t k = 0; k < xs.size(); ++k) traj.push_back(double(k), pose({xs[k], 0, 0}));
  return traj;
}

Eigen::Isometry3d yaw_z(double yaw_rad, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace

TEST_CASE("Metrics: rot_part is |R(E) - I|_F = 2 sqrt(2) |sin(theta/2)|", "[eval][metrics][evo-options]") {
  posefuse::Trajectory ref, est;
  for (int k = 0; k < 4; ++k) {
    ref.push_back(k, pose({double(k), 0, 0}));
    est.push_back(k, pose({double(k), 0, 0}, 0.1 * k));
  }
  const auto r = posefuse::ape(ref, est, PoseRelation::kRotationPart);
  for (int k = 0; k < 4; ++k) CHECK(r.errors[k] == Approx(2 * std::sqrt(2.0) * std::sin(0.05 * k)).margin(1e-15));
  CHECK(posefuse::unit_of(PoseRelation::kRotationPart).empty());
  CHECK(posefuse::parse_pose_relation("rot_part") == PoseRelation::kRotationPart);
}

TEST_CASE("Metrics: point_distance compares distances, not directions", "[eval][metrics][evo-options]") {
  // The reference steps 1 m along x, the estimate 1.1 m along y: trans_part
  // sees the whole direction error, point_distance only the 0.1 m of length.
  posefuse::Trajectory ref, est;
  for (int k = 0; k < 5; ++k) {
    ref.push_back(k, pose({double(k), 0, 0}));
    est.push_back(k, pose({0, 1.1 * k, 0}));
  }
  posefuse::RpeOptions o;
  o.relation = PoseRelation::kPointDistance;
  const auto d = posefuse::rpe(ref, est, o);
  REQUIRE(d.errors.size() == 4);
  for (const double e : d.errors) CHECK(e == Approx(0.1).margin(1e-14));
  o.relation = PoseRelation::kPointDistanceErrorRatio;
  const auto ratio = posefuse::rpe(ref, est, o);
  for (const double e : ratio.errors) CHECK(e == Approx(10.0).margin(1e-12));
  CHECK(posefuse::unit_of(PoseRelation::kPointDistanceErrorRatio) == "%");
  o.relation = PoseRelation::kTranslation;
  CHECK(posefuse::rpe(ref, est, o).errors[0] == Approx(std::hypot(1.0, 1.1)));
  // APE point_distance = position distance; the ratio is RPE only.
  const auto ape = posefuse::ape(ref, est, PoseRelation::kPointDistance);
  CHECK(ape.errors[2] == Approx(std::hypot(2.0, 2.2)));
  CHECK_THROWS_WITH(posefuse::ape(ref, est, PoseRelation::kPointDistanceErrorRatio),
                    Catch::Contains("relative (RPE) measure"));
  // A pair whose reference does not move has no ratio and is left out.
  posefuse::Trajectory still = ref;
  still.poses[1] = still.poses[0];
  o.relation = PoseRelation::kPointDistanceErrorRatio;
  const auto skipped = posefuse::rpe(still, est, o);
  CHECK(skipped.errors.size() == 3);
  CHECK(skipped.pairs.front() == std::pair<std::size_t, std::size_t>{1, 2});
}

TEST_CASE("Metrics: all pairs by index and by path with a tolerance", "[eval][metrics][evo-options]") {
  CHECK(posefuse::rpe_pairs_by_index(5, 2, true) == Pairs{{0, 2}, {1, 3}, {2, 4}});
  CHECK(posefuse::rpe_pairs_by_index(5, 2, false) == Pairs{{0, 2}, {2, 4}});
  // Path 0, 1, 2, 3.5, 4 m; delta 2 m, tolerance 10 % = 0.2 m: pose 0 pairs
  // with pose 2 (exactly 2 m), pose 1 finds 1 or 2.5 m (both too far), pose 2
  // pairs with 4 (2 m), poses 3 and 4 have nothing 2 m ahead.
  const posefuse::Trajectory t = line_along_x({0, 1, 2, 3.5, 4});
  posefuse::RpeOptions o;
  o.delta = 2.0;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  o.all_pairs = true;
  CHECK(posefuse::rpe(t, t, o).pairs == Pairs{{0, 2}, {2, 4}});
  o.delta_tol = 0.26;  // 0.52 m: pose 1 now pairs with pose 3 (2.5 m, 0.5 m off)
  CHECK(posefuse::rpe(t, t, o).pairs == Pairs{{0, 2}, {1, 3}, {2, 4}});
  o.delta = 10.0;
  CHECK_THROWS_WITH(posefuse::rpe(t, t, o), Catch::Contains("or a larger --delta-tol"));
  o.delta_tol = -1.0;
  CHECK_THROWS_AS(posefuse::rpe(t, t, o), posefuse::invalid_argument);
}

TEST_CASE("Metrics: RPE by rotation angle in degrees and radians", "[eval][metrics][evo-options]") {
  // Ten poses turning 10 degrees each about z: a 29.9-degree step gives the
  // ids 0, 3, 6, 9 (the sum reaches 30 degrees at every third pose).
  posefuse::Trajectory t;
  for (int k = 0; k < 10; ++k) t.push_back(k, yaw_z(k * 10.0 * std::numbers::pi / 180.0));
  posefuse::RpeOptions o;
  o.delta = 29.9;
  o.delta_unit = posefuse::DeltaUnit::kDegrees;
  CHECK(posefuse::rpe(t, t, o).pairs == Pairs{{0, 3}, {3, 6}, {6, 9}});
  o.delta = 29.9 * std::numbers::pi / 180.0;
  o.delta_unit = posefuse::DeltaUnit::kRadians;
  CHECK(posefuse::rpe(t, t, o).pairs == Pairs{{0, 3}, {3, 6}, {6, 9}});
  CHECK(posefuse::parse_delta_unit("d") == posefuse::DeltaUnit::kDegrees);
  CHECK(posefuse::parse_delta_unit("rad") == posefuse::DeltaUnit::kRadians);
}

TEST_CASE("Metrics: scale-only alignment, n_to_align and origin alignment", "[eval][metrics][evo-options]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(60, 3, 50.0);
  SECTION("scale only multiplies positions and leaves rotations") {
    posefuse::Trajectory est = ref;
    for (auto& T : est.poses) T.translation() *= 2.5;
    const auto r = posefuse::ape(ref, est, PoseRelation::kTranslation, posefuse::Alignment::kScale);
    CHECK(r.alignment.scale == Approx(0.4).epsilon(1e-12));
    CHECK(r.alignment.rotation == Eigen::Matrix3d::Identity());
    CHECK(r.alignment.translation == Eigen::Vector3d::Zero());
    CHECK(r.stats.max < 1e-9);
    // A rotated copy is not fixed by scale alone.
    posefuse::Trajectory turned = est;
    for (auto& T : turned.poses) T = yaw_z(0.3) * T;
    CHECK(posefuse::ape(ref, turned, PoseRelation::kTranslation, posefuse::Alignment::kScale).stats.max > 1.0);
  }
  SECTION("n_to_align uses only the first poses") {
    // The first 10 estimate poses are the reference moved by a known T; the
    // rest drift. Aligning on the first 10 recovers T exactly.
    const Eigen::Isometry3d T = yaw_z(0.7, {3, -2, 1});
    posefuse::Trajectory est = ref;
    for (std::size_t k = 0; k < est.size(); ++k) {
      est.poses[k] = T.inverse() * ref.poses[k];
      if (k >= 10) est.poses[k].translation() += Eigen::Vector3d(0.2 * double(k - 9), 0, 0);
    }
    posefuse::AlignmentOptions a;
    a.alignment = posefuse::Alignment::kSE3;
    a.n_to_align = 10;
    const auto r = posefuse::ape(ref, est, PoseRelation::kTranslation, a);
    CHECK(r.alignment.rotation.isApprox(T.linear(), 1e-12));
    CHECK((r.alignment.translation - T.translation()).norm() < 1e-10);
    for (std::size_t k = 0; k < 10; ++k) CHECK(r.errors[k] < 1e-10);
    CHECK(r.errors.back() == Approx(0.2 * 50).epsilon(1e-9));
    a.n_to_align = 61;
    CHECK_THROWS_WITH(posefuse::ape(ref, est, PoseRelation::kTranslation, a),
                      Catch::Contains("only 60 are associated"));
  }
  SECTION("origin alignment maps the first pose onto the reference's") {
    const Eigen::Isometry3d T = yaw_z(-1.1, {10, 5, 0});
    posefuse::Trajectory est = ref;
    for (auto& P : est.poses) P = T * P;
    posefuse::AlignmentOptions a;
    a.align_origin = true;
    const auto r = posefuse::ape(ref, est, PoseRelation::kTranslation, a);
    CHECK(r.stats.max < 1e-9);  // a rigid copy: every pose lands on the reference
    CHECK(r.alignment.rotation.isApprox(T.linear().transpose(), 1e-12));
    a.alignment = posefuse::Alignment::kSE3;
    CHECK_THROWS_WITH(posefuse::ape(ref, est, PoseRelation::kTranslation, a),
                      Catch::Contains("exclude each other"));
  }
}

TEST_CASE("Metrics: time range, down-sampling and the motion filter", "[eval][metrics][evo-options]") {
  const posefuse::Trajectory t = line_along_x({0, 0.4, 0.8, 1.2, 1.6, 2.0, 2.4, 2.8, 3.2, 3.6});
  const auto stamps = [](const posefuse::Trajectory& x) { return x.t_s; };
  CHECK(stamps(posefuse::reduce_to_time_range(t, 2.5, 6.0)) == std::vector<double>{3, 4, 5, 6});
  CHECK(stamps(posefuse::reduce_to_time_range(t, std::nullopt, 1.0)) == std::vector<double>{0, 1});
  CHECK(stamps(posefuse::reduce_to_time_range(t, 8.0, std::nullopt)) == std::vector<double>{8, 9});
  CHECK(posefuse::reduce_to_time_range(t, 20.0, std::nullopt).empty());
  CHECK_THROWS_AS(posefuse::reduce_to_time_range(t, 3.0, 2.0), posefuse::invalid_argument);
  // numpy.linspace(0, 9, m, dtype=int)
  CHECK(stamps(posefuse::downsample(t, 4)) == std::vector<double>{0, 3, 6, 9});
  CHECK(stamps(posefuse::downsample(t, 3)) == std::vector<double>{0, 4, 9});
  CHECK(stamps(posefuse::downsample(t, 1)) == std::vector<double>{0});
  CHECK(posefuse::downsample(t, 10).size() == 10);
  CHECK_THROWS_AS(posefuse::downsample(t, 0), posefuse::invalid_argument);
  // 0.4 m steps, 1 m threshold: kept at 1.2 m (pose 3), 2.4 m (6), 3.6 m (9).
  CHECK(stamps(posefuse::motion_filter(t, 1.0, 10.0)) == std::vector<double>{0, 3, 6, 9});
  // Turning in place 10 degrees a step, 25-degree threshold: 0, 3, 6, 9.
  posefuse::Trajectory turn;
  for (int k = 0; k < 10; ++k) turn.push_back(k, yaw_z(k * 10.0 * std::numbers::pi / 180.0));
  CHECK(stamps(posefuse::motion_filter(turn, 1.0, 25.0 * std::numbers::pi / 180.0)) ==
        std::vector<double>{0, 3, 6, 9});
  CHECK_THROWS_AS(posefuse::motion_filter(t, -1.0, 1.0), posefuse::invalid_argument);
}

TEST_CASE("Metrics: projection to a plane keeps the angle about its normal", "[eval][metrics][evo-options]") {
  // R = Rz(0.5) Ry(0.2) Rx(0.1) at (1, 2, 3).
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, 2, 3);
  posefuse::Trajectory t;
  t.push_back(0.0, T);
  const struct {
    posefuse::Plane plane;
    Eigen::Vector3d position;
    Eigen::Vector3d axis;
    double angle;
  } cases[] = {{posefuse::Plane::kXY, {1, 2, 0}, Eigen::Vector3d::UnitZ(), 0.5},
               {posefuse::Plane::kXZ, {1, 0, 3}, Eigen::Vector3d::UnitY(), 0.2},
               {posefuse::Plane::kYZ, {0, 2, 3}, Eigen::Vector3d::UnitX(), 0.1}};
  for (const auto& c : cases) {
    const posefuse::Trajectory p = posefuse::project_poses_to_plane(t, c.plane);
    CHECK(p.poses[0].translation() == c.position);
    CHECK(p.poses[0].linear().isApprox(Eigen::AngleAxisd(c.angle, c.axis).toRotationMatrix(), 1e-14));
  }
  // In the metric: a height and tilt error vanish in the xy projection.
  posefuse::Trajectory ref, est;
  for (int k = 0; k < 5; ++k) {
    ref.push_back(k, yaw_z(0.1 * k, {double(k), 0, 0}));
    Eigen::Isometry3d P = ref.poses.back();
    P.translation().z() += 0.5;
    P.linear() = P.linear() * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
    est.push_back(k, P);
  }
  posefuse::AlignmentOptions a;
  CHECK(posefuse::ape(ref, est, PoseRelation::kTranslation, a).stats.max == Approx(0.5));
  a.project_to_plane = posefuse::Plane::kXY;
  CHECK(posefuse::ape(ref, est, PoseRelation::kTranslation, a).stats.max < 1e-15);
  CHECK(posefuse::ape(ref, est, PoseRelation::kRotationAngleRad, a).stats.max < 1e-7);
}

TEST_CASE("Metrics: posyaw alignment recovers a 4-DoF transform and leaves roll/pitch visible",
          "[eval][metrics][evo-options]") {
  // A z-up drive with height changes, so that a tilt shows in the positions.
  posefuse::Trajectory ref;
  for (int k = 0; k < 80; ++k) {
    const double a = 0.08 * k;
    ref.push_back(k, yaw_z(a + 1.2, {20 * std::cos(a), 12 * std::sin(a), 2 * std::sin(3 * a)}));
  }
  const Eigen::Isometry3d T4 = yaw_z(2.1, {-7, 3, 1.5});  // a 4-DoF transform
  posefuse::Trajectory est = ref;
  for (auto& P : est.poses) P = T4 * P;
  const auto exact = posefuse::ape(ref, est, PoseRelation::kTranslation, posefuse::Alignment::kPosYaw);
  CHECK(exact.stats.max < 1e-9);
  CHECK(exact.alignment.rotation.isApprox(T4.linear().transpose(), 1e-12));
  CHECK(posefuse::ape(ref, est, PoseRelation::kRotationAngleDeg, posefuse::Alignment::kPosYaw).stats.max < 1e-9);
  // A 2-degree roll of the whole estimate: SE(3) alignment absorbs it,
  // position + yaw cannot, so the roll error stays in the rotation APE.
  const Eigen::Isometry3d roll(Eigen::AngleAxisd(2.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()));
  for (auto& P : est.poses) P = roll * P;
  const auto se3 = posefuse::ape(ref, est, PoseRelation::kRotationAngleDeg, posefuse::Alignment::kSE3);
  const auto posyaw = posefuse::ape(ref, est, PoseRelation::kRotationAngleDeg, posefuse::Alignment::kPosYaw);
  CHECK(se3.stats.max < 1e-6);
  CHECK(posyaw.stats.min == Approx(2.0).epsilon(1e-3));
  CHECK(posyaw.stats.max == Approx(2.0).epsilon(1e-3));
  CHECK(posefuse::parse_alignment("posyaw") == posefuse::Alignment::kPosYaw);
  CHECK(posefuse::to_string(posefuse::Alignment::kPosYaw) == "posyaw");
}

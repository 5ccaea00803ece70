// The sound fuser: information weighting, gates, angle awareness, re-anchoring.
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/fusion/gated_fuser.hpp>

using posefuse::FilterStatus;
using posefuse::FuserGate;
using posefuse::FuserStatus;
using posefuse::GatedFuser;
using posefuse::GatedFuserParams;
using Pose = posefuse::PlanarPose<double>;

static_assert(posefuse::Stage<GatedFuser<double>>);
static_assert(posefuse::Stage<GatedFuser<float>>);

namespace {

constexpr double kPi = std::numbers::pi;

// True pose on a 2 m-radius circle driven counter-clockwise, at arc length s.
Pose circle(double s) {
  const double a = s / 2.0;
  return {2.0 * std::sin(a), 2.0 - 2.0 * std::cos(a), posefuse::wrap_angle(a)};
}

// Odometry that drifts: heading error grows 2° per metre, so its frame rotates away.
Pose drifting_odometry(double s) {
  const double drift = 2.0 * kPi / 180.0;
  Pose p{0, 0, 0};
  const int n = int(s / 0.01);
  for (int i = 0; i < n; ++i) {
    const double a = (i + 0.5) * 0.01 / 2.0 + drift * (i + 0.5) * 0.01;
    p.x += 0.01 * std::cos(a);
    p.y += 0.01 * std::sin(a);
  }
  p.theta = posefuse::wrap_angle(s / 2.0 + drift * s);
  return p;
}

double distance(const Pose& a, const Pose& b) { return std::hypot(a.x - b.x, a.y - b.y); }

}  // namespace

TEST_CASE("GatedFuser: SE(2) helpers", "[fusion][gated]") {
  const Pose a{1.0, -2.0, 2.5}, b{0.3, 0.7, -3.0};
  const Pose e = posefuse::se2_compose(posefuse::se2_inverse(a), a);
  CHECK(e.x == Approx(0).margin(1e-12));
  CHECK(e.y == Approx(0).margin(1e-12));
  CHECK(e.theta == Approx(0).margin(1e-12));
  const Pose c = posefuse::se2_compose(a, b);
  const Pose back = posefuse::se2_compose(c, posefuse::se2_inverse(b));
  CHECK(back.x == Approx(a.x));
  CHECK(back.y == Approx(a.y));
  CHECK(back.theta == Approx(a.theta));
  // They are thin wrappers over SE2.
  const posefuse::SE2d c2 = posefuse::as_se2(a) * posefuse::as_se2(b);
  CHECK(c.x == c2.x());
  CHECK(c.y == c2.y());
  CHECK(c.theta == c2.angle());
  CHECK(c.theta == Approx(posefuse::wrap_angle(2.5 - 3.0)));
}

TEST_CASE("GatedFuser: fuse_poses is the information-weighted mean", "[fusion][gated]") {
  Eigen::Matrix3d Pa = Eigen::Vector3d(0.04, 0.01, 0.001).asDiagonal();
  Eigen::Matrix3d Pb = Eigen::Vector3d(0.01, 0.04, 0.003).asDiagonal();
  const Pose a{1.0, 2.0, 0.1}, b{2.0, 1.0, 0.2};
  const auto f = posefuse::fuse_poses(a, Pa, b, Pb);
  const Eigen::Matrix3d P = (Pa.inverse() + Pb.inverse()).inverse();
  const Eigen::Vector3d x = P * (Pa.inverse() * a.vector() + Pb.inverse() * b.vector());
  CHECK(f.pose.x == Approx(x(0)));  // 1.8
  CHECK(f.pose.y == Approx(x(1)));  // 1.8
  CHECK(f.pose.theta == Approx(x(2)));  // 0.125
  CHECK(f.pose.x == Approx(1.8));
  CHECK(f.pose.theta == Approx(0.125));
  CHECK((f.cov - P).cwiseAbs().maxCoeff() < 1e-12);
  // Across ±180°: 170° (weight 3) and -170° (weight 1) fuse to 175°.
  const double d = kPi / 180.0;
  const Eigen::Matrix3d P1 = Eigen::Matrix3d::Identity() * 0.01, P3 = P1 * 3.0;
  const auto g = posefuse::fuse_poses<double>({0, 0, 170 * d}, P1, {0, 0, -170 * d}, P3);
  CHECK(g.pose.theta == Approx(175 * d));
}

TEST_CASE("GatedFuser: the first SLAM poses anchor the map frame, then SLAM is fused",
          "[fusion][gated]") {
  GatedFuser<double> f;  // >= 8 anchor samples over >= 0.5 m
  const Pose T_wm{3.0, -1.0, 2.0};  // SLAM map frame, unknown to the fuser
  int fused = 0, anchored_at = -1;
  for (int k = 0; k <= 300; ++k) {
    const double s = 0.02 * k;
    REQUIRE(f.predict(drifting_odometry(s)) == FilterStatus::kApplied);
    const Pose z = posefuse::se2_compose(posefuse::se2_inverse(T_wm), circle(s));
    const FuserStatus st = f.update_slam(z, false);
    if (anchored_at < 0) CHECK((st == FuserStatus::kAnchoring || st == FuserStatus::kAnchored));
    if (st == FuserStatus::kAnchored) anchored_at = k;
    fused += st == FuserStatus::kFused;
  }
  CHECK(anchored_at >= 25);  // 0.5 m of travel at 2 cm per sample
  CHECK(anchored_at <= 26);
  CHECK(fused == 300 - anchored_at);
  CHECK(f.anchored());
  CHECK(f.anchor_count() == 1);
  // The anchored map frame is the true one up to the odometry's drift while
  // anchoring (2°/m here, about 1° over the 0.5 m window — unobservable), and
  // the fused pose follows the truth far better than the drifting odometry.
  CHECK(distance(f.map_in_world(), T_wm) < 0.05);
  CHECK(std::abs(posefuse::angle_diff(f.map_in_world().theta, T_wm.theta)) < 0.03);
  CHECK(distance(f.pose(), circle(6.0)) < 0.1);
  CHECK(distance(drifting_odometry(6.0), circle(6.0)) > 0.45);
  // Rebasing: the correction maps the odometry frame onto the fused estimate.
  const Pose rebased = posefuse::se2_compose(f.odometry_correction(), drifting_odometry(6.0));
  CHECK(distance(rebased, f.pose()) < 1e-9);
}

TEST_CASE("GatedFuser: a re-initialised SLAM map is re-anchored, not discarded",
          "[fusion][gated][reanchor]") {
  // Two fusers see the same drifting odometry; SLAM is lost for 2 m and comes
  // back in a new map frame. One re-anchors it; the other (as the seed's fuser
  // effectively does with a map it cannot place) gets no SLAM after the loss.
  GatedFuser<double> f, discard;
  const Pose map0{0, 0, 0}, map1{-4.0, 7.0, -2.5};
  int anchored = 0, fused_after = 0;
  double max_jump = 0;
  Pose prev = f.pose();
  for (int k = 0; k <= 600; ++k) {
    const double s = 0.02 * k;
    (void)f.predict(drifting_odometry(s));
    (void)discard.predict(drifting_odometry(s));
    const bool lost = k > 200 && k < 300;  // SLAM lost for 2 m
    if (!lost) {
      const Pose& m = k <= 200 ? map0 : map1;
      const Pose z = posefuse::se2_compose(posefuse::se2_inverse(m), circle(s));
      const bool reinit = k == 300;  // first pose in the new frame
      const FuserStatus st = f.update_slam(z, reinit);
      if (k <= 200) (void)discard.update_slam(z, false);
      anchored += st == FuserStatus::kAnchored;
      if (k > 340) fused_after += st == FuserStatus::kFused;
    }
    max_jump = std::max(max_jump, distance(prev, f.pose()));
    prev = f.pose();
  }
  CHECK(anchored == 2);  // first map, then the re-initialised one
  CHECK(fused_after == 260);
  CHECK(max_jump < 0.1);  // continuous: no jump into the new map frame
  // What remains is the heading drift accumulated while SLAM was lost (about
  // 5° here), which no fuser can observe; re-anchoring stops further drift.
  const double err = distance(f.pose(), circle(12.0));
  const double err_discard = distance(discard.pose(), circle(12.0));
  CHECK(err < 0.4);
  CHECK(err < 0.6 * err_discard);  // 0.35 m vs 0.69 m
}

TEST_CASE("GatedFuser: an unannounced SLAM frame jump is rejected, then re-anchored",
          "[fusion][gated][reanchor]") {
  GatedFuserParams<double> p;
  p.reanchor_after_rejects = 5;
  GatedFuser<double> f(p);
  const Pose map1{2.0, 2.0, 1.0};
  int rejected = 0, anchored = 0;
  for (int k = 0; k <= 400; ++k) {
    const double s = 0.02 * k;
    (void)f.predict(circle(s));
    const Pose z = s < 4.0 ? circle(s) : posefuse::se2_compose(posefuse::se2_inverse(map1), circle(s));
    const FuserStatus st = f.update_slam(z, false);
    rejected += posefuse::is_rejection(st);
    anchored += st == FuserStatus::kAnchored;
  }
  CHECK(rejected == 5);
  CHECK(anchored == 2);
  CHECK(distance(f.pose(), circle(8.0)) < 0.05);
}

TEST_CASE("GatedFuser: a frozen SLAM pose does not get anchored", "[fusion][gated]") {
  GatedFuser<double> f;
  for (int k = 0; k <= 100; ++k) {
    (void)f.predict({0.027 * k, 0, 0});  // 0.4 m/s with SLAM at 15 Hz
    CHECK(f.update_slam({0, 0, 0}, false) == FuserStatus::kAnchoring);
  }
  CHECK_FALSE(f.anchored());
  CHECK(f.pose().x == Approx(2.7));
}

TEST_CASE("GatedFuser: separate gates reject position or heading alone; Mahalanobis mode",
          "[fusion][gated]") {
  GatedFuserParams<double> p;
  p.anchor_samples = 1;
  p.anchor_min_travel_m = 0;
  for (auto mode : {posefuse::GateMode::kSeparate, posefuse::GateMode::kMahalanobis,
                    posefuse::GateMode::kBoth}) {
    p.gate = mode;
    GatedFuser<double> f(p);
    (void)f.predict({0, 0, 0});
    REQUIRE(f.update_slam({0, 0, 0}, false) == FuserStatus::kAnchored);
    (void)f.predict({1, 0, 0});
    const FuserStatus pos = f.update_slam({1.5, 0, 0}, false);       // 0.5 m off, same heading
    const FuserStatus head = f.update_slam({1.0, 0, 0.5}, false);    // same place, 29° off
    const FuserStatus ok = f.update_slam({1.02, -0.01, 0.01}, false);
    if (mode == posefuse::GateMode::kMahalanobis) {
      CHECK(pos == FuserStatus::kRejectedJoint);
      CHECK(head == FuserStatus::kRejectedJoint);
    } else {
      CHECK(pos == FuserStatus::kRejectedPosition);
      CHECK(head == FuserStatus::kRejectedHeading);
    }
    // One step status (the Ekf's), the gate in its own field.
    CHECK(pos.step == FilterStatus::kGated);
    CHECK(head.step == FilterStatus::kGated);
    CHECK(pos.rejected_by != FuserGate::kNone);
    CHECK(posefuse::is_rejection(head));
    CHECK(ok == FuserStatus::kFused);
    CHECK(ok.step == FilterStatus::kApplied);
    CHECK(ok.rejected_by == FuserGate::kNone);
  }
}

TEST_CASE("GatedFuser: heading updates and non-finite input", "[fusion][gated]") {
  GatedFuser<double> f;
  (void)f.predict({0, 0, 0});
  (void)f.predict({1, 0, 0.2});
  const double var0 = f.covariance()(2, 2);
  CHECK(f.update_heading(0.21, 0.05) == FuserStatus::kFused);
  CHECK(f.covariance()(2, 2) < var0);
  CHECK(f.pose().theta > 0.2);
  const FuserStatus rej = f.update_heading(0.2 + kPi / 2, 0.01);
  CHECK(rej == FuserStatus::kRejectedHeading);
  CHECK(rej.rejected_by == FuserGate::kHeading);
  // Across ±π the residual wraps: 179° measured at a heading near -179°.
  posefuse::GatedFuser<double> g;
  g.reset(Pose{0, 0, -179 * kPi / 180}, Eigen::Matrix3d::Identity() * 0.01);
  REQUIRE(g.update_heading(179 * kPi / 180, 0.05) == FuserStatus::kFused);
  CHECK(std::abs(g.pose().theta) > 179 * kPi / 180);  // moved through ±180°, not through 0
  const Pose before = f.pose();
  const Eigen::Matrix3d P_before = f.covariance();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(f.predict({nan, 0, 0}) == FilterStatus::kNonFinite);
  CHECK(f.update_slam({0, nan, 0}, false) == FuserStatus::kNonFinite);
  CHECK(f.update_heading(nan, 0.1) == FuserStatus::kNonFinite);
  CHECK(f.update_heading(0.2, 0.0) == FilterStatus::kInvalidInput);
  CHECK(f.update_heading(0.2, -0.1).step == FilterStatus::kInvalidInput);
  CHECK(f.pose().x == before.x);
  CHECK(f.pose().theta == before.theta);
  CHECK(f.covariance() == P_before);
}

TEST_CASE("GatedFuser: invalid parameters throw", "[fusion][gated]") {
  GatedFuserParams<double> p;
  p.slam_xy_sigma_m = 0;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
  p = {};
  p.odom_xy_sigma_per_sqrt_m = -1;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
  p = {};
  p.anchor_samples = 0;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
  p.anchor_samples = 33;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
  p = {};
  p.anchor_min_travel_m = -0.1;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
  p = {};
  p.reanchor_after_rejects = 0;
  CHECK_THROWS_AS(GatedFuser<double>(p), posefuse::invalid_argument);
}

TEMPLATE_TEST_CASE("GatedFuser: stage form in float and double", "[fusion][gated]", float, double) {
  using T = TestType;
  GatedFuser<T> f;
  typename GatedFuser<T>::Output out{};
  for (int k = 0; k <= 50; ++k) {
    typename GatedFuser<T>::Input in;
    in.odom = {T(0.05) * T(k), T(0), T(0)};
    in.has_slam = true;
    in.slam = {T(0.05) * T(k) + T(0.01), T(0), T(0)};
    out = f(in);
  }
  CHECK(out.slam_status == FuserStatus::kFused);
  CHECK(out.odom_status == FilterStatus::kApplied);
  CHECK(out.pose.x == Approx(2.5).margin(0.02));
  CHECK(out.cov(0, 0) > T(0));
  // Without a SLAM pose there is no SLAM status.
  typename GatedFuser<T>::Input odom_only;
  odom_only.odom = {T(2.6), T(0), T(0)};
  out = f(odom_only);
  CHECK(out.odom_status == FilterStatus::kApplied);
  CHECK_FALSE(out.slam_status.has_value());
  CHECK(out.pose.x == Approx(2.6).margin(0.02));
}

TEST_CASE("GatedFuser: reset() forgets the distance travelled and the anchor count",
          "[fusion][gated]") {
  GatedFuserParams<double> p;
  p.anchor_samples = 4;
  p.anchor_min_travel_m = 0.3;
  GatedFuser<double> f(p);
  // Drive 2 m straight with SLAM in the world frame: anchors once.
  for (int k = 0; k <= 40; ++k) {
    const Pose o{0.05 * k, 0, 0};
    (void)f.predict(o);
    (void)f.update_slam(o, false);
  }
  REQUIRE(f.anchor_count() == 1);
  CHECK(f.travelled() == Approx(2.0));
  f.reset(Pose{}, Eigen::Matrix3d::Identity() * 1e-6);
  CHECK(f.anchor_count() == 0);
  CHECK(f.travelled() == 0.0);
  CHECK_FALSE(f.anchored());
  // After the reset, standing still never spans anchor_min_travel_m: no anchor.
  for (int k = 0; k < 10; ++k) {
    (void)f.predict(Pose{5, 5, 0});
    CHECK(f.update_slam(Pose{1, 1, 0}, false) == FuserStatus::kAnchoring);
  }
  CHECK(f.anchor_count() == 0);
  // A covariance that is not one is refused, and the fuser keeps its state.
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(0, 1) = 2.0;
  bad(1, 0) = 2.0;  // symmetric, indefinite
  const Pose kept = f.pose();
  const Eigen::Matrix3d kept_cov = f.covariance();
  CHECK_THROWS_AS(f.reset(Pose{1, 2, 3}, bad), posefuse::invalid_argument);
  CHECK(f.pose().x == kept.x);
  CHECK(f.covariance() == kept_cov);
}

TEST_CASE("GatedFuser: predicted covariance matches Monte Carlo propagation on a curve",
          "[fusion][gated][odometry]") {
  // Noise-free odometry (all odometry sigmas 0) along a left-turning arc:
  // the covariance then comes from the initial uncertainty alone, carried by
  // the motion model's Jacobian. Its position-heading terms (the lever arm of
  // a heading error) must agree with propagating samples through exact SE(2)
  // composition; a sign error in the heading column of F flips them.
  GatedFuserParams<double> p;
  p.odom_xy_sigma_per_sqrt_m = 0;
  p.odom_theta_sigma_per_sqrt_m = 0;
  p.odom_theta_sigma_per_sqrt_rad = 0;
  GatedFuser<double> f(p);
  const Pose start{1.0, -0.5, 2.8};  // heading near +π; the arc crosses it
  Eigen::Matrix3d P0;
  P0 << 4e-4, 1e-4, 0, 1e-4, 9e-4, 2e-4, 0, 2e-4, 1e-3;
  f.reset(start, P0);
  std::vector<Pose> odom;
  Pose o{0, 0, 0};
  for (int k = 0; k <= 40; ++k) {
    odom.push_back(o);
    o = posefuse::se2_compose(o, Pose{0.1, 0.0, 0.03});
  }
  for (const Pose& ok : odom) REQUIRE(f.predict(ok) == FilterStatus::kApplied);

  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Matrix3d L = P0.llt().matrixL();
  const posefuse::SE2d delta = posefuse::as_se2(odom.front()).between(posefuse::as_se2(odom.back()));
  constexpr int kSamples = 40000;
  std::vector<Pose> ends;
  ends.reserve(kSamples);
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d e = L * Eigen::Vector3d(n(rng), n(rng), n(rng));
    ends.push_back(posefuse::as_planar_pose(posefuse::as_se2(start.plus(e)) * delta));
  }
  const Pose mean_end = posefuse::as_planar_pose(posefuse::as_se2(start) * delta);
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const Pose& y : ends) {
    const Eigen::Vector3d d = y.minus(mean_end);
    C += d * d.transpose() / double(kSamples);
  }
  const Eigen::Matrix3d& P = f.covariance();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      INFO("entry (" << i << ", " << j << "): fuser " << P(i, j) << ", Monte Carlo " << C(i, j));
      CHECK(std::abs(P(i, j) - C(i, j)) < 0.03 * std::sqrt(C(i, i) * C(j, j)));
    }
  // The lever arm is long here: the position-heading covariance comes from
  // the heading error, not from P0 (whose P0(0, 2) = 0, P0(1, 2) = 2e-4).
  INFO("P(0, 2) = " << P(0, 2) << ", P(1, 2) = " << P(1, 2));
  CHECK(std::hypot(C(0, 2), C(1, 2)) > 10 * std::hypot(P0(0, 2), P0(1, 2)));
  CHECK(f.pose().minus(mean_end).norm() < 1e-9);
}

TEST_CASE("GatedFuser: its prediction and SLAM update are Ekf steps of the planar models",
          "[fusion][gated]") {
  // The fuser, and an Ekf<Se2Odometry> driven by hand with the same models,
  // agree bit for bit once the map frame is anchored at the identity.
  GatedFuserParams<double> p;
  p.anchor_samples = 1;
  p.anchor_min_travel_m = 0;
  GatedFuser<double> f(p);
  (void)f.predict({0, 0, 0});
  REQUIRE(f.update_slam({0, 0, 0}, false) == FuserStatus::kAnchored);
  REQUIRE(f.map_in_world().x == 0.0);
  REQUIRE(f.map_in_world().theta == 0.0);
  posefuse::Ekf<posefuse::Se2Odometry<double>> ekf{posefuse::Se2Odometry<double>(
      {p.odom_xy_sigma_per_sqrt_m, p.odom_theta_sigma_per_sqrt_m, p.odom_theta_sigma_per_sqrt_rad})};
  ekf.reset(f.pose(), f.covariance());
  const auto slam = posefuse::PlanarPoseFix<double>::from_sigmas(p.slam_xy_sigma_m,
                                                                 p.slam_theta_sigma_rad);
  Pose prev{0, 0, 0};
  for (int k = 1; k <= 60; ++k) {
    const Pose o = circle(0.05 * k);
    REQUIRE(f.predict(o) == FilterStatus::kApplied);
    REQUIRE(ekf.predict(posefuse::as_se2(prev).between(posefuse::as_se2(o)), 0.0) ==
            FilterStatus::kApplied);
    prev = o;
    REQUIRE(f.pose().x == ekf.state().x);
    REQUIRE(f.covariance() == ekf.covariance());
    if (k % 3 == 0) {
      const Pose z{o.x + 0.01, o.y - 0.02, posefuse::wrap_angle(o.theta + 0.005)};
      REQUIRE(f.update_slam(z, false) == FuserStatus::kFused);
      // T_wm (+) z as the fuser forms it: position through the map frame's
      // rotation, heading as the wrapped sum of the two headings.
      const Pose a = f.map_in_world();
      const Eigen::Vector2d pw = posefuse::as_se2(a).act(z.position());
      const Pose zw{pw.x(), pw.y(), posefuse::wrap_angle(a.theta + z.theta)};
      REQUIRE(ekf.update_with(slam, zw));
      REQUIRE(f.pose().x == ekf.state().x);
      REQUIRE(f.pose().theta == ekf.state().theta);
      REQUIRE(f.covariance() == ekf.covariance());
    }
  }
  CHECK(&f.filter().covariance() == &f.covariance());
}

TEST_CASE("GatedFuser: status fields and names", "[fusion][gated]") {
  CHECK(FuserStatus::kFused.applied());
  CHECK_FALSE(FuserStatus::kAnchoring.applied());
  CHECK(FuserStatus::kAnchoring.anchor == posefuse::AnchorEvent::kCollecting);
  CHECK(FuserStatus::kAnchored.anchor == posefuse::AnchorEvent::kAnchored);
  CHECK(FuserStatus::kSingularInnovation.step == FilterStatus::kNotPositiveDefinite);
  CHECK(FuserStatus(FilterStatus::kNonFinite) == FuserStatus::kNonFinite);
  CHECK(FuserStatus::kRejectedPosition != FuserStatus::kRejectedHeading);
  for (auto g : {FuserGate::kNone, FuserGate::kPosition, FuserGate::kHeading, FuserGate::kJoint})
    CHECK(std::string(posefuse::to_string(g)) != "unknown");
  for (auto e : {posefuse::AnchorEvent::kNone, posefuse::AnchorEvent::kCollecting,
                 posefuse::AnchorEvent::kAnchored})
    CHECK(std::string(posefuse::to_string(e)) != "unknown");
}

TEST_CASE("GatedFuser: fuse_poses is one Ekf update; bad covariances throw", "[fusion][gated]") {
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() * 0.01;
  const Pose a{1, 2, 0.1}, b{1.2, 1.8, 0.3};
  const auto f = posefuse::fuse_poses(a, P, b, P);
  CHECK(f.pose.x == Approx(1.1));
  CHECK(f.pose.theta == Approx(0.2));
  CHECK((f.cov - P / 2).cwiseAbs().maxCoeff() < 1e-15);
  // Pa + Pb singular: NaN, as documented.
  Eigen::Matrix3d Z = Eigen::Matrix3d::Zero();
  const auto s = posefuse::fuse_poses(a, Z, b, Z);
  CHECK(std::isnan(s.pose.x));
  CHECK(std::isnan(s.cov(0, 0)));
  Eigen::Matrix3d bad = P;
  bad(2, 2) = -1;
  CHECK_THROWS_AS(posefuse::fuse_poses(a, bad, b, P), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::fuse_poses(a, P, b, bad), posefuse::invalid_argument);
}

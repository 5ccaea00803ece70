#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <posefuse/eval/metrics.hpp>
#include <apps/trajectory_correction.hpp>
#include <posefuse/sim/kitti_like_drive.hpp>

using namespace posefuse;

namespace {
std::vector<Eigen::Vector2d> plane_points(const Trajectory& t) {
  return project_to_plane(t, Plane::kXZ);
}
}  // namespace

TEST_CASE("Seed 000 corrector returns its input, for any R and Q", "[filters][seed000]") {
  // SPEC.md A: with u_t = z_t - z_{t-1} and mu_0 = z_0, e_t = (I - K_t) e_{t-1} = 0.
  const sim::SyntheticDrive drive = sim::make_kitti_like_drive();
  const auto raw = plane_points(drive.estimate);
  for (const double r : {1e-4, 0.05, 10.0}) {
    for (const double q : {1e-3, 0.5, 100.0}) {
      auto corrector = make_seed000_corrector(Plane::kXZ, Eigen::Matrix2d::Identity() * r,
                                              Eigen::Matrix2d::Identity() * q,
                                              Eigen::Matrix2d::Identity());
      double max_dev = 0;
      for (std::size_t i = 0; i < drive.estimate.size(); ++i) {
        const CorrectedPoint c = corrector({drive.estimate.t_s[i], drive.estimate.poses[i]});
        REQUIRE(c.status == FilterStatus::kApplied);
        max_dev = std::max(max_dev, (c.p - raw[i]).cwiseAbs().maxCoeff());
      }
      // Equal up to the rounding of z_{t-1} + (z_t - z_{t-1}) (positions ~ 1e3 m).
      CHECK(max_dev < 1e-12 * 1e3);
    }
  }
}

TEST_CASE("Seed 000 corrector started away from its input converges to it",
          "[filters][seed000]") {
  DisplacementEkf ekf(Eigen::Matrix2d::Identity() * 0.01, Eigen::Matrix2d::Identity() * 0.01,
                      Eigen::Matrix2d::Identity());
  DisplacementControl control;
  (void)ekf(control({0.0, Eigen::Vector2d(5, 5)}));
  // Knock the filter off its input once by a biased control, then feed truth.
  CorrectorStep s = control({1.0, Eigen::Vector2d(6, 5)});
  s.u += Eigen::Vector2d(3, 0);
  double err = (ekf(s).p - Eigen::Vector2d(6, 5)).norm();
  CHECK(err > 0.01);
  for (int k = 2; k < 30; ++k) {
    const double e = (ekf(control({double(k), Eigen::Vector2d(5 + k, 5)})).p -
                      Eigen::Vector2d(5 + k, 5))
                         .norm();
    CHECK(e <= err);  // e_t = (I - K) e_{t-1}: monotone decay
    err = e;
  }
  CHECK(err < 1e-6);
}

TEST_CASE("Constant-velocity corrector and RTS smoother remove jitter, not drift",
          "[filters][cv][rts]") {
  sim::KittiLikeDriveConfig cfg;
  const sim::SyntheticDrive drive = sim::make_kitti_like_drive(cfg);
  const auto truth = plane_points(drive.groundtruth);
  const auto raw = plane_points(drive.estimate);
  auto cv = make_constant_velocity_corrector(Plane::kXZ, 1.0, cfg.jitter_m);
  std::vector<Eigen::Vector2d> filtered;
  for (std::size_t i = 0; i < drive.estimate.size(); ++i)
    filtered.push_back(cv({drive.estimate.t_s[i], drive.estimate.poses[i]}).p);
  const auto smoothed_beliefs = rts_smooth(cv.stage<1>().history());
  std::vector<Eigen::Vector2d> smoothed;
  for (const auto& b : smoothed_beliefs) smoothed.push_back(b.mean.head<2>());

  const double e_raw = rmse_2d(truth, raw);
  const double e_rts = rmse_2d(truth, smoothed);
  // Without jitter the estimate would be pure drift: the best a smoother can do.
  cfg.jitter_m = 0;
  const auto drift_only = plane_points(sim::make_kitti_like_drive(cfg).estimate);
  const double e_drift = rmse_2d(truth, drift_only);
  INFO("raw " << e_raw << " cv " << rmse_2d(truth, filtered) << " rts " << e_rts << " drift-only "
              << e_drift);
  CHECK(e_rts < e_raw);
  CHECK(rmse_2d(truth, filtered) < e_raw);
  CHECK(e_rts < 1.02 * e_drift);  // jitter gone ...
  CHECK(e_rts > 0.9 * e_drift);   // ... drift stays
  // Smoothing takes the white noise out: the smoothed path is much closer to
  // the jitter-free estimate than the raw one.
  CHECK(rmse_2d(drift_only, smoothed) < 0.5 * rmse_2d(drift_only, raw));
}

TEST_CASE("RTS smoother: smoothed covariance never exceeds the filtered one",
          "[filters][rts]") {
  ConstantVelocityFilter f(0.5, 0.3);
  for (int k = 0; k < 50; ++k) (void)f({0.1 * k, Eigen::Vector2d(0.1 * k, std::sin(0.1 * k))});
  const auto& run = f.history();
  const auto s = rts_smooth(run);
  REQUIRE(s.size() == run.size());
  for (std::size_t k = 0; k < s.size(); ++k) {
    const Eigen::Matrix4d d = run[k].filtered_cov - s[k].cov;
    REQUIRE(is_positive_semidefinite(d));
  }
  // The last smoothed belief is the last filtered one.
  CHECK((s.back().mean - run.back().filtered_mean).norm() == 0.0);
}

TEST_CASE("Constant-velocity filter: a prediction that is not applied is reported, and the "
          "smoother gets no stale Jacobian",
          "[filters][cv][rts]") {
  ConstantVelocityFilter f(0.5, 0.3), g(0.5, 0.3);  // g never sees the bad frame
  for (const double t : {0.0, 0.1, 0.2}) {
    REQUIRE(f({t, Eigen::Vector2d(t, 0.5 * t)}).status == FilterStatus::kApplied);
    REQUIRE(g({t, Eigen::Vector2d(t, 0.5 * t)}).status == FilterStatus::kApplied);
  }
  const Eigen::Vector4d belief = f.history().back().filtered_mean;
  const Eigen::Matrix4d cov = f.history().back().filtered_cov;
  // Time goes backwards: the prediction is refused (dt < 0) and no update is tried.
  const CorrectedPoint back = f({0.15, Eigen::Vector2d(5.0, 5.0)});
  CHECK(back.status == FilterStatus::kInvalidInput);
  CHECK(back.p == belief.head<2>());  // the previous belief, not the fix
  REQUIRE(f.history().size() == 4);
  const auto& rec = f.history()[3];
  CHECK(rec.F == Eigen::Matrix4d::Identity());  // "no change", not the last applied F
  CHECK(rec.predicted_mean == belief);
  CHECK(rec.filtered_mean == belief);
  CHECK(rec.filtered_cov == cov);
  // The next frame predicts from the belief's time (0.2 s), exactly as if the
  // bad frame had not been there.
  const CorrectedPoint a = f({0.3, Eigen::Vector2d(0.3, 0.15)});
  const CorrectedPoint b = g({0.3, Eigen::Vector2d(0.3, 0.15)});
  REQUIRE(a.status == FilterStatus::kApplied);
  CHECK(a.p == b.p);
  CHECK(a.P == b.P);
  CHECK(f.history()[4].F == g.history()[3].F);
  CHECK(f.history()[4].F != Eigen::Matrix4d::Identity());
  // The smoother runs over the recorded "no change" step.
  const auto s = rts_smooth(f.history());
  REQUIRE(s.size() == 5);
  for (const auto& x : s) CHECK(x.mean.allFinite());
  // The refused frame's smoothed belief is that of the frame before it (F = I, no update).
  CHECK((s[3].mean - s[2].mean).norm() < 1e-12);
}

TEST_CASE("Seed 000 filter: a prediction that is not applied is reported", "[filters][seed000]") {
  DisplacementEkf ekf(Eigen::Matrix2d::Identity() * 0.01, Eigen::Matrix2d::Identity() * 0.25,
                      Eigen::Matrix2d::Identity());
  DisplacementControl control;
  (void)ekf(control({0.0, Eigen::Vector2d(1, 2)}));
  const CorrectedPoint ok = ekf(control({0.1, Eigen::Vector2d(1.5, 2)}));
  REQUIRE(ok.status == FilterStatus::kApplied);
  CorrectorStep bad = control({0.2, Eigen::Vector2d(2, 2)});
  bad.u.x() = std::numeric_limits<double>::infinity();
  const CorrectedPoint c = ekf(bad);
  CHECK(c.status != FilterStatus::kApplied);
  CHECK(c.p == ok.p);  // state untouched
  CHECK(c.P == ok.P);
}

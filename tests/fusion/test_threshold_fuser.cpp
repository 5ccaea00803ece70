// Seed 001 eq 14-15, reproduced as printed, flaws included.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/seed/threshold_fuser.hpp>

using posefuse::seed::SeedOdometry;
using posefuse::seed::ThresholdFuser;

static_assert(posefuse::Stage<ThresholdFuser<double>>);
static_assert(posefuse::Stage<ThresholdFuser<float>>);

TEMPLATE_TEST_CASE("ThresholdFuser: eq 14 against a hand-worked value", "[fusion][threshold]",
                   float, double) {
  using T = TestType;
  const SeedOdometry<T> m{T(1), T(2), T(0.1), T(0.2), T(0.3)};
  const SeedOdometry<T> v{};
  // sqrt((1 + 4) / 2) = 1.58113883; sqrt((0.01 + 0.04 + 0.09) / 3) = 0.21602469;
  // product / 3 = 0.11385501.
  CHECK(posefuse::seed::seed_o_diff(m, v) == Approx(0.11385501).epsilon(1e-5));
  CHECK(posefuse::seed::seed_o_diff(v, m) == Approx(0.11385501).epsilon(1e-5));
}

TEMPLATE_TEST_CASE("ThresholdFuser: eq 15 averages below the threshold, falls back above it",
                   "[fusion][threshold]", float, double) {
  using T = TestType;
  const ThresholdFuser<T> fuser(T(0.01));
  const SeedOdometry<T> m{T(1), T(1), T(0), T(0), T(0.5)};
  const SeedOdometry<T> close{T(1.1), T(0.9), T(0), T(0), T(0.52)};
  const auto a = fuser({m, close});
  REQUIRE(a.averaged);
  CHECK_FALSE(a.reinitialise);
  CHECK(a.pose.x == Approx(1.05));
  CHECK(a.pose.y == Approx(0.95));
  CHECK(a.pose.yaw == Approx(0.51));

  const SeedOdometry<T> far{T(2), T(2), T(0.1), T(0), T(0.9)};
  const auto b = fuser({m, far});
  CHECK(b.o_diff > T(0.01));
  CHECK_FALSE(b.averaged);
  CHECK(b.reinitialise);  // seed: ORB-SLAM re-initialises from O_m
  CHECK(b.pose.x == m.x);
  CHECK(b.pose.yaw == m.yaw);
}

TEST_CASE("ThresholdFuser: flaw 1 — a 5 m position disagreement passes when the angles agree",
          "[fusion][threshold][flaw]") {
  const ThresholdFuser<double> fuser(0.01);
  const SeedOdometry<double> odom{10.0, 0.0, 0.0, 0.0, 0.3};
  const SeedOdometry<double> slam{15.0, 0.0, 0.0, 0.0, 0.3};  // frozen/jumped SLAM, same heading
  const auto out = fuser({odom, slam});
  CHECK(out.o_diff == 0.0);  // the angle RMS is 0, so the product is 0
  CHECK(out.averaged);       // accepted ...
  CHECK(out.pose.x == Approx(12.5));  // ... and the fused pose is 2.5 m off

  // The sound fuser rejects the same disagreement (see test_gated_fuser.cpp
  // for the full scenario): its position gate ignores the heading agreement.
  posefuse::GatedFuserParams<double> p;
  p.anchor_samples = 1;
  p.anchor_min_travel_m = 0;
  posefuse::GatedFuser<double> gated(p);
  (void)gated.predict({0, 0, 0.3});
  REQUIRE(gated.update_slam({0, 0, 0.3}, false) == posefuse::FuserStatus::kAnchored);
  (void)gated.predict({10, 0, 0.3});  // odometry: straight ahead in its own frame
  const auto st = gated.update_slam({15, 0, 0.3}, false);
  CHECK(st == posefuse::FuserStatus::kRejectedPosition);
}

TEST_CASE("ThresholdFuser: flaw 2 — plain angle arithmetic breaks across ±180°",
          "[fusion][threshold][flaw]") {
  const double d179 = 179.0 * std::numbers::pi / 180.0;
  const SeedOdometry<double> m{0, 0, 0, 0, d179};
  const SeedOdometry<double> v{0, 0, 0, 0, -d179};
  // eq 15-a: (179° + -179°) / 2 = 0°, the opposite direction.
  CHECK(posefuse::seed::seed_average(m, v).yaw == Approx(0.0).margin(1e-12));
  // eq 14 sees a 358° disagreement where there is 2°.
  const SeedOdometry<double> m2{1, 0, 0, 0, d179};
  const SeedOdometry<double> v2{0, 0, 0, 0, -d179};
  const double seen = posefuse::seed::seed_o_diff(m2, v2);
  const double true_diff = std::sqrt(0.5) * std::sqrt((2.0 * std::numbers::pi / 180.0) *
                                                      (2.0 * std::numbers::pi / 180.0) / 3.0) / 3.0;
  CHECK(seen == Approx(true_diff * 179.0));

  // The angle-aware fusion gives 180°.
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() * 0.01;
  const auto f = posefuse::fuse_poses<double>({0, 0, d179}, P, {0, 0, -d179}, P);
  CHECK(std::abs(std::abs(f.pose.theta) - std::numbers::pi) < 1e-9);
}

TEST_CASE("ThresholdFuser: invalid threshold and NaN input", "[fusion][threshold]") {
  CHECK_THROWS_AS(ThresholdFuser<double>(0.0), posefuse::invalid_argument);
  CHECK_THROWS_AS(ThresholdFuser<double>(-1.0), posefuse::invalid_argument);
  CHECK_THROWS_AS(ThresholdFuser<double>(std::numeric_limits<double>::infinity()),
                  posefuse::invalid_argument);
  const ThresholdFuser<double> fuser(0.1);
  const SeedOdometry<double> m{1, 2, 0, 0, 0};
  const SeedOdometry<double> bad{std::numeric_limits<double>::quiet_NaN(), 0, 0, 0, 0};
  const auto out = fuser({m, bad});
  CHECK_FALSE(out.averaged);  // NaN fails the comparison: eq 15-b
  CHECK(out.pose.x == 1.0);
  CHECK(fuser.threshold() == 0.1);
}

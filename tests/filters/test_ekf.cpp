#include <catch2/catch.hpp>
#include <limits>
#include <random>
#include <posefuse/core/chi_square.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/position.hpp>

using namespace posefuse;

TEMPLATE_TEST_CASE("Ekf: seed-000 step matches a hand computation", "[filters][ekf]", float,
                   double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 2, 1>;
  using M = Eigen::Matrix<T, 2, 2>;
  // x0 = 0, P0 = I, u = (1, 2), process noise R = 0.5 I  =>  xbar = (1, 2), Pbar = 1.5 I.
  // z = (2, 2), measurement noise Q = I  =>  S = 2.5 I, K = 0.6 I, r = (1, 0),
  // x = (1.6, 2), P = (1 - 0.6)^2 1.5 + 0.6^2 1 = 0.6 I, NIS = 1^2 / 2.5 = 0.4.
  Ekf<PlanarDisplacement<T>, PositionFix<2, 2, T>> ekf(
      PlanarDisplacement<T>(M::Identity() * T(0.5)), PositionFix<2, 2, T>(M::Identity()));
  ekf.reset(V::Zero(), M::Identity());
  REQUIRE(ekf.predict(V(1, 2), T(1)) == FilterStatus::kApplied);
  CHECK(ekf.state().x() == Approx(1));
  CHECK(ekf.covariance()(0, 0) == Approx(1.5));
  const auto r = ekf.template update<0>(V(2, 2));
  REQUIRE(r.status == FilterStatus::kApplied);
  CHECK(r.innovation.x() == Approx(1));
  CHECK(r.S(0, 0) == Approx(2.5));
  CHECK(r.nis == Approx(0.4));
  CHECK(ekf.state().x() == Approx(1.6));
  CHECK(ekf.state().y() == Approx(2.0));
  CHECK(ekf.covariance()(0, 0) == Approx(0.6));
  CHECK(ekf.covariance()(1, 1) == Approx(0.6));
  CHECK(ekf.covariance()(0, 1) == Approx(0).margin(1e-6));
}

TEST_CASE("Ekf: constant-velocity step with a non-identity Jacobian", "[filters][ekf]") {
  // Per axis: P0 = I, dt = 1, q = 3  =>  F P F^T = [2 1; 1 1], Q = [1 1.5; 1.5 3],
  // Pbar = [3 2.5; 2.5 4]. Fix on x with R = 1: S = 4, K = (0.75, 0.625),
  // x: r = 2 - 1 = 1 => p = 1.75, v = 1.625; P = Pbar - K S K^T = [0.75 0.625; 0.625 2.4375].
  Ekf<ConstantVelocity2<double>, PositionFix<4>> ekf(ConstantVelocity2<double>(3.0),
                                                     PositionFix<4>::isotropic(1.0));
  ekf.reset(Eigen::Vector4d(0, 0, 1, 0), Eigen::Matrix4d::Identity());
  REQUIRE(ekf.predict(NoControl{}, 1.0) == FilterStatus::kApplied);
  CHECK(ekf.covariance()(0, 0) == Approx(3));
  CHECK(ekf.covariance()(0, 2) == Approx(2.5));
  CHECK(ekf.covariance()(2, 2) == Approx(4));
  const auto r = ekf.update<PositionFix<4>>(Eigen::Vector2d(2, 0));
  REQUIRE(r);
  CHECK(r.nis == Approx(0.25));
  CHECK(ekf.state()(0) == Approx(1.75));
  CHECK(ekf.state()(2) == Approx(1.625));
  CHECK(ekf.state()(1) == Approx(0).margin(1e-12));
  CHECK(ekf.covariance()(0, 0) == Approx(0.75));
  CHECK(ekf.covariance()(0, 2) == Approx(0.625));
  CHECK(ekf.covariance()(2, 0) == Approx(0.625));
  CHECK(ekf.covariance()(2, 2) == Approx(2.4375));
}

namespace {
/// A heading-only compass on a planar pose: z = theta, wrapped residual.
struct HeadingFix {
  struct Heading {
    using Scalar = double;
    static constexpr int Dim = 1;
    double value = 0;
    [[nodiscard]] Heading plus(const Eigen::Matrix<double, 1, 1>& d) const {
      return {wrap_angle(value + d(0))};
    }
    [[nodiscard]] Eigen::Matrix<double, 1, 1> minus(const Heading& o) const {
      return Eigen::Matrix<double, 1, 1>(angle_diff(value, o.value));
    }
  };
  using State = PlanarPose<double>;
  using Measurement = Heading;
  double sigma = 0.1;
  [[nodiscard]] Heading predict(const State& x) const { return {x.theta}; }
  [[nodiscard]] Eigen::Matrix<double, 1, 3> jacobian(const State&) const { return {0, 0, 1}; }
  [[nodiscard]] Eigen::Matrix<double, 1, 1> noise() const {
    return Eigen::Matrix<double, 1, 1>(sigma * sigma);
  }
};
struct StillPose {
  using State = PlanarPose<double>;
  using Control = NoControl;
  [[nodiscard]] State predict(const State& x, const Control&, double) const { return x; }
  [[nodiscard]] Eigen::Matrix3d jacobian(const State&, const Control&, double) const {
    return Eigen::Matrix3d::Identity();
  }
  [[nodiscard]] Eigen::Matrix3d noise(const State&, const Control&, double) const {
    return Eigen::Matrix3d::Identity() * 1e-4;
  }
};
}  // namespace

TEST_CASE("Ekf: angle residuals wrap across +-180 degrees", "[filters][ekf]") {
  Ekf<StillPose, HeadingFix> ekf(StillPose{}, HeadingFix{});
  ekf.reset(PlanarPose<double>{0, 0, deg2rad(179.0)}, Eigen::Matrix3d::Identity() * 0.01);
  const auto r = ekf.update<0>(HeadingFix::Heading{deg2rad(-179.0)});
  REQUIRE(r);
  CHECK(rad2deg(r.innovation(0)) == Approx(2.0));
  // The estimate moves towards -179 through 180, not through 0.
  CHECK(std::abs(ekf.state().theta) > deg2rad(179.0));
}

TEST_CASE("Ekf: covariance stays symmetric PSD over many steps", "[filters][ekf]") {
  Ekf<ConstantVelocity2<double>, PositionFix<4>> ekf(ConstantVelocity2<double>(0.01),
                                                     PositionFix<4>::isotropic(1e-3));
  ekf.reset(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity() * 1e6);
  for (int k = 0; k < 2000; ++k) {
    REQUIRE(ekf.predict(NoControl{}, 0.01) == FilterStatus::kApplied);
    REQUIRE(ekf.update<0>(Eigen::Vector2d(0.01 * k, -0.02 * k)));
    const Eigen::Matrix4d& P = ekf.covariance();
    REQUIRE((P - P.transpose()).cwiseAbs().maxCoeff() == 0.0);
    REQUIRE(is_positive_semidefinite(P));
  }
}

TEST_CASE("Ekf: bad data is reported and leaves the filter untouched", "[filters][ekf]") {
  using Filter = Ekf<PlanarDisplacement<double>, PositionFix<2>>;
  Filter ekf(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), PositionFix<2>::isotropic(1));
  const Eigen::Vector2d x0(1, 2);
  ekf.reset(x0, Eigen::Matrix2d::Identity());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  CHECK(ekf.predict(Eigen::Vector2d(nan, 0), 1) == FilterStatus::kNonFinite);
  CHECK(ekf.predict(Eigen::Vector2d(0, 0), inf) == FilterStatus::kNonFinite);
  CHECK(ekf.predict(Eigen::Vector2d(0, 0), -1) == FilterStatus::kInvalidInput);
  CHECK(ekf.update<0>(Eigen::Vector2d(inf, 0)).status == FilterStatus::kNonFinite);
  CHECK(ekf.state() == x0);
  CHECK(ekf.covariance() == Eigen::Matrix2d::Identity());

  // A NIS gate rejects an outlier and still reports its statistics.
  ekf.set_gate<0>(chi_square_quantile(0.99, 2));
  const auto r = ekf.update<0>(Eigen::Vector2d(100, 2));
  CHECK(r.status == FilterStatus::kGated);
  CHECK(r.nis == Approx(99.0 * 99.0 / 2.0));
  CHECK(ekf.state() == x0);
  // A measurement inside the gate is applied.
  CHECK(ekf.update<0>(Eigen::Vector2d(1.5, 2)).status == FilterStatus::kApplied);
}

TEST_CASE("Ekf: non-positive-definite innovation covariance is reported", "[filters][ekf]") {
  // A zero-covariance belief measured by a sensor whose noise is zero on one
  // axis gives a singular S; build one through a custom model.
  struct DegenerateFix {
    using State = Eigen::Vector2d;
    using Measurement = Eigen::Vector2d;
    [[nodiscard]] Eigen::Vector2d predict(const State& x) const { return x; }
    [[nodiscard]] Eigen::Matrix2d jacobian(const State&) const {
      Eigen::Matrix2d J;
      J << 1, 0, 0, 0;
      return J;
    }
    [[nodiscard]] Eigen::Matrix2d noise() const {
      Eigen::Matrix2d R;
      R << 1, 0, 0, 0;
      return R;
    }
  };
  Ekf<PlanarDisplacement<double>, DegenerateFix> ekf(
      PlanarDisplacement<double>::from_sigmas(0.1, 0.1), DegenerateFix{});
  ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity());
  const auto r = ekf.update<0>(Eigen::Vector2d(2, 2));
  CHECK(r.status == FilterStatus::kNotPositiveDefinite);
  CHECK(ekf.state() == Eigen::Vector2d(1, 1));
}

TEST_CASE("Ekf: invalid configuration throws", "[filters][ekf]") {
  Eigen::Matrix2d bad;
  bad << 1, 2, 2, 1;  // symmetric, eigenvalues 3 and -1
  CHECK_THROWS_AS(PlanarDisplacement<double>(bad), posefuse::invalid_argument);
  CHECK_THROWS_AS(PositionFix<2>(Eigen::Matrix2d::Zero()), posefuse::invalid_argument);
  CHECK_THROWS_AS(ConstantVelocity2<double>(-1.0), posefuse::invalid_argument);
  Ekf<PlanarDisplacement<double>, PositionFix<2>> ekf(
      PlanarDisplacement<double>::from_sigmas(0.1, 0.1), PositionFix<2>::isotropic(1));
  CHECK_THROWS_AS(ekf.reset(Eigen::Vector2d::Zero(), bad), posefuse::invalid_argument);
  CHECK_THROWS_AS(ekf.reset(Eigen::Vector2d(std::nan(""), 0), Eigen::Matrix2d::Identity()),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(ekf.set_gate<0>(0.0), posefuse::invalid_argument);
}

TEST_CASE("chi_square_quantile: known table values", "[filters][chi2]") {
  // Values from any chi-square table (e.g. NIST/SEMATECH e-Handbook, 1.3.6.7.4).
  CHECK(chi_square_quantile(0.95, 1) == Approx(3.841459).epsilon(1e-6));
  CHECK(chi_square_quantile(0.99, 2) == Approx(9.210340).epsilon(1e-6));
  CHECK(chi_square_quantile(0.95, 3) == Approx(7.814728).epsilon(1e-6));
  CHECK(chi_square_quantile(0.999, 6) == Approx(22.457744).epsilon(1e-6));
  CHECK(chi_square_cdf(chi_square_quantile(0.5, 10), 10) == Approx(0.5).epsilon(1e-12));
  CHECK_THROWS_AS(chi_square_quantile(1.0, 2), posefuse::invalid_argument);
  CHECK_THROWS_AS(chi_square_quantile(0.5, 0), posefuse::invalid_argument);
}

TEST_CASE("Ekf: reusing a converged gain is bit-identical to recomputing it",
          "[filters][ekf][steady]") {
  // update<0> reuses the covariance part while P repeats (PositionFix is
  // time-invariant); update_with always recomputes. Both filters see the
  // same data, including a gap in dt that moves P off its steady state.
  using Filter = Ekf<ConstantVelocity2<double>, PositionFix<4>>;
  const PositionFix<4> fix = PositionFix<4>::isotropic(0.4);
  Filter memo(ConstantVelocity2<double>(0.7), fix);
  Filter plain(ConstantVelocity2<double>(0.7), fix);
  memo.reset(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity());
  plain.reset(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity());
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.4);
  for (int k = 0; k < 3000; ++k) {
    const double dt = (k % 700 == 699) ? 0.5 : 0.1;
    const Eigen::Vector2d z(0.3 * k + n(rng), -0.1 * k + n(rng));
    REQUIRE(memo.predict(NoControl{}, dt) == FilterStatus::kApplied);
    REQUIRE(plain.predict(NoControl{}, dt) == FilterStatus::kApplied);
    const auto a = memo.update<0>(z);
    const auto b = plain.update_with(fix, z);
    REQUIRE(a.status == b.status);
    REQUIRE(a.nis == b.nis);
    REQUIRE(memo.state() == plain.state());
    REQUIRE(memo.covariance() == plain.covariance());
  }
}

#include <catch2/catch.hpp>
#include <Eigen/LU>
#include <limits>
#include <random>
#include <string>
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

// ---------------------------------------------------------------------------
// One estimation core: initialisation, state-dependent noise, solves, gates.

TEST_CASE("Ekf: stepping before reset() is reported and changes nothing", "[filters][ekf]") {
  using Filter = Ekf<PlanarDisplacement<double>, PositionFix<2>>;
  const PositionFix<2> fix = PositionFix<2>::isotropic(1);
  Filter ekf(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), fix);
  CHECK_FALSE(ekf.initialised());
  const Eigen::Vector2d x_before = ekf.state();
  const Eigen::Matrix2d P_before = ekf.covariance();
  CHECK(ekf.predict(Eigen::Vector2d(1, 2), 1) == FilterStatus::kNotInitialised);
  CHECK(ekf.update<0>(Eigen::Vector2d(3, 4)).status == FilterStatus::kNotInitialised);
  CHECK(ekf.update_with(fix, {3, 4}).status == FilterStatus::kNotInitialised);
  CHECK(ekf.state() == x_before);
  CHECK(ekf.covariance() == P_before);
  ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity());
  CHECK(ekf.initialised());
  CHECK(ekf.predict(Eigen::Vector2d(1, 2), 1) == FilterStatus::kApplied);
  CHECK(ekf.state() == Eigen::Vector2d(2, 3));
}

TEST_CASE("FilterStatus: every enumerator has its own name", "[filters][ekf]") {
  const FilterStatus all[] = {FilterStatus::kApplied,   FilterStatus::kNonFinite,
                              FilterStatus::kInvalidInput, FilterStatus::kNotPositiveDefinite,
                              FilterStatus::kGated,     FilterStatus::kNotInitialised};
  for (FilterStatus a : all) {
    CHECK(std::string(to_string(a)) != "unknown");
    for (FilterStatus b : all)
      if (a != b) CHECK(std::string(to_string(a)) != std::string(to_string(b)));
  }
}

namespace {
/// Range to a beacon at b whose error grows with distance:
/// z = |x - b|, sigma(d) = sigma0 + k d.
struct RangeToBeacon {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Matrix<double, 1, 1>;
  Eigen::Vector2d b{0, 0};
  double sigma0 = 0.05, k = 0.1;
  [[nodiscard]] Measurement predict(const State& x) const { return Measurement((x - b).norm()); }
  [[nodiscard]] Eigen::Matrix<double, 1, 2> jacobian(const State& x) const {
    return (x - b).transpose() / (x - b).norm();
  }
  [[nodiscard]] Eigen::Matrix<double, 1, 1> noise(const State& x) const {
    const double s = sigma0 + k * (x - b).norm();
    return Eigen::Matrix<double, 1, 1>(s * s);
  }
};
/// The same model claiming time invariance: with state-dependent noise the
/// claim is ignored (no gain memo).
struct RangeClaimingInvariance : RangeToBeacon {
  static constexpr bool kTimeInvariant = true;
};
}  // namespace

static_assert(MeasurementModel<RangeToBeacon>);
static_assert(has_state_dependent_noise_v<RangeToBeacon>);
static_assert(!has_state_dependent_noise_v<PositionFix<2>>);
static_assert(!is_time_invariant_v<RangeClaimingInvariance>);
static_assert(is_time_invariant_v<PositionFix<2>>);

TEST_CASE("Ekf: state-dependent measurement noise is evaluated at the prior state",
          "[filters][ekf][noise]") {
  // State x = (3, 4), P = 0.5 I, beacon at 0: d = 5, J = (0.6, 0.8),
  // R(x) = (0.05 + 0.1 * 5)^2 = 0.3025, S = 0.5 + 0.3025 = 0.8025.
  // z = 5.5: r = 0.5, K = 0.5 J^T / S, x += K r, NIS = 0.25 / S.
  using Filter = Ekf<PlanarDisplacement<double>, RangeToBeacon>;
  Filter ekf(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), RangeToBeacon{});
  ekf.reset(Eigen::Vector2d(3, 4), Eigen::Matrix2d::Identity() * 0.5);
  const auto r = ekf.update<0>(Eigen::Matrix<double, 1, 1>(5.5));
  REQUIRE(r);
  CHECK(r.S(0, 0) == Approx(0.8025));
  CHECK(r.nis == Approx(0.25 / 0.8025));
  CHECK(ekf.state().x() == Approx(3 + 0.5 * 0.6 * 0.5 / 0.8025));
  CHECK(ekf.state().y() == Approx(4 + 0.5 * 0.8 * 0.5 / 0.8025));
  // P = (I - K J) P (I - K J)^T + K R K^T.
  const Eigen::Vector2d J(0.6, 0.8);
  const Eigen::Vector2d K = 0.5 * J / 0.8025;
  const Eigen::Matrix2d IKH = Eigen::Matrix2d::Identity() - K * J.transpose();
  const Eigen::Matrix2d P = IKH * (0.5 * IKH.transpose()) + 0.3025 * K * K.transpose();
  CHECK((ekf.covariance() - P).cwiseAbs().maxCoeff() < 1e-15);

  // The same 0.5 m range error moves a far-away state less than a near one.
  Filter near(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), RangeToBeacon{});
  Filter far(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), RangeToBeacon{});
  near.reset(Eigen::Vector2d(0.6, 0.8), Eigen::Matrix2d::Identity() * 0.5);
  far.reset(Eigen::Vector2d(30, 40), Eigen::Matrix2d::Identity() * 0.5);
  REQUIRE(near.update<0>(Eigen::Matrix<double, 1, 1>(1.5)));
  REQUIRE(far.update<0>(Eigen::Matrix<double, 1, 1>(50.5)));
  const double moved_near = (near.state() - Eigen::Vector2d(0.6, 0.8)).norm();
  const double moved_far = (far.state() - Eigen::Vector2d(30, 40)).norm();
  CHECK(moved_near > 3 * moved_far);
}

TEST_CASE("Ekf: a kTimeInvariant flag on state-dependent noise does not freeze the gain",
          "[filters][ekf][noise]") {
  // Held (update<0>) and per-call (update_with) updates must agree at every
  // step, although the flag would otherwise let the filter reuse the gain.
  using Filter = Ekf<PlanarDisplacement<double>, RangeClaimingInvariance>;
  const RangeClaimingInvariance h{};
  Filter held(PlanarDisplacement<double>(Eigen::Matrix2d::Zero()), h);
  Filter plain(PlanarDisplacement<double>(Eigen::Matrix2d::Zero()), h);
  held.reset(Eigen::Vector2d(3, 4), Eigen::Matrix2d::Identity());
  plain.reset(Eigen::Vector2d(3, 4), Eigen::Matrix2d::Identity());
  for (int k = 0; k < 20; ++k) {
    const Eigen::Matrix<double, 1, 1> z(5.0 + 0.3 * k);
    const auto a = held.update<0>(z);
    const auto b = plain.update_with(h, z);
    REQUIRE(a.status == b.status);
    REQUIRE(a.S == b.S);
    REQUIRE(held.state() == plain.state());
    REQUIRE(held.covariance() == plain.covariance());
  }
}

namespace {
/// A 3-D measurement of a planar pose with a configurable J and R (to make
/// S whatever a test needs).
struct Linear3 {
  using State = PlanarPose<double>;
  using Measurement = Eigen::Vector3d;
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  [[nodiscard]] Measurement predict(const State& x) const { return J * x.vector(); }
  [[nodiscard]] Eigen::Matrix3d jacobian(const State&) const { return J; }
  [[nodiscard]] Eigen::Matrix3d noise() const { return R; }
};
}  // namespace

TEST_CASE("Ekf: a 3-D update solves with S and matches the explicit formulas",
          "[filters][ekf][solve]") {
  Ekf<StillPose> ekf(StillPose{});
  Eigen::Matrix3d P;
  P << 0.04, 0.01, 0.002, 0.01, 0.09, -0.003, 0.002, -0.003, 0.01;
  const PlanarPose<double> x0{1.0, -2.0, 0.3};
  ekf.reset(x0, P);
  Linear3 h;
  h.J << 1, 0.2, 0, 0, 1, 0.5, 0.1, 0, 1;
  h.R = Eigen::Vector3d(0.01, 0.02, 0.005).asDiagonal();
  const Eigen::Vector3d z(1.3, -1.7, 0.1);
  const auto r = ekf.update_with(h, z);
  REQUIRE(r);
  // Reference with an explicit inverse (fine in a test, 3x3, well conditioned).
  const Eigen::Matrix3d S = h.J * P * h.J.transpose() + h.R;
  const Eigen::Matrix3d K = P * h.J.transpose() * S.inverse();
  const Eigen::Vector3d innov = z - h.J * x0.vector();
  CHECK((r.S - S).cwiseAbs().maxCoeff() < 1e-15);
  CHECK(r.nis == Approx(innov.dot(S.inverse() * innov)).epsilon(1e-12));
  const Eigen::Vector3d x = x0.vector() + K * innov;
  CHECK(ekf.state().x == Approx(x(0)).epsilon(1e-12));
  CHECK(ekf.state().y == Approx(x(1)).epsilon(1e-12));
  CHECK(ekf.state().theta == Approx(x(2)).epsilon(1e-12));
  const Eigen::Matrix3d IKH = Eigen::Matrix3d::Identity() - K * h.J;
  const Eigen::Matrix3d P_post = IKH * P * IKH.transpose() + K * h.R * K.transpose();
  CHECK((ekf.covariance() - P_post).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("Ekf: an indefinite or singular innovation covariance is never accepted",
          "[filters][ekf][solve]") {
  const PlanarPose<double> x0{1.0, 2.0, 0.5};
  SECTION("3x3 indefinite (noise with a negative eigenvalue)") {
    Ekf<StillPose> ekf(StillPose{});
    ekf.reset(x0, Eigen::Matrix3d::Identity() * 0.01);
    Linear3 h;
    h.R = Eigen::Vector3d(0.01, -0.5, 0.01).asDiagonal();
    CHECK(ekf.update_with(h, Eigen::Vector3d(1, 2, 0.5)).status ==
          FilterStatus::kNotPositiveDefinite);
    CHECK(ekf.state().x == x0.x);
  }
  SECTION("3x3 singular that round-off makes look positive definite") {
    // S = J P J^T with J's third row a combination of the first two (rank 2):
    // on x86-64 its last Cholesky pivot comes out as about 7e-18 instead of
    // 0, which Eigen's LLT alone accepts (its test is pivot <= 0).
    Ekf<StillPose> ekf(StillPose{});
    const Eigen::Matrix3d P0 = Eigen::Vector3d(0.1, 0.1, 0.7).asDiagonal();
    ekf.reset(x0, P0);
    Linear3 h;
    h.J << 1, 0, 0, 0, 1, 0, 0.1, 0.7, 0;
    h.R.setZero();
    const auto r = ekf.update_with(h, Eigen::Vector3d(1.1, 2.1, 1.2));
    CHECK(r.status == FilterStatus::kNotPositiveDefinite);
    CHECK(ekf.state().y == x0.y);
    CHECK(ekf.covariance() == P0);
  }
  SECTION("2x2 singular and indefinite") {
    struct Fix2 {
      using State = Eigen::Vector2d;
      using Measurement = Eigen::Vector2d;
      Eigen::Matrix2d R;
      [[nodiscard]] Measurement predict(const State& x) const { return x; }
      [[nodiscard]] Eigen::Matrix2d jacobian(const State&) const {
        return Eigen::Matrix2d::Identity();
      }
      [[nodiscard]] Eigen::Matrix2d noise() const { return R; }
    };
    Ekf<PlanarDisplacement<double>> ekf(PlanarDisplacement<double>::from_sigmas(0.1, 0.1));
    ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Zero());
    Eigen::Matrix2d R;
    R << 0.3, 0.3, 0.3, 0.3;  // singular
    CHECK(ekf.update_with(Fix2{R}, {2, 2}).status == FilterStatus::kNotPositiveDefinite);
    R << 0.3, 0.4, 0.4, 0.3;  // indefinite
    CHECK(ekf.update_with(Fix2{R}, {2, 2}).status == FilterStatus::kNotPositiveDefinite);
    R << 0.3, 0.1, 0.1, 0.3;  // fine
    CHECK(ekf.update_with(Fix2{R}, {2, 2}).status == FilterStatus::kApplied);
  }
}

TEST_CASE("Ekf: gate functors reject parts of a measurement; the caller sees why",
          "[filters][ekf][gate]") {
  Ekf<StillPose> ekf(StillPose{});
  const PlanarPose<double> x0{0, 0, 0};
  ekf.reset(x0, Eigen::Matrix3d::Identity() * 0.01);
  Linear3 h;  // J = I, R = I
  h.R = Eigen::Matrix3d::Identity() * 0.01;
  // Accept when the heading part is within 3 sigma of its own variance.
  const auto heading_gate = [](const Eigen::Vector3d& r, const Eigen::Matrix3d& S) {
    return r(2) * r(2) <= 9.0 * S(2, 2);
  };
  // 1 rad of heading disagreement (S_thth = 0.02): rejected.
  const auto bad = ekf.update_with(h, Eigen::Vector3d(0.01, 0, 1.0), heading_gate);
  CHECK(bad.status == FilterStatus::kGated);
  CHECK(bad.innovation(2) == Approx(1.0));  // the caller can tell which part failed
  CHECK_FALSE(heading_gate(bad.innovation, bad.S));
  CHECK(ekf.state().x == x0.x);
  CHECK(ekf.covariance() == Eigen::Matrix3d::Identity() * 0.01);
  // The same position error with a matching heading passes the heading gate
  // although its joint NIS (5) exceeds a 3-dof threshold of 3.
  double seen_nis = -1;
  const auto nis_gate = [&seen_nis](const Eigen::Vector3d&, const Eigen::Matrix3d&, double nis) {
    seen_nis = nis;
    return true;
  };
  const auto ok = ekf.update_with(h, Eigen::Vector3d(0.3162277660168379, 0, 0), nis_gate);
  REQUIRE(ok);
  CHECK(seen_nis == ok.nis);
  CHECK(ok.nis == Approx(5.0));
  // A number is a NIS threshold.
  ekf.reset(x0, Eigen::Matrix3d::Identity() * 0.01);
  CHECK(ekf.update_with(h, Eigen::Vector3d(0.3162277660168379, 0, 0), 3.0).status ==
        FilterStatus::kGated);
  CHECK(ekf.update_with(h, Eigen::Vector3d(0.3162277660168379, 0, 0), 6.0).status ==
        FilterStatus::kApplied);
}

TEST_CASE("Ekf: a held model takes a gate functor on top of its NIS gate", "[filters][ekf][gate]") {
  using Filter = Ekf<PlanarDisplacement<double>, PositionFix<2>>;
  Filter ekf(PlanarDisplacement<double>::from_sigmas(0.1, 0.1), PositionFix<2>::isotropic(1));
  ekf.reset(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity());
  const auto x_only = [](const Eigen::Vector2d& r, const Eigen::Matrix2d& S) {
    return r(0) * r(0) <= 4.0 * S(0, 0);  // 2 sigma on x; y ungated
  };
  CHECK(ekf.update<0>(Eigen::Vector2d(3.0, 0), x_only).status == FilterStatus::kGated);
  CHECK(ekf.state() == Eigen::Vector2d(0, 0));
  CHECK(ekf.update<0>(Eigen::Vector2d(0.5, 30.0), x_only).status == FilterStatus::kApplied);
  // The filter's own NIS gate still applies.
  ekf.reset(Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity());
  ekf.set_gate<0>(chi_square_quantile(0.99, 2));
  CHECK(ekf.update<0>(Eigen::Vector2d(0.5, 30.0), x_only).status == FilterStatus::kGated);
}

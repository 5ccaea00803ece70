// The compile-time fast paths of BasicEkf (selection Jacobians, identity
// Jacobians, model-supplied covariance propagation, one-triangle updates,
// the options of EkfOptions) against the generic dense path, and the
// conformance checks of declared structure.
//
// "Generic" filters run the same models through Hidden<...> wrappers that
// forward predict / jacobian / noise only, so the filter cannot see any
// declared structure and multiplies by the dense F and H.

#include <catch2/catch.hpp>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include <posefuse/core/gaussian.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/testing/conformance.hpp>
#include "support/random_matrices.hpp"

using namespace posefuse;

namespace {

/// A motion model seen through predict / jacobian / noise only.
template <class M>
struct HiddenMotion {
  using State = typename M::State;
  using Control = typename M::Control;
  using T = ScalarOf<State>;
  M m;
  State predict(const State& x, const Control& u, T dt) const { return m.predict(x, u, dt); }
  CovarianceOf<State> jacobian(const State& x, const Control& u, T dt) const {
    return m.jacobian(x, u, dt);
  }
  CovarianceOf<State> noise(const State& x, const Control& u, T dt) const {
    return m.noise(x, u, dt);
  }
};

/// A measurement model seen through predict / jacobian / noise only.
template <class H>
struct HiddenSensor {
  using State = typename H::State;
  using Measurement = typename H::Measurement;
  H h;
  Measurement predict(const State& x) const { return h.predict(x); }
  MeasurementJacobianOf<H> jacobian(const State& x) const { return h.jacobian(x); }
  CovarianceOf<Measurement> noise() const { return h.noise(); }
};

/// Options that change no arithmetic but switch the memo off, so that every
/// update of both filters recomputes.
struct NoMemo : EkfOptions {
  static constexpr bool kGainMemo = false;
};
struct Standard : EkfOptions {
  static constexpr CovarianceUpdate kCovarianceUpdate = CovarianceUpdate::kStandard;
  static constexpr bool kGainMemo = false;
};
struct Lean : EkfOptions {
  static constexpr NisPolicy kNis = NisPolicy::kWhenGated;
  static constexpr bool kRecordJacobian = false;
  static constexpr bool kGainMemo = false;
};

/// A random symmetric positive definite n x n matrix with eigenvalues in
/// [lo, hi] times scale (a random rotation of a diagonal).
template <int N>
Eigen::Matrix<double, N, N> random_spd(std::mt19937& rng, double lo, double hi, double scale) {
  std::uniform_real_distribution<double> u(lo, hi);
  const Eigen::Matrix<double, N, N> Q = posefuse::test::random_orthogonal<N>(rng);
  Eigen::Matrix<double, N, 1> d;
  for (int i = 0; i < N; ++i) d(i) = u(rng) * scale;
  Eigen::Matrix<double, N, N> P = Q * d.asDiagonal() * Q.transpose();
  return 0.5 * (P + P.transpose());
}

template <class A, class B>
double rel_diff(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
}

template <class FilterA, class FilterB>
void require_same(const FilterA& a, const FilterB& b, double tol) {
  const auto dx = minus(a.state(), b.state());
  INFO("state difference " << dx.transpose());
  REQUIRE(dx.cwiseAbs().maxCoeff() <= tol * (1.0 + minus(b.state(), decltype(b.state())(b.state())).norm()));
  INFO("covariance difference " << rel_diff(a.covariance(), b.covariance()));
  REQUIRE(rel_diff(a.covariance(), b.covariance()) <= tol);
  // The fast path's covariance is exactly symmetric.
  REQUIRE(a.covariance() == a.covariance().transpose());
}

}  // namespace

TEST_CASE("Ekf fast paths: constant velocity (propagate) + position fix (selection) equal the "
          "dense path",
          "[filters][ekf][fast]") {
  std::mt19937 rng(91);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> udt(0.0, 0.5);
  for (int draw = 0; draw < 300; ++draw) {
    const double q = 0.01 + std::abs(n01(rng));
    const double sigma = 0.05 + std::abs(n01(rng));
    Ekf<ConstantVelocity2<double>, PositionFix<4>> fast(ConstantVelocity2<double>(q),
                                                        PositionFix<4>::isotropic(sigma));
    BasicEkf<NoMemo, HiddenMotion<ConstantVelocity2<double>>, HiddenSensor<PositionFix<4>>> slow(
        {ConstantVelocity2<double>(q)}, {PositionFix<4>::isotropic(sigma)});
    Eigen::Vector4d x0;
    for (int i = 0; i < 4; ++i) x0(i) = n01(rng);
    const Eigen::Matrix4d P0 = random_spd<4>(rng, 0.01, 1.0, std::exp(n01(rng)));
    fast.reset(x0, P0);
    slow.reset(x0, P0);
    for (int k = 0; k < 5; ++k) {
      const double dt = udt(rng);
      REQUIRE(fast.predict(NoControl{}, dt) == slow.predict(NoControl{}, dt));
      require_same(fast, slow, 1e-12);
      REQUIRE(fast.last_jacobian() == slow.last_jacobian());
      const double zx = n01(rng);
      const double zy = n01(rng);
      const Eigen::Vector2d z(zx, zy);
      const auto ra = fast.update<0>(z);
      const auto rb = slow.update<0>(z);
      REQUIRE(ra.status == rb.status);
      REQUIRE(std::abs(ra.nis - rb.nis) <= 1e-12 * (1.0 + rb.nis));
      require_same(fast, slow, 1e-12);
    }
  }
}

TEST_CASE("Ekf fast paths: identity Jacobians (seed 000) and a 1-of-3 selection equal the dense "
          "path",
          "[filters][ekf][fast]") {
  std::mt19937 rng(92);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int draw = 0; draw < 300; ++draw) {
    const double sx = 0.05 + std::abs(n01(rng));
    const double sy = 0.05 + std::abs(n01(rng));
    const double sz = 0.05 + std::abs(n01(rng));
    const auto motion = PlanarDisplacement<double>::from_sigmas(sx, sy);
    const auto fix = PositionFix<2>::isotropic(sz);
    Ekf<PlanarDisplacement<double>, PositionFix<2>> fast(motion, fix);
    BasicEkf<NoMemo, HiddenMotion<PlanarDisplacement<double>>, HiddenSensor<PositionFix<2>>> slow(
        {motion}, {fix});
    const double x0x = n01(rng);
    const double x0y = n01(rng);
    const Eigen::Matrix2d P0 = random_spd<2>(rng, 0.01, 1.0, std::exp(n01(rng)));
    fast.reset(Eigen::Vector2d(x0x, x0y), P0);
    slow.reset(Eigen::Vector2d(x0x, x0y), P0);
    for (int k = 0; k < 5; ++k) {
      const double ux = n01(rng);
      const double uy = n01(rng);
      REQUIRE(fast.predict(Eigen::Vector2d(ux, uy), 1.0) ==
              slow.predict(Eigen::Vector2d(ux, uy), 1.0));
      require_same(fast, slow, 1e-12);
      const double zx = n01(rng);
      const double zy = n01(rng);
      REQUIRE(fast.update<0>(Eigen::Vector2d(zx, zy)).status ==
              slow.update<0>(Eigen::Vector2d(zx, zy)).status);
      require_same(fast, slow, 1e-12);
    }
  }
  // A heading fix (kSelection = {2}) on a unicycle (dense F).
  for (int draw = 0; draw < 300; ++draw) {
    Unicycle<double> motion;
    const double sv = 0.01 + std::abs(n01(rng));
    const double sw = 0.01 + std::abs(n01(rng));
    motion.control_cov = Eigen::Vector2d(sv, sw).asDiagonal();
    const HeadingFix<double> fix(0.01 + 0.2 * std::abs(n01(rng)));
    Ekf<Unicycle<double>, HeadingFix<double>> fast(motion, fix);
    BasicEkf<NoMemo, HiddenMotion<Unicycle<double>>, HiddenSensor<HeadingFix<double>>> slow(
        {motion}, {fix});
    PlanarPose<double> x0;
    x0.x = n01(rng);
    x0.y = n01(rng);
    x0.theta = wrap_angle(3.0 * n01(rng));
    const Eigen::Matrix3d P0 = random_spd<3>(rng, 0.01, 1.0, std::exp(n01(rng)));
    fast.reset(x0, P0);
    slow.reset(x0, P0);
    for (int k = 0; k < 5; ++k) {
      const double v = n01(rng);
      const double w = n01(rng);
      REQUIRE(fast.predict(Eigen::Vector2d(v, w), 0.1) == slow.predict(Eigen::Vector2d(v, w), 0.1));
      require_same(fast, slow, 1e-12);
      const SO2<double> z(3.0 * n01(rng));
      REQUIRE(fast.update<0>(z).status == slow.update<0>(z).status);
      require_same(fast, slow, 1e-12);
    }
  }
}

TEST_CASE("Ekf fast paths: SE(2) odometry (linearize + propagate) with a pose fix equals the "
          "dense path",
          "[filters][ekf][fast]") {
  std::mt19937 rng(93);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int draw = 0; draw < 300; ++draw) {
    const Se2Odometry<double> motion;
    const auto fix = PlanarPoseFix<double>::from_sigmas(0.05 + std::abs(n01(rng)),
                                                        0.01 + 0.1 * std::abs(n01(rng)));
    Ekf<Se2Odometry<double>, PlanarPoseFix<double>> fast(motion, fix);
    BasicEkf<NoMemo, HiddenMotion<Se2Odometry<double>>, HiddenSensor<PlanarPoseFix<double>>> slow(
        {motion}, {fix});
    PlanarPose<double> x0;
    x0.x = n01(rng);
    x0.y = n01(rng);
    x0.theta = wrap_angle(3.0 * n01(rng));
    const Eigen::Matrix3d P0 = random_spd<3>(rng, 0.01, 1.0, std::exp(n01(rng)));
    fast.reset(x0, P0);
    slow.reset(x0, P0);
    for (int k = 0; k < 5; ++k) {
      const double dx = n01(rng);
      const double dy = 0.3 * n01(rng);
      const double dth = 0.5 * n01(rng);
      const SE2<double> d(dx, dy, dth);
      REQUIRE(fast.predict(d, 0.0) == slow.predict(d, 0.0));
      require_same(fast, slow, 1e-12);
      PlanarPose<double> z;
      z.x = fast.state().x + 0.1 * n01(rng);
      z.y = fast.state().y + 0.1 * n01(rng);
      z.theta = wrap_angle(fast.state().theta + 0.1 * n01(rng));
      REQUIRE(fast.update<0>(z).status == slow.update<0>(z).status);
      require_same(fast, slow, 1e-12);
    }
  }
}

TEST_CASE("Ekf fast paths: a 15-state filter with a 6-of-15 selection equals the dense path",
          "[filters][ekf][fast]") {
  using Fix = PositionFix<15, 6>;
  struct Dense15 {  // x' = F x with a random well-conditioned F, Q = 0.01 I
    using State = Eigen::Matrix<double, 15, 1>;
    using Control = NoControl;
    Eigen::Matrix<double, 15, 15> F;
    State predict(const State& x, const Control&, double) const { return F * x; }
    Eigen::Matrix<double, 15, 15> jacobian(const State&, const Control&, double) const { return F; }
    Eigen::Matrix<double, 15, 15> noise(const State&, const Control&, double) const {
      return Eigen::Matrix<double, 15, 15>::Identity() * 0.01;
    }
  };
  std::mt19937 rng(94);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int draw = 0; draw < 40; ++draw) {
    Dense15 motion;
    motion.F = Eigen::Matrix<double, 15, 15>::Identity();
    for (int i = 0; i < 15; ++i)
      for (int j = 0; j < 15; ++j) motion.F(i, j) += 0.05 * n01(rng);
    const Fix fix = Fix::isotropic(0.1 + std::abs(n01(rng)));
    Ekf<Dense15, Fix> fast(motion, fix);
    BasicEkf<NoMemo, Dense15, HiddenSensor<Fix>> slow(motion, {fix});
    Eigen::Matrix<double, 15, 1> x0;
    for (int i = 0; i < 15; ++i) x0(i) = n01(rng);
    const Eigen::Matrix<double, 15, 15> P0 = random_spd<15>(rng, 0.01, 1.0, 1.0);
    fast.reset(x0, P0);
    slow.reset(x0, P0);
    for (int k = 0; k < 4; ++k) {
      REQUIRE(fast.predict(NoControl{}, 0.1) == FilterStatus::kApplied);
      REQUIRE(slow.predict(NoControl{}, 0.1) == FilterStatus::kApplied);
      require_same(fast, slow, 1e-12);
      Eigen::Matrix<double, 6, 1> z;
      for (int i = 0; i < 6; ++i) z(i) = fast.state()(i) + 0.1 * n01(rng);
      REQUIRE(fast.update<0>(z).status == FilterStatus::kApplied);
      REQUIRE(slow.update<0>(z).status == FilterStatus::kApplied);
      require_same(fast, slow, 1e-12);
    }
  }
}

TEST_CASE("Ekf options: standard and Joseph forms agree on well-conditioned problems; the "
          "memo and the lean options change no result",
          "[filters][ekf][fast]") {
  std::mt19937 rng(95);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int draw = 0; draw < 200; ++draw) {
    const ConstantVelocity2<double> motion(0.5);
    const auto fix = PositionFix<4>::isotropic(0.3);
    Ekf<ConstantVelocity2<double>, PositionFix<4>> joseph(motion, fix);
    BasicEkf<Standard, ConstantVelocity2<double>, PositionFix<4>> standard(motion, fix);
    BasicEkf<Lean, ConstantVelocity2<double>, PositionFix<4>> lean(motion, fix);
    Eigen::Vector4d x0;
    for (int i = 0; i < 4; ++i) x0(i) = n01(rng);
    const Eigen::Matrix4d P0 = random_spd<4>(rng, 0.1, 1.0, 1.0);
    joseph.reset(x0, P0);
    standard.reset(x0, P0);
    lean.reset(x0, P0);
    for (int k = 0; k < 10; ++k) {
      REQUIRE(joseph.predict(NoControl{}, 0.1) == FilterStatus::kApplied);
      REQUIRE(standard.predict(NoControl{}, 0.1) == FilterStatus::kApplied);
      REQUIRE(lean.predict(NoControl{}, 0.1) == FilterStatus::kApplied);
      const double zx = n01(rng);
      const double zy = n01(rng);
      const Eigen::Vector2d z(zx, zy);
      const auto rj = joseph.update<0>(z);
      REQUIRE(rj.status == FilterStatus::kApplied);
      REQUIRE(standard.update<0>(z).status == FilterStatus::kApplied);
      const auto rl = lean.update<0>(z);
      REQUIRE(rl.status == FilterStatus::kApplied);
      REQUIRE(std::isnan(rl.nis));  // kWhenGated, no gate: not computed
      REQUIRE(std::isfinite(rj.nis));
      require_same(standard, joseph, 1e-10);
      // Same arithmetic as the default: bit-identical.
      REQUIRE(minus(lean.state(), joseph.state()).isZero(0.0));
      REQUIRE(lean.covariance() == joseph.covariance());
    }
    // A NIS gate makes kWhenGated compute the NIS.
    lean.set_gate<0>(1e6);
    const auto rg = lean.update<0>(Eigen::Vector2d(lean.state()(0), lean.state()(1)));
    REQUIRE(std::isfinite(rg.nis));
  }
}

TEST_CASE("Ekf fast paths: refused steps leave the filter bit-identical", "[filters][ekf][fast]") {
  // A propagated covariance that overflows: kNonFinite, nothing changed.
  Ekf<ConstantVelocity2<double>, PositionFix<4>> ekf(ConstantVelocity2<double>(1.0),
                                                     PositionFix<4>::isotropic(1.0));
  Eigen::Matrix4d P0 = Eigen::Matrix4d::Identity() * 1e300;
  ekf.reset(Eigen::Vector4d::Zero(), P0);
  const Eigen::Matrix4d F0 = ekf.last_jacobian();
  REQUIRE(ekf.predict(NoControl{}, 1e10) == FilterStatus::kNonFinite);
  REQUIRE(ekf.covariance() == P0);
  REQUIRE(ekf.last_jacobian() == F0);
  REQUIRE(ekf.state() == Eigen::Vector4d::Zero());
  // A NaN measurement: kNonFinite, nothing changed.
  ekf.reset(Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity());
  const auto r = ekf.update<0>(Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 0.0));
  REQUIRE(r.status == FilterStatus::kNonFinite);
  REQUIRE(ekf.covariance() == Eigen::Matrix4d::Identity());
}

namespace {
/// Claims to select state component 1 but measures component 0.
struct WrongSelection {
  using State = Eigen::Vector4d;
  using Measurement = Eigen::Matrix<double, 1, 1>;
  static constexpr std::array<int, 1> kSelection = {1};
  Measurement predict(const State& x) const { return Measurement(x(0)); }
  Eigen::Matrix<double, 1, 4> jacobian(const State&) const { return {1.0, 0.0, 0.0, 0.0}; }
  Eigen::Matrix<double, 1, 1> noise() const { return Eigen::Matrix<double, 1, 1>(0.1); }
};
/// Claims an identity Jacobian for a position fix of a 4-state.
struct WrongIdentity {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  static constexpr bool kIdentityJacobian = true;
  Measurement predict(const State& x) const { return Measurement(x(1), x(0)); }
  Eigen::Matrix2d jacobian(const State&) const {
    Eigen::Matrix2d J;
    J << 0, 1, 1, 0;
    return J;
  }
  Eigen::Matrix2d noise() const { return Eigen::Matrix2d::Identity(); }
};
/// Constant velocity whose propagate() forgets the second column pass.
struct WrongPropagate : ConstantVelocity2<double> {
  WrongPropagate() : ConstantVelocity2<double>(1.0) {}
  Matrix propagate(const Matrix& P, const State&, const Control&, double dt) const {
    Matrix B = P;
    B.topRows<2>() += dt * P.bottomRows<2>();
    return B;
  }
};
/// SE(2) odometry whose linearisation propagates with the wrong sign.
struct WrongLinearizePropagate : Se2Odometry<double> {
  WrongLinearizePropagate() : Se2Odometry<double>(Se2OdometryNoise<double>{}) {}
  struct Linearization : Se2Odometry<double>::Linearization {
    Matrix3 propagate(const Matrix3& P) const {
      Linearization flipped = *this;
      flipped.jacobian(0, 2) = -jacobian(0, 2);
      return flipped.Se2Odometry<double>::Linearization::propagate(P);
    }
  };
  Linearization linearize(const State& x, const Control& d, double dt) const {
    Linearization out;
    static_cast<Se2Odometry<double>::Linearization&>(out) = Se2Odometry<double>::linearize(x, d, dt);
    return out;
  }
};
}  // namespace

TEST_CASE("Conformance: declared structure is checked against the model's own Jacobian",
          "[filters][ekf][fast][conformance]") {
  // Correct declarations pass.
  CHECK(testing::check_measurement_model(PositionFix<4>::isotropic(0.5),
                                         Eigen::Vector4d(1, 2, 3, 4), 1e-6));
  CHECK(testing::check_measurement_model(HeadingFix<double>(0.1), PlanarPose<double>{1, 2, 0.3},
                                         1e-6));
  CHECK(testing::check_motion_model(ConstantVelocity2<double>(1.0), Eigen::Vector4d(1, 2, 3, 4),
                                    NoControl{}, 0.3, 1e-6));
  CHECK(testing::check_motion_model(Se2Odometry<double>{}, PlanarPose<double>{1, 2, 0.3},
                                    SE2<double>(0.5, 0.1, 0.2), 0.0, 1e-6));
  // Wrong ones fail, naming the declaration.
  const auto a = testing::check_measurement_model(WrongSelection{}, Eigen::Vector4d(1, 2, 3, 4), 1e-6);
  CHECK_FALSE(a.ok);
  CHECK(a.message.find("kSelection") != std::string::npos);
  const auto b = testing::check_measurement_model(WrongIdentity{}, Eigen::Vector2d(1, 2), 1e-6);
  CHECK_FALSE(b.ok);
  CHECK(b.message.find("kIdentityJacobian") != std::string::npos);
  static_assert(HasPropagate<WrongPropagate>);
  const auto c = testing::check_motion_model(WrongPropagate{}, Eigen::Vector4d(1, 2, 3, 4),
                                             NoControl{}, 0.3, 1e-6);
  CHECK_FALSE(c.ok);
  CHECK(c.message.find("propagate") != std::string::npos);
  static_assert(HasLinearizePropagate<WrongLinearizePropagate>);
  const auto d = testing::check_motion_model(WrongLinearizePropagate{}, PlanarPose<double>{1, 2, 0.3},
                                             SE2<double>(0.5, 0.1, 0.2), 0.0, 1e-6);
  CHECK_FALSE(d.ok);
  CHECK(d.message.find("linearize().propagate") != std::string::npos);
}

namespace {
template <int N>
void check_shifted_psd_path(std::mt19937& rng) {
  using M = Eigen::Matrix<double, N, N>;
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int accepted = 0, well_conditioned = 0;
  for (int draw = 0; draw < 150; ++draw) {
    const int kind = draw % 5;
    M P;
    if (kind == 0) {  // well-conditioned PSD, rescaled rows and columns
      P = random_spd<N>(rng, 1e-3, 1.0, 1.0);
      Eigen::Matrix<double, N, 1> s;
      for (int i = 0; i < N; ++i) s(i) = std::exp(5.0 * n01(rng));
      P = s.asDiagonal() * P * s.asDiagonal();
    } else if (kind == 1) {  // indefinite by a little
      P = random_spd<N>(rng, 1e-3, 1.0, 1.0);
      Eigen::Matrix<double, N, 1> v;
      for (int i = 0; i < N; ++i) v(i) = n01(rng);
      v.normalize();
      P -= (1e-3 + 1e-12 * u(rng)) * 2.0 * (v * v.transpose());
    } else if (kind == 2) {  // singular PSD (rank N - 1)
      M A = M::Zero();
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N - 1; ++j) A(i, j) = n01(rng);
      P = A * A.transpose();
    } else if (kind == 3) {  // nearly singular: smallest eigenvalue around the shift
      P = random_spd<N>(rng, 1e-13, 1e-12, 1.0) + random_spd<N>(rng, 0.0, 1.0, 1.0) * 0.0;
      P += M::Identity() * 1e-13;
      Eigen::Matrix<double, N, 1> v;
      for (int i = 0; i < N; ++i) v(i) = n01(rng);
      P += v * v.transpose();
    } else {  // a non-finite entry
      P = random_spd<N>(rng, 0.1, 1.0, 1.0);
      P(N - 1, 0) = P(0, N - 1) = std::numeric_limits<double>::infinity();
    }
    P = (0.5 * (P + P.transpose())).eval();
    const bool fast = detail::psd_fast_accepts(P);
    const bool ref = detail::psd_reference(P, true);
    INFO("N " << N << " kind " << kind);
    REQUIRE((!fast || ref));  // never accepts what the reference refuses
    REQUIRE(is_positive_semidefinite(P) == detail::psd_reference(P, false));
    if (kind == 0) {
      ++well_conditioned;
      if (fast) ++accepted;
    }
  }
  CHECK(accepted == well_conditioned);  // and decides the usual case itself
}
}  // namespace

TEST_CASE("is_positive_semidefinite: the minors (3x3, 4x4) and shifted-LDLT (above 6x6) fast paths "
          "only accept what the reference accepts",
          "[filters][ekf][fast][psd]") {
  std::mt19937 rng(96);
  check_shifted_psd_path<3>(rng);
  check_shifted_psd_path<4>(rng);
  check_shifted_psd_path<7>(rng);
  check_shifted_psd_path<9>(rng);
  check_shifted_psd_path<12>(rng);
  check_shifted_psd_path<15>(rng);
}

TEST_CASE("Ekf fast paths: the expanded Joseph form of one- and two-row selections keeps ill-conditioned "
          "posteriors PSD wherever the dense Joseph form does",
          "[filters][ekf][fast][psd]") {
  // Priors with eigenvalues down to 1e-14 of the largest (rescaled rows and
  // columns), measurement noise from 1e-12 to 1 of the prior's scale: the
  // closed-form path (filters/detail/ekf_update.hpp,
  // closed_form_selection_gain) against the generic dense path. Every applied step must hold a PSD covariance, the fast path
  // must apply every step the dense path applies, and where both apply and
  // the problem is well-conditioned they agree to 1e-12.
  std::mt19937 rng(97);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int both_applied = 0, only_fast = 0, only_dense = 0, compared = 0;
  for (int draw = 0; draw < 2000; ++draw) {
    const double r_scale = std::pow(10.0, -12.0 * u(rng));
    const double sigma = std::sqrt(r_scale);
    Ekf<ConstantVelocity2<double>, PositionFix<4>> fast(ConstantVelocity2<double>(1.0),
                                                        PositionFix<4>::isotropic(sigma));
    BasicEkf<NoMemo, HiddenMotion<ConstantVelocity2<double>>, HiddenSensor<PositionFix<4>>> dense(
        {ConstantVelocity2<double>(1.0)}, {PositionFix<4>::isotropic(sigma)});
    const double lo = std::pow(10.0, -14.0 * u(rng));
    Eigen::Matrix4d P0 = random_spd<4>(rng, lo, 1.0, 1.0);
    Eigen::Vector4d s;
    for (int i = 0; i < 4; ++i) s(i) = std::exp(2.0 * n01(rng));
    P0 = (s.asDiagonal() * P0 * s.asDiagonal()).eval();
    P0 = (0.5 * (P0 + P0.transpose())).eval();
    if (!is_positive_semidefinite(P0)) continue;
    Eigen::Vector4d x0;
    for (int i = 0; i < 4; ++i) x0(i) = n01(rng);
    fast.reset(x0, P0);
    dense.reset(x0, P0);
    const double zx = n01(rng);
    const double zy = n01(rng);
    const Eigen::Vector2d z(zx, zy);
    const bool a = fast.update<0>(z).status == FilterStatus::kApplied;
    const bool b = dense.update<0>(z).status == FilterStatus::kApplied;
    REQUIRE(is_positive_semidefinite(fast.covariance()));
    REQUIRE(is_positive_semidefinite(dense.covariance()));
    if (!a) REQUIRE(fast.covariance() == P0);
    both_applied += a && b;
    only_fast += a && !b;
    only_dense += !a && b;
    if (a && b && lo > 1e-3 && r_scale > 1e-3) {
      ++compared;
      require_same(fast, dense, 1e-12);
    }
  }
  INFO("both applied " << both_applied << ", only fast " << only_fast << ", only dense "
                       << only_dense << ", compared " << compared);
  CHECK(only_dense == 0);
  CHECK(both_applied > 1000);
  CHECK(compared > 20);
}

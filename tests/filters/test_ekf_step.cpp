// BasicEkf::step(u, dt, z...): the fused predict + updates against the
// separate calls, and the argument that lets it skip the check of the
// predicted covariance (filters/ekf.hpp, BasicEkf::step): an update whose
// S is positive definite never turns a covariance the PSD check refuses
// into a posterior the check accepts.

#include <catch2/catch.hpp>
#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <posefuse/core/definiteness.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/ctrv.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/unicycle.hpp>
#include "support/random_matrices.hpp"

using namespace posefuse;

namespace {

/// x' = F x + u dt with process noise Q dt; Q may be anything (indefinite,
/// NaN), so that the predicted covariance can be refused.
struct LinearMotion4 {
  using State = Eigen::Vector4d;
  using Control = Eigen::Vector4d;
  Eigen::Matrix4d F = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d Q = Eigen::Matrix4d::Identity();
  [[nodiscard]] State predict(const State& x, const Control& u, double dt) const { return F * x + u * dt; }
  [[nodiscard]] Eigen::Matrix4d jacobian(const State&, const Control&, double) const { return F; }
  [[nodiscard]] Eigen::Matrix4d noise(const State&, const Control&, double dt) const { return Q * dt; }
};

/// A dense three-row measurement of the 4-D state.
struct Dense3 {
  using State = Eigen::Vector4d;
  using Measurement = Eigen::Vector3d;
  Eigen::Matrix<double, 3, 4> J = Eigen::Matrix<double, 3, 4>::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  [[nodiscard]] Measurement predict(const State& x) const { return J * x; }
  [[nodiscard]] Eigen::Matrix<double, 3, 4> jacobian(const State&) const { return J; }
  [[nodiscard]] Eigen::Matrix3d noise() const { return R; }
};

/// A symmetric matrix Q diag(lambda) Q^T, rows and columns scaled by s.
template <int N>
Eigen::Matrix<double, N, N> with_spectrum(std::mt19937& rng, const Eigen::Matrix<double, N, 1>& lambda,
                                          const Eigen::Matrix<double, N, 1>& s) {
  const Eigen::Matrix<double, N, N> Q = posefuse::test::random_orthogonal<N>(rng);
  Eigen::Matrix<double, N, N> M = s.asDiagonal() * Q * lambda.asDiagonal() * Q.transpose() * s.asDiagonal();
  return 0.5 * (M + M.transpose());
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}
template <class R>
bool same_result(const R& a, const R& b) {
  return a.status == b.status && same_bits(a.innovation, b.innovation) && same_bits(a.S, b.S) &&
         (same_bits(a.nis, b.nis) || (std::isnan(a.nis) && std::isnan(b.nis)));
}

struct Counts {
  int applied = 0, predict_refused = 0, first_not_applied = 0, memo_steps = 0;
};

/// Runs `steps` steps of one random problem through step() and through the
/// separate calls; every status, UpdateResult, state and covariance must be
/// bit-identical.
template <class Options>
void compare_step_with_separate_calls(std::mt19937& rng, Counts& c) {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01;
  LinearMotion4 m;
  m.F = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m.F(i, j) += 0.3 * n01(rng);
  Eigen::Vector4d lambda, s;
  for (int i = 0; i < 4; ++i) {
    lambda(i) = std::exp(2 * n01(rng));
    s(i) = std::exp(n01(rng));
  }
  const int kind = int(u01(rng) * 5);
  if (kind == 1) lambda(0) = -lambda.maxCoeff() * std::pow(10.0, -8 * u01(rng));  // indefinite Q
  m.Q = with_spectrum<4>(rng, lambda, s);
  if (kind == 2) {  // indefinite in the velocity block alone (unobserved by the fix)
    m.Q.setZero();
    m.Q.diagonal() << 0.1, 0.1, -std::pow(10.0, -6 * u01(rng)), 0.2;
  }
  if (kind == 3 && u01(rng) < 0.2) m.Q(3, 3) = std::numeric_limits<double>::quiet_NaN();
  Dense3 d;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) d.J(i, j) = n01(rng);
  d.R = with_spectrum<3>(rng, Eigen::Vector3d(0.1 + u01(rng), 0.1 + u01(rng), 0.1 + u01(rng)),
                         Eigen::Vector3d::Ones());
  const PositionFix<4> fix = PositionFix<4>::isotropic(std::pow(10.0, -2 * u01(rng)));
  BasicEkf<Options, LinearMotion4, PositionFix<4>, Dense3> fused(m, fix, d), separate(m, fix, d);
  if (u01(rng) < 0.3) {  // a tight gate: the first update is often gated
    fused.template set_gate<0>(0.05);
    separate.template set_gate<0>(0.05);
  }
  Eigen::Vector4d x0;
  for (int i = 0; i < 4; ++i) x0(i) = n01(rng);
  Eigen::Vector4d l0;
  for (int i = 0; i < 4; ++i) l0(i) = std::pow(10.0, -6 * u01(rng));
  const Eigen::Matrix4d P0 = with_spectrum<4>(rng, l0, s);
  if (!is_positive_semidefinite(P0)) return;
  fused.reset(x0, P0);
  separate.reset(x0, P0);
  const double dt = u01(rng) < 0.5 ? 0.1 : 0.05 + u01(rng);
  for (int k = 0; k < 8; ++k) {
    Eigen::Vector4d uk;
    for (int i = 0; i < 4; ++i) uk(i) = n01(rng);
    const Eigen::Vector2d z0(n01(rng), n01(rng));
    const Eigen::Vector3d z1(n01(rng), n01(rng), n01(rng));
    const auto r = fused.step(uk, dt, z0, z1);
    const FilterStatus p = separate.predict(uk, dt);
    const auto r0 = separate.template update<0>(z0);
    const auto r1 = separate.template update<1>(z1);
    INFO("kind " << kind << " step " << k << " predict " << to_string(p) << " / " << to_string(r.predict));
    REQUIRE(r.predict == p);
    REQUIRE(same_result(r.template update<0>(), r0));
    REQUIRE(same_result(r.template update<1>(), r1));
    REQUIRE(same_bits(fused.state(), separate.state()));
    REQUIRE(same_bits(fused.covariance(), separate.covariance()));
    REQUIRE(static_cast<bool>(r) ==
            (p == FilterStatus::kApplied && r0.status == FilterStatus::kApplied &&
             r1.status == FilterStatus::kApplied));
    c.applied += static_cast<bool>(r);
    c.predict_refused += p != FilterStatus::kApplied;
    c.first_not_applied += p == FilterStatus::kApplied && r0.status != FilterStatus::kApplied;
    c.memo_steps += k > 2 && dt == 0.1;
  }
}

/// The argument of BasicEkf::step on one update kernel: for P̄ refused by
/// the PSD check, an update with S positive definite must refuse its
/// posterior too. @return how many refused P̄ had S positive definite
template <class Options, class H>
int refused_prior_stays_refused(std::mt19937& rng, const H& sensor) {
  using State = typename H::State;
  constexpr int N = DimOf<State>;
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01;
  int tested = 0;
  for (int draw = 0; draw < 3000; ++draw) {
    Vec lambda, s;
    for (int i = 0; i < N; ++i) {
      lambda(i) = std::exp(2 * n01(rng));
      s(i) = std::exp(n01(rng));
    }
    // One negative eigenvalue, from 1e-8 to 1 of the largest.
    lambda(int(u01(rng) * N)) = -lambda.maxCoeff() * std::pow(10.0, -8 * u01(rng));
    const Mat Pbar = with_spectrum<N>(rng, lambda, s);
    if (detail::psd_reference(Pbar, false)) continue;  // round-off made it PSD
    detail::EkfGain<H> g;
    const State x{};
    const FilterStatus st = detail::compute_gain<Options>(sensor, x, Pbar, g);
    // S = H P̄ H^T + R positive definite: the update would run to its posterior.
    typename detail::EkfGain<H>::SMat S;
    const auto J = sensor.jacobian(x);
    S = J * Pbar * J.transpose() + measurement_noise(sensor, x);
    S = (0.5 * (S + S.transpose())).eval();
    if (!detail::SpdSolver<typename detail::EkfGain<H>::SMat>{}.compute(S)) continue;
    ++tested;
    INFO("P̄ =\n" << Pbar << "\nposterior =\n" << g.P_post);
    REQUIRE(st != FilterStatus::kApplied);
  }
  return tested;
}

struct StandardForm : EkfOptions {
  static constexpr CovarianceUpdate kCovarianceUpdate = CovarianceUpdate::kStandard;
};

}  // namespace

TEST_CASE("Ekf::step equals predict() then update<I>() bit for bit, statuses included",
          "[filters][ekf][step]") {
  std::mt19937 rng(2212);
  Counts c;
  for (int trial = 0; trial < 600; ++trial) {
    compare_step_with_separate_calls<EkfOptions>(rng, c);
    compare_step_with_separate_calls<LeanEkfOptions>(rng, c);
  }
  INFO("applied " << c.applied << ", predict refused " << c.predict_refused
                  << ", first update not applied " << c.first_not_applied);
  // Every branch of step() is exercised.
  CHECK(c.applied > 1000);
  CHECK(c.predict_refused > 100);
  CHECK(c.first_not_applied > 100);
  CHECK(c.memo_steps > 1000);
}

TEST_CASE("Ekf::step's one check: an update never accepts the posterior of a refused prior",
          "[filters][ekf][step][psd]") {
  std::mt19937 rng(2213);
  // Two-row selection (closed form), three-row identity (closed form),
  // three-row dense H (SpdSolver), in both covariance forms.
  const PositionFix<4> fix2 = PositionFix<4>::isotropic(0.3);
  const PlanarPoseFix<double> fix3(Eigen::Vector3d(0.04, 0.04, 0.0025).asDiagonal());
  Dense3 dense;
  dense.J << 1, 0.2, 0, 0.5, 0, 1, 0.3, 0, 0.1, 0, 1, 1;
  dense.R = Eigen::Vector3d(0.01, 0.02, 0.05).asDiagonal();
  const CtrvPositionFix<double> ctrv_fix = CtrvPositionFix<double>::isotropic(0.5);
  CHECK(refused_prior_stays_refused<EkfOptions>(rng, fix2) > 500);
  CHECK(refused_prior_stays_refused<StandardForm>(rng, fix2) > 500);
  CHECK(refused_prior_stays_refused<EkfOptions>(rng, fix3) > 500);
  CHECK(refused_prior_stays_refused<StandardForm>(rng, fix3) > 500);
  CHECK(refused_prior_stays_refused<EkfOptions>(rng, dense) > 500);
  CHECK(refused_prior_stays_refused<StandardForm>(rng, dense) > 500);
  CHECK(refused_prior_stays_refused<EkfOptions>(rng, ctrv_fix) > 500);
}

TEST_CASE("Ekf::step on the library's models equals the separate calls", "[filters][ekf][step]") {
  // Unicycle + pose fix (3-row closed form) and CTRV + position fix.
  std::mt19937 rng(2214);
  std::normal_distribution<double> n01;
  Unicycle<double> uni;
  uni.control_cov = Eigen::Vector2d(0.05 * 0.05, 0.02 * 0.02).asDiagonal();
  const PlanarPoseFix<double> pose_fix(Eigen::Vector3d(0.04, 0.04, 0.0025).asDiagonal());
  Ekf<Unicycle<double>, PlanarPoseFix<double>> a(uni, pose_fix), b(uni, pose_fix);
  a.reset(PlanarPose<double>{}, Eigen::Matrix3d::Identity() * 0.1);
  b.reset(PlanarPose<double>{}, Eigen::Matrix3d::Identity() * 0.1);
  Ekf<Ctrv<double>, CtrvPositionFix<double>> c(Ctrv<double>(0.5, 0.05), CtrvPositionFix<double>::isotropic(0.5)),
      d(Ctrv<double>(0.5, 0.05), CtrvPositionFix<double>::isotropic(0.5));
  const Eigen::Matrix<double, 5, 1> p0(1.0, 1.0, 0.1, 1.0, 0.01);
  c.reset(CtrvState<double>(0, 0, 3.0, 8.0, 0.3), p0.asDiagonal());
  d.reset(CtrvState<double>(0, 0, 3.0, 8.0, 0.3), p0.asDiagonal());
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector2d u(1.0 + 0.1 * n01(rng), 0.3 + 0.1 * n01(rng));
    const double t = 0.3 * n01(rng);  // headings across +-pi now and then
    const PlanarPose<double> z{0.1 * k + 0.2 * n01(rng), 0.2 * n01(rng), wrap_angle(3.1 + t)};
    REQUIRE(static_cast<bool>(a.step(u, 0.1, z)) ==
            (b.predict(u, 0.1) == FilterStatus::kApplied && b.update<0>(z).status == FilterStatus::kApplied));
    REQUIRE(same_bits(a.state(), b.state()));
    REQUIRE(same_bits(a.covariance(), b.covariance()));
    REQUIRE(same_bits(a.last_jacobian(), b.last_jacobian()));
    const Eigen::Vector2d zc(c.state().x() + n01(rng), c.state().y() + n01(rng));
    const auto rc = c.step(NoControl{}, 0.1, zc);
    REQUIRE(rc.predict == d.predict(NoControl{}, 0.1));
    REQUIRE(same_result(rc.update<0>(), d.update<0>(zc)));
    REQUIRE(same_bits(c.state(), d.state()));
    REQUIRE(same_bits(c.covariance(), d.covariance()));
  }
}

TEST_CASE("Ekf::step before reset() reports kNotInitialised everywhere", "[filters][ekf][step]") {
  Ekf<Ctrv<double>, CtrvPositionFix<double>> ekf(Ctrv<double>(0.5, 0.05), CtrvPositionFix<double>::isotropic(0.5));
  const auto r = ekf.step(NoControl{}, 0.1, Eigen::Vector2d(1, 2));
  CHECK(r.predict == FilterStatus::kNotInitialised);
  CHECK(r.update<0>().status == FilterStatus::kNotInitialised);
  CHECK_FALSE(r);
  CHECK_FALSE(ekf.initialised());
}

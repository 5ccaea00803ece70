// The IMU factor (inertial/imu_factor.hpp): zero residual at its own
// prediction, small residual at the simulator's truth, conformance-checked
// Jacobians with respect to both states (a flipped block fails), whitening.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <apps/sim/imu.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/testing/conformance.hpp>

namespace {

using posefuse::ImuFactor;
using posefuse::ImuState;

struct Fixture {
  posefuse::sim::ImuSimConfig c;
  posefuse::sim::ImuSequence seq;
  posefuse::Preintegration pre;
  Fixture() {
    c.rate_hz = 200.0;
    seq = posefuse::sim::simulate_imu(c, 1.0);
    posefuse::ImuBias lin;
    lin.accel << 0.02, -0.01, 0.03;
    lin.gyro << 0.001, -0.002, 0.0015;
    pre = posefuse::Preintegration(posefuse::ImuNoise{}, lin);
    for (const posefuse::ImuSample& s : seq.samples) (void)pre.add(s);
  }
  [[nodiscard]] ImuState truth(std::size_t k) const {
    const posefuse::sim::ImuTruth& t = seq.truth[k];
    return ImuState{t.p_w, t.R_w_b, t.v_w, t.bias};
  }
  [[nodiscard]] Eigen::Vector3d gravity() const { return {0, 0, -c.gravity_mps2}; }
};

// A state near x, drawn one coordinate at a time (same draws under any compiler).
ImuState perturbed(const ImuState& x, double scale, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, scale);
  ImuState::Tangent d;
  for (int i = 0; i < 15; ++i) d(i) = n(rng);
  return x.plus(d);
}

}  // namespace

TEST_CASE("ImuFactor: zero residual at its prediction, small at the truth", "[inertial][factor]") {
  const Fixture f;
  const ImuFactor factor(f.pre, f.gravity());
  std::mt19937_64 rng(7);
  const ImuState xi = perturbed(f.truth(0), 0.05, rng);
  const ImuState xj = factor.predict(xi);
  CHECK(factor.residual(xi, xj).cwiseAbs().maxCoeff() < 1e-12);
  // The truth, with the pre-integration linearised at another bias than the
  // (zero) true one: first-order correction plus the mid-point error.
  const ImuFactor::Residual r = factor.residual(f.truth(0), f.truth(f.seq.samples.size() - 1));
  INFO("residual at the truth " << r.transpose());
  CHECK(r.cwiseAbs().maxCoeff() < 1e-4);
}

TEST_CASE("ImuFactor: Jacobians pass the conformance check; a flipped block fails",
          "[inertial][factor][conformance]") {
  const Fixture f;
  const ImuFactor factor(f.pre, f.gravity());
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const ImuState xi = perturbed(f.truth(0), 0.1, rng);
    const ImuState xj = perturbed(f.truth(f.seq.samples.size() - 1), 0.1, rng);
    ImuFactor::Jacobian J_i, J_j;
    (void)factor.residual(xi, xj, &J_i, &J_j);
    const auto fi = [&](const ImuState& x) { return factor.residual(x, xj); };
    const auto fj = [&](const ImuState& x) { return factor.residual(xi, x); };
    const auto ri = posefuse::testing::check_jacobian("J_r_xi", fi, xi, J_i, 1e-6);
    const auto rj = posefuse::testing::check_jacobian("J_r_xj", fj, xj, J_j, 1e-6);
    INFO(ri.message << "\n" << rj.message);
    CHECK(ri);
    CHECK(rj);
    if (trial > 0) continue;
    // Every non-zero 3x3 block, flipped, fails.
    for (int bi = 0; bi < 5; ++bi) {
      for (int bj = 0; bj < 5; ++bj) {
        for (int which = 0; which < 2; ++which) {
          ImuFactor::Jacobian J = which == 0 ? J_i : J_j;
          if (J.block<3, 3>(3 * bi, 3 * bj).isZero()) continue;
          J.block<3, 3>(3 * bi, 3 * bj) *= -1.0;
          const auto r = which == 0 ? posefuse::testing::check_jacobian("flip", fi, xi, J, 1e-6)
                                    : posefuse::testing::check_jacobian("flip", fj, xj, J, 1e-6);
          INFO("block " << bi << "," << bj << " of J_r_x" << (which == 0 ? "i" : "j"));
          CHECK_FALSE(r);
        }
      }
    }
  }
  // Whitened: |L^-1 r|^2 = r^T P^-1 r, and the Jacobians scale alike.
  const ImuState xi = perturbed(f.truth(0), 0.01, rng);
  const ImuState xj = perturbed(f.truth(f.seq.samples.size() - 1), 0.01, rng);
  ImuFactor::Jacobian J_i, W_i;
  const ImuFactor::Residual r = factor.residual(xi, xj, &J_i);
  const ImuFactor::Residual w = factor.whitened_residual(xi, xj, &W_i);
  const double m = r.dot(factor.covariance().ldlt().solve(r));
  CHECK(w.squaredNorm() == Approx(m).epsilon(1e-9));
  CHECK((W_i - factor.whitening() * J_i).cwiseAbs().maxCoeff() < 1e-9 * W_i.cwiseAbs().maxCoeff());
  CHECK_THROWS_AS(ImuFactor(posefuse::Preintegration{}, f.gravity()), posefuse::invalid_argument);
}

// IMU pre-integration (inertial/preintegration.hpp): relative motion of the
// simulator, conformance-checked bias Jacobians, bias correction vs
// re-integration, structured vs dense covariance, Monte-Carlo consistency,
// sample statuses and boundary interpolation.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <posefuse/testing/dense_preintegration.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/testing/conformance.hpp>

namespace {

using posefuse::ImuBias;
using posefuse::ImuDelta;
using posefuse::ImuNoise;
using posefuse::ImuSample;
using posefuse::ImuStatus;
using posefuse::Preintegration;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// Pre-integrates samples[i0..i1] (inclusive) about `bias`.
Preintegration integrate(const std::vector<ImuSample>& s, std::size_t i0, std::size_t i1,
                         const ImuBias& bias = {}, const ImuNoise& noise = {}) {
  Preintegration pre(noise, bias);
  for (std::size_t k = i0; k <= i1; ++k) {
    const ImuStatus st = pre.add(s[k]);
    REQUIRE((st == ImuStatus::kApplied || st == ImuStatus::kStarted));
  }
  return pre;
}

posefuse::sim::ImuSimConfig noise_free(double rate_hz) {
  posefuse::sim::ImuSimConfig c;
  c.rate_hz = rate_hz;
  return c;
}

double max_abs(const Eigen::Matrix<double, 9, 1>& e) { return e.cwiseAbs().maxCoeff(); }

// Largest |P_ij - Pd_ij| relative to each entry's scale sqrt(Pd_ii Pd_jj).
double normalised_difference(const Eigen::Matrix<double, 15, 15>& P,
                             const Eigen::Matrix<double, 15, 15>& Pd) {
  double worst = 0;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j)
      worst = std::max(worst, std::abs(P(i, j) - Pd(i, j)) / std::sqrt(Pd(i, i) * Pd(j, j)));
  return worst;
}

// The structured pre-integration equals the dense reference: covariance to
// 1e-12 of each entry's scale (and exactly symmetric), bias Jacobians to
// 1e-12 of their largest entry, the deltas within `delta_tol`.
void check_equals_dense(const Preintegration& pre, const posefuse::testing::DensePreintegration& dense,
                        double delta_tol) {
  const Eigen::Matrix<double, 15, 15> P = pre.covariance();
  const double worst = normalised_difference(P, dense.covariance());
  INFO("worst normalised covariance difference " << worst);
  CHECK(worst < 1e-12);
  CHECK((P - P.transpose()).cwiseAbs().maxCoeff() == 0.0);
  CHECK((pre.bias_jacobian() - dense.bias_jacobian()).cwiseAbs().maxCoeff() <
        1e-12 * dense.bias_jacobian().cwiseAbs().maxCoeff());
  CHECK(max_abs(pre.delta().minus(dense.delta())) < delta_tol);
}

}  // namespace

TEST_CASE("Preintegration: noise-free simulation reproduces the relative motion",
          "[inertial][preintegration]") {
  // 1 s windows; the mid-point rule is second order, so halving the step
  // divides the error by about 4.
  double err_prev = 0;
  for (const double rate : {200.0, 400.0, 800.0}) {
    const auto c = noise_free(rate);
    const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 3.0);
    const std::size_t n1 = std::size_t(rate);  // 1 s
    double err = 0;
    for (std::size_t i0 : {std::size_t(0), n1, 2 * n1}) {
      const Preintegration pre = integrate(seq.samples, i0, i0 + n1);
      const ImuDelta truth =
          posefuse::sim::true_delta(seq.truth[i0], seq.truth[i0 + n1], c.gravity_mps2);
      CHECK(pre.dt_s() == Approx(1.0).epsilon(1e-12));
      err = std::max(err, max_abs(pre.delta().minus(truth)));
    }
    INFO("rate " << rate << " Hz: max error " << err);
    if (rate == 800.0) CHECK(err < 2e-5);
    if (err_prev > 0) {
      CHECK(err_prev / err > 3.0);
      CHECK(err_prev / err < 5.0);
    }
    err_prev = err;
  }
}

TEST_CASE("Preintegration: bias Jacobians pass the conformance check; a flipped block fails",
          "[inertial][preintegration][conformance]") {
  const auto c = noise_free(200.0);
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 1.0);
  Vec6 b0;
  b0 << 0.05, -0.1, 0.2, 0.01, -0.02, 0.015;
  const auto f = [&](const Vec6& b) {
    return integrate(seq.samples, 0, seq.samples.size() - 1, ImuBias::from_vector(b)).delta();
  };
  const Preintegration pre =
      integrate(seq.samples, 0, seq.samples.size() - 1, ImuBias::from_vector(b0));
  const Eigen::Matrix<double, 9, 6> J = pre.bias_jacobian();
  const auto r = posefuse::testing::check_jacobian("J_delta_bias", f, b0, J, 1e-6);
  INFO(r.message);
  CHECK(r);
  CHECK(J.block<3, 3>(3, 0).isZero());  // ΔR does not depend on b_a
  // Every non-zero block, with its sign flipped, must fail.
  for (int bi = 0; bi < 3; ++bi) {
    for (int bj = 0; bj < 2; ++bj) {
      if (J.block<3, 3>(3 * bi, 3 * bj).isZero()) continue;
      Eigen::Matrix<double, 9, 6> Jf = J;
      Jf.block<3, 3>(3 * bi, 3 * bj) *= -1.0;
      CHECK_FALSE(posefuse::testing::check_jacobian("flipped", f, b0, Jf, 1e-6));
    }
  }
  // The corrected delta's own Jacobian (rotation rows through J_r).
  Vec6 b1 = b0;
  b1 << 0.07, -0.08, 0.19, 0.013, -0.018, 0.02;
  Eigen::Matrix<double, 9, 6> J_d_b;
  (void)pre.delta(ImuBias::from_vector(b1), &J_d_b);
  const auto g = [&](const Vec6& b) { return pre.delta(ImuBias::from_vector(b)); };
  const auto r2 = posefuse::testing::check_jacobian("J_corrected_bias", g, b1, J_d_b, 1e-7);
  INFO(r2.message);
  CHECK(r2);
}

TEST_CASE("Preintegration: first-order bias correction agrees with re-integration",
          "[inertial][preintegration]") {
  const auto c = noise_free(200.0);
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 1.0);
  const std::size_t last = seq.samples.size() - 1;
  const Preintegration pre = integrate(seq.samples, 0, last);
  double prev = 0;
  for (const double scale : {1e-2, 1e-3}) {
    Vec6 db;
    db << 1.0, -0.5, 0.7, 0.1, -0.2, 0.15;
    db *= scale;
    const ImuBias b = ImuBias::from_vector(db);
    const ImuDelta corrected = pre.delta(b);
    const ImuDelta reint = integrate(seq.samples, 0, last, b).delta();
    const double err = max_abs(corrected.minus(reint));
    const double change = max_abs(pre.delta().minus(reint));
    INFO("bias change scale " << scale << ": correction error " << err << ", change " << change);
    CHECK(err < 1e-2 * change);  // the correction removes > 99 % of the change
    if (prev > 0) CHECK(prev / err > 50.0);  // second order: 10x smaller change, ~100x smaller error
    prev = err;
  }
  // update_bias: below the thresholds it keeps the integration, above it re-integrates.
  Preintegration p2 = integrate(seq.samples, 0, last);
  ImuBias small;
  small.gyro << 0.001, 0, 0;
  CHECK_FALSE(p2.update_bias(small));
  CHECK(p2.bias().gyro.isZero());
  ImuBias large;
  large.gyro << 0.05, 0, 0;
  CHECK(p2.update_bias(large));
  CHECK(p2.bias().gyro == large.gyro);
  const ImuDelta direct = integrate(seq.samples, 0, last, large).delta();
  CHECK(max_abs(p2.delta().minus(direct)) == 0.0);
  CHECK_THROWS_AS(p2.update_bias(ImuBias{Eigen::Vector3d::Constant(NAN), {}}),
                  posefuse::invalid_argument);
}

TEST_CASE("Preintegration: the structured update equals the dense F P F^T + G Q G^T to 1e-12",
          "[inertial][preintegration]") {
  auto c = noise_free(200.0);
  c.noise = ImuNoise{};  // EuRoC figures
  c.initial_bias.accel << 0.1, -0.05, 0.2;
  c.initial_bias.gyro << 0.01, 0.02, -0.01;
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 2.0);
  ImuBias lin;
  lin.accel << 0.05, 0.0, 0.1;
  lin.gyro << 0.005, 0.01, 0.0;
  Preintegration pre(ImuNoise{}, lin);
  posefuse::testing::DensePreintegration dense(ImuNoise{}, lin);
  for (const ImuSample& s : seq.samples) {
    (void)pre.add(s);
    dense.add(s);
  }
  check_equals_dense(pre, dense, 1e-12);
  const Eigen::Matrix<double, 15, 15> P = pre.covariance();
  // Positive definite after the first step.
  CHECK(Eigen::LLT<Eigen::Matrix<double, 15, 15>>(P).info() == Eigen::Success);
}

TEST_CASE("Preintegration: structured equals dense after every step, across the re-basing of r = p - tau v",
          "[inertial][preintegration]") {
  // 0.6 s at 200 Hz: the propagation's reference instant moves to the
  // present twice (every 0.25 s), so the reads below see tau = 0, small
  // and near 0.25 s.
  auto c = noise_free(200.0);
  c.noise = ImuNoise{};
  c.initial_bias.accel << 0.1, -0.05, 0.2;
  c.initial_bias.gyro << 0.01, 0.02, -0.01;
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 0.6);
  REQUIRE(seq.samples.size() > 100);
  Preintegration pre(ImuNoise{}, ImuBias{});
  posefuse::testing::DensePreintegration dense(ImuNoise{}, ImuBias{});
  for (std::size_t k = 0; k < seq.samples.size(); ++k) {
    (void)pre.add(seq.samples[k]);
    dense.add(seq.samples[k]);
    if (k > 0) check_equals_dense(pre, dense, 1e-12);
  }
}

TEST_CASE("Preintegration: structured equals dense over a long window with large per-step rotations",
          "[inertial][preintegration]") {
  // 60 s at 50 Hz of fast rotation (steps above the 0.05 rad series limit of
  // detail::small_exp as well as below): the structured update (6x3 stacked
  // blocks, closed forms, first-order quaternion renormalisation) must not
  // drift from the dense reference over 3000 steps.
  auto c = noise_free(50.0);
  c.attitude_amplitude_rad << 1.0, 0.8, 2.0;
  c.attitude_rate_radps << 4.0, 3.0, 2.5;
  c.noise = ImuNoise{};
  c.initial_bias.gyro << 0.01, -0.02, 0.03;
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 60.0);
  Preintegration pre(ImuNoise{}, ImuBias{}, posefuse::PreintegrationOptions{.reserve_samples = 4096});
  posefuse::testing::DensePreintegration dense(ImuNoise{}, ImuBias{});
  double max_step = 0, min_step = 1e9;
  for (std::size_t k = 0; k < seq.samples.size(); ++k) {
    if (k > 0) {
      const double step = (0.5 * (seq.samples[k].gyro_radps + seq.samples[k - 1].gyro_radps)).norm() / 50.0;
      max_step = std::max(max_step, step);
      min_step = std::min(min_step, step);
    }
    REQUIRE(pre.add(seq.samples[k]) != ImuStatus::kGap);
    dense.add(seq.samples[k]);
  }
  INFO("per-step rotation " << min_step << " .. " << max_step << " rad");
  REQUIRE(max_step > 0.05);
  REQUIRE(min_step < 0.05);
  check_equals_dense(pre, dense, 1e-12 * (1.0 + pre.delta().p.norm()));
  CHECK(std::abs(pre.delta().R.quaternion().norm() - 1.0) < 1e-14);
}

TEST_CASE("Preintegration: covariance matches Monte-Carlo statistics of noisy simulations",
          "[inertial][preintegration][montecarlo]") {
  // 300 runs of a 1 s window at 200 Hz with EuRoC-like densities (inflated
  // gyroscope noise so that rotation errors matter): the sample covariance of
  // the 15-dim error [δp, δφ, δv, δb_a, δb_g] against the propagated one.
  ImuNoise noise;
  noise.gyro_noise_density = 2e-3;
  noise.accel_noise_density = 2e-2;
  noise.gyro_random_walk = 2e-4;
  noise.accel_random_walk = 3e-3;
  auto c = noise_free(200.0);
  const posefuse::sim::ImuSequence clean = posefuse::sim::simulate_imu(c, 1.0);
  const Preintegration ref = integrate(clean.samples, 0, clean.samples.size() - 1, {}, noise);
  const Eigen::Matrix<double, 15, 15> P = ref.covariance();
  const int runs = 300;
  Eigen::Matrix<double, 15, 15> S = Eigen::Matrix<double, 15, 15>::Zero();
  double nees_sum = 0;
  const Eigen::LDLT<Eigen::Matrix<double, 15, 15>> ldlt(P);
  for (int r = 0; r < runs; ++r) {
    c.noise = noise;
    c.seed = 1000 + std::uint64_t(r);
    const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 1.0);
    const Preintegration pre = integrate(seq.samples, 0, seq.samples.size() - 1, {}, noise);
    Eigen::Matrix<double, 15, 1> e;
    // The model's error state: truth (the clean pre-integration) minus the
    // estimate (the noisy one, integrated with the start bias), and the
    // bias drift over the window (true bias minus the linearisation bias).
    e.head<9>() = ref.delta().minus(pre.delta());
    e.segment<3>(9) = seq.truth.back().bias.accel - seq.truth.front().bias.accel;
    e.segment<3>(12) = seq.truth.back().bias.gyro - seq.truth.front().bias.gyro;
    S += e * e.transpose();
    nees_sum += e.dot(ldlt.solve(e));
  }
  S /= runs;
  const double nees = nees_sum / runs;
  INFO("mean NEES " << nees << " (15 expected)");
  // Mean of 300 chi2(15) draws: sd sqrt(30/300) = 0.32; allow 4 sd.
  CHECK(std::abs(nees - 15.0) < 1.3);
  for (int i = 0; i < 15; ++i) {
    INFO("diagonal " << i << ": Monte-Carlo " << S(i, i) << " vs propagated " << P(i, i));
    CHECK(S(i, i) / P(i, i) > 0.75);
    CHECK(S(i, i) / P(i, i) < 1.3);
  }
}

TEST_CASE("Preintegration: out-of-order, repeated, gapped and non-finite samples are reported",
          "[inertial][preintegration]") {
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(noise_free(200.0), 0.1);
  posefuse::PreintegrationOptions o;
  o.max_gap_ns = 20'000'000;
  Preintegration pre(ImuNoise{}, ImuBias{}, o);
  CHECK(pre.add(seq.samples[0]) == ImuStatus::kStarted);
  CHECK(pre.add(seq.samples[1]) == ImuStatus::kApplied);
  CHECK(pre.add(seq.samples[2]) == ImuStatus::kApplied);
  const ImuDelta before = pre.delta();
  const Eigen::Matrix<double, 15, 15> P_before = pre.covariance();
  CHECK(pre.add(seq.samples[1]) == ImuStatus::kOutOfOrder);
  CHECK(pre.add(seq.samples[2]) == ImuStatus::kRepeated);
  CHECK(pre.add(seq.samples[8]) == ImuStatus::kGap);  // 30 ms > 20 ms
  ImuSample bad = seq.samples[3];
  bad.gyro_radps.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK(pre.add(bad) == ImuStatus::kNonFinite);
  CHECK(pre.sample_count() == 3);
  CHECK(max_abs(pre.delta().minus(before)) == 0.0);
  CHECK(pre.covariance() == P_before);
  CHECK(pre.add(seq.samples[3]) == ImuStatus::kApplied);
  CHECK_THROWS_AS(Preintegration(ImuNoise{-1, 0, 0, 0}), posefuse::invalid_argument);
}

TEST_CASE("Preintegration: integration between arbitrary stamps interpolates the boundaries",
          "[inertial][preintegration]") {
  const auto c = noise_free(1000.0);
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 2.0);
  // Stamps between samples: 0.2503 s and 1.4217 s after the start.
  const std::int64_t t0 = c.start_t_ns + 250'300'000, t1 = c.start_t_ns + 1'421'700'000;
  Preintegration pre;
  REQUIRE(posefuse::preintegrate(seq.samples, t0, t1, pre) == ImuStatus::kApplied);
  CHECK(pre.start_t_ns() == t0);
  CHECK(pre.end_t_ns() == t1);
  CHECK(pre.dt_s() == Approx(1.1714).epsilon(1e-12));
  const posefuse::sim::ImuTrajectory traj(c);
  const auto truth_at = [&](std::int64_t t_ns) {
    const double t = posefuse::seconds_between(t_ns, c.start_t_ns);
    return posefuse::sim::ImuTruth{t_ns, traj.position(t), traj.velocity(t), traj.rotation(t), {}};
  };
  const ImuDelta truth = posefuse::sim::true_delta(truth_at(t0), truth_at(t1), c.gravity_mps2);
  CHECK(max_abs(pre.delta().minus(truth)) < 2e-5);
  // Stamps on samples use them as they are.
  Preintegration on;
  REQUIRE(posefuse::preintegrate(seq.samples, seq.samples[10].t_ns, seq.samples[500].t_ns, on) ==
          ImuStatus::kApplied);
  CHECK(on.sample_count() == 491);
  CHECK(posefuse::preintegrate(seq.samples, t1, t0, pre) == ImuStatus::kOutOfRange);
  CHECK(posefuse::preintegrate(seq.samples, c.start_t_ns - 1, t1, pre) == ImuStatus::kOutOfRange);
  CHECK(posefuse::preintegrate(seq.samples, t0, seq.samples.back().t_ns + 1, pre) ==
        ImuStatus::kOutOfRange);
}

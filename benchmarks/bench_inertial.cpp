// Seed 003's inertial core: cost per IMU sample of pre-integration with
// covariance and bias Jacobians — posefuse's structured update against the
// dense 15x15 F / 15x18 G products of VINS-Mono (same mathematics; a test in
// tests/inertial checks they agree to 1e-12) — and the other inertial costs.
//
// Run (Release; ratios within one binary):
//   ./build-release/benchmarks/bench_inertial --benchmark_enable_random_interleaving=true \
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cstddef>
#include <vector>

#include <posefuse/testing/dense_preintegration.hpp>
#include <posefuse/sim/imu.hpp>
#include <array>

#include <posefuse/inertial/alignment.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/inertial/preintegration.hpp>

namespace {

// 1 s of noisy 200 Hz samples; every benchmark integrates them as windows of
// 200 steps (one keyframe interval), restarting at the end.
const posefuse::sim::ImuSequence& samples() {
  static const posefuse::sim::ImuSequence seq = [] {
    posefuse::sim::ImuSimConfig c;
    c.noise = posefuse::ImuNoise{};
    c.initial_bias.accel << 0.1, -0.05, 0.2;
    c.initial_bias.gyro << 0.01, 0.02, -0.01;
    return posefuse::sim::simulate_imu(c, 1.0);
  }();
  return seq;
}

void BM_Preintegration_posefuse(benchmark::State& state) {
  const std::vector<posefuse::ImuSample>& s = samples().samples;
  posefuse::Preintegration pre(posefuse::ImuNoise{}, posefuse::ImuBias{});
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == s.size()) {
      pre.reset(posefuse::ImuBias{});
      k = 0;
    }
    benchmark::DoNotOptimize(pre.add(s[k++]));
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(pre.covariance());
  state.SetItemsProcessed(state.iterations());
}

void BM_Preintegration_dense(benchmark::State& state) {
  const std::vector<posefuse::ImuSample>& s = samples().samples;
  posefuse::testing::DensePreintegration pre(posefuse::ImuNoise{}, posefuse::ImuBias{});
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == s.size()) {
      pre = posefuse::testing::DensePreintegration(posefuse::ImuNoise{}, posefuse::ImuBias{});
      k = 0;
    }
    pre.add(s[k++]);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(pre.covariance());
  state.SetItemsProcessed(state.iterations());
}

// One residual with both 15x15 Jacobians, whitened (what a solver calls per
// factor per iteration), over a 1 s interval.
void BM_ImuFactor_residual_jacobians(benchmark::State& state) {
  const posefuse::sim::ImuSequence& seq = samples();
  posefuse::Preintegration pre(posefuse::ImuNoise{}, posefuse::ImuBias{});
  for (const posefuse::ImuSample& s : seq.samples) (void)pre.add(s);
  const posefuse::ImuFactor factor(pre, Eigen::Vector3d(0, 0, -9.81));
  const auto state_at = [&](std::size_t k) {
    const posefuse::sim::ImuTruth& t = seq.truth[k];
    return posefuse::ImuState{t.p_w, t.R_w_b, t.v_w, t.bias};
  };
  const posefuse::ImuState xi = state_at(0), xj = state_at(seq.truth.size() - 1);
  posefuse::ImuFactor::Jacobian J_i, J_j;
  for (auto _ : state) {
    benchmark::DoNotOptimize(factor.whitened_residual(xi, xj, &J_i, &J_j));
    benchmark::ClobberMemory();
  }
}

// One visual-inertial alignment of 10 keyframes 0.3 s apart (gyro bias,
// re-integration of the 9 intervals, the 54x34 and 54x33 least-squares
// solves of the refinement, world frame). The pre-integrations are copied
// in each iteration (the alignment re-integrates them); the copy is timed too.
void BM_Alignment_10_keyframes(benchmark::State& state) {
  posefuse::sim::ImuSimConfig c;
  c.initial_bias.gyro << 0.01, -0.02, 0.005;
  const posefuse::sim::ImuSequence seq = posefuse::sim::simulate_imu(c, 2.8);
  const posefuse::SE3d T_b_c(Eigen::Vector3d(0.05, 0, 0), posefuse::SO3d());
  std::array<posefuse::SE3d, 10> T_c0_c;
  std::array<posefuse::Preintegration, 9> pre0;
  const posefuse::SE3d T_c0_w = posefuse::SE3d(seq.truth[0].p_w, seq.truth[0].R_w_b).compose(T_b_c).inverse();
  for (std::size_t k = 0; k < 10; ++k) {
    const posefuse::sim::ImuTruth& t = seq.truth[60 * k];
    const posefuse::SE3d T = T_c0_w.compose(posefuse::SE3d(t.p_w, t.R_w_b).compose(T_b_c));
    T_c0_c[k] = posefuse::SE3d(T.translation() * 0.37, T.so3());
    if (k < 9)
      for (std::size_t i = 60 * k; i <= 60 * (k + 1); ++i) (void)pre0[k].add(seq.samples[i]);
  }
  for (auto _ : state) {
    std::array<posefuse::Preintegration, 9> pre = pre0;
    const auto r = posefuse::align_visual_inertial<10>(T_c0_c, T_b_c, pre);
    benchmark::DoNotOptimize(r.scale);
  }
}

}  // namespace

BENCHMARK(BM_Alignment_10_keyframes)->Name("BM_Alignment/10_keyframes");
BENCHMARK(BM_ImuFactor_residual_jacobians)->Name("BM_ImuFactor/residual_jacobians_whitened");
BENCHMARK(BM_Preintegration_posefuse)->Name("BM_Preintegration/posefuse");
BENCHMARK(BM_Preintegration_dense)->Name("BM_Preintegration/dense");

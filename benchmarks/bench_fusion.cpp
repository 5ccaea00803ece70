// Per-sample cost of the seed-001 fusers side by side: the threshold fuser
// (eq 14-15 as printed) against the gated fuser's odometry step, SLAM update
// and whole stage step, plus the pose-level information fusion; and the
// whole corridor run per log sample. Build in Release.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <apps/corridor_runner.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/seed/threshold_fuser.hpp>
#include <posefuse/sim/corridor.hpp>

namespace {

constexpr std::size_t kN = 256;  // distinct inputs, cycled, so nothing is constant-folded

template <class T>
std::array<posefuse::PlanarPose<T>, kN> circle_poses(T noise) {
  std::array<posefuse::PlanarPose<T>, kN> p{};
  for (std::size_t i = 0; i < kN; ++i) {
    const T a = T(0.01) * T(i);
    p[i] = {T(2) * std::sin(a) + noise * std::sin(T(7) * a), T(2) - T(2) * std::cos(a),
            posefuse::wrap_angle(a + noise * std::cos(T(5) * a))};
  }
  return p;
}

template <class T>
void BM_ThresholdFuser_Step(benchmark::State& state) {
  const posefuse::seed::ThresholdFuser<T> fuser(T(0.01));
  const auto odom = circle_poses<T>(T(0));
  const auto slam = circle_poses<T>(T(0.03));
  std::array<typename posefuse::seed::ThresholdFuser<T>::Input, kN> in{};
  for (std::size_t i = 0; i < kN; ++i)
    in[i] = {{odom[i].x, odom[i].y, T(0.01), T(-0.02), odom[i].theta},
             {slam[i].x, slam[i].y, T(0), T(0), slam[i].theta}};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(fuser(in[i]));
    i = (i + 1) % kN;
  }
  state.SetItemsProcessed(state.iterations());
}

template <class T>
posefuse::GatedFuser<T> anchored_fuser() {
  posefuse::GatedFuserParams<T> p;
  p.anchor_samples = 1;
  p.anchor_min_travel_m = T(0);
  posefuse::GatedFuser<T> f(p);
  (void)f.predict({T(0), T(0), T(0)});
  (void)f.update_slam({T(0), T(0), T(0)}, false);
  return f;
}

template <class T>
void BM_GatedFuser_Predict(benchmark::State& state) {
  auto f = anchored_fuser<T>();
  const auto odom = circle_poses<T>(T(0));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.predict(odom[i]));
    i = (i + 1) % kN;
  }
  state.SetItemsProcessed(state.iterations());
}

template <class T>
void BM_GatedFuser_PredictAndUpdate(benchmark::State& state) {
  auto f = anchored_fuser<T>();
  const auto odom = circle_poses<T>(T(0));
  const auto slam = circle_poses<T>(T(0.01));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.predict(odom[i]));
    benchmark::DoNotOptimize(f.update_slam(slam[i], false));
    i = (i + 1) % kN;
  }
  state.SetItemsProcessed(state.iterations());
}

template <class T>
void BM_GatedFuser_StageStep(benchmark::State& state) {
  auto f = anchored_fuser<T>();
  const auto odom = circle_poses<T>(T(0));
  const auto slam = circle_poses<T>(T(0.01));
  std::array<typename posefuse::GatedFuser<T>::Input, kN> in{};
  for (std::size_t i = 0; i < kN; ++i) in[i] = {odom[i], true, slam[i], false};
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(f(in[i]));
    i = (i + 1) % kN;
  }
  state.SetItemsProcessed(state.iterations());
}

template <class T>
void BM_FusePoses(benchmark::State& state) {
  const auto a = circle_poses<T>(T(0));
  const auto b = circle_poses<T>(T(0.05));
  const Eigen::Matrix<T, 3, 3> Pa = Eigen::Matrix<T, 3, 1>(T(0.04), T(0.02), T(0.001)).asDiagonal();
  const Eigen::Matrix<T, 3, 3> Pb = Eigen::Matrix<T, 3, 3>::Identity() * T(0.0025);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::fuse_poses(a[i], Pa, b[i], Pb));
    i = (i + 1) % kN;
  }
  state.SetItemsProcessed(state.iterations());
}

// The whole comparison (four methods, both sensor chains, metrics) per log sample.
void BM_CorridorRunner_PerSample(benchmark::State& state) {
  const auto log = posefuse::sim::simulate_corridor({}, 1).log;
  const auto samples = std::int64_t(log.wheels.size() + log.imu.size() + log.slam.size());
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::run_corridor(log));
  state.SetItemsProcessed(state.iterations() * samples);
}

}  // namespace

BENCHMARK_TEMPLATE(BM_ThresholdFuser_Step, float);
BENCHMARK_TEMPLATE(BM_ThresholdFuser_Step, double);
BENCHMARK_TEMPLATE(BM_GatedFuser_Predict, float);
BENCHMARK_TEMPLATE(BM_GatedFuser_Predict, double);
BENCHMARK_TEMPLATE(BM_GatedFuser_PredictAndUpdate, float);
BENCHMARK_TEMPLATE(BM_GatedFuser_PredictAndUpdate, double);
BENCHMARK_TEMPLATE(BM_GatedFuser_StageStep, float);
BENCHMARK_TEMPLATE(BM_GatedFuser_StageStep, double);
BENCHMARK_TEMPLATE(BM_FusePoses, float);
BENCHMARK_TEMPLATE(BM_FusePoses, double);
BENCHMARK(BM_CorridorRunner_PerSample)->Unit(benchmark::kMillisecond);

// Evaluation hot spots on KITTI-sized inputs (synthetic, fixed seeds):
// timestamp association, Umeyama alignment, APE and RPE.
#include <Eigen/Geometry>
#include <benchmark/benchmark.h>
#include <cmath>
#include <random>
#include <vector>

#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>

namespace {

// A 10 Hz drive along a gently curving road in KITTI's x-z plane, with a
// noisy, rotated copy as the estimate.
struct Pair {
  posefuse::Trajectory ref, est;
};

Pair make_pair(std::size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.3);
  Pair p;
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  G.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (std::size_t k = 0; k < n; ++k) {
    const double t = 0.1 * static_cast<double>(k);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.01 * t, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(50.0 * std::sin(0.01 * t), 0.0, 1000.0 * std::sin(0.001 * t));
    p.ref.push_back(t, T);
    Eigen::Isometry3d E = G * T;
    E.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    p.est.push_back(t + 0.003, E);
  }
  return p;
}

void BM_Association_Associate(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::associate(p.ref.t_s, p.est.t_s));
  }
}
BENCHMARK(BM_Association_Associate)->Arg(1101)->Arg(30000);

void BM_Umeyama_Sim3(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  const std::vector<Eigen::Vector3d> x = p.est.positions(), y = p.ref.positions();
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::umeyama_alignment(x, y, true));
}
BENCHMARK(BM_Umeyama_Sim3)->Arg(1101);

void BM_Ape_TranslationSE3(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::ape(p.ref, p.est, posefuse::PoseRelation::kTranslation,
                                           posefuse::Alignment::kSE3));
  }
}
BENCHMARK(BM_Ape_TranslationSE3)->Arg(1101);

void BM_Rpe_AngleByMeters(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  posefuse::RpeOptions o;
  o.relation = posefuse::PoseRelation::kRotationAngleDeg;
  o.delta = 10.0;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::rpe(p.ref, p.est, o));
}
BENCHMARK(BM_Rpe_AngleByMeters)->Arg(1101);

}  // namespace

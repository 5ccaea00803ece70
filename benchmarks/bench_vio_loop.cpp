// bench_vio_loop: the two costs of loop closure (vio/loop_closure.hpp).
//
// The scene: a body flying a circle (radius 3 m, 20 s a lap) looking outward
// at 3000 landmarks on a cylinder wall (radius 7 m) whose ids recur on every
// lap; keyframe records every 0.25 s made from the truth with a drift of
// 0.2 deg/s in yaw and 2 cm/s in translation, normalised observations with
// 0.5 px noise (460 px focal), world points with 1 cm noise (about 340
// features per keyframe, all with a point).
//
//   BM_LoopVerify        one candidate's verification: the correspondences
//                        of a second-lap keyframe with the first-lap keyframe
//                        at the same place and its two neighbours on each
//                        side, then PnP + RANSAC (vio/pnp.hpp; 10 px at
//                        460 px, at most 200 trials, LM refinement) and the
//                        loop edge; LoopClosure::verify_between, graph unchanged
//   BM_LoopUpdate/N      one loop's pose-graph update on a chain of N
//                        keyframes that already holds a loop every 4 s after
//                        the first lap (5 for N = 160, 120 for 2000): a copy of
//                        the graph (not timed), the loop edge added and the
//                        4-DoF graph re-optimised (PoseGraph4Dof::optimize,
//                        Levenberg–Marquardt, defaults)
//
// Counters: inliers and correspondences (verify), iterations (update).
// Run: bench_vio_loop --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
//      --benchmark_report_aggregates_only=true (results in docs/benchmarks.md).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/vio/loop_closure.hpp>

namespace {

using posefuse::SE3d;
using posefuse::SO3d;

struct Scene {
  std::vector<Eigen::Vector3d> landmarks;
  SE3d T_b_c;
  Scene() {
    std::mt19937_64 g(11);
    std::uniform_real_distribution<double> a(0, 2 * std::numbers::pi), h(-1.0, 3.0);
    for (int i = 0; i < 3000; ++i) {
      const double t = a(g);
      landmarks.emplace_back(7 * std::cos(t), 7 * std::sin(t), h(g));
    }
    Eigen::Matrix3d R_bc;
    R_bc << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    T_b_c = SE3d(Eigen::Vector3d(0.05, 0, 0), SO3d(R_bc));
  }
  // The keyframe at time t (s) with drift, as the odometry would record it.
  [[nodiscard]] posefuse::KeyframeRecord record(double t, std::uint64_t seed) const {
    std::mt19937_64 g(seed);
    std::normal_distribution<double> px(0.0, 0.5 / 460.0), pt(0.0, 0.01);
    const double th = 2 * std::numbers::pi * t / 20.0;
    const SE3d T_w_b(Eigen::Vector3d(3 * std::cos(th), 3 * std::sin(th), 1.0),
                     SO3d(Eigen::Matrix3d(Eigen::AngleAxisd(th, Eigen::Vector3d::UnitZ()))));
    const posefuse::DriftCorrection D{0.2 * std::numbers::pi / 180.0 * t, Eigen::Vector3d(0.015, -0.012, 0.004) * t};
    const SE3d T_c_w = (T_w_b * T_b_c).inverse();
    posefuse::KeyframeRecord r;
    r.t_ns = std::int64_t(std::llround(t * 1e9));
    r.T_w_b = D.apply(T_w_b);
    r.T_b_c = T_b_c;
    for (std::size_t i = 0; i < landmarks.size(); ++i) {
      const Eigen::Vector3d p = T_c_w.act(landmarks[i]);
      if (p.z() < 0.5 || std::abs(p.x() / p.z()) > 0.75 || std::abs(p.y() / p.z()) > 0.5) continue;
      posefuse::KeyframeFeature f;
      f.id = i;
      f.m = Eigen::Vector2d(p.x() / p.z() + px(g), p.y() / p.z() + px(g));
      f.has_point = true;
      f.p_w = D.rotation() * landmarks[i] + D.t + Eigen::Vector3d(pt(g), pt(g), pt(g));
      r.features.push_back(f);
    }
    return r;
  }
};

// N keyframes (0.25 s apart) with a loop every 4 s after the first lap
// (not at the last keyframe), and the ids of the last keyframe and its first-lap match.
struct Chain {
  posefuse::LoopClosure lc;
  std::int64_t query = 0, match = 0;
};

void build_chain(Chain& c, int n) {
  const Scene scene;
  std::vector<std::int64_t> ids;
  for (int k = 0; k < n; ++k) {
    const double t = 0.25 * k;
    ids.push_back(c.lc.add_keyframe(scene.record(t, 100 + std::uint64_t(k))));
    if (k + 1 < n && t >= 21 && std::fmod(t, 4.0) == 1.0) (void)c.lc.add_loop_between(ids.back(), ids[std::size_t(k - 80)]);
  }
  c.query = ids.back();
  c.match = ids[std::size_t(n - 1 - 80)];
}

void BM_LoopVerify(benchmark::State& state) {
  Chain c;
  build_chain(c, 160);
  posefuse::LoopResult r;
  for (auto _ : state) {
    r = c.lc.verify_between(c.query, c.match);
    benchmark::DoNotOptimize(r);
  }
  if (r.status != posefuse::LoopStatus::kAccepted) state.SkipWithError(r.reason.c_str());
  state.counters["inliers"] = r.inliers;
  state.counters["correspondences"] = r.correspondences;
}
BENCHMARK(BM_LoopVerify)->Unit(benchmark::kMillisecond);

void BM_LoopUpdate(benchmark::State& state) {
  Chain c;
  build_chain(c, int(state.range(0)));
  const posefuse::LoopResult r = c.lc.verify_between(c.query, c.match);
  if (r.status != posefuse::LoopStatus::kAccepted) {
    state.SkipWithError(r.reason.c_str());
    return;
  }
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    posefuse::PoseGraph4Dof g = c.lc.graph();
    state.ResumeTiming();
    g.add_edge(r.edge);
    iterations = g.optimize().iterations;
    benchmark::DoNotOptimize(g);
  }
  state.counters["iterations"] = iterations;
  state.counters["loops"] = c.lc.loops();
}
BENCHMARK(BM_LoopUpdate)->Arg(160)->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace

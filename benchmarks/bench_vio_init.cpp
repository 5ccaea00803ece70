// bench_vio_init: the geometry of a visual initialisation and of a loop
// candidate's verification.
//
//   BM_SfmWindow   structure from motion on one 10-frame window
//                  (vio/sfm.hpp, default options): a camera moving 0.8 m
//                  sideways (and 0.2 m forward) past 250 points 4-10 m
//                  ahead, 90° field of view, 1 px noise at 460 px focal
//                  (about 245 features per frame)
//   BM_PnpRansac   PnP + RANSAC (vio/pnp.hpp, default options: 2 px, at most
//                  200 trials, adaptive stop at 0.999, LM refinement) on 100
//                  correspondences 2-8 m away, 1 px noise, 30 % of them wrong
//                  (a random image point)
//
// Counters: points and reference frame (SfM), inliers (PnP).
// Run: bench_vio_init --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <posefuse/vio/pnp.hpp>
#include <posefuse/vio/sfm.hpp>

namespace {

using posefuse::SE3d;
using posefuse::SO3d;

constexpr double kFocal = 460.0;

std::vector<std::vector<posefuse::SfmObservation>> sfm_window() {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0 / kFocal);
  std::vector<SE3d> T;
  for (int k = 0; k < 10; ++k) {
    const double s = k / 9.0;
    T.emplace_back(Eigen::Vector3d(0.8 * s, 0.1 * std::sin(4.0 * s), 0.2 * s),
                   SO3d::exp(Eigen::Vector3d(0.02 * std::sin(3.0 * s), 0.05 * s, 0.01 * k)));
  }
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 250; ++i) pts.emplace_back(0.4 + 5.0 * u(rng), 4.0 * u(rng), 7.0 + 3.0 * u(rng));
  std::vector<std::vector<posefuse::SfmObservation>> frames;
  for (const SE3d& Tk : T) {
    frames.emplace_back();
    const SE3d T_c_w = Tk.inverse();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3d q = T_c_w.act(pts[i]);
      const Eigen::Vector2d m = q.head<2>() / q.z();
      if (q.z() < 0.5 || m.cwiseAbs().maxCoeff() > 1.0) continue;
      frames.back().push_back({std::uint64_t(i), m + Eigen::Vector2d(g(rng), g(rng))});
    }
  }
  return frames;
}

void BM_SfmWindow(benchmark::State& state) {
  const auto frames = sfm_window();
  posefuse::SfmResult r;
  for (auto _ : state) {
    r = posefuse::structure_from_motion(frames);
    benchmark::DoNotOptimize(r.T_c0_c.data());
  }
  if (r.status != posefuse::SfmStatus::kOk) state.SkipWithError(r.reason.c_str());
  state.counters["points"] = double(r.points_c0.size());
  state.counters["reference"] = r.reference_frame;
}
BENCHMARK(BM_SfmWindow)->Unit(benchmark::kMillisecond);

void BM_PnpRansac(benchmark::State& state) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0 / kFocal);
  const SE3d T_w_c(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 5.0, SO3d::exp(Eigen::Vector3d(u(rng), u(rng), u(rng))));
  std::vector<Eigen::Vector3d> P;
  std::vector<Eigen::Vector2d> M;
  for (int i = 0; i < 100; ++i) {
    const double z = 5.0 + 3.0 * u(rng);
    const Eigen::Vector3d p_c(z * u(rng), z * u(rng), z);
    P.push_back(T_w_c.act(p_c));
    M.push_back(i < 30 ? Eigen::Vector2d(u(rng), u(rng))
                       : Eigen::Vector2d(p_c.head<2>() / p_c.z() + Eigen::Vector2d(g(rng), g(rng))));
  }
  posefuse::PnpResult r;
  for (auto _ : state) {
    r = posefuse::solve_pnp_ransac(P, M);
    benchmark::DoNotOptimize(r.inliers);
  }
  if (r.status != posefuse::PnpStatus::kOk) state.SkipWithError(r.reason.c_str());
  state.counters["inliers"] = r.inliers;
}
BENCHMARK(BM_PnpRansac)->Unit(benchmark::kMicrosecond);

}  // namespace

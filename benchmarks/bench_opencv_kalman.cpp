// Seed 000's filter step, posefuse against OpenCV's cv::KalmanFilter, on the
// same model and the same inputs, in one binary. Built only when CMake finds
// OpenCV (core, video); see benchmarks/CMakeLists.txt.
//
//   cmake --preset release && cmake --build --preset release --target bench_opencv_kalman
//   OMP_THREAD_LIMIT=1 ./build-release/benchmarks/bench_opencv_kalman --benchmark_repetitions=3 \
//       --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
//
// The model (seed 000): x' = x + u + w, w ~ N(0, diag(0.1^2, 0.1^2));
// z = x + v, v ~ N(0, diag(0.5^2, 0.5^2)); x0 = z_0, P0 = I. The inputs are
// bench_filters' seed-000 frames (1024 frames, generator seed 3, cycled; one
// frame per iteration). Rows:
//   BM_Seed000_Step/opencv             cv::KalmanFilter(2, 2, 2, CV_64F) with A = B = H = I:
//                                      predict(u) then correct(z); u and z are
//                                      cv::Mat headers on the frames (no copy)
//   BM_Seed000_Step/posefuse           posefuse::Ekf, default options, the
//                                      filter's own sensor (update<0>: the
//                                      steady-state gain memo can hit)
//   BM_Seed000_Step/posefuse_recompute posefuse::Ekf::update_with() a sensor held
//                                      outside the filter: the gain is computed
//                                      afresh every step
// Before timing, each row's implementation and OpenCV are run side by side
// over all 1024 frames; the benchmark stops with an error unless the states
// agree to 1e-9 (relative) at every frame.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>
#include <random>
#include <string>
#include <vector>

#include "seed000_frames.hpp"

namespace {

constexpr std::size_t kFrames = 1024;
static_assert(kFrames == posefuse_bench::kSeed000Frames);
constexpr double kSigmaProcess = 0.1, kSigmaMeasurement = 0.5;

using Frames = posefuse_bench::PlanarFrames;
/// Seed 000's inputs, the frames bench_filters times.
const Frames& frames() { return posefuse_bench::seed000_frames(); }

struct OpenCv {
  cv::KalmanFilter kf{2, 2, 2, CV_64F};
  OpenCv() {
    kf.transitionMatrix = cv::Mat::eye(2, 2, CV_64F);
    kf.controlMatrix = cv::Mat::eye(2, 2, CV_64F);
    kf.measurementMatrix = cv::Mat::eye(2, 2, CV_64F);
    kf.processNoiseCov = cv::Mat::eye(2, 2, CV_64F) * (kSigmaProcess * kSigmaProcess);
    kf.measurementNoiseCov = cv::Mat::eye(2, 2, CV_64F) * (kSigmaMeasurement * kSigmaMeasurement);
    const Eigen::Vector2d& z0 = frames().z[0];
    kf.statePost = (cv::Mat_<double>(2, 1) << z0.x(), z0.y());
    kf.errorCovPost = cv::Mat::eye(2, 2, CV_64F);
  }
  double step(std::size_t k) {
    const Frames& f = frames();
    const cv::Mat u(2, 1, CV_64F, const_cast<double*>(f.u[k].data()));
    const cv::Mat z(2, 1, CV_64F, const_cast<double*>(f.z[k].data()));
    kf.predict(u);
    return kf.correct(z).at<double>(0);
  }
  Eigen::Vector2d state() const { return {kf.statePost.at<double>(0), kf.statePost.at<double>(1)}; }
};

using Motion = posefuse::PlanarDisplacement<double>;
using Fix = posefuse::PositionFix<2>;

struct Posefuse {
  posefuse::Ekf<Motion, Fix> ekf{Motion::from_sigmas(kSigmaProcess, kSigmaProcess),
                                 Fix::isotropic(kSigmaMeasurement)};
  Posefuse() { ekf.reset(frames().z[0], Eigen::Matrix2d::Identity()); }
  posefuse::FilterStatus step(std::size_t k) {
    const Frames& f = frames();
    (void)ekf.predict(f.u[k], 1.0);
    return ekf.update<0>(f.z[k]).status;
  }
  Eigen::Vector2d state() const { return ekf.state(); }
};

struct PosefuseRecompute {
  Fix fix = Fix::isotropic(kSigmaMeasurement);
  posefuse::Ekf<Motion, Fix> ekf{Motion::from_sigmas(kSigmaProcess, kSigmaProcess), fix};
  PosefuseRecompute() { ekf.reset(frames().z[0], Eigen::Matrix2d::Identity()); }
  posefuse::FilterStatus step(std::size_t k) {
    const Frames& f = frames();
    (void)ekf.predict(f.u[k], 1.0);
    return ekf.update_with(fix, f.z[k]).status;
  }
  Eigen::Vector2d state() const { return ekf.state(); }
};

/// Runs Impl and OpenCV over every frame. @return empty, or the first disagreement
template <class Impl>
std::string disagreement() {
  OpenCv ref;
  Impl impl;
  for (std::size_t k = 0; k < kFrames; ++k) {
    (void)ref.step(k);
    (void)impl.step(k);
    const Eigen::Vector2d a = impl.state(), b = ref.state();
    const double e = (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
    if (!(e <= 1e-9)) return "state differs from cv::KalmanFilter at frame " + std::to_string(k);
  }
  return {};
}

template <class Impl>
void BM_Step(benchmark::State& st) {
  static const std::string why = disagreement<Impl>();
  if (!why.empty()) {
    st.SkipWithError(why.c_str());
    return;
  }
  Impl impl;
  std::size_t k = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(impl.step(k));
    k = (k + 1) & (kFrames - 1);
  }
  benchmark::DoNotOptimize(impl.state());
}

const bool registered = [] {
  benchmark::RegisterBenchmark("BM_Seed000_Step/opencv", BM_Step<OpenCv>);
  benchmark::RegisterBenchmark("BM_Seed000_Step/posefuse", BM_Step<Posefuse>);
  benchmark::RegisterBenchmark("BM_Seed000_Step/posefuse_recompute", BM_Step<PosefuseRecompute>);
  return true;
}();

}  // namespace

// The image front end (frontend/klt_tracker.hpp) per frame on 752 x 480
// images with 150 features, and its parts side by side. Built only when
// CMake finds OpenCV (posefuse::frontend); see benchmarks/CMakeLists.txt.
//
//   cmake --preset release && cmake --build --preset release --target bench_frontend
//   ./build-release/benchmarks/bench_frontend --benchmark_repetitions=3 \
//       --benchmark_report_aggregates_only=true
//
// Images: EuRoC V1_01_easy's first 95 cam0 frames from the data folder
// (POSEFUSE_DATA_DIR, euroc/V1_01_easy/cam0_first95), cycled; without it a
// seeded synthetic texture moving 3 px per frame (the label says which).
// OpenCV runs on one thread (cv::setNumThreads(1)), so the figures do not
// depend on the cores free. Rows (time per frame):
//   BM_Tracker        KltTracker::track: everything below, plus bookkeeping;
//                     on the still EuRoC frames nearly every feature stays,
//                     so detection rarely runs
//   BM_Tracker_Moving KltTracker::track on the synthetic texture moving 3 px
//                     per frame to and fro (64 frames each way): features
//                     leave at one edge and detection runs every frame
//   BM_Part_Klt       pyramid of the new image, forward and backward
//                     Lucas-Kanade of 150 points (klt_track)
//   BM_Part_Ransac    undistortion and fundamental-matrix RANSAC of 150
//                     pairs (fundamental_inliers)
//   BM_Part_Detect    minimum-distance mask of 140 kept features and
//                     Shi-Tomasi detection of 10 new corners
//                     (min_distance_mask, detect_corners)
//   BM_Part_Clahe     CLAHE of one image (only with --clahe; not in BM_Tracker)
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <posefuse/frontend/image_folder.hpp>
#include <posefuse/frontend/klt_tracker.hpp>
#include <posefuse/vio/camera.hpp>

namespace {

namespace pf = posefuse::frontend;

// One OpenCV thread, set before any benchmark runs.
const bool kOneThread = [] {
  cv::setNumThreads(1);
  return true;
}();

struct Sequence {
  posefuse::PinholeRadtan camera;
  std::vector<cv::Mat> images;
  std::string label;
};

// A seeded synthetic texture moving 3 px per frame to the right, 64 frames.
Sequence synthetic() {
  Sequence q;
  q.camera.fu = q.camera.fv = 460;
  q.camera.cu = 376;
  q.camera.cv = 240;
  q.camera.width = 752;
  q.camera.height = 480;
  cv::Mat tex(480 + 64, 752 + 3 * 64, CV_32FC1);
  cv::RNG rng(7);
  rng.fill(tex, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(tex, tex, cv::Size(0, 0), 2.5);
  cv::normalize(tex, tex, 20.0, 235.0, cv::NORM_MINMAX);
  for (int k = 0; k < 64; ++k) {
    cv::Mat img;
    tex(cv::Rect(3 * k, 32, 752, 480)).convertTo(img, CV_8UC1);
    q.images.push_back(img);
  }
  q.label = "synthetic texture, 3 px per frame";
  return q;
}

// The data folder's frames, or the synthetic texture.
const Sequence& sequence() {
  static const Sequence s = [] {
    Sequence q;
    const char* env = std::getenv("POSEFUSE_DATA_DIR");
    const std::filesystem::path data = env != nullptr && *env != '\0' ? env : POSEFUSE_DEFAULT_DATA_DIR;
    const std::filesystem::path dir = data / "euroc/V1_01_easy/cam0_first95";
    if (std::filesystem::is_directory(dir)) {
      q.camera = posefuse::read_euroc_camera(dir / "sensor.yaml");
      const pf::EurocImageFolder folder(dir, q.camera.width, q.camera.height);
      for (std::size_t k = 0; k < folder.size(); ++k) q.images.push_back(folder.image(k));
      q.label = "EuRoC V1_01 cam0, 95 frames";
      return q;
    }
    q = synthetic();
    q.label = "synthetic texture (no data folder)";
    return q;
  }();
  return s;
}

void BM_Tracker(benchmark::State& state) {
  const Sequence& s = sequence();
  pf::KltTracker tracker(s.camera);
  std::int64_t t = 0;
  std::size_t k = 0;
  for (std::size_t w = 0; w < 5; ++w) tracker.track(++t, s.images[k++ % s.images.size()]);  // fill up
  double features = 0, detected = 0;
  for (auto _ : state) {
    const pf::KltFrameStats& st = tracker.track(++t, s.images[k++ % s.images.size()]);
    features += st.features;
    detected += st.detected;
  }
  state.counters["features"] = benchmark::Counter(features, benchmark::Counter::kAvgIterations);
  state.counters["detected"] = benchmark::Counter(detected, benchmark::Counter::kAvgIterations);
  state.SetLabel(s.label);
}

void BM_Tracker_Moving(benchmark::State& state) {
  static const Sequence s = synthetic();
  pf::KltTracker tracker(s.camera);
  const std::size_t n = s.images.size();
  std::int64_t t = 0;
  std::size_t k = 0;
  const auto next = [&]() -> const cv::Mat& {  // 0, 1, ..., 63, 62, ..., 1, 0, 1, ...
    const std::size_t phase = k++ % (2 * n - 2);
    return s.images[phase < n ? phase : 2 * n - 2 - phase];
  };
  for (std::size_t w = 0; w < 5; ++w) tracker.track(++t, next());
  double features = 0, detected = 0;
  for (auto _ : state) {
    const pf::KltFrameStats& st = tracker.track(++t, next());
    features += st.features;
    detected += st.detected;
  }
  state.counters["features"] = benchmark::Counter(features, benchmark::Counter::kAvgIterations);
  state.counters["detected"] = benchmark::Counter(detected, benchmark::Counter::kAvgIterations);
  state.SetLabel(s.label);
}

// The 150 features of frame k's tracker state and frame k+1.
struct PartInput {
  std::vector<cv::Point2f> points;
  std::vector<pf::TrackedFeature> features;
};

PartInput part_input(std::size_t k) {
  const Sequence& s = sequence();
  pf::KltTracker tracker(s.camera);
  for (std::size_t i = 0; i <= k; ++i) tracker.track(std::int64_t(i + 1), s.images[i % s.images.size()]);
  PartInput in;
  in.features = tracker.features();
  for (const auto& f : in.features) in.points.emplace_back(float(f.uv.x()), float(f.uv.y()));
  return in;
}

void BM_Part_Klt(benchmark::State& state) {
  const Sequence& s = sequence();
  const pf::KltTrackerOptions o;
  const PartInput in = part_input(10);
  const std::vector<cv::Mat> previous = pf::klt_pyramid(s.images[10], o);
  std::vector<cv::Point2f> tracked;
  for (auto _ : state) {
    const std::vector<cv::Mat> current = pf::klt_pyramid(s.images[11], o);
    benchmark::DoNotOptimize(pf::klt_track(previous, current, in.points, tracked, o));
  }
  state.counters["points"] = double(in.points.size());
  state.SetLabel(s.label);
}

void BM_Part_Ransac(benchmark::State& state) {
  const Sequence& s = sequence();
  const pf::KltTrackerOptions o;
  const PartInput in = part_input(10);
  const std::vector<cv::Mat> previous = pf::klt_pyramid(s.images[10], o);
  const std::vector<cv::Mat> current = pf::klt_pyramid(s.images[11], o);
  std::vector<cv::Point2f> tracked;
  (void)pf::klt_track(previous, current, in.points, tracked, o);
  for (auto _ : state) benchmark::DoNotOptimize(pf::fundamental_inliers(s.camera, in.points, tracked, o));
  state.counters["points"] = double(in.points.size());
  state.SetLabel(s.label);
}

void BM_Part_Detect(benchmark::State& state) {
  const Sequence& s = sequence();
  const pf::KltTrackerOptions o;
  PartInput in = part_input(10);
  in.features.resize(140);
  for (auto _ : state) {
    std::vector<pf::TrackedFeature> kept = in.features;
    const cv::Mat mask = pf::min_distance_mask(s.images[11].size(), kept, o.min_distance_px);
    benchmark::DoNotOptimize(pf::detect_corners(s.images[11], mask, o.max_features - int(kept.size()), o));
  }
  state.SetLabel(s.label);
}

void BM_Part_Clahe(benchmark::State& state) {
  const Sequence& s = sequence();
  const pf::KltTrackerOptions o;
  const cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE(o.clahe_clip_limit, cv::Size(o.clahe_tiles, o.clahe_tiles));
  cv::Mat out;
  for (auto _ : state) {
    clahe->apply(s.images[11], out);
    benchmark::DoNotOptimize(out.data);
  }
  state.SetLabel(s.label);
}

}  // namespace

BENCHMARK(BM_Tracker)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Tracker_Moving)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Part_Klt)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Part_Ransac)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Part_Detect)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Part_Clahe)->Unit(benchmark::kMillisecond);

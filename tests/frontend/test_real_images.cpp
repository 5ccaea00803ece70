// The tracker on real images: EuRoC V1_01_easy's first 95 cam0 frames (the
// data folder's euroc/V1_01_easy/cam0_first95), taken while the MAV stands
// on the floor. What must hold on a camera at rest: the features fill up to
// the maximum and stay, their pixels move by sub-pixel amounts, and RANSAC
// finds almost nothing to reject.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include <posefuse/frontend/image_folder.hpp>
#include <posefuse/frontend/klt_tracker.hpp>
#include <posefuse/vio/camera.hpp>

#include "support/data_path.hpp"

namespace pf = posefuse::frontend;

namespace {

// True when the 21 x 21 Lucas-Kanade window around `p` lies inside the image
// with a pixel to spare.
bool window_inside(const Eigen::Vector2d& p, const posefuse::PinholeRadtan& camera) {
  constexpr double kHalf = 11.0;
  return p.x() >= kHalf && p.y() >= kHalf && p.x() <= camera.width - 1 - kHalf && p.y() <= camera.height - 1 - kHalf;
}

}  // namespace

TEST_CASE("KLT on EuRoC V1_01's first 95 frames: a camera at rest keeps its tracks", "[frontend][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "euroc/V1_01_easy/cam0_first95");
  const posefuse::PinholeRadtan camera = posefuse::read_euroc_camera(dir / "sensor.yaml");
  const pf::EurocImageFolder folder(dir, camera.width, camera.height);
  REQUIRE(folder.size() == 95);

  pf::KltTracker tracker(camera);  // VINS-Mono's defaults: 150 features, 30 px apart
  std::vector<std::map<std::uint64_t, Eigen::Vector2d>> frames;
  int rejected = 0, tracked = 0, fewest_after_first = 1 << 30;
  for (std::size_t k = 0; k < folder.size(); ++k) {
    const pf::KltFrameStats& s = tracker.track(folder.entries()[k].t_ns, folder.image(k));
    rejected += s.rejected_ransac;
    tracked += s.tracked;
    if (k > 0) fewest_after_first = std::min(fewest_after_first, s.features);
    std::map<std::uint64_t, Eigen::Vector2d> f;
    for (const pf::TrackedFeature& x : tracker.features()) f[x.id] = x.uv;
    frames.push_back(std::move(f));
  }

  // Features per frame: the first frame's detection may stop short (the
  // corner threshold is relative to the strongest corner); from the second
  // frame on the tracker tops up to the maximum.
  INFO("fewest features in frames 2-95: " << fewest_after_first);
  CHECK(fewest_after_first == 150);

  // Track lengths: of the features of frame 2, most last to frame 95.
  int survived = 0;
  for (const auto& [id, uv] : frames[1]) survived += frames.back().count(id) != 0 ? 1 : 0;
  INFO("features of frame 2 still tracked in frame 95: " << survived << " of " << frames[1].size());
  CHECK(survived >= int(0.75 * double(frames[1].size())));

  // Sub-pixel stability: from one frame to the next no tracked point whose
  // 21 x 21 window lies inside the image moves by a pixel (nearer the edge
  // OpenCV pads the image by reflection and no accuracy is claimed); over the whole sequence, after removing the camera's small
  // common motion (the per-frame median displacement), the median track
  // stays within 0.5 px of where it started.
  double largest_step = 0;
  std::vector<Eigen::Vector2d> common(frames.size(), Eigen::Vector2d::Zero());
  for (std::size_t k = 1; k < frames.size(); ++k) {
    std::vector<double> du, dv;
    for (const auto& [id, uv] : frames[k]) {
      const auto it = frames[k - 1].find(id);
      if (it == frames[k - 1].end()) continue;
      if (window_inside(uv, camera) && window_inside(it->second, camera))
        largest_step = std::max(largest_step, (uv - it->second).norm());
      du.push_back(uv.x() - it->second.x());
      dv.push_back(uv.y() - it->second.y());
    }
    REQUIRE(du.size() >= 75);
    std::nth_element(du.begin(), du.begin() + long(du.size() / 2), du.end());
    std::nth_element(dv.begin(), dv.begin() + long(dv.size() / 2), dv.end());
    common[k] = common[k - 1] + Eigen::Vector2d(du[du.size() / 2], dv[dv.size() / 2]);
  }
  std::map<std::uint64_t, std::pair<std::size_t, Eigen::Vector2d>> start;
  std::map<std::uint64_t, double> wander;  // largest distance from the start, common motion removed (px)
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (const auto& [id, uv] : frames[k]) {
      const auto [it, fresh] = start.try_emplace(id, k, uv);
      const Eigen::Vector2d d = uv - it->second.second - (common[k] - common[it->second.first]);
      wander[id] = std::max(wander[id], d.norm());
    }
  }
  std::vector<double> w;
  for (const auto& [id, x] : wander) w.push_back(x);
  std::sort(w.begin(), w.end());
  INFO("largest frame-to-frame step " << largest_step << " px; median wander " << w[w.size() / 2]
                                      << " px; camera's common motion " << common.back().norm() << " px");
  CHECK(largest_step < 1.0);
  CHECK(w[w.size() / 2] < 0.5);

  // RANSAC: almost nothing to reject (at most 1 in 1000 tracked features).
  INFO("rejected by RANSAC " << rejected << " of " << tracked);
  CHECK(rejected * 1000 <= tracked);
}

// The KLT tracker (frontend/klt_tracker.hpp) on synthetic images whose
// motion is known: sub-pixel accuracy, RANSAC, ids, the minimum-distance
// mask, determinism and the options' validation.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <posefuse/frontend/klt_tracker.hpp>
#include <posefuse/io/feature_tracks.hpp>

#include "frontend/synthetic_images.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace pf = posefuse::frontend;
namespace syn = posefuse_test::frontend;

namespace {

// True when the 21 x 21 Lucas-Kanade window around `p` lies inside the
// image with a pixel to spare: there the image holds all the texture the
// window compares; nearer the edge OpenCV pads the pyramid by reflection,
// which does not move with the texture, so no accuracy is claimed there.
bool window_inside(const Eigen::Vector2d& p) {
  constexpr double kHalf = 11.0;
  return p.x() >= kHalf && p.y() >= kHalf && p.x() <= syn::kWidth - 1 - kHalf && p.y() <= syn::kHeight - 1 - kHalf;
}

struct Accuracy {
  double worst = 0;  // px, over features whose window is inside both images
  int interior = 0;  // features of `before` whose window is inside both images
  int tracked = 0;   // of those, tracked into `after`
};

// Where the features of `before` went in `after`, against the motion.
Accuracy accuracy(const std::vector<pf::TrackedFeature>& before, const std::vector<pf::TrackedFeature>& after,
                  const std::function<Eigen::Vector2d(const Eigen::Vector2d&)>& motion) {
  std::map<std::uint64_t, Eigen::Vector2d> now;
  for (const auto& f : after) now[f.id] = f.uv;
  Accuracy a;
  for (const auto& f : before) {
    const Eigen::Vector2d q = motion(f.uv);
    if (!window_inside(f.uv) || !window_inside(q)) continue;
    ++a.interior;
    const auto it = now.find(f.id);
    if (it == now.end()) continue;
    ++a.tracked;
    a.worst = std::max(a.worst, (it->second - q).norm());
  }
  return a;
}

}  // namespace

TEST_CASE("KLT: a translated texture is tracked to within 0.1 px", "[frontend]") {
  const cv::Mat tex = syn::texture();
  const cv::Mat img0 = syn::view(tex, 0, 0);
  // A sub-pixel shift and one of several pixels.
  for (const auto& shift : {std::pair{0.37, -0.62}, std::pair{6.4, 3.75}, std::pair{-11.25, 8.5}}) {
    const double dx = shift.first, dy = shift.second;  // not a structured binding: clang 14 cannot capture one
    CAPTURE(dx, dy);
    pf::KltTracker tracker(syn::pinhole());
    const pf::KltFrameStats s0 = tracker.track(1, img0);
    REQUIRE(s0.features == 150);
    REQUIRE(s0.detected == 150);
    const std::vector<pf::TrackedFeature> before = tracker.features();
    tracker.track(2, syn::view(tex, dx, dy));
    const Accuracy a =
        accuracy(before, tracker.features(), [&](const Eigen::Vector2d& p) { return syn::moved_pixel(p, dx, dy); });
    CHECK(a.interior >= 120);
    // Every feature whose window stays inside is tracked, but for those the
    // minimum-distance mask drops (rounding moves two features 30 px apart
    // onto each other's disc).
    CHECK(a.tracked >= a.interior - tracker.stats().dropped_min_distance);
    CHECK(tracker.stats().dropped_min_distance <= 3);
    CHECK(a.worst < 0.1);
    CHECK(tracker.stats().rejected_ransac == 0);
    CHECK(tracker.stats().features == 150);
  }
}

TEST_CASE("KLT: a rotated and zoomed texture is tracked to sub-pixel accuracy", "[frontend]") {
  // The Lucas-Kanade window moves but does not turn or scale, so its error
  // grows with the rotation and zoom between two frames: within 0.1 px at
  // 0.5 deg and 0.5 % (10 deg/s at 20 Hz), within 0.2 px at 1.5 deg and 2 %.
  const cv::Mat tex = syn::texture();
  constexpr double kDeg = 3.14159265358979 / 180.0;
  for (const auto& motion : {std::tuple{0.5 * kDeg, 1.005, 0.1}, std::tuple{1.5 * kDeg, 1.02, 0.2}}) {
    const auto [angle_, scale_, bound] = motion;
    const double angle = angle_, scale = scale_;  // plain variables: clang 14 cannot capture a structured binding
    CAPTURE(angle, scale);
    pf::KltTracker tracker(syn::pinhole());
    tracker.track(1, syn::view(tex, 0, 0));
    const std::vector<pf::TrackedFeature> before = tracker.features();
    tracker.track(2, syn::view(tex, 1.5, -0.75, angle, scale));
    const Accuracy a = accuracy(before, tracker.features(), [&](const Eigen::Vector2d& p) {
      return syn::moved_pixel(p, 1.5, -0.75, angle, scale);
    });
    CHECK(a.interior >= 120);
    CHECK(a.tracked >= a.interior - tracker.stats().dropped_min_distance);
    CHECK(a.worst < bound);
    CHECK(tracker.stats().rejected_ransac == 0);
  }
}

TEST_CASE("KLT: RANSAC on undistorted points drops planted outliers", "[frontend]") {
  // Points in front of two EuRoC cam0 poses (distorted pixels); 15 of 120
  // moved off their epipolar lines by 4 to 20 px.
  const posefuse::PinholeRadtan cam = syn::euroc_cam0();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ux(-2.5, 2.5), uy(-1.6, 1.6), uz(4.0, 9.0), off(4.0, 20.0), sign(-1, 1);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.25, 0.03, 0.05);
  std::vector<cv::Point2f> a, b;
  while (a.size() < 120) {
    const Eigen::Vector3d p(ux(rng), uy(rng), uz(rng));
    const auto pa = cam.project(p), pb = cam.project(R * p + t);
    if (!pa || !pb) continue;
    a.emplace_back(float(pa->x()), float(pa->y()));
    b.emplace_back(float(pb->x()), float(pb->y()));
  }
  std::set<std::size_t> planted;
  for (std::size_t i = 0; i < 120; i += 8) {
    // Perpendicular-ish offset: along both axes with random signs.
    b[i].x += float(off(rng) * (sign(rng) < 0 ? -1 : 1));
    b[i].y += float(off(rng) * (sign(rng) < 0 ? -1 : 1));
    planted.insert(i);
  }
  const std::vector<unsigned char> in = pf::fundamental_inliers(cam, a, b, {});
  int kept = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    CAPTURE(i);
    if (planted.count(i) != 0) CHECK(in[i] == 0);
    kept += planted.count(i) == 0 && in[i] != 0 ? 1 : 0;
  }
  CHECK(kept == 120 - int(planted.size()));

  // Fewer than 8 points: nothing is rejected.
  const std::vector<cv::Point2f> a7(a.begin(), a.begin() + 7), b7(b.begin(), b.begin() + 7);
  const std::vector<unsigned char> in7 = pf::fundamental_inliers(cam, a7, b7, {});
  CHECK(std::count(in7.begin(), in7.end(), 1) == 7);
}

TEST_CASE("KLT: ids stay with their feature and new ids count up", "[frontend]") {
  const cv::Mat tex = syn::texture();
  pf::KltTracker tracker(syn::pinhole());
  std::map<std::uint64_t, Eigen::Vector2d> last;
  std::uint64_t highest = 0;
  bool any = false;
  for (int k = 0; k < 12; ++k) {
    // 3 px per frame to the right and 1 down: features leave on one side, new ones come in.
    tracker.track(k + 1, syn::view(tex, 3.0 * k, 1.0 * k));
    std::set<std::uint64_t> seen;
    for (const auto& f : tracker.features()) {
      REQUIRE(seen.insert(f.id).second);  // unique within the frame
      const auto it = last.find(f.id);
      if (it != last.end()) {
        // The same landmark: it moved by the frame's motion (accuracy
        // claimed where the window is inside both images, see window_inside).
        if (window_inside(it->second) && window_inside(f.uv))
          CHECK((f.uv - it->second - Eigen::Vector2d(3.0, 1.0)).norm() < 0.1);
      }
    }
    // New ids are above every id handed out before.
    for (const auto& f : tracker.features())
      if (last.count(f.id) == 0 && any) CHECK(f.id > highest);
    for (const auto& f : tracker.features()) highest = std::max(highest, f.id);
    CHECK(tracker.next_id() == highest + 1);
    if (k > 0) CHECK(tracker.stats().tracked >= 100);
    last.clear();
    for (const auto& f : tracker.features()) last[f.id] = f.uv;
    any = true;
  }
  CHECK(tracker.frames() == 12);
}

TEST_CASE("KLT: the minimum-distance mask keeps the longest tracks and spaces features", "[frontend]") {
  SECTION("min_distance_mask") {
    std::vector<pf::TrackedFeature> f = {{5, {100.0, 100.0}, 3},   // dropped: 20 px from id 9, a longer track
                                         {9, {120.0, 100.0}, 7},   // kept first
                                         {2, {100.0, 160.0}, 3},   // kept: 60 px from id 9
                                         {4, {100.0, 185.0}, 3}};  // dropped: 25 px from id 2, same length, larger id
    const cv::Mat mask = pf::min_distance_mask(cv::Size(300, 300), f, 30);
    REQUIRE(f.size() == 2);
    CHECK(f[0].id == 9);
    CHECK(f[1].id == 2);
    CHECK(mask.at<unsigned char>(100, 120) == 0);
    CHECK(mask.at<unsigned char>(100, 149) == 0);  // 29 px from id 9
    CHECK(mask.at<unsigned char>(100, 152) == 255);  // 32 px away
    CHECK(mask.at<unsigned char>(20, 20) == 255);
  }
  SECTION("tracker") {
    const cv::Mat tex = syn::texture();
    for (const int d : {12, 30, 45}) {
      CAPTURE(d);
      pf::KltTrackerOptions o;
      o.min_distance_px = d;
      pf::KltTracker tracker(syn::pinhole(), o);
      for (int k = 0; k < 6; ++k) {
        tracker.track(k + 1, syn::view(tex, 4.0 * k, -2.5 * k));
        const auto f = tracker.features();
        double closest = 1e9;
        for (std::size_t i = 0; i < f.size(); ++i)
          for (std::size_t j = i + 1; j < f.size(); ++j) closest = std::min(closest, (f[i].uv - f[j].uv).norm());
        // Discs are drawn around rounded pixels: a feature may be up to
        // sqrt(2)/2 px nearer than d to another's rounded pixel.
        CHECK(closest >= d - std::sqrt(0.5));
      }
    }
  }
}

TEST_CASE("KLT: the same images give the same tracks bit for bit", "[frontend]") {
  const cv::Mat tex = syn::texture();
  posefuse::test::TempDir dir("frontend-determinism");
  std::vector<std::string> files;
  for (int run = 0; run < 2; ++run) {
    pf::KltTrackerOptions o;
    o.clahe = true;
    pf::KltTracker tracker(syn::euroc_cam0(), o);
    posefuse::FeatureTracks tracks;
    for (int k = 0; k < 8; ++k) {
      tracker.track(1000 + k, syn::view(tex, 2.3 * k, 0.7 * k, 0.002 * k, 1.0 + 0.003 * k));
      tracks.push_back(tracker.frame());
    }
    const auto p = dir.path() / ("run" + std::to_string(run) + ".csv");
    posefuse::write_feature_tracks(p, tracks);
    files.push_back(posefuse::test::slurp(p));
  }
  REQUIRE(files[0].size() > 1000);
  CHECK(files[0] == files[1]);
}

TEST_CASE("KLT: options out of range are refused naming the option", "[frontend]") {
  CHECK_NOTHROW(pf::KltTrackerOptions{}.validate());
  const std::vector<std::pair<std::string, std::function<void(pf::KltTrackerOptions&)>>> bad = {
      {"max_features", [](auto& o) { o.max_features = 0; }},
      {"min_distance_px", [](auto& o) { o.min_distance_px = -1; }},
      {"ransac_threshold_px", [](auto& o) { o.ransac_threshold_px = 0; }},
      {"ransac_threshold_px", [](auto& o) { o.ransac_threshold_px = std::nan(""); }},
      {"ransac_confidence", [](auto& o) { o.ransac_confidence = 1.0; }},
      {"virtual_focal_px", [](auto& o) { o.virtual_focal_px = 0.5; }},
      {"window_px", [](auto& o) { o.window_px = 20; }},
      {"window_px", [](auto& o) { o.window_px = 1; }},
      {"pyramid_levels", [](auto& o) { o.pyramid_levels = -1; }},
      {"klt_max_iterations", [](auto& o) { o.klt_max_iterations = 0; }},
      {"klt_epsilon_px", [](auto& o) { o.klt_epsilon_px = 0; }},
      {"max_forward_backward_px", [](auto& o) { o.max_forward_backward_px = -0.1; }},
      {"border_px", [](auto& o) { o.border_px = -1; }},
      {"corner_quality", [](auto& o) { o.corner_quality = 0; }},
      {"corner_quality", [](auto& o) { o.corner_quality = 1.5; }},
      {"corner_block_px", [](auto& o) { o.corner_block_px = 2; }},
      {"clahe_clip_limit", [](auto& o) { o.clahe_clip_limit = 0; }},
      {"clahe_tiles", [](auto& o) { o.clahe_tiles = 0; }},
  };
  for (const auto& [name, spoil] : bad) {
    CAPTURE(name);
    pf::KltTrackerOptions o;
    spoil(o);
    CHECK_THROWS_WITH(o.validate(), Catch::Contains(name));
    CHECK_THROWS_AS(pf::KltTracker(syn::pinhole(), o), posefuse::invalid_argument);
  }
}

TEST_CASE("KLT: images of the wrong size or type and stamps that go back are refused", "[frontend]") {
  pf::KltTracker tracker(syn::pinhole());
  const cv::Mat tex = syn::texture();
  CHECK_THROWS_WITH(tracker.track(1, cv::Mat(100, 100, CV_8UC1, cv::Scalar(0))),
                    Catch::Contains("100x100") && Catch::Contains("752x480"));
  CHECK_THROWS_WITH(tracker.track(1, cv::Mat(480, 752, CV_8UC3, cv::Scalar(0))), Catch::Contains("CV_8UC1"));
  tracker.track(5, syn::view(tex, 0, 0));
  CHECK_THROWS_WITH(tracker.track(5, syn::view(tex, 1, 0)), Catch::Contains("does not follow"));
  CHECK(tracker.frames() == 1);
}

#pragma once
/// @file
/// The image front end: a KLT feature tracker after VINS-Mono's
/// feature_tracker (Qin et al., T-RO 2018), whose output is the feature
/// tracks the visual-inertial estimator reads (io/feature_tracks.hpp).
/// Needs OpenCV (core, imgproc, video, calib3d); no other posefuse header
/// includes this one. CMake target `posefuse::frontend`.
///
/// **Per frame** (KltTracker::track):
/// 1. optional CLAHE (contrast-limited adaptive histogram equalisation);
/// 2. the previous frame's points are tracked into the new image by
///    pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK on pyramids built
///    once per image), then tracked back; a point is kept when both passes
///    converge and the backward pass returns within
///    `max_forward_backward_px` of where it started;
/// 3. points whose rounded pixel lies within `border_px` of the image edge
///    are dropped;
/// 4. outliers are rejected by RANSAC on the fundamental matrix (at least 8
///    points, else none is rejected): both frames' points are undistorted
///    through posefuse's camera model (PinholeRadtan::undistort) and
///    re-projected onto a virtual pinhole of focal length `virtual_focal_px`
///    centred on the image, so that `ransac_threshold_px` means the same on
///    every camera, and cv::findFundamentalMat(FM_RANSAC) keeps the points
///    within `ransac_threshold_px` of their epipolar line. OpenCV's RANSAC
///    is seeded with a constant, so the result is deterministic.
///    solve_two_view (vio/two_view.hpp) is not used here: its inlier set is
///    also a cheirality test (positive depth in both cameras), which on a
///    camera that does not translate holds for about half the points by
///    chance, so it would discard good tracks exactly when the camera rests;
///    its epipolar inlier set alone is not part of its API;
/// 5. the surviving points are ordered by track length, longest first (ties:
///    smaller id first); each one that lies within `min_distance_px` of a
///    point kept before it is dropped, and a disc of that radius around each
///    kept point is masked;
/// 6. up to `max_features` minus the kept count new Shi-Tomasi corners
///    (cv::goodFeaturesToTrack) are detected outside the mask, at least
///    `min_distance_px` apart, and given new ids.
///
/// **Ids.** A feature keeps its id while it is tracked; new features get
/// ids counting up from 0 in detection order (best corner first), never
/// reused. frame() lists the features by increasing id.
///
/// **Determinism.** Every step is a fixed function of the images and the
/// options (OpenCV's RANSAC has a fixed seed; ties are broken by id), so the
/// same images give the same tracks bit for bit.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/message_number.hpp>
#include <posefuse/io/feature_tracks.hpp>
#include <posefuse/vio/camera.hpp>

namespace posefuse::frontend {

/// Settings of KltTracker; defaults after VINS-Mono's (config/euroc).
struct KltTrackerOptions {
  /// Most features kept per frame (count); new corners top up to it. VINS-Mono: 150.
  int max_features = 150;
  /// Smallest distance between two features (px); VINS-Mono: 30.
  int min_distance_px = 30;
  /// RANSAC inlier distance to the epipolar line on the virtual pinhole (px); VINS-Mono: 1.
  double ransac_threshold_px = 1.0;
  /// RANSAC confidence, in (0, 1); VINS-Mono: 0.99.
  double ransac_confidence = 0.99;
  /// Focal length of the virtual pinhole the RANSAC works on (px); VINS-Mono: 460.
  double virtual_focal_px = 460.0;
  /// Side of the Lucas-Kanade window (px), odd, at least 3; VINS-Mono: 21.
  int window_px = 21;
  /// Coarsest pyramid level of Lucas-Kanade (0: the full image only; OpenCV's
  /// maxLevel); VINS-Mono: 3.
  int pyramid_levels = 3;
  /// Lucas-Kanade iterations per level at most (count); OpenCV's default 30.
  int klt_max_iterations = 30;
  /// Lucas-Kanade stops when an update is below this (px); OpenCV's default 0.01.
  double klt_epsilon_px = 0.01;
  /// Forward-backward check: largest distance between a point and its
  /// forward-then-backward track (px); VINS-Fusion: 0.5.
  double max_forward_backward_px = 0.5;
  /// Points whose rounded pixel is closer than this to the edge are dropped (px); VINS-Mono: 1.
  int border_px = 1;
  /// Shi-Tomasi quality: corners weaker than this fraction of the strongest
  /// corner's minimum eigenvalue are not detected (unitless, in (0, 1]); VINS-Mono: 0.01.
  double corner_quality = 0.01;
  /// Side of the Shi-Tomasi gradient covariance block (px), at least 3; OpenCV's default 3.
  int corner_block_px = 3;
  /// Equalise each image by CLAHE before tracking; VINS-Mono's EQUALIZE (on for EuRoC).
  bool clahe = false;
  /// CLAHE contrast limit (unitless, > 0); VINS-Mono: 3.
  double clahe_clip_limit = 3.0;
  /// CLAHE tiles per image side (count, >= 1); VINS-Mono: 8.
  int clahe_tiles = 8;

  /// Checks every setting.
  /// @throws posefuse::invalid_argument naming the first option out of range
  void validate() const {
    const auto fail = [](const char* name, const std::string& rule, double value) {
      throw invalid_argument(std::string("KltTrackerOptions: ") + name + " must be " + rule + ", got " +
                             detail::message_number(value));
    };
    if (max_features < 1 || max_features > 100000) fail("max_features", "from 1 to 100000", max_features);
    if (min_distance_px < 0 || min_distance_px > 10000) fail("min_distance_px", "from 0 to 10000", min_distance_px);
    if (!(ransac_threshold_px > 0 && ransac_threshold_px <= 1000))
      fail("ransac_threshold_px", "> 0 and at most 1000", ransac_threshold_px);
    if (!(ransac_confidence > 0 && ransac_confidence < 1)) fail("ransac_confidence", "in (0, 1)", ransac_confidence);
    if (!(virtual_focal_px >= 1 && virtual_focal_px <= kMaxFocalPx))
      fail("virtual_focal_px", "from 1 to " + detail::message_number(kMaxFocalPx), virtual_focal_px);
    if (window_px < 3 || window_px > 101 || window_px % 2 == 0)
      fail("window_px", "odd, from 3 to 101", window_px);
    if (pyramid_levels < 0 || pyramid_levels > 8) fail("pyramid_levels", "from 0 to 8", pyramid_levels);
    if (klt_max_iterations < 1 || klt_max_iterations > 1000)
      fail("klt_max_iterations", "from 1 to 1000", klt_max_iterations);
    if (!(klt_epsilon_px > 0 && klt_epsilon_px <= 1)) fail("klt_epsilon_px", "> 0 and at most 1", klt_epsilon_px);
    if (!(max_forward_backward_px > 0 && max_forward_backward_px <= 100))
      fail("max_forward_backward_px", "> 0 and at most 100", max_forward_backward_px);
    if (border_px < 0 || border_px > 1000) fail("border_px", "from 0 to 1000", border_px);
    if (!(corner_quality > 0 && corner_quality <= 1)) fail("corner_quality", "in (0, 1]", corner_quality);
    if (corner_block_px < 3 || corner_block_px > 31) fail("corner_block_px", "from 3 to 31", corner_block_px);
    if (!(clahe_clip_limit > 0 && clahe_clip_limit <= 1000))
      fail("clahe_clip_limit", "> 0 and at most 1000", clahe_clip_limit);
    if (clahe_tiles < 1 || clahe_tiles > 64) fail("clahe_tiles", "from 1 to 64", clahe_tiles);
  }
};

/// One tracked feature.
struct TrackedFeature {
  std::uint64_t id = 0;                          ///< stable while tracked
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  ///< pixel in the raw image (px)
  int track_length = 1;                          ///< frames it has been seen in, this one included
};

/// What one KltTracker::track call did (counts of features).
struct KltFrameStats {
  std::int64_t t_ns = 0;           ///< the frame's stamp (ns)
  int previous = 0;                ///< features of the previous frame
  int lost_klt = 0;                ///< not converged forward or backward, or failed the forward-backward check
  int lost_border = 0;             ///< tracked to within border_px of the edge
  int rejected_ransac = 0;         ///< off the fundamental matrix's epipolar lines
  int dropped_min_distance = 0;    ///< within min_distance_px of a longer track
  int tracked = 0;                 ///< kept from the previous frame
  int detected = 0;                ///< new corners
  int features = 0;                ///< tracked + detected
  double ms_klt = 0;               ///< pyramid, forward and backward Lucas-Kanade, border (ms)
  double ms_ransac = 0;            ///< undistortion and RANSAC (ms)
  double ms_detect = 0;            ///< mask and corner detection (ms)
  double ms_total = 0;             ///< the whole call, CLAHE included (ms)
};

namespace detail::klt {

using Clock = std::chrono::steady_clock;

[[nodiscard]] inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

[[nodiscard]] inline cv::Point2f to_cv(const Eigen::Vector2d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y())};
}

}  // namespace detail::klt

/// The pyramid cv::calcOpticalFlowPyrLK reads for one image.
/// @param[in] image 8-bit single-channel image
/// @param[in] o     window_px and pyramid_levels are used
/// @return the pyramid (with derivatives)
[[nodiscard]] inline std::vector<cv::Mat> klt_pyramid(const cv::Mat& image, const KltTrackerOptions& o) {
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(image, pyramid, cv::Size(o.window_px, o.window_px), o.pyramid_levels, true);
  return pyramid;
}

/// Tracks points from one image into the next by pyramidal Lucas-Kanade
/// with the forward-backward check (file comment, step 2).
/// @param[in]  previous pyramid of the earlier image (klt_pyramid)
/// @param[in]  current  pyramid of the later image (klt_pyramid)
/// @param[in]  points   pixels in the earlier image
/// @param[out] tracked  their pixels in the later image (one per point)
/// @param[in]  o        the Lucas-Kanade settings and max_forward_backward_px
/// @return one flag per point: 1 when it is tracked and passes the check
[[nodiscard]] inline std::vector<unsigned char> klt_track(const std::vector<cv::Mat>& previous,
                                                          const std::vector<cv::Mat>& current,
                                                          const std::vector<cv::Point2f>& points,
                                                          std::vector<cv::Point2f>& tracked,
                                                          const KltTrackerOptions& o) {
  std::vector<unsigned char> ok(points.size(), 0);
  tracked.assign(points.begin(), points.end());
  if (points.empty()) return ok;
  const cv::Size window(o.window_px, o.window_px);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, o.klt_max_iterations,
                              o.klt_epsilon_px);
  std::vector<unsigned char> forward, backward;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(previous, current, points, tracked, forward, err, window, o.pyramid_levels, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> back(points.begin(), points.end());
  cv::calcOpticalFlowPyrLK(current, previous, tracked, back, backward, err, window, o.pyramid_levels, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  const double max2 = o.max_forward_backward_px * o.max_forward_backward_px;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double dx = double(back[i].x) - double(points[i].x), dy = double(back[i].y) - double(points[i].y);
    ok[i] = forward[i] != 0 && backward[i] != 0 && dx * dx + dy * dy <= max2 ? 1 : 0;
  }
  return ok;
}

/// RANSAC on the fundamental matrix of undistorted points (file comment,
/// step 4).
/// @param[in] camera   the camera that took both images
/// @param[in] previous pixels in the earlier image
/// @param[in] current  the same points' pixels in the later image
/// @param[in] o        ransac_threshold_px, ransac_confidence, virtual_focal_px
/// @return one flag per point: 1 for an inlier; all 1 for fewer than 8
///         points or when OpenCV finds no fundamental matrix; 0 for a point
///         the camera model cannot undistort
[[nodiscard]] inline std::vector<unsigned char> fundamental_inliers(const PinholeRadtan& camera,
                                                                    const std::vector<cv::Point2f>& previous,
                                                                    const std::vector<cv::Point2f>& current,
                                                                    const KltTrackerOptions& o) {
  if (previous.size() != current.size())
    throw invalid_argument("fundamental_inliers: " + std::to_string(previous.size()) + " points in one image, " +
                           std::to_string(current.size()) + " in the other");
  std::vector<unsigned char> inlier(previous.size(), 1);
  if (previous.size() < 8) return inlier;
  const Eigen::Vector2d centre(camera.width / 2.0, camera.height / 2.0);
  std::vector<cv::Point2f> a, b;
  std::vector<std::size_t> index;
  a.reserve(previous.size());
  b.reserve(previous.size());
  index.reserve(previous.size());
  for (std::size_t i = 0; i < previous.size(); ++i) {
    const Eigen::Vector2d p = camera.undistort({previous[i].x, previous[i].y});
    const Eigen::Vector2d c = camera.undistort({current[i].x, current[i].y});
    if (!p.allFinite() || !c.allFinite()) {
      inlier[i] = 0;
      continue;
    }
    a.push_back(detail::klt::to_cv(o.virtual_focal_px * p + centre));
    b.push_back(detail::klt::to_cv(o.virtual_focal_px * c + centre));
    index.push_back(i);
  }
  if (a.size() < 8) return inlier;
  std::vector<unsigned char> status;
  const cv::Mat F = cv::findFundamentalMat(a, b, cv::FM_RANSAC, o.ransac_threshold_px, o.ransac_confidence, status);
  if (F.empty() || status.size() != a.size()) return inlier;
  for (std::size_t k = 0; k < index.size(); ++k) inlier[index[k]] = status[k] != 0 ? 1 : 0;
  return inlier;
}

/// The detection mask of file comment step 5: orders `features` longest
/// track first (ties: smaller id first), drops each one within
/// `min_distance_px` of one kept before it, and returns 255 where new
/// corners may go and 0 on a disc of that radius around each kept feature.
/// @param[in]     size            the image size
/// @param[in,out] features        the tracked features; on return the kept ones, in that order
/// @param[in]     min_distance_px the disc's radius (px)
/// @return the mask (CV_8UC1)
[[nodiscard]] inline cv::Mat min_distance_mask(cv::Size size, std::vector<TrackedFeature>& features,
                                               int min_distance_px) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  std::stable_sort(features.begin(), features.end(), [](const TrackedFeature& x, const TrackedFeature& y) {
    return x.track_length != y.track_length ? x.track_length > y.track_length : x.id < y.id;
  });
  std::vector<TrackedFeature> kept;
  kept.reserve(features.size());
  for (const TrackedFeature& f : features) {
    const cv::Point p(cvRound(f.uv.x()), cvRound(f.uv.y()));
    if (p.x < 0 || p.y < 0 || p.x >= size.width || p.y >= size.height) continue;
    if (mask.at<unsigned char>(p) != 255) continue;
    kept.push_back(f);
    if (min_distance_px > 0) cv::circle(mask, p, min_distance_px, cv::Scalar(0), cv::FILLED);
  }
  features = std::move(kept);
  return mask;
}

/// New Shi-Tomasi corners outside a mask (file comment, step 6).
/// @param[in] image the (equalised) image, 8-bit single-channel
/// @param[in] mask  255 where corners may go (min_distance_mask), or empty for anywhere
/// @param[in] count most corners wanted (count); none when <= 0
/// @param[in] o     corner_quality, corner_block_px and min_distance_px
/// @return the corners, strongest first
[[nodiscard]] inline std::vector<cv::Point2f> detect_corners(const cv::Mat& image, const cv::Mat& mask, int count,
                                                             const KltTrackerOptions& o) {
  std::vector<cv::Point2f> corners;
  if (count <= 0) return corners;
  cv::goodFeaturesToTrack(image, corners, count, o.corner_quality, double(o.min_distance_px), mask,
                          o.corner_block_px);
  return corners;
}

/// The tracker of the file comment: feed it the images of one camera in
/// time order.
class KltTracker {
 public:
  /// @param[in] camera  the camera (its resolution is the images' size)
  /// @param[in] options the settings (validated here)
  /// @throws posefuse::invalid_argument for options out of range or a camera that fails validate()
  explicit KltTracker(const PinholeRadtan& camera, const KltTrackerOptions& options = {})
      : camera_(camera), options_(options) {
    options_.validate();
    camera_.validate();
    if (options_.clahe)
      clahe_ = cv::createCLAHE(options_.clahe_clip_limit, cv::Size(options_.clahe_tiles, options_.clahe_tiles));
  }

  /// Tracks the features into a new image and tops them up.
  /// @param[in] t_ns  the image's stamp (ns), later than the previous one's
  /// @param[in] image 8-bit single-channel image of the camera's resolution
  /// @return what the call did
  /// @throws posefuse::invalid_argument for an image of another type or size,
  ///         or a stamp not later than the previous one (the tracker is unchanged)
  const KltFrameStats& track(std::int64_t t_ns, const cv::Mat& image) {
    using detail::klt::Clock;
    using detail::klt::ms_since;
    if (image.type() != CV_8UC1)
      throw invalid_argument("KltTracker::track: the image must be 8-bit single-channel (CV_8UC1)");
    if (image.cols != camera_.width || image.rows != camera_.height)
      throw invalid_argument("KltTracker::track: the image is " + std::to_string(image.cols) + "x" +
                             std::to_string(image.rows) + " px, the camera's resolution " +
                             std::to_string(camera_.width) + "x" + std::to_string(camera_.height) + " px");
    if (frames_ > 0 && !(t_ns > stats_.t_ns))
      throw invalid_argument("KltTracker::track: stamp " + std::to_string(t_ns) + " does not follow " +
                             std::to_string(stats_.t_ns));
    const auto t_start = Clock::now();
    KltFrameStats s;
    s.t_ns = t_ns;
    s.previous = int(features_.size());
    cv::Mat img;
    if (clahe_)
      clahe_->apply(image, img);
    else
      img = image;

    // 2-3: Lucas-Kanade, forward-backward, border.
    auto t0 = Clock::now();
    std::vector<cv::Mat> pyramid = klt_pyramid(img, options_);
    std::vector<cv::Point2f> before, after;
    if (!features_.empty()) {
      before.reserve(features_.size());
      for (const TrackedFeature& f : features_) before.push_back(detail::klt::to_cv(f.uv));
      const std::vector<unsigned char> ok = klt_track(pyramid_, pyramid, before, after, options_);
      std::size_t n = 0;
      const int b = options_.border_px;
      for (std::size_t i = 0; i < features_.size(); ++i) {
        if (ok[i] == 0) {
          ++s.lost_klt;
          continue;
        }
        const int u = cvRound(after[i].x), v = cvRound(after[i].y);
        if (!(u >= b && v >= b && u < camera_.width - b && v < camera_.height - b)) {
          ++s.lost_border;
          continue;
        }
        features_[n] = features_[i];
        features_[n].uv = Eigen::Vector2d(after[i].x, after[i].y);
        ++features_[n].track_length;
        before[n] = before[i];
        after[n] = after[i];
        ++n;
      }
      features_.resize(n);
      before.resize(n);
      after.resize(n);
    }
    s.ms_klt = ms_since(t0);

    // 4: RANSAC on the fundamental matrix.
    t0 = Clock::now();
    if (!features_.empty()) {
      const std::vector<unsigned char> in = fundamental_inliers(camera_, before, after, options_);
      std::size_t n = 0;
      for (std::size_t i = 0; i < features_.size(); ++i)
        if (in[i] != 0) features_[n++] = features_[i];
      s.rejected_ransac = int(features_.size() - n);
      features_.resize(n);
    }
    s.ms_ransac = ms_since(t0);

    // 5-6: minimum-distance mask, new corners.
    t0 = Clock::now();
    const std::size_t before_mask = features_.size();
    const cv::Mat mask = min_distance_mask(img.size(), features_, options_.min_distance_px);
    s.dropped_min_distance = int(before_mask - features_.size());
    s.tracked = int(features_.size());
    const std::vector<cv::Point2f> corners =
        detect_corners(img, mask, options_.max_features - int(features_.size()), options_);
    for (const cv::Point2f& c : corners) features_.push_back({next_id_++, Eigen::Vector2d(c.x, c.y), 1});
    s.detected = int(corners.size());
    s.features = int(features_.size());
    s.ms_detect = ms_since(t0);

    pyramid_ = std::move(pyramid);
    ++frames_;
    s.ms_total = ms_since(t_start);
    stats_ = s;
    return stats_;
  }

  /// The features after the last track() call, by increasing id.
  [[nodiscard]] std::vector<TrackedFeature> features() const {
    std::vector<TrackedFeature> out = features_;
    std::sort(out.begin(), out.end(), [](const TrackedFeature& x, const TrackedFeature& y) { return x.id < y.id; });
    return out;
  }

  /// The last frame as the estimator's input (io/feature_tracks.hpp), by increasing id.
  [[nodiscard]] TrackFrame frame() const {
    TrackFrame f;
    f.t_ns = stats_.t_ns;
    for (const TrackedFeature& x : features()) f.features.push_back({x.id, x.uv});
    return f;
  }

  /// What the last track() call did.
  [[nodiscard]] const KltFrameStats& stats() const noexcept { return stats_; }
  /// Frames tracked so far.
  [[nodiscard]] std::size_t frames() const noexcept { return frames_; }
  /// The id the next new feature will get.
  [[nodiscard]] std::uint64_t next_id() const noexcept { return next_id_; }
  /// The settings.
  [[nodiscard]] const KltTrackerOptions& options() const noexcept { return options_; }
  /// The camera.
  [[nodiscard]] const PinholeRadtan& camera() const noexcept { return camera_; }

 private:
  PinholeRadtan camera_;
  KltTrackerOptions options_;
  cv::Ptr<cv::CLAHE> clahe_;
  std::vector<cv::Mat> pyramid_;
  std::vector<TrackedFeature> features_;
  KltFrameStats stats_;
  std::uint64_t next_id_ = 0;
  std::size_t frames_ = 0;
};

}  // namespace posefuse::frontend

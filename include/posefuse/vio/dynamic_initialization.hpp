#pragma once
/// @file
/// Initial states of a visual-inertial estimator from a start in motion
/// (VINS-Mono, Qin, Li, Shen, IEEE T-RO 2018, §V): a few frames with
/// parallax between them, vision-only structure from motion on them
/// (vio/sfm.hpp), then the visual-inertial alignment (inertial/alignment.hpp:
/// gyroscope bias from the rotations, velocities, gravity and scale from the
/// linear system, gravity refined on its sphere).
///
/// **Frames.** DynamicInitBuffer keeps the frames the start is tried on: the
/// newest frame always, and an older one only when it has at least
/// `keyframe_parallax_px` mean parallax against the one kept before it (or
/// shares fewer than `min_tracked` features with it) and comes at least
/// `min_interval_s` after it, at most `frames` of them: keyframes, as in the
/// window, spaced so that the frames span long enough for the accelerometer
/// to give the scale (rotation alone passes the parallax test).
///
/// **Checks** — every one gives a sentence in `reason`, and the caller tries
/// again on later frames: too few frames or too short a span (`min_span_s`);
/// SfM failures (too few tracks, too little parallax, PnP, reprojection
/// error above SfmOptions::max_rms_reprojection_px); no IMU over an interval;
/// the alignment's failures (too little excitation, a rank-deficient system,
/// a scale ≤ 0, |g| more than `max_gravity_norm_error` from G); a gyroscope
/// bias above `max_gyro_bias_radps`; a speed above `max_speed_mps`.
///
/// The world frame of the result has z up (gravity along −z), the first
/// frame's body at the origin with zero yaw. The accelerometer bias is zero
/// (not separable from tilt over a short window; the window estimates it).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/inertial/alignment.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/inertial/preintegrate.hpp>
#include <posefuse/vio/sfm.hpp>

namespace posefuse {

/// Options of the start in motion (see the file comment).
struct DynamicInitOptions {
  int frames = 10;                        ///< frames of the initial window, 4 or more
  double keyframe_parallax_px = 10.0;     ///< mean parallax that keeps an older frame
  int min_tracked = 20;                   ///< fewer shared features also keeps it
  double min_interval_s = 0.15;           ///< and only when at least this long after the one before (s)
  double min_span_s = 1.2;                ///< the frames must span at least this long (s)
  int solve_iterations = 30;              ///< LM trials of the first window solve after the start
  double max_gyro_bias_radps = 0.1;       ///< a larger estimated gyroscope bias fails the start
  double max_speed_mps = 10.0;            ///< a faster estimated body fails the start
  SfmOptions sfm;                         ///< vision-only SfM (its focal_px is set from the camera)
  VisualInertialAlignmentOptions alignment;  ///< gravity norm, excitation and |g| checks
};

/// One frame of the start: its stamp and normalised observations.
struct DynamicInitFrame {
  std::int64_t t_ns = 0;                 ///< image stamp (ns)
  std::vector<SfmObservation> features;  ///< id and normalised coordinates
};

/// The frames a start in motion is tried on (see the file comment).
class DynamicInitBuffer {
 public:
  /// @param[in] o frames kept, the keyframe rule's thresholds
  /// @param[in] focal_px focal length that converts parallax to pixels
  explicit DynamicInitBuffer(const DynamicInitOptions& o = {}, double focal_px = 460.0)
      : max_frames_(o.frames), parallax_px_(o.keyframe_parallax_px), min_tracked_(o.min_tracked),
        min_interval_ns_(std::int64_t(std::llround(o.min_interval_s * 1e9))), focal_px_(focal_px) {}

  /// Adds the newest frame (stamps must increase); the previous newest stays
  /// only when it has parallax against the one before it.
  void add(DynamicInitFrame f) {
    if (frames_.size() >= 2 && !has_parallax(frames_[frames_.size() - 2], frames_.back())) frames_.pop_back();
    frames_.push_back(std::move(f));
    if (int(frames_.size()) > max_frames_) frames_.erase(frames_.begin());
  }

  /// The frames kept, oldest first.
  [[nodiscard]] std::span<const DynamicInitFrame> frames() const noexcept { return frames_; }

  /// Forgets every frame.
  void clear() noexcept { frames_.clear(); }

 private:
  [[nodiscard]] bool has_parallax(const DynamicInitFrame& a, const DynamicInitFrame& b) const {
    if (b.t_ns - a.t_ns < min_interval_ns_) return false;
    double sum = 0;
    int shared = 0;
    for (const SfmObservation& x : b.features) {
      for (const SfmObservation& y : a.features) {
        if (y.id != x.id) continue;
        sum += (y.m - x.m).norm();
        ++shared;
        break;
      }
    }
    return shared < min_tracked_ || sum / shared * focal_px_ >= parallax_px_;
  }

  std::vector<DynamicInitFrame> frames_;
  int max_frames_;
  double parallax_px_;
  int min_tracked_;
  std::int64_t min_interval_ns_;
  double focal_px_;
};

/// Result of a start in motion.
struct DynamicInitResult {
  bool ok = false;                 ///< the states may be used
  std::string reason;              ///< why not, otherwise empty
  std::vector<std::int64_t> t_ns;  ///< the frames' stamps (when ok)
  std::vector<ImuState> states;    ///< one per frame, world frame of the file comment (when ok)
  double scale = 0;                ///< metric per SfM unit
  double gravity_norm_unrefined = 0;  ///< |g| before the refinement (m/s²)
  double sfm_rms_px = 0;           ///< SfM reprojection error (px at the focal length)
};

/// Tries a start in motion on `frames` (see the file comment).
/// @param[in] frames oldest first (DynamicInitBuffer::frames)
/// @param[in] imu time-ordered samples covering the frames
/// @param[in] T_b_c camera pose in the body frame
/// @param[in] noise, pre_options the pre-integrations' noise and options
/// @param[in] o checks and settings
template <class Lazy = void>
[[nodiscard]] DynamicInitResult initialize_from_motion(std::span<const DynamicInitFrame> frames,
                                                       std::span<const ImuSample> imu, const SE3d& T_b_c,
                                                       const ImuNoise& noise, const PreintegrationOptions& pre_options,
                                                       const DynamicInitOptions& o) {
  if (o.frames < 4) throw invalid_argument("initialize_from_motion: frames " + std::to_string(o.frames) + " < 4");
  DynamicInitResult out;
  const int N = int(frames.size());
  if (N < 4) {
    out.reason = "start in motion: " + std::to_string(N) + " frame(s) with parallax, 4 needed";
    return out;
  }
  const double span_s = seconds_between(frames.back().t_ns, frames.front().t_ns);
  if (span_s < o.min_span_s) {
    out.reason = "start in motion: the frames with parallax span " + std::to_string(span_s) + " s, " +
                 std::to_string(o.min_span_s) + " s needed";
    return out;
  }
  std::vector<std::vector<SfmObservation>> obs;
  obs.reserve(frames.size());
  for (const DynamicInitFrame& f : frames) obs.push_back(f.features);
  const SfmResult sfm = structure_from_motion(std::span<const std::vector<SfmObservation>>(obs), o.sfm);
  if (sfm.status != SfmStatus::kOk) {
    out.reason = "start in motion: " + sfm.reason;
    return out;
  }
  out.sfm_rms_px = sfm.rms_reprojection_px;
  std::vector<Preintegration> pre;
  pre.reserve(frames.size() - 1);
  for (int k = 0; k + 1 < N; ++k) {
    pre.emplace_back(noise, ImuBias{}, pre_options);
    const ImuStatus st = preintegrate(imu, frames[std::size_t(k)].t_ns, frames[std::size_t(k) + 1].t_ns, pre.back());
    if (st != ImuStatus::kApplied) {
      out.reason = std::string("start in motion: IMU between frames: ") + to_string(st);
      return out;
    }
  }
  const VisualInertialAlignmentResult a =
      align_visual_inertial(std::span<const SE3d>(sfm.T_c0_c), T_b_c, std::span<Preintegration>(pre), o.alignment);
  out.scale = a.scale;
  out.gravity_norm_unrefined = a.gravity_norm_unrefined;
  if (a.status != VisualInertialAlignmentStatus::kOk) {
    out.reason = std::string("start in motion: alignment: ") + to_string(a.status);
    if (a.status == VisualInertialAlignmentStatus::kGravityNorm)
      out.reason += " (|g| = " + std::to_string(a.gravity_norm_unrefined) + " m/s^2)";
    if (a.status == VisualInertialAlignmentStatus::kInsufficientExcitation)
      out.reason += " (acceleration spread " + std::to_string(a.accel_std) + " m/s^2)";
    return out;
  }
  if (!(a.gyro_bias.norm() <= o.max_gyro_bias_radps)) {
    out.reason = "start in motion: gyroscope bias " + std::to_string(a.gyro_bias.norm()) + " rad/s above " +
                 std::to_string(o.max_gyro_bias_radps);
    return out;
  }
  for (int k = 0; k < N; ++k) {
    ImuState x;
    x.p = a.T_w_b[std::size_t(k)].translation();
    x.R = a.T_w_b[std::size_t(k)].so3();
    x.v = a.velocity_w[std::size_t(k)];
    x.bias.gyro = a.gyro_bias;
    if (!(x.v.norm() <= o.max_speed_mps) || !x.p.allFinite()) {
      out.reason = "start in motion: speed " + std::to_string(x.v.norm()) + " m/s above " +
                   std::to_string(o.max_speed_mps);
      out.states.clear();
      return out;
    }
    out.states.push_back(x);
    out.t_ns.push_back(frames[std::size_t(k)].t_ns);
  }
  out.ok = true;
  return out;
}

}  // namespace posefuse

#pragma once
/// @file
/// The sliding-window visual-inertial estimator: IMU samples and feature
/// tracks in, one state and status per image out.
///
/// Per image (stamp t): the IMU samples since the previous frame are
/// pre-integrated (inertial/preintegrate.hpp) and the new frame's state is
/// predicted by the IMU factor; its observations (undistorted to normalised
/// coordinates by the camera) join their features; features with two or more
/// observations are triangulated; the window is solved
/// (vio/window_problem.hpp); outliers are removed; and the window slides
/// (vio/sliding_window.hpp) once it holds more than `window_size` keyframes.
///
/// **Start.** Either a static start (vio/static_initialization.hpp; the
/// first frame after at least its duration of IMU samples at rest) or an
/// explicit initial state. Either way the first frame gets a prior with the
/// stated standard deviations (position and yaw fix the gauge; roll and
/// pitch in the world frame).
///
/// **Rest.** A frame whose features have not moved since the last keyframe
/// (is_stationary, vio/sliding_window.hpp) gets a zero-velocity factor
/// (vio/window_problem.hpp), as does the first frame of a static start.
///
/// **Status** of each frame: kInitializing (no state yet: nothing written),
/// kTracking, kNotEnoughFeatures (fewer than `min_features` triangulated
/// features seen in the frame: the state rests mostly on the IMU),
/// kDegenerate (the solve produced a non-finite value: the IMU prediction is
/// kept), kReset (the window restarted from the last good state after a
/// degenerate solve or a velocity above `max_speed_mps`). A state returned
/// with a status other than kInitializing is always finite.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/vio/camera.hpp>
#include <posefuse/vio/feature_tracks.hpp>
#include <posefuse/vio/keyframe_record.hpp>
#include <posefuse/vio/sliding_window.hpp>
#include <posefuse/vio/static_initialization.hpp>

namespace posefuse {

/// Status of one frame (see the file comment).
enum class VioStatus { kInitializing, kTracking, kNotEnoughFeatures, kDegenerate, kReset };

/// Name of a VioStatus.
[[nodiscard]] constexpr const char* to_string(VioStatus s) noexcept {
  switch (s) {
    case VioStatus::kInitializing: return "initializing";
    case VioStatus::kTracking: return "tracking";
    case VioStatus::kNotEnoughFeatures: return "not enough features";
    case VioStatus::kDegenerate: return "degenerate";
    case VioStatus::kReset: return "reset";
  }
  return "unknown";
}

/// Standard deviations of the first frame's prior.
struct VioInitialSigma {
  double position_m = 1e-3;        ///< each axis
  double roll_pitch_rad = 0.02;    ///< about the world x and y axes
  double yaw_rad = 1e-3;           ///< about the world z axis
  double velocity_mps = 0.05;      ///< each axis
  double accel_bias_mps2 = 0.2;    ///< each axis
  double gyro_bias_radps = 0.01;   ///< each axis
};

/// Options of the estimator.
struct VioEstimatorOptions {
  SlidingWindowOptions window;          ///< window, keyframes, outliers, solve
  ImuNoise noise;                       ///< IMU noise densities
  PreintegrationOptions preintegration; ///< gap limit, re-propagation thresholds
  StaticInitOptions static_init;        ///< static start
  VioInitialSigma initial_sigma;        ///< prior on the first frame
  int min_features = 10;                ///< below this a frame is kNotEnoughFeatures
  double max_speed_mps = 50.0;          ///< above this the window is reset
};

/// What the estimator returns for one image.
struct VioFrameResult {
  std::int64_t t_ns = 0;                     ///< image stamp
  VioStatus status = VioStatus::kInitializing;  ///< see the file comment
  ImuState state;                            ///< the newest frame's estimate (finite unless initializing)
  int features = 0;                          ///< triangulated features seen in the frame
  int iterations = 0;                        ///< LM trials of its solve
  std::string message;                       ///< why initializing, when it is
  /// Set when a keyframe left the window with this frame (its pose and
  /// triangulated features are then final for the odometry).
  std::optional<KeyframeRecord> keyframe;
};

/// The estimator (see the file comment).
class VioEstimator {
 public:
  /// @param[in] camera intrinsics, distortion and extrinsic (T_BS)
  /// @param[in] o the estimator's options
  VioEstimator(const PinholeRadtan& camera, const VioEstimatorOptions& o = {}) : cam_(camera), o_(o) {
    w_.T_bc = RigidPose{camera.T_BS.translation(), SO3d(Eigen::Quaterniond(camera.T_BS.rotation()).normalized())};
    w_.gravity_w = Eigen::Vector3d(0, 0, -o.static_init.gravity_mps2);
    w_.sqrt_info = Eigen::Vector2d(camera.fu, camera.fv) / o.window.pixel_sigma_px;
    o_.window.focal_px = 0.5 * (camera.fu + camera.fv);
  }

  /// Starts from an explicit state at the first frame (instead of the static start).
  void set_initial_state(const ImuState& x) { initial_ = x; }

  /// Makes the camera-IMU extrinsic a variable of the solve (from the next window on).
  void set_estimate_extrinsic(bool on) { w_.estimate_extrinsic = on; }

  /// Adds one IMU sample (time-ordered; frames need the samples up to their stamp).
  void add_imu(const ImuSample& s) { imu_.push_back(s); }

  /// Processes one image (see the file comment).
  VioFrameResult add_frame(const TrackFrame& frame) {
    VioFrameResult res;
    res.t_ns = frame.t_ns;
    if (w_.frames.empty()) {
      ImuState x0;
      if (initial_) {
        x0 = *initial_;
      } else {
        const StaticInitResult si = static_initialize(imu_, frame.t_ns, o_.static_init);
        if (!si.state) {
          res.message = si.reason;
          return res;
        }
        x0 = *si.state;
      }
      start_window(frame.t_ns, x0);
      w_.frames.back().stationary = !initial_;  // the static start found the body at rest
      add_observations(frame);
      last_good_ = w_.frames.back().x;
      res.status = VioStatus::kNotEnoughFeatures;
      res.state = last_good_;
      trim_imu();
      return res;
    }
    VioFrame f;
    f.t_ns = frame.t_ns;
    f.id = next_id_++;
    f.pre = Preintegration(o_.noise, w_.frames.back().x.bias, o_.preintegration);
    const ImuStatus st = preintegrate(imu_, w_.frames.back().t_ns, frame.t_ns, f.pre);
    if (st != ImuStatus::kApplied) {  // no IMU over the interval: restart from the last good state
      reset(frame.t_ns, last_good_);
      add_observations(frame);
      res.status = VioStatus::kReset;
      res.state = w_.frames.back().x;
      res.message = std::string("IMU: ") + to_string(st);
      return res;
    }
    f.imu.emplace(f.pre, w_.gravity_w);
    f.x = f.imu->predict(w_.frames.back().x);
    const ImuState predicted = f.x;
    w_.frames.push_back(std::move(f));
    add_observations(frame);
    {
      // At rest against the last keyframe (the frame before the previous one once the window is full).
      const std::size_t n = w_.frames.size();
      const std::size_t ref = n >= 3 ? n - 3 : 0;
      w_.frames.back().stationary = is_stationary(w_, ref, n - 1, o_.window);
    }
    (void)triangulate_features(w_, o_.window);
    const VioWindow before = w_;
    const WindowSolveSummary s = problem_.solve(w_, o_.window.solve);
    res.iterations = s.iterations;
    const ImuState& xn = w_.frames.back().x;
    if (!finite(w_)) {
      w_ = before;
      w_.frames.back().x = predicted;
      res.status = VioStatus::kDegenerate;
    } else if (xn.v.norm() > o_.max_speed_mps) {
      reset(frame.t_ns, last_good_);
      add_observations(frame);
      res.status = VioStatus::kReset;
      res.state = w_.frames.back().x;
      return res;
    }
    (void)remove_outliers(w_, o_.window);
    res.features = features_in_newest();
    if (res.status != VioStatus::kDegenerate)
      res.status = res.features >= o_.min_features ? VioStatus::kTracking : VioStatus::kNotEnoughFeatures;
    res.state = w_.frames.back().x;
    if (res.status != VioStatus::kDegenerate) last_good_ = res.state;
    if (int(w_.frames.size()) > o_.window.window_size) {
      if (is_keyframe(w_, w_.frames.size() - 2, o_.window)) {
        res.keyframe = record_oldest();
        marginalize_oldest(w_, o_.window, problem_);
      } else {
        drop_second_newest(w_);
      }
    }
    trim_imu();
    return res;
  }

  /// The window (for inspection and tests).
  [[nodiscard]] const VioWindow& window() const noexcept { return w_; }

 private:
  void start_window(std::int64_t t_ns, const ImuState& x0) {
    w_.frames.clear();
    w_.landmarks.clear();
    w_.prior.reset();
    w_.T_bc_fej.reset();
    VioFrame f;
    f.t_ns = t_ns;
    f.id = next_id_++;
    f.x = x0;
    f.fej = x0;
    f.pre = Preintegration(o_.noise, x0.bias, o_.preintegration);
    // Prior on the first frame: rotation sigmas about the world axes (δθ_w = R δφ).
    const VioInitialSigma& s = o_.initial_sigma;
    Eigen::Matrix<double, 15, 15> J = Eigen::Matrix<double, 15, 15>::Zero();
    J.block<3, 3>(0, 0) = Eigen::Matrix3d::Identity() / s.position_m;
    J.block<3, 3>(3, 3) =
        Eigen::Vector3d(1.0 / s.roll_pitch_rad, 1.0 / s.roll_pitch_rad, 1.0 / s.yaw_rad).asDiagonal() *
        x0.R.matrix();
    J.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() / s.velocity_mps;
    J.block<3, 3>(9, 9) = Eigen::Matrix3d::Identity() / s.accel_bias_mps2;
    J.block<3, 3>(12, 12) = Eigen::Matrix3d::Identity() / s.gyro_bias_radps;
    VioPrior p;
    p.linear.J = J;
    p.linear.r0 = Eigen::VectorXd::Zero(15);
    for (int i = 0; i < 15; ++i) p.linear.kept.push_back(i);
    VioPriorBlock b;
    b.frame_id = f.id;
    b.frame_ref = x0;
    p.blocks.push_back(b);
    w_.prior = std::move(p);
    w_.frames.push_back(std::move(f));
  }

  void reset(std::int64_t t_ns, const ImuState& x) {
    ImuState x0 = x;
    start_window(t_ns, x0);
  }

  void add_observations(const TrackFrame& frame) {
    const std::uint64_t fid = w_.frames.back().id;
    for (const FeatureObservation& ob : frame.features) {
      const Eigen::Vector2d m = normalised(cam_, ob);
      if (!m.allFinite()) continue;
      w_.landmarks[ob.id].obs.push_back(VioObservation{fid, m});
    }
  }

  // The oldest keyframe with its features, before it is marginalised.
  [[nodiscard]] KeyframeRecord record_oldest() const {
    const VioFrame& f = w_.frames.front();
    KeyframeRecord r;
    r.t_ns = f.t_ns;
    r.T_w_b = SE3d(f.x.p, f.x.R);
    r.T_b_c = SE3d(w_.T_bc.p, w_.T_bc.R);
    for (const auto& [id, l] : w_.landmarks) {
      for (const VioObservation& ob : l.obs) {
        if (ob.frame_id != f.id) continue;
        KeyframeFeature kf;
        kf.id = id;
        kf.m = ob.m;
        if (l.initialised && l.obs.size() >= 2) {
          kf.p_w = landmark_world_point(w_, l);
          kf.has_point = kf.p_w.allFinite();
        }
        r.features.push_back(kf);
        break;
      }
    }
    return r;
  }

  [[nodiscard]] int features_in_newest() const {
    const std::uint64_t fid = w_.frames.back().id;
    int n = 0;
    for (const auto& [id, l] : w_.landmarks)
      if (l.initialised && l.obs.back().frame_id == fid) ++n;
    return n;
  }

  [[nodiscard]] static bool finite(const VioWindow& w) {
    for (const VioFrame& f : w.frames)
      if (!f.x.p.allFinite() || !f.x.v.allFinite() || !f.x.R.quaternion().coeffs().allFinite() ||
          !f.x.bias.vector().allFinite())
        return false;
    for (const auto& [id, l] : w.landmarks)
      if (!std::isfinite(l.inv_depth)) return false;
    return true;
  }

  // Keeps the samples from the last one at or before the oldest needed stamp.
  void trim_imu() {
    const std::int64_t keep_from = w_.frames.empty() ? 0 : w_.frames.back().t_ns;
    std::size_t k = 0;
    while (k + 1 < imu_.size() && imu_[k + 1].t_ns <= keep_from) ++k;
    if (k > 4096) imu_.erase(imu_.begin(), imu_.begin() + std::ptrdiff_t(k));
  }

  PinholeRadtan cam_;
  VioEstimatorOptions o_;
  VioWindow w_;
  WindowProblem problem_;
  std::vector<ImuSample> imu_;
  std::optional<ImuState> initial_;
  ImuState last_good_;
  std::uint64_t next_id_ = 1;
};

}  // namespace posefuse

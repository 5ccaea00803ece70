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
/// **Start** (`VioEstimatorOptions::init`). `kStatic`: the first frame
/// after at least `static_init.duration_s` of IMU samples at rest
/// (vio/static_initialization.hpp). `kDynamic`: VINS-Mono's start in motion
/// (vio/dynamic_initialization.hpp: frames with parallax, vision-only SfM,
/// visual-inertial alignment); the window then starts with those frames as
/// its keyframes. `kAuto` (default): static when the IMU is at rest before
/// the frame and the features have moved less than the keyframe parallax
/// over that time (a smooth flight can pass the IMU's rest test), otherwise
/// from motion. Every frame before a start is
/// kInitializing with the reasons of the attempts in its message.
/// `set_initial_state` replaces the next start by a given state. The
/// window's first frame gets a prior with the stated standard deviations
/// (position and yaw fix the gauge; roll and pitch in the world frame).
///
/// **Rest.** A frame whose features have not moved since the last keyframe
/// (is_stationary, vio/sliding_window.hpp) gets a zero-velocity factor
/// (vio/window_problem.hpp), as does the first frame of a static start.
///
/// **Failure and restart** (VioFailureOptions). After each solve the newest
/// state is checked: a speed above `max_speed_mps`, a bias above its bound,
/// a pose that moved farther from its IMU prediction than the jump bounds,
/// fewer than `min_features` tracked features for longer than `max_lost_s`
/// (not at rest), or no frame at all for that long fail the frame (kFailed, the reason in its
/// message): the window is emptied and the estimator starts again as at the
/// beginning. A start within `anchor_within_s` of the last good frame is
/// anchored to it: the last good state is carried through the IMU to the new
/// start's first frame, whose position and yaw (unobservable, so free) are
/// set to the carried ones; the output stays in one world frame, with the
/// IMU-only drift of the gap. Later starts begin a new frame (position 0,
/// yaw 0).
///
/// **Status** of each frame: kInitializing (no state yet: nothing written),
/// kTracking, kNotEnoughFeatures (fewer than `min_features` triangulated
/// features seen in the frame: the state rests mostly on the IMU),
/// kDegenerate (the solve produced a non-finite value: the IMU prediction is
/// kept), kReset (the window restarted from the last good state: no IMU over
/// the interval), kFailed (see above; no state). A state returned with
/// kTracking, kNotEnoughFeatures, kDegenerate or kReset is always finite.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/vio/camera.hpp>
#include <posefuse/vio/dynamic_initialization.hpp>
#include <posefuse/vio/feature_tracks.hpp>
#include <posefuse/vio/keyframe_record.hpp>
#include <posefuse/vio/sliding_window.hpp>
#include <posefuse/vio/static_initialization.hpp>

namespace posefuse {

/// Status of one frame (see the file comment).
enum class VioStatus { kInitializing, kTracking, kNotEnoughFeatures, kDegenerate, kReset, kFailed };

/// How the estimator starts (see the file comment).
enum class VioInit { kAuto, kStatic, kDynamic };

/// Name of a VioInit ("auto", "static", "dynamic").
[[nodiscard]] constexpr const char* to_string(VioInit i) noexcept {
  switch (i) {
    case VioInit::kAuto: return "auto";
    case VioInit::kStatic: return "static";
    case VioInit::kDynamic: return "dynamic";
  }
  return "unknown";
}

/// Name of a VioStatus.
[[nodiscard]] constexpr const char* to_string(VioStatus s) noexcept {
  switch (s) {
    case VioStatus::kInitializing: return "initializing";
    case VioStatus::kTracking: return "tracking";
    case VioStatus::kNotEnoughFeatures: return "not enough features";
    case VioStatus::kDegenerate: return "degenerate";
    case VioStatus::kReset: return "reset";
    case VioStatus::kFailed: return "failed";
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
  double velocity_in_motion_mps = 0.2;  ///< each axis, after a start in motion (the alignment's velocity)
};

/// When the estimator gives up and starts again (see the file comment).
struct VioFailureOptions {
  double max_lost_s = 1.0;             ///< longest stretch with fewer than min_features tracked (s)
  double max_accel_bias_mps2 = 2.5;    ///< |b_a| above this fails (VINS-Mono's bound)
  double max_gyro_bias_radps = 1.0;    ///< |b_g| above this fails (VINS-Mono's bound)
  double max_position_jump_m = 0.5;    ///< solved newest position vs its IMU prediction
  double max_rotation_jump_rad = 0.17; ///< solved newest attitude vs its IMU prediction (about 10°)
  double anchor_within_s = 5.0;        ///< a restart this soon after the last good frame is anchored to it
};

/// Options of the estimator.
struct VioEstimatorOptions {
  SlidingWindowOptions window;          ///< window, keyframes, outliers, solve
  ImuNoise noise;                       ///< IMU noise densities
  PreintegrationOptions preintegration; ///< gap limit, re-propagation thresholds
  StaticInitOptions static_init;        ///< static start
  VioInitialSigma initial_sigma;        ///< prior on the first frame
  DynamicInitOptions dynamic_init;      ///< start in motion
  VioInit init = VioInit::kAuto;        ///< how to start
  VioFailureOptions failure;            ///< failure detection
  int min_features = 10;                ///< below this a frame is kNotEnoughFeatures
  double max_speed_mps = 10.0;          ///< a faster newest state is a failure
};

/// What the estimator returns for one image.
struct VioFrameResult {
  std::int64_t t_ns = 0;                     ///< image stamp
  VioStatus status = VioStatus::kInitializing;  ///< see the file comment
  ImuState state;                            ///< the newest frame's estimate (finite unless initializing or failed)
  int features = 0;                          ///< triangulated features seen in the frame
  int iterations = 0;                        ///< LM trials of its solve
  std::string message;                       ///< why initializing or failed; how a start was made
  bool started = false;                      ///< a start (or restart) was made with this frame
  /// With `started`: the start was anchored to the last good state (same
  /// world frame as before). A start that is not anchored begins a new
  /// world frame: position 0 and yaw 0 at its first frame.
  bool anchored = false;
  /// Set when a keyframe left the window with this frame (its pose and
  /// triangulated features are then final for the odometry).
  std::optional<KeyframeRecord> keyframe;
};

/// The estimator (see the file comment).
class VioEstimator {
 public:
  /// @param[in] camera intrinsics, distortion and extrinsic (T_BS)
  /// @param[in] o the estimator's options
  /// @throws posefuse::invalid_argument when dynamic_init.frames < 4
  VioEstimator(const PinholeRadtan& camera, const VioEstimatorOptions& o = {}) : cam_(camera), o_(o) {
    w_.T_bc = RigidPose{camera.T_BS.translation(), SO3d(Eigen::Quaterniond(camera.T_BS.rotation()).normalized())};
    w_.gravity_w = Eigen::Vector3d(0, 0, -o.static_init.gravity_mps2);
    w_.sqrt_info = Eigen::Vector2d(camera.fu, camera.fv) / o.window.pixel_sigma_px;
    o_.window.focal_px = 0.5 * (camera.fu + camera.fv);  // the camera's, whatever o says (SlidingWindowOptions)
    if (o_.dynamic_init.frames < 4)
      throw invalid_argument("VioEstimator: dynamic_init.frames " + std::to_string(o_.dynamic_init.frames) + " < 4");
    o_.dynamic_init.frames = std::max(4, std::min(o_.dynamic_init.frames, o_.window.window_size + 1));
    o_.dynamic_init.sfm.focal_px = o_.window.focal_px;
    o_.dynamic_init.alignment.gravity_norm = o.static_init.gravity_mps2;
    buffer_ = DynamicInitBuffer(o_.dynamic_init, o_.window.focal_px);
  }

  /// Starts from an explicit state at the next start (instead of the static
  /// or dynamic one); later restarts use the configured start.
  void set_initial_state(const ImuState& x) { initial_ = x; }

  /// Makes the camera-IMU extrinsic a variable of the solve (from the next window on).
  void set_estimate_extrinsic(bool on) { w_.estimate_extrinsic = on; }

  /// Adds one IMU sample (time-ordered; frames need the samples up to their stamp).
  void add_imu(const ImuSample& s) { imu_.push_back(s); }

  /// Processes one image (see the file comment).
  VioFrameResult add_frame(const TrackFrame& frame) {
    if (w_.frames.empty()) return start(frame);
    VioFrameResult res;
    res.t_ns = frame.t_ns;
    // No frame (hence no feature) for longer than the loss bound.
    if (const double gap_s = seconds_between(frame.t_ns, w_.frames.back().t_ns); gap_s > o_.failure.max_lost_s)
      return fail(res, "no frame for " + format_number(gap_s) + " s");
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
    if (!finite(w_)) {
      w_ = before;
      w_.frames.back().x = predicted;
      res.status = VioStatus::kDegenerate;
    } else if (const std::string why = failure(predicted); !why.empty()) {
      return fail(res, why);
    }
    (void)remove_outliers(w_, o_.window);
    res.features = features_in_newest();
    if (res.status != VioStatus::kDegenerate)
      res.status = res.features >= o_.min_features ? VioStatus::kTracking : VioStatus::kNotEnoughFeatures;
    // Lost: too few tracked features for too long while not at rest.
    if (tracked_in_newest() >= o_.min_features || w_.frames.back().stationary) {
      lost_since_.reset();
    } else {
      if (!lost_since_) lost_since_ = frame.t_ns;
      const double lost_s = seconds_between(frame.t_ns, *lost_since_);
      if (lost_s > o_.failure.max_lost_s)
        return fail(res, "fewer than " + std::to_string(o_.min_features) + " tracked features for " +
                             format_number(lost_s) + " s");
    }
    res.state = w_.frames.back().x;
    if (res.status == VioStatus::kTracking) {
      last_good_ = res.state;
      last_good_t_ns_ = frame.t_ns;
    }
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

  /// Starts made so far (the first and every restart).
  [[nodiscard]] int starts() const noexcept { return starts_; }

 private:
  // A frame without a window: try the configured start.
  VioFrameResult start(const TrackFrame& frame) {
    VioFrameResult res;
    res.t_ns = frame.t_ns;
    anchored_ = false;
    if (initial_) {
      const ImuState x0 = *initial_;
      initial_.reset();
      begin(frame, x0, /*at_rest=*/false);
      res.message = "started from the given state";
      return started(res);
    }
    std::string why;
    DynamicInitFrame df;
    df.t_ns = frame.t_ns;
    for (const FeatureObservation& ob : frame.features) {
      const Eigen::Vector2d m = normalised(cam_, ob);
      if (m.allFinite()) df.features.push_back(SfmObservation{ob.id, m});
    }
    const double image_rest_s = image_rest(df);
    if (o_.init != VioInit::kDynamic) {
      const StaticInitResult si = static_initialize(imu_, frame.t_ns, o_.static_init);
      // In kAuto the images must show rest too (a smooth flight can pass the IMU's test).
      const bool images_agree = o_.init == VioInit::kStatic || image_rest_s >= 0.9 * o_.static_init.duration_s;
      if (si.state && !images_agree)
        why = "static start: the features moved during the last " + format_number(o_.static_init.duration_s) +
              " s";
      else if (si.state) {
        begin(frame, anchored(frame.t_ns, *si.state, frame.t_ns), /*at_rest=*/true);
        res.message = "started at rest";
        return started(res);
      }
      if (!si.state) why = "static start: " + si.reason;
    }
    if (o_.init != VioInit::kStatic) {
      buffer_.add(std::move(df));
      const DynamicInitResult d = initialize_from_motion(buffer_.frames(), imu_, SE3d(w_.T_bc.p, w_.T_bc.R),
                                                         o_.noise, o_.preintegration, o_.dynamic_init);
      if (d.ok) {
        begin_in_motion(d);
        res.message = "started in motion (" + std::to_string(d.states.size()) + " frames over " +
                      format_number(seconds_between(d.t_ns.back(), d.t_ns.front())) + " s, scale " +
                      std::to_string(d.scale) + ")";
        res.features = features_in_newest();
        return started(res);
      }
      why += (why.empty() ? "" : "; ") + d.reason;
    }
    res.message = why;
    trim_imu();
    return res;
  }

  // How long (s) the images have shown (near) rest up to `f`: the median
  // displacement of the features shared with the first frame of the rest
  // below the keyframe parallax (less than a keyframe's worth of motion),
  // with at least min_tracked of them; otherwise `f` begins a new rest and 0
  // is returned.
  double image_rest(const DynamicInitFrame& f) {
    std::vector<double> d;
    for (const SfmObservation& x : f.features)
      for (const SfmObservation& y : rest_ref_.features)
        if (y.id == x.id) {
          d.push_back((x.m - y.m).norm() * o_.window.focal_px);
          break;
        }
    if (int(d.size()) >= o_.window.min_tracked && !rest_ref_.features.empty()) {
      const auto mid = d.begin() + std::ptrdiff_t(d.size() / 2);
      std::nth_element(d.begin(), mid, d.end());
      if (*mid < o_.window.min_parallax_px) return seconds_between(f.t_ns, rest_ref_.t_ns);
    }
    rest_ref_ = f;
    return 0.0;
  }

  // The result of the frame a start was made with.
  VioFrameResult started(VioFrameResult& res) {
    ++starts_;
    buffer_.clear();
    rest_ref_ = {};
    res.started = true;
    res.anchored = anchored_;
    res.status = res.features >= o_.min_features ? VioStatus::kTracking : VioStatus::kNotEnoughFeatures;
    res.state = w_.frames.back().x;
    last_good_ = res.state;
    last_good_t_ns_ = res.t_ns;
    lost_since_.reset();
    trim_imu();
    return res;
  }

  // A window of one frame with state x0.
  void begin(const TrackFrame& frame, const ImuState& x0, bool at_rest) {
    start_window(frame.t_ns, x0, o_.initial_sigma.velocity_mps);
    w_.frames.back().stationary = at_rest;
    add_observations(frame);
  }

  // A window made of the start in motion's frames, solved once.
  void begin_in_motion(const DynamicInitResult& d) {
    const std::span<const DynamicInitFrame> fr = buffer_.frames();
    const std::size_t n = d.states.size();
    // The frames' states, moved so that the first one is where the anchor says.
    const ImuState x0 = anchored(d.t_ns.front(), d.states.front(), d.t_ns.back());
    const SE3d move = SE3d(x0.p, x0.R).compose(SE3d(d.states.front().p, d.states.front().R).inverse());
    start_window(d.t_ns.front(), x0, o_.initial_sigma.velocity_in_motion_mps);
    add_normalised(fr[0].features);
    for (std::size_t k = 1; k < n; ++k) {
      VioFrame f;
      f.t_ns = d.t_ns[k];
      f.id = next_id_++;
      f.pre = Preintegration(o_.noise, x0.bias, o_.preintegration);
      (void)preintegrate(imu_, d.t_ns[k - 1], d.t_ns[k], f.pre);  // applied: the start checked it
      f.imu.emplace(f.pre, w_.gravity_w);
      f.x = d.states[k];
      f.x.p = move.act(d.states[k].p);
      f.x.R = move.so3().compose(d.states[k].R);
      f.x.v = move.so3().act(d.states[k].v);
      w_.frames.push_back(std::move(f));
      add_normalised(fr[k].features);
    }
    (void)triangulate_features(w_, o_.window);
    const VioWindow before = w_;
    WindowSolveOptions so = o_.window.solve;
    so.max_iterations = o_.dynamic_init.solve_iterations;
    (void)problem_.solve(w_, so);
    if (!finite(w_)) w_ = before;
    (void)remove_outliers(w_, o_.window);
  }

  // `x` (a start's state at t_ns, in its own frame: position 0, yaw 0 at the
  // start's first frame) moved in position and yaw to the last good state
  // carried through the IMU, when that is recent enough (file comment).
  // `t_newest_ns` bounds the samples the carry may need.
  // Records in anchored_ whether it anchored `x`.
  [[nodiscard]] ImuState anchored(std::int64_t t_ns, const ImuState& x, std::int64_t t_newest_ns) {
    anchored_ = false;
    if (starts_ == 0 || !last_good_t_ns_ || t_ns <= *last_good_t_ns_ ||
        seconds_between(t_ns, *last_good_t_ns_) > o_.failure.anchor_within_s || t_newest_ns < t_ns)
      return x;
    Preintegration pre(o_.noise, last_good_.bias, o_.preintegration);
    if (preintegrate(imu_, *last_good_t_ns_, t_ns, pre) != ImuStatus::kApplied) return x;
    const ImuState carried = ImuFactor(pre, w_.gravity_w).predict(last_good_);
    const auto yaw_of = [](const SO3d& R) {
      const Eigen::Matrix3d M = R.matrix();
      return std::atan2(M(1, 0), M(0, 0));
    };
    const SO3d dyaw = SO3d::exp(Eigen::Vector3d(0, 0, yaw_of(carried.R) - yaw_of(x.R)));
    ImuState out = x;
    out.R = dyaw.compose(x.R);
    out.v = dyaw.act(x.v);
    out.p = carried.p;
    anchored_ = true;
    return out;
  }

  // Empties the window; the next frame starts again (file comment).
  VioFrameResult fail(VioFrameResult& res, const std::string& why) {
    res.status = VioStatus::kFailed;
    res.message = why;
    res.state = ImuState{};
    res.features = 0;
    w_.frames.clear();
    w_.landmarks.clear();
    w_.prior.reset();
    w_.T_bc_fej.reset();
    buffer_.clear();
    rest_ref_ = {};
    lost_since_.reset();
    trim_imu();
    return res;
  }

  // Why the newest state (after a finite solve) is a failure, or "".
  [[nodiscard]] std::string failure(const ImuState& predicted) const {
    const ImuState& x = w_.frames.back().x;
    const VioFailureOptions& f = o_.failure;
    if (x.v.norm() > o_.max_speed_mps)
      return "speed " + format_number(x.v.norm()) + " m/s above " + format_number(o_.max_speed_mps) + " m/s";
    if (x.bias.accel.norm() > f.max_accel_bias_mps2)
      return "accelerometer bias " + format_number(x.bias.accel.norm()) + " m/s^2 above " +
             format_number(f.max_accel_bias_mps2);
    if (x.bias.gyro.norm() > f.max_gyro_bias_radps)
      return "gyroscope bias " + format_number(x.bias.gyro.norm()) + " rad/s above " +
             format_number(f.max_gyro_bias_radps);
    const double dp = (x.p - predicted.p).norm();
    if (dp > f.max_position_jump_m)
      return "the position jumped " + format_number(dp) + " m from its IMU prediction (bound " +
             format_number(f.max_position_jump_m) + " m)";
    const double dr = predicted.R.inverse().compose(x.R).log().norm();
    if (dr > f.max_rotation_jump_rad)
      return "the attitude jumped " + format_number(dr * 180.0 / 3.14159265358979) +
             " deg from its IMU prediction (bound " + format_number(f.max_rotation_jump_rad * 180.0 / 3.14159265358979) +
             " deg)";
    return {};
  }

  // A number to three significant digits, for messages.
  [[nodiscard]] static std::string format_number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
  }

  void start_window(std::int64_t t_ns, const ImuState& x0, double velocity_sigma_mps) {
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
    J.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() / velocity_sigma_mps;
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

  void reset(std::int64_t t_ns, const ImuState& x) { start_window(t_ns, x, o_.initial_sigma.velocity_mps); }

  void add_observations(const TrackFrame& frame) {
    const std::uint64_t fid = w_.frames.back().id;
    for (const FeatureObservation& ob : frame.features) {
      const Eigen::Vector2d m = normalised(cam_, ob);
      if (!m.allFinite()) continue;
      w_.landmarks[ob.id].obs.push_back(VioObservation{fid, m});
    }
  }

  void add_normalised(std::span<const SfmObservation> obs) {
    const std::uint64_t fid = w_.frames.back().id;
    for (const SfmObservation& ob : obs) w_.landmarks[ob.id].obs.push_back(VioObservation{fid, ob.m});
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

  // Features seen in the newest frame and in an earlier frame of the window.
  [[nodiscard]] int tracked_in_newest() const {
    const std::uint64_t fid = w_.frames.back().id;
    int n = 0;
    for (const auto& [id, l] : w_.landmarks)
      if (l.obs.size() >= 2 && l.obs.back().frame_id == fid) ++n;
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

  // Keeps the samples from the last one at or before the newest frame's
  // stamp; everything while there is no window (a start being tried needs
  // the samples of its frames, of the rest test, and of the carry from the
  // last good frame).
  void trim_imu() {
    if (w_.frames.empty()) return;
    const std::int64_t keep_from = w_.frames.back().t_ns;
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
  DynamicInitBuffer buffer_;
  DynamicInitFrame rest_ref_;  // first frame of the images' current rest
  ImuState last_good_;
  std::optional<std::int64_t> last_good_t_ns_;
  std::optional<std::int64_t> lost_since_;
  int starts_ = 0;
  bool anchored_ = false;  // the last start was anchored (see anchored())
  std::uint64_t next_id_ = 1;
};

}  // namespace posefuse

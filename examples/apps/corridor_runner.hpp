#pragma once
/// @file
/// Runs seed 001's corridor comparison on a RobotLog (recorded or simulated):
/// SLAM alone, odometry alone, the seed's threshold fuser (eq 14-15) and the
/// gated fuser, processing the asynchronous streams in time order.
///
/// **Time.** All streams are merged by `t_ns` with the library's
/// for_each_in_time_order (core/stream_merge.hpp; ties: IMU, wheels, SLAM);
/// t = 0 is the first sample of any stream, and times are seconds since then
/// (seconds_between, which cannot overflow). A SLAM pose is held until the
/// next wheel sample, and odometry is interpolated to the SLAM pose's time
/// (core/interpolation.hpp: linear in position, shorter arc in angles), so no
/// two streams need shared timestamps. SLAM poses after the last wheel sample
/// use the last odometry.
///
/// **Chains.** Odometry: wheels.csv → eq 8 → eq 9 → dead reckoning (eq 10,
/// Euler as printed, by default) = (x, y, θ_enc). Attitude: imu.csv → eq 1-2
/// → complementary filter eq 3-4 as printed (GyroToTiltRate::kSeed;
/// robot.txt alpha) → tilt-compensated compass (eq 5-7 corrected)
/// = (roll, pitch, yaw). The log carries no magnetometer
/// calibration, so the runner fits hard and soft iron in the horizontal
/// plane (fit_horizontal_ellipse, sensors/magnetometer_calibration.hpp: an
/// ellipse through all readings; a ground robot turns about z only, which
/// leaves a 3-D ellipsoid fit undetermined; this uses the whole log, i.e. it
/// is an offline calibration, as the seed's sensor did it internally). The
/// compass yaw is aligned to the world (= odometry) frame by the circular
/// mean of angle_diff(compass yaw, encoder heading) over the first
/// `heading_align_s` in which both streams have data, so an IMU that starts
/// late, or a robot that turns at the start, is aligned correctly.
/// Seed odometry O_m = (x, y from the wheels; roll, pitch, yaw from the IMU).
/// An attitude older than `attitude_max_age_s` (default: 5 median IMU
/// periods) is not used: O_m's yaw is then the encoder heading plus the last
/// compass-minus-encoder offset, and roll = pitch = 0 (an IMU that stops,
/// starts late or has gaps); the time this happens is warned about.
///
/// **Methods** (each reports poses in the world = odometry frame):
/// * `slam_only` — SLAM poses as reported (tracking and reinit rows), placed
///   in the world once by the first valid pose (aligned to odometry there,
///   i.e. the known start). It cannot place a re-initialised map, so it keeps
///   that first placement: after a re-init its poses are in the wrong frame.
/// * `odometry_only` — O_m at every wheel sample (yaw from the compass).
/// * `seed_fuser` — at each valid SLAM pose, ThresholdFuser(O_m, O_v) with
///   robot.txt's threshold; O_v is the SLAM pose (eq 11-13 for its angles)
///   placed in the world. Its re-initialise signal is emulated as the seed
///   describes (SLAM "restarts from the odometry pose"): the next valid SLAM
///   pose is placed onto O_m at that time; a `reinit` row is placed the same
///   way. When SLAM is lost or older than `slam_stale_s`, O_r = O_m at the
///   wheel samples (eq 15-b).
/// * `gated_fuser` — GatedFuser: wheel odometry (x, y, θ_enc) increments and
///   SLAM pose updates (re-anchored on `reinit`), reported at every wheel
///   sample. Compass heading updates (every `compass_period_s`, σ
///   `compass_sigma_rad`) are off by default: indoor compass errors are
///   spatially correlated (steel, wiring), which a white-noise update
///   over-trusts; on the simulated corridor (seeds 1-8) they made the loop
///   closure better on some seeds and worse on others, the same on average.
///
/// **Checks.** The log first goes through check_robot_log()
/// (io/robot_log_checks.hpp): clocks, IMU axes, SLAM poses that are not z-up
/// body poses (more than half tilted by more than 20° is an error, naming
/// slam.csv), encoder wrap-around, and warnings. Those warnings, and the
/// runner's own (SLAM never anchored by the gated fuser, stale attitude), are
/// in `warnings`: a number computed from a doubtful log says so.
///
/// **Structure.** run_corridor() is a sequence of small steps in
/// `posefuse::corridor`: log checks, magnetometer calibration, compass
/// alignment, the attitude chain (AttitudeTracker), the odometry chain
/// (OdometryTracker), one object per method, the runner's warnings, and the
/// metrics (apps/corridor_metrics.hpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <apps/corridor_metrics.hpp>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/stream_merge.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/io/robot_log_checks.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/seed/threshold_fuser.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <posefuse/sensors/pipelines.hpp>

namespace posefuse {

/// The four methods compared, in table order.
enum class CorridorMethod { kSlamOnly, kOdometryOnly, kSeedFuser, kGatedFuser };
/// Their names in tables and JSON, indexed by CorridorMethod.
inline constexpr std::array<const char*, 4> kCorridorMethodNames{"slam_only", "odometry_only",
                                                                 "seed_fuser", "gated_fuser"};

/// Options of run_corridor(); the defaults are the documented configuration.
struct CorridorRunConfig {
  Integration integration = Integration::kEuler;  ///< eq 10 as printed (the seed's choice)
  WheelNoiseParams wheel_noise{};                 ///< dead-reckoning covariance (not used by the methods)
  GatedFuserParams<double> gated{};               ///< the sound fuser
  double slam_stale_s = 0.3;       ///< seed fuser: SLAM older than this → O_r = O_m (s)
  double gap_s = 0.5;              ///< metrics: longer gaps count as "no valid pose" (s)
  double heading_align_s = 1.0;    ///< compass → world heading alignment window (s)
  double attitude_max_age_s = 0;   ///< older attitude is not used (s); 0: 5 median IMU periods
  bool calibrate_magnetometer = true;  ///< horizontal hard/soft-iron fit over the log
  bool compass_in_gated = false;       ///< gated fuser uses compass heading updates (see file comment)
  double compass_period_s = 1.0;       ///< at most one compass update per period (s)
  double compass_sigma_rad = 5.0 * std::numbers::pi / 180.0;  ///< indoor compass σ (rad)
};

/// Everything run_corridor() computed. Tracks are (x m, y m, θ rad) poses at
/// seconds since the log's first sample.
struct CorridorRunResult {
  std::array<PlanarTrajectory, 4> tracks;   ///< poses per method (CorridorMethod order)
  std::array<CorridorMetrics, 4> metrics;   ///< figures per method
  PlanarTrajectory groundtruth;             ///< groundtruth.csv (empty when absent)
  PlanarTrajectory dead_reckoning;          ///< wheel-only (x, y, θ_enc)
  std::vector<TurnEvent> turns;             ///< turns evaluated
  bool turns_from_groundtruth = false;      ///< else from dead reckoning
  double duration_s = 0;                    ///< first to last sample (s)
  MagnetometerCalibration magnetometer;     ///< calibration used
  bool magnetometer_calibrated = false;     ///< the hard/soft-iron fit succeeded
  std::string magnetometer_note;            ///< how it was obtained
  double heading_offset_rad = 0;            ///< compass minus encoder heading at the start (subtracted)
  double attitude_max_age_s = 0;            ///< attitude older than this was not used (s)
  double attitude_stale_s = 0;              ///< wheel time without a usable attitude (s)
  std::vector<std::string> warnings;        ///< doubts about the log or the result, one line each
  int slam_valid = 0, slam_lost = 0, slam_reinit = 0;          ///< SLAM rows by state
  int slam_tilted = 0;                      ///< valid SLAM poses tilted > 20° from z-up
  int seed_averaged = 0, seed_fallback = 0, seed_restarts = 0;  ///< eq 15-a / 15-b / restarts
  int gated_fused = 0, gated_rejected = 0, gated_anchors = 0;   ///< SLAM poses in the gated fuser
  int compass_fused = 0, compass_rejected = 0;                  ///< compass updates
};

/// The steps of run_corridor(), each usable and testable on its own.
namespace corridor {

/// Seconds since the log's first sample of any stream.
///
/// The integer difference t_ns - t0_ns is taken exactly and converted once,
/// \f$ 10^{-9}\,(t - t_0) \f$ — the stamps this runner has always used,
/// to the last bit (detect_turns compares 0.1 s windows of a 100 Hz ground
/// truth, so one ulp moves a turn). Only a difference outside the int64
/// range, which used to overflow, is computed by seconds_between instead.
struct LogClock {
  std::int64_t t0_ns = 0;  ///< the first stamp of wheels, IMU and SLAM (ns)
  /// @return the seconds from t0_ns to t_ns (s)
  [[nodiscard]] double operator()(std::int64_t t_ns) const noexcept {
    const std::int64_t d = saturating_difference(t_ns, t0_ns);
    if (d == std::numeric_limits<std::int64_t>::max() || d == std::numeric_limits<std::int64_t>::min())
      return seconds_between(t_ns, t0_ns);
    return double(d) * 1e-9;
  }
};

/// The clock of a log (wheels and IMU must be non-empty) and its duration (s).
struct LogSpan {
  LogClock clock;         ///< t = 0 at the first sample
  double duration_s = 0;  ///< first to last sample of wheels, IMU and SLAM (s)
};

/// The span of a log's wheel, IMU and SLAM samples (ground truth excluded).
/// @throws posefuse::invalid_argument if the log has no wheel or no IMU sample
[[nodiscard]] inline LogSpan log_span(const RobotLog& log) {
  if (log.wheels.empty() || log.imu.empty())
    throw invalid_argument("run_corridor: the log needs wheel and IMU samples");
  std::int64_t t0 = std::min(log.wheels.front().t_ns, log.imu.front().t_ns);
  std::int64_t t1 = std::max(log.wheels.back().t_ns, log.imu.back().t_ns);
  if (!log.slam.empty()) {
    t0 = std::min(t0, log.slam.front().t_ns);
    t1 = std::max(t1, log.slam.back().t_ns);
  }
  const LogClock clock{t0};
  return {clock, clock(t1)};
}

/// (x, y, θ) of a planar pose, the PlanarTrajectory layout.
[[nodiscard]] inline Eigen::Vector3d xyt(const PlanarPose<double>& p) { return p.vector(); }
/// The planar pose of an (x, y, θ) vector (exact).
[[nodiscard]] inline PlanarPose<double> pose_of(const Eigen::Vector3d& v) { return {v(0), v(1), v(2)}; }
/// The planar part (x, y, wrapped yaw) of a seed odometry vector.
[[nodiscard]] inline PlanarPose<double> planar(const seed::SeedOdometry<double>& o) {
  return {o.x, o.y, wrap_angle(o.yaw)};
}

/// Ground truth as a track (seconds since the log's first sample).
[[nodiscard]] inline PlanarTrajectory groundtruth_track(const RobotLog& log, const LogClock& clock) {
  PlanarTrajectory gt;
  for (const PlanarPoseSample& g : log.groundtruth) gt.push_back(clock(g.t_ns), g.pose);
  return gt;
}

/// The magnetometer calibration used, and how it was obtained.
struct MagnetometerSetup {
  MagnetometerCalibration calibration;  ///< identity unless calibrated
  bool calibrated = false;              ///< the fit succeeded
  std::string note;                     ///< for the table and JSON
};

/// Horizontal hard/soft-iron calibration over every IMU reading of the log
/// (fit_horizontal_ellipse), or none when `enabled` is false.
[[nodiscard]] inline MagnetometerSetup calibrate_magnetometer(const RobotLog& log, bool enabled) {
  MagnetometerSetup m;
  if (!enabled) {
    m.note = "not calibrated (disabled)";
    return m;
  }
  // A vector, not `log.imu | std::views::transform(...)`: clang 14 cannot
  // compile libstdc++ 12's views (any std::ranges::view_interface).
  std::vector<Eigen::Vector2d> horizontal;
  horizontal.reserve(log.imu.size());
  for (const ImuSample& s : log.imu) horizontal.emplace_back(s.mag_uT.x(), s.mag_uT.y());
  const HorizontalEllipseFitOptions options;
  const HorizontalEllipseFit fit = fit_horizontal_ellipse(horizontal, options);
  m.calibrated = fit.ok();
  m.calibration = fit.calibration;
  m.note = fit.ok() ? "horizontal hard/soft-iron ellipse fit over " + std::to_string(fit.readings) +
                          " readings"
                    : "not calibrated: " +
                          to_string(fit.status, options.min_readings, options.min_coverage_deg);
  return m;
}

/// The encoder dead-reckoning track of the whole log (for the compass alignment).
[[nodiscard]] inline PlanarTrajectory encoder_track(const RobotLog& log, const DiffDriveParams& dd,
                                                    const CorridorRunConfig& cfg, const LogClock& clock) {
  PlanarTrajectory enc;
  auto odo = make_odometry_pipeline(dd, cfg.wheel_noise, cfg.integration);
  for (const WheelSample& w : log.wheels) enc.push_back(clock(w.t_ns), xyt(odo(w).pose.mean));
  return enc;
}

/// Compass yaw minus encoder heading at the start: the circular mean of
/// angle_diff(compass yaw, encoder heading) over the first `heading_align_s`
/// in which both streams have data (0 when there is no such sample).
[[nodiscard]] inline double compass_heading_offset(const RobotLog& log, const AttitudeConfig& att_cfg,
                                                   const DiffDriveParams& dd,
                                                   const CorridorRunConfig& cfg,
                                                   const LogClock& clock) {
  const PlanarTrajectory enc = encoder_track(log, dd, cfg, clock);
  const double ta = std::max(clock(log.wheels.front().t_ns), clock(log.imu.front().t_ns));
  auto align = make_attitude_pipeline(att_cfg);
  double ss = 0, sc = 0;
  int n = 0;
  for (const ImuSample& r : log.imu) {
    const double t = clock(r.t_ns);
    if (t > ta + cfg.heading_align_s) break;
    const Attitude a = align(r);
    const auto e = interpolate_at(enc, t);
    if (t < ta || !e || (a.status != SampleStatus::kOk && a.status != SampleStatus::kFirst)) continue;
    const double d = angle_diff(a.yaw, (*e)(2));
    ss += std::sin(d);
    sc += std::cos(d);
    ++n;
  }
  return n == 0 ? 0.0 : std::atan2(ss, sc);
}

/// The oldest attitude still used (s): the configured value, else 5 median
/// IMU periods (0.5 s for a single IMU sample), periods on the log's clock.
[[nodiscard]] inline double attitude_max_age(const RobotLog& log, const CorridorRunConfig& cfg,
                                             const LogClock& clock) {
  if (cfg.attitude_max_age_s > 0) return cfg.attitude_max_age_s;
  std::vector<double> dt;
  for (std::size_t i = 1; i < log.imu.size(); ++i)
    dt.push_back(clock(log.imu[i].t_ns) - clock(log.imu[i - 1].t_ns));
  if (dt.empty()) return 0.5;
  std::nth_element(dt.begin(), dt.begin() + std::ptrdiff_t(dt.size() / 2), dt.end());
  return 5 * dt[dt.size() / 2];
}

/// The attitude chain over the run: the latest usable attitude, its yaw in
/// the world frame (compass minus the heading offset), and its age.
class AttitudeTracker {
 public:
  /// @param[in] cfg the attitude pipeline's configuration
  /// @param[in] heading_offset_rad compass minus world heading (subtracted)
  /// @param[in] max_age_s an attitude older than this is not fresh (s)
  AttitudeTracker(const AttitudeConfig& cfg, double heading_offset_rad, double max_age_s)
      : chain_(make_attitude_pipeline(cfg)), offset_(heading_offset_rad), max_age_s_(max_age_s) {}

  /// Feeds one IMU sample at time t (s); a sample whose attitude is not finite is skipped.
  void on_imu(const ImuSample& s, double t) {
    const Attitude a = chain_(s);
    if (a.status == SampleStatus::kNonFinite) return;
    att_ = a;
    att_.yaw = wrap_angle(a.yaw - offset_);
    t_ = t;
    have_ = true;
  }
  /// True when an attitude at most max_age_s old exists at time t (s).
  [[nodiscard]] bool fresh_at(double t) const noexcept { return have_ && t - t_ <= max_age_s_; }
  /// The latest usable attitude (yaw in the world frame).
  [[nodiscard]] const Attitude& attitude() const noexcept { return att_; }

 private:
  AttitudePipeline chain_;
  double offset_;
  double max_age_s_;
  Attitude att_{};
  double t_ = 0;
  bool have_ = false;
};

/// Odometry at one time: dead reckoning (x, y, θ_enc) and the seed's O_m.
struct OdometryAt {
  PlanarPose<double> dr;          ///< encoder dead reckoning
  seed::SeedOdometry<double> om;  ///< O_m: wheels' x, y; IMU roll, pitch, yaw (or the fallback)
};

/// O_m interpolated between two samples: x, y linearly, angles along the shorter arc.
[[nodiscard]] inline seed::SeedOdometry<double> interpolate(const seed::SeedOdometry<double>& a,
                                                            const seed::SeedOdometry<double>& b,
                                                            double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), angle_interpolate(a.roll, b.roll, f),
          angle_interpolate(a.pitch, b.pitch, f), angle_interpolate(a.yaw, b.yaw, f)};
}

/// The odometry chain over the run: dead reckoning at every wheel sample,
/// combined with the attitude into O_m, and both interpolated to any time
/// since the previous wheel sample.
class OdometryTracker {
 public:
  /// @throws posefuse::invalid_argument for unusable robot geometry or noise
  OdometryTracker(const DiffDriveParams& dd, const CorridorRunConfig& cfg)
      : chain_(make_odometry_pipeline(dd, cfg.wheel_noise, cfg.integration)) {}

  /// Feeds one wheel sample at time t (s). With a fresh attitude O_m takes
  /// its roll, pitch and yaw and the compass-minus-encoder offset is updated;
  /// without one, O_m's yaw is the encoder heading plus the last offset and
  /// the time since the previous wheel sample is added to `stale_s`.
  /// @return the odometry at t
  OdometryAt on_wheel(const WheelSample& w, double t, const AttitudeTracker& att, double& stale_s) {
    prev_ = now_;
    t_prev_ = t_now_;
    now_.dr = chain_(w).pose.mean;
    const bool fresh = att.fresh_at(t);
    const Attitude& a = att.attitude();
    if (fresh) enc_offset_ = angle_diff(a.yaw, now_.dr.theta);
    else if (have_) stale_s += t - t_prev_;
    now_.om = {now_.dr.x, now_.dr.y, fresh ? a.roll : 0.0, fresh ? a.pitch : 0.0,
               fresh ? a.yaw : wrap_angle(now_.dr.theta + enc_offset_)};
    t_now_ = t;
    if (!have_) {
      prev_ = now_;
      t_prev_ = t;
      have_ = true;
    }
    return now_;
  }

  /// The odometry at time ts (s) between the previous and the latest wheel
  /// sample (clamped to them; the latest when they coincide).
  [[nodiscard]] OdometryAt at(double ts) const {
    const double f = t_now_ > t_prev_ ? std::clamp((ts - t_prev_) / (t_now_ - t_prev_), 0.0, 1.0) : 1.0;
    return {pose_of(interpolate_planar_pose(xyt(prev_.dr), xyt(now_.dr), f)),
            interpolate(prev_.om, now_.om, f)};
  }
  /// The latest odometry.
  [[nodiscard]] const OdometryAt& latest() const noexcept { return now_; }

 private:
  OdometryPipeline chain_;
  OdometryAt prev_{}, now_{};
  double t_prev_ = 0, t_now_ = 0;
  double enc_offset_ = 0;  // world yaw minus encoder heading, from the last fresh attitude
  bool have_ = false;
};

/// A valid SLAM pose as the methods use it.
struct SlamPose {
  double t = 0;                ///< time (s)
  bool reinit = false;         ///< first pose of a new map frame
  PlanarPose<double> z;        ///< x, y, yaw in the SLAM map frame
  EulerZYX<double> euler;      ///< roll, pitch, yaw (eq 11-13)
};

/// The planar SLAM pose of a valid sample (eq 11-13 for its angles).
[[nodiscard]] inline SlamPose slam_pose(const SlamSample& r, double t) {
  SlamPose p;
  p.t = t;
  p.reinit = r.state == SlamState::kReinit;
  p.euler = euler_zyx_from_rotation(r.orientation.normalized().toRotationMatrix());
  p.z = {r.position_m.x(), r.position_m.y(), wrap_angle(p.euler.yaw)};
  return p;
}

/// `slam_only`: SLAM poses placed in the world once, by the first valid pose.
class SlamOnlyMethod {
 public:
  /// Places (at the first pose) and reports a SLAM pose; `dr` is odometry at its time.
  void on_slam(const SlamPose& s, const PlanarPose<double>& dr, PlanarTrajectory& track) {
    if (!aligned_) T_world_map_ = se2_compose(dr, se2_inverse(s.z));
    aligned_ = true;
    track.push_back(s.t, xyt(se2_compose(T_world_map_, s.z)));
  }

 private:
  bool aligned_ = false;
  PlanarPose<double> T_world_map_;
};

/// `seed_fuser`: ThresholdFuser (eq 14-15) at each valid SLAM pose, O_m in between.
class SeedFuserMethod {
 public:
  /// @param[in] threshold eq 15 threshold (m·rad)
  /// @param[in] slam_stale_s SLAM older than this → O_r = O_m at wheel samples (s)
  SeedFuserMethod(double threshold, double slam_stale_s) : fuser_(threshold), stale_s_(slam_stale_s) {}

  /// Fuses a SLAM pose with O_m at its time; (re)places the map on `reinit`
  /// or after the fuser's own re-initialise signal.
  void on_slam(const SlamPose& s, const seed::SeedOdometry<double>& om, PlanarTrajectory& track,
               CorridorRunResult& res) {
    if (s.reinit || place_) {
      T_world_map_ = se2_compose(planar(om), se2_inverse(s.z));
      res.seed_restarts += place_ && !s.reinit && started_;
      place_ = false;
      started_ = true;
    }
    const PlanarPose<double> zw = se2_compose(T_world_map_, s.z);
    const seed::SeedOdometry<double> ov{zw.x, zw.y, s.euler.roll, s.euler.pitch, zw.theta};
    const auto out = fuser_({om, ov});
    (out.averaged ? res.seed_averaged : res.seed_fallback) += 1;
    place_ = out.reinitialise;
    track.push_back(s.t, xyt(planar(out.pose)));
    last_slam_t_ = s.t;
  }
  /// At a wheel sample: O_r = O_m when SLAM is lost or stale (eq 15-b).
  void on_wheel(double t, const seed::SeedOdometry<double>& om, PlanarTrajectory& track) const {
    if (t - last_slam_t_ > stale_s_) track.push_back(t, xyt(planar(om)));
  }

 private:
  seed::ThresholdFuser<double> fuser_;
  double stale_s_;
  double last_slam_t_ = -1e300;
  bool place_ = true, started_ = false;
  PlanarPose<double> T_world_map_;
};

/// `gated_fuser`: GatedFuser with odometry increments, SLAM updates and,
/// optionally, compass heading updates.
class GatedFuserMethod {
 public:
  /// @throws posefuse::invalid_argument for invalid fuser parameters
  explicit GatedFuserMethod(const CorridorRunConfig& cfg) : fuser_(cfg.gated), cfg_(cfg) {}

  /// Odometry up to the SLAM pose's time, then the SLAM pose.
  void on_slam(const SlamPose& s, const PlanarPose<double>& dr, CorridorRunResult& res) {
    (void)fuser_.predict(dr);
    const FuserStatus st = fuser_.update_slam(s.z, s.reinit);
    res.gated_fused += st == FuserStatus::kFused;
    res.gated_rejected += is_rejection(st);
  }
  /// At a wheel sample: the odometry increment, a compass update when enabled
  /// and due, and the fused pose reported.
  void on_wheel(double t, const PlanarPose<double>& dr, const AttitudeTracker& att,
                PlanarTrajectory& track, CorridorRunResult& res) {
    (void)fuser_.predict(dr);
    if (cfg_.compass_in_gated && att.fresh_at(t) && t - last_compass_t_ >= cfg_.compass_period_s) {
      const FuserStatus st = fuser_.update_heading(att.attitude().yaw, cfg_.compass_sigma_rad);
      res.compass_fused += st == FuserStatus::kFused;
      res.compass_rejected += is_rejection(st);
      last_compass_t_ = t;
    }
    report(t, track);
  }
  /// Reports the current fused pose at time t (s).
  void report(double t, PlanarTrajectory& track) const { track.push_back(t, xyt(fuser_.pose())); }
  /// Map frames anchored so far.
  [[nodiscard]] int anchors() const noexcept { return fuser_.anchor_count(); }

 private:
  GatedFuser<double> fuser_;
  CorridorRunConfig cfg_;
  double last_compass_t_ = -1e300;
};

/// The runner's own doubts about a result: a SLAM map the gated fuser never
/// anchored or mostly rejected, and wheel time without a fresh attitude.
[[nodiscard]] inline std::vector<std::string> runner_warnings(const CorridorRunResult& res) {
  std::vector<std::string> w;
  if (res.slam_valid > 0 && res.gated_anchors == 0)
    w.push_back(
        "gated_fuser: SLAM map never anchored: none of the " + std::to_string(res.slam_valid) +
        " valid SLAM poses agreed with odometry (non-metric, e.g. monocular, SLAM scale? wrong "
        "robot.txt geometry? a frozen pose?); gated_fuser is odometry only");
  else if (res.slam_valid >= 20 && 2 * res.gated_fused < res.slam_valid)
    w.push_back(
        "gated_fuser: fused only " + std::to_string(res.gated_fused) + " of " +
        std::to_string(res.slam_valid) + " valid SLAM poses (" + std::to_string(res.gated_rejected) +
        " rejected by the gates, the rest spent anchoring): SLAM and odometry disagree "
        "(non-metric SLAM scale? wrong robot.txt geometry?)");
  if (res.attitude_stale_s > 1.0)
    w.push_back(
        "imu.csv: no attitude younger than " + detail::num_text(res.attitude_max_age_s, 3) +
        " s for " + detail::num_text(res.attitude_stale_s, 1) +
        " s of the wheel data (IMU starts late, stops early or has gaps); odometry_only and "
        "seed_fuser used the encoder heading plus the last compass offset there");
  return w;
}

/// Finds the turns (in ground truth, else in dead reckoning) and evaluates
/// every method's track (evaluate_track).
inline void evaluate_methods(CorridorRunResult& res, const CorridorRunConfig& cfg) {
  res.turns_from_groundtruth = !res.groundtruth.empty();
  res.turns = detect_turns(res.turns_from_groundtruth ? res.groundtruth : res.dead_reckoning);
  const Eigen::Vector2d start =
      res.groundtruth.empty() ? Eigen::Vector2d::Zero() : res.groundtruth.position(0);
  for (std::size_t m = 0; m < 4; ++m)
    res.metrics[m] = evaluate_track(res.tracks[m], res.groundtruth, res.turns, start, 0.0,
                                    res.duration_s, cfg.gap_s);
}

}  // namespace corridor

/// Runs the four methods over a log and evaluates them (see the file comment).
/// @param[in] log a log as read by read_robot_log() or made by simulate_corridor()
/// @param[in] cfg options
/// @return tracks, metrics and counters
/// @throws posefuse::invalid_argument if robot.txt's parameters are unusable,
///         or (for a log not made by read_robot_log) stamps do not increase or
///         a value is not finite
/// @throws posefuse::io_error for the errors of check_robot_log(), naming the
///         file (slam.csv for camera-frame poses, ...)
[[nodiscard]] inline CorridorRunResult run_corridor(const RobotLog& log,
                                                    const CorridorRunConfig& cfg = {}) {
  using namespace corridor;
  CorridorRunResult res;
  const LogSpan span = log_span(log);
  const LogClock& clock = span.clock;
  res.warnings = check_robot_log(log);
  res.duration_s = span.duration_s;
  res.groundtruth = groundtruth_track(log, clock);

  // --- Magnetometer calibration and compass alignment (pre-passes).
  MagnetometerSetup mag = calibrate_magnetometer(log, cfg.calibrate_magnetometer);
  res.magnetometer = mag.calibration;
  res.magnetometer_calibrated = mag.calibrated;
  res.magnetometer_note = std::move(mag.note);
  // The seed's eq 3-4 as printed (the library's default is the Euler kinematics).
  const AttitudeConfig att_cfg{log.params.complementary_alpha, GyroToTiltRate::kSeed,
                               res.magnetometer, 0.0};
  const DiffDriveParams dd{log.params.ticks_per_rev, log.params.wheel_radius_m, log.params.track_width_m};
  res.heading_offset_rad = compass_heading_offset(log, att_cfg, dd, cfg, clock);
  res.attitude_max_age_s = attitude_max_age(log, cfg, clock);

  // --- Chains and methods, fed in time order.
  AttitudeTracker attitude(att_cfg, res.heading_offset_rad, res.attitude_max_age_s);
  OdometryTracker odometry(dd, cfg);
  SlamOnlyMethod slam_only;
  SeedFuserMethod seed(log.params.fuser_threshold, cfg.slam_stale_s);
  GatedFuserMethod gated(cfg);
  // Plain references, not a structured binding: the lambdas below capture them,
  // which clang <= 15 rejects for structured bindings.
  PlanarTrajectory& slam_track = res.tracks[static_cast<std::size_t>(CorridorMethod::kSlamOnly)];
  PlanarTrajectory& odom_track = res.tracks[static_cast<std::size_t>(CorridorMethod::kOdometryOnly)];
  PlanarTrajectory& seed_track = res.tracks[static_cast<std::size_t>(CorridorMethod::kSeedFuser)];
  PlanarTrajectory& gated_track = res.tracks[static_cast<std::size_t>(CorridorMethod::kGatedFuser)];
  std::vector<const SlamSample*> pending;  // SLAM held until odometry reaches its time

  const auto process_slam = [&](const SlamSample& r, const OdometryAt& o) {
    if (r.state == SlamState::kLost) return void(++res.slam_lost);
    ++res.slam_valid;
    const SlamPose s = slam_pose(r, clock(r.t_ns));
    res.slam_reinit += s.reinit;
    res.slam_tilted += slam_pose_tilted(r);
    slam_only.on_slam(s, o.dr, slam_track);
    seed.on_slam(s, o.om, seed_track, res);
    gated.on_slam(s, o.dr, res);
  };
  for_each_in_time_order(
      Overloaded{
          [&](const ImuSample& s) { attitude.on_imu(s, clock(s.t_ns)); },
          [&](const WheelSample& w) {
            const double t = clock(w.t_ns);
            const OdometryAt o = odometry.on_wheel(w, t, attitude, res.attitude_stale_s);
            for (const SlamSample* r : pending) process_slam(*r, odometry.at(clock(r->t_ns)));
            pending.clear();
            gated.on_wheel(t, o.dr, attitude, gated_track, res);
            odom_track.push_back(t, xyt(planar(o.om)));
            res.dead_reckoning.push_back(t, xyt(o.dr));
            seed.on_wheel(t, o.om, seed_track);
          },
          [&](const SlamSample& r) { pending.push_back(&r); }},
      log.imu, log.wheels, log.slam);
  for (const SlamSample* r : pending) process_slam(*r, odometry.latest());
  if (!pending.empty()) gated.report(clock(pending.back()->t_ns), gated_track);  // keep it current
  res.gated_anchors = gated.anchors();
  for (std::string& w : runner_warnings(res)) res.warnings.push_back(std::move(w));

  // --- Metrics.
  evaluate_methods(res, cfg);
  return res;
}

}  // namespace posefuse

#pragma once
/// @file
/// Runs seed 001's corridor comparison on a RobotLog (recorded or simulated):
/// SLAM alone, odometry alone, the seed's threshold fuser (eq 14-15) and the
/// gated fuser, processing the asynchronous streams in time order.
///
/// **Time.** All streams are merged by `t_ns` (ties: IMU, wheels, SLAM);
/// t = 0 is the first sample of any stream. A SLAM pose is held until the
/// next wheel sample, and odometry is interpolated to the SLAM pose's time
/// (linear in position, shorter arc in angles), so no two streams need
/// shared timestamps. SLAM poses after the last wheel sample use the last
/// odometry.
///
/// **Chains.** Odometry: wheels.csv → eq 8 → eq 9 → dead reckoning (eq 10,
/// Euler as printed, by default) = (x, y, θ_enc). Attitude: imu.csv → eq 1-2
/// → complementary filter eq 3-4 (robot.txt alpha) → tilt-compensated compass
/// (eq 5-7 corrected) = (roll, pitch, yaw). The log carries no magnetometer
/// calibration, so the runner fits hard and soft iron in the horizontal
/// plane (an ellipse through all readings: a ground robot turns about z only,
/// which leaves a 3-D ellipsoid fit undetermined; this uses the whole log,
/// i.e. it is an offline calibration, as the seed's sensor did it
/// internally). The compass yaw is aligned to the world (= odometry) frame
/// by the circular mean of angle_diff(compass yaw, encoder heading) over the
/// first `heading_align_s` in which both streams have data, so an IMU that
/// starts late, or a robot that turns at the start, is aligned correctly.
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

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/rotation.hpp>
#include <posefuse/fusion/corridor_metrics.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/fusion/threshold_fuser.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/io/robot_log_checks.hpp>
#include <posefuse/sensors/pipelines.hpp>

namespace posefuse {

/// The four methods compared, in table order.
enum class CorridorMethod { kSlamOnly, kOdometryOnly, kSeedFuser, kGatedFuser };
/// Their names in tables and JSON, indexed by CorridorMethod.
inline constexpr std::array<const char*, 4> kCorridorMethodNames{"slam_only", "odometry_only",
                                                                 "seed_fuser", "gated_fuser"};

/// Options of run_corridor(); the defaults are the documented configuration.
struct CorridorRunConfig {
  Integration integration = Integration::kEuler;  ///< eq 10 as printed
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

/// Everything run_corridor() computed.
struct CorridorRunResult {
  std::array<PlanarTrack, 4> tracks;        ///< poses per method (CorridorMethod order)
  std::array<CorridorMetrics, 4> metrics;   ///< figures per method
  PlanarTrack groundtruth;                  ///< groundtruth.csv (empty when absent)
  PlanarTrack dead_reckoning;               ///< wheel-only (x, y, θ_enc)
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

namespace detail {

/// Horizontal hard/soft-iron calibration: least-squares conic
/// \f$ a x^2 + b xy + c y^2 + d x + e y = 1 \f$ through (m_x, m_y).
inline bool fit_horizontal_ellipse(const std::vector<ImuRecord>& imu, MagnetometerCalibration& cal,
                                   std::string& note) {
  const auto fail = [&note](const char* why) {
    note = std::string("not calibrated: ") + why;
    return false;
  };
  if (imu.size() < 20) return fail("fewer than 20 readings");
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& r : imu) c += Eigen::Vector2d(r.mag_uT[0], r.mag_uT[1]);
  c /= double(imu.size());
  double s = 0;
  for (const auto& r : imu) s += (Eigen::Vector2d(r.mag_uT[0], r.mag_uT[1]) - c).squaredNorm();
  s = std::sqrt(s / double(imu.size()));
  if (!(s > 0)) return fail("constant readings");
  Eigen::Matrix<double, 5, 5> N = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
  for (const auto& r : imu) {
    const Eigen::Vector2d p = (Eigen::Vector2d(r.mag_uT[0], r.mag_uT[1]) - c) / s;
    const Eigen::Matrix<double, 5, 1> v(p.x() * p.x(), p.x() * p.y(), p.y() * p.y(), p.x(), p.y());
    N += v * v.transpose();
    rhs += v;
  }
  const Eigen::Matrix<double, 5, 1> b = N.ldlt().solve(rhs);
  Eigen::Matrix2d M;
  M << b(0), b(1) / 2, b(1) / 2, b(2);
  const double det = M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0);
  const Eigen::Vector2d ctr =
      -0.5 * Eigen::Vector2d(M(1, 1) * b(3) - M(0, 1) * b(4), M(0, 0) * b(4) - M(1, 0) * b(3)) / det;
  const Eigen::Matrix2d Q = M / (1.0 + ctr.dot(M * ctr));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
  es.computeDirect(Q);
  const Eigen::Vector2d ev = es.eigenvalues();
  if (!b.allFinite() || !(ev.minCoeff() > 0) || ev.maxCoeff() / ev.minCoeff() > 4.0)
    return fail("readings are not on a plausible ellipse");
  std::array<bool, 36> seen{};  // 10° bins of the reading's direction about the centre
  for (const auto& r : imu) {
    const Eigen::Vector2d p = (Eigen::Vector2d(r.mag_uT[0], r.mag_uT[1]) - c) / s - ctr;
    const double a = std::atan2(p.y(), p.x()) + std::numbers::pi;
    seen[std::size_t(std::min(35.0, a / (2 * std::numbers::pi) * 36))] = true;
  }
  const int bins = int(std::count(seen.begin(), seen.end(), true));
  if (bins < 27) return fail("the robot turned through less than 270 deg");
  const double k = 1.0 / std::sqrt(std::sqrt(ev.prod()));  // keep the geometric-mean radius
  const Eigen::Matrix2d S = k * es.eigenvectors() * ev.cwiseSqrt().asDiagonal() *
                            es.eigenvectors().transpose();
  cal.hard_iron << c + s * ctr, 0.0;
  cal.soft_iron.setIdentity();
  cal.soft_iron.topLeftCorner<2, 2>() = S;
  note = "horizontal hard/soft-iron ellipse fit over " + std::to_string(imu.size()) + " readings";
  return true;
}

inline ImuSample to_sample(const ImuRecord& r, double t_s) {
  ImuSample s;
  s.t_s = t_s;
  s.accel_mps2 = Eigen::Vector3d(r.accel_mps2[0], r.accel_mps2[1], r.accel_mps2[2]);
  s.gyro_radps = Eigen::Vector3d(r.gyro_radps[0], r.gyro_radps[1], r.gyro_radps[2]);
  s.mag_uT = Eigen::Vector3d(r.mag_uT[0], r.mag_uT[1], r.mag_uT[2]);
  return s;
}

inline SeedOdometry<double> interpolate(const SeedOdometry<double>& a, const SeedOdometry<double>& b,
                                        double f) {
  return {a.x + f * (b.x - a.x), a.y + f * (b.y - a.y), angle_interpolate(a.roll, b.roll, f),
          angle_interpolate(a.pitch, b.pitch, f), angle_interpolate(a.yaw, b.yaw, f)};
}

inline PlanarPose<double> planar(const SeedOdometry<double>& o) { return {o.x, o.y, wrap_angle(o.yaw)}; }

}  // namespace detail

/// Runs the four methods over a log and evaluates them (see the file comment).
/// @param[in] log a log as read by read_robot_log() or made by simulate_corridor()
/// @param[in] cfg options
/// @return tracks, metrics and counters
/// @throws posefuse::invalid_argument if robot.txt's parameters are unusable,
///         or (for a log not made by read_robot_log) stamps do not increase
/// @throws posefuse::io_error for the errors of check_robot_log(), naming the
///         file (slam.csv for camera-frame poses, ...)
[[nodiscard]] inline CorridorRunResult run_corridor(const RobotLog& log,
                                                    const CorridorRunConfig& cfg = {}) {
  CorridorRunResult res;
  if (log.wheels.empty() || log.imu.empty())
    throw invalid_argument("run_corridor: the log needs wheel and IMU samples");
  res.warnings = check_robot_log(log);
  std::int64_t t0 = std::min(log.wheels.front().t_ns, log.imu.front().t_ns);
  std::int64_t t1 = std::max(log.wheels.back().t_ns, log.imu.back().t_ns);
  if (!log.slam.empty()) {
    t0 = std::min(t0, log.slam.front().t_ns);
    t1 = std::max(t1, log.slam.back().t_ns);
  }
  const auto sec = [t0](std::int64_t t) { return double(t - t0) * 1e-9; };
  res.duration_s = sec(t1);
  for (const auto& g : log.groundtruth) res.groundtruth.push_back({sec(g.t_ns), {g.x, g.y, g.yaw}});

  // --- Magnetometer calibration and heading alignment (pre-passes).
  if (cfg.calibrate_magnetometer)
    res.magnetometer_calibrated =
        detail::fit_horizontal_ellipse(log.imu, res.magnetometer, res.magnetometer_note);
  else res.magnetometer_note = "not calibrated (disabled)";
  const AttitudeConfig att_cfg{log.params.complementary_alpha, GyroToTiltRate::kSeed, res.magnetometer, 0.0};
  const DiffDriveParams dd{log.params.ticks_per_rev, log.params.wheel_radius_m, log.params.track_width_m};
  {
    PlanarTrack enc;  // encoder heading, to align the compass to
    auto odo = make_odometry_pipeline(dd, cfg.wheel_noise, cfg.integration);
    for (const auto& w : log.wheels)
      enc.push_back({sec(w.t_ns), odo(StampedWheelTicks{sec(w.t_ns), {w.fl, w.fr, w.bl, w.br}}).pose});
    const double ta = std::max(sec(log.wheels.front().t_ns), sec(log.imu.front().t_ns));
    auto align = make_attitude_pipeline(att_cfg);
    double ss = 0, sc = 0;
    int n = 0;
    for (const auto& r : log.imu) {
      const double t = sec(r.t_ns);
      if (t > ta + cfg.heading_align_s) break;
      const Attitude a = align(detail::to_sample(r, t));
      const auto e = interpolate_track(enc, t);
      if (t < ta || !e || (a.status != SampleStatus::kOk && a.status != SampleStatus::kFirst)) continue;
      const double d = angle_diff(a.yaw, e->theta);
      ss += std::sin(d);
      sc += std::cos(d);
      ++n;
    }
    res.heading_offset_rad = n == 0 ? 0.0 : std::atan2(ss, sc);
    std::vector<double> dt;
    for (std::size_t i = 1; i < log.imu.size(); ++i) dt.push_back(sec(log.imu[i].t_ns) - sec(log.imu[i - 1].t_ns));
    std::nth_element(dt.begin(), dt.begin() + std::ptrdiff_t(dt.size() / 2), dt.end());
    res.attitude_max_age_s = cfg.attitude_max_age_s > 0 ? cfg.attitude_max_age_s
                             : dt.empty()               ? 0.5
                                                        : 5 * dt[dt.size() / 2];
  }

  // --- Chains and methods.
  auto attitude = make_attitude_pipeline(att_cfg);
  auto odometry = make_odometry_pipeline(dd, cfg.wheel_noise, cfg.integration);
  const ThresholdFuser<double> seed(log.params.fuser_threshold);
  GatedFuser<double> gated(cfg.gated);
  auto& [slam_only, odom_only, seed_track, gated_track] = res.tracks;

  bool have_att = false, have_wheel = false, so_aligned = false, seed_place = true, seed_started = false;
  Attitude att;
  double t_prev = 0, last_slam_t = -1e300, last_compass_t = -1e300, att_t = -1e300;
  double enc_offset = 0;  // world yaw minus encoder heading, from the last usable attitude
  PlanarPose<double> dr_prev, dr_now, T_so, T_seed;
  SeedOdometry<double> om_prev, om_now;
  std::vector<const SlamRecord*> pending;

  const auto process_slam = [&](const SlamRecord& r, double t, const PlanarPose<double>& dr,
                                const SeedOdometry<double>& om) {
    if (r.state == SlamState::kLost) return void(++res.slam_lost);
    ++res.slam_valid;
    const bool reinit = r.state == SlamState::kReinit;
    res.slam_reinit += reinit;
    const Eigen::Quaterniond q(r.q[3], r.q[0], r.q[1], r.q[2]);
    const EulerZYX<double> e = euler_zyx_from_rotation(q.normalized().toRotationMatrix());  // eq 11-13
    const PlanarPose<double> z{r.p[0], r.p[1], wrap_angle(e.yaw)};
    res.slam_tilted += slam_pose_tilted(r);
    // SLAM alone: placed once, at its first valid pose.
    if (!so_aligned) T_so = se2_compose(dr, se2_inverse(z));
    so_aligned = true;
    slam_only.push_back({t, se2_compose(T_so, z)});
    // Seed fuser: (re)start from the odometry pose on reinit or after its own signal.
    if (reinit || seed_place) {
      T_seed = se2_compose(detail::planar(om), se2_inverse(z));
      res.seed_restarts += seed_place && !reinit && seed_started;
      seed_place = false;
      seed_started = true;
    }
    const PlanarPose<double> zw = se2_compose(T_seed, z);
    const SeedOdometry<double> ov{zw.x, zw.y, e.roll, e.pitch, zw.theta};
    const auto out = seed({om, ov});
    (out.averaged ? res.seed_averaged : res.seed_fallback) += 1;
    seed_place = out.reinitialise;
    seed_track.push_back({t, detail::planar(out.pose)});
    last_slam_t = t;
    // Gated fuser: odometry up to the SLAM time, then the SLAM pose.
    (void)gated.predict(dr);
    const FuserStatus st = gated.update_slam(z, reinit);
    res.gated_fused += st == FuserStatus::kFused;
    res.gated_rejected += is_rejection(st);
  };

  std::size_t iw = 0, ii = 0, is = 0;
  constexpr std::int64_t kEnd = std::numeric_limits<std::int64_t>::max();
  for (;;) {
    const std::int64_t tw = iw < log.wheels.size() ? log.wheels[iw].t_ns : kEnd;
    const std::int64_t ti = ii < log.imu.size() ? log.imu[ii].t_ns : kEnd;
    const std::int64_t ts = is < log.slam.size() ? log.slam[is].t_ns : kEnd;
    if (tw == kEnd && ti == kEnd && ts == kEnd) break;
    if (ti <= tw && ti <= ts) {  // IMU
      const Attitude a = attitude(detail::to_sample(log.imu[ii], sec(ti)));
      ++ii;
      if (a.status == SampleStatus::kNonFinite) continue;
      att = a;
      att.yaw = wrap_angle(a.yaw - res.heading_offset_rad);
      att_t = sec(ti);
      have_att = true;
    } else if (tw <= ts) {  // wheels
      const auto& w = log.wheels[iw++];
      const double t = sec(w.t_ns);
      const PoseWithCovariance pw = odometry(StampedWheelTicks{t, {w.fl, w.fr, w.bl, w.br}});
      dr_now = pw.pose;
      const bool fresh = have_att && t - att_t <= res.attitude_max_age_s;
      if (fresh) enc_offset = angle_diff(att.yaw, dr_now.theta);
      else if (have_wheel) res.attitude_stale_s += t - t_prev;
      om_now = {dr_now.x, dr_now.y, fresh ? att.roll : 0.0, fresh ? att.pitch : 0.0,
                fresh ? att.yaw : wrap_angle(dr_now.theta + enc_offset)};
      if (!have_wheel) {
        dr_prev = dr_now;
        om_prev = om_now;
        t_prev = t;
        have_wheel = true;
      }
      for (const SlamRecord* r : pending) {
        const double ts_s = sec(r->t_ns);
        const double f = t > t_prev ? std::clamp((ts_s - t_prev) / (t - t_prev), 0.0, 1.0) : 1.0;
        const PlanarPose<double> dr{dr_prev.x + f * (dr_now.x - dr_prev.x),
                                    dr_prev.y + f * (dr_now.y - dr_prev.y),
                                    angle_interpolate(dr_prev.theta, dr_now.theta, f)};
        process_slam(*r, ts_s, dr, detail::interpolate(om_prev, om_now, f));
      }
      pending.clear();
      (void)gated.predict(dr_now);
      if (cfg.compass_in_gated && fresh && t - last_compass_t >= cfg.compass_period_s) {
        const FuserStatus st = gated.update_heading(att.yaw, cfg.compass_sigma_rad);
        res.compass_fused += st == FuserStatus::kFused;
        res.compass_rejected += is_rejection(st);
        last_compass_t = t;
      }
      odom_only.push_back({t, detail::planar(om_now)});
      gated_track.push_back({t, gated.pose()});
      res.dead_reckoning.push_back({t, dr_now});
      if (t - last_slam_t > cfg.slam_stale_s) seed_track.push_back({t, detail::planar(om_now)});
      dr_prev = dr_now;
      om_prev = om_now;
      t_prev = t;
    } else {  // SLAM: held until odometry reaches its time
      pending.push_back(&log.slam[is++]);
    }
  }
  for (const SlamRecord* r : pending) process_slam(*r, sec(r->t_ns), dr_now, om_now);
  if (!pending.empty()) {  // keep the fused tracks' last pose current
    gated_track.push_back({sec(pending.back()->t_ns), gated.pose()});
  }
  res.gated_anchors = gated.anchor_count();
  if (res.slam_valid > 0 && res.gated_anchors == 0)
    res.warnings.push_back(
        "gated_fuser: SLAM map never anchored: none of the " + std::to_string(res.slam_valid) +
        " valid SLAM poses agreed with odometry (non-metric, e.g. monocular, SLAM scale? wrong "
        "robot.txt geometry? a frozen pose?); gated_fuser is odometry only");
  else if (res.slam_valid >= 20 && 2 * res.gated_fused < res.slam_valid)
    res.warnings.push_back(
        "gated_fuser: fused only " + std::to_string(res.gated_fused) + " of " +
        std::to_string(res.slam_valid) + " valid SLAM poses (" + std::to_string(res.gated_rejected) +
        " rejected by the gates, the rest spent anchoring): SLAM and odometry disagree "
        "(non-metric SLAM scale? wrong robot.txt geometry?)");
  if (res.attitude_stale_s > 1.0)
    res.warnings.push_back(
        "imu.csv: no attitude younger than " + detail::num_text(res.attitude_max_age_s, 3) +
        " s for " + detail::num_text(res.attitude_stale_s, 1) +
        " s of the wheel data (IMU starts late, stops early or has gaps); odometry_only and "
        "seed_fuser used the encoder heading plus the last compass offset there");

  // --- Metrics.
  res.turns_from_groundtruth = !res.groundtruth.empty();
  res.turns = detect_turns(res.turns_from_groundtruth ? res.groundtruth : res.dead_reckoning);
  const PlanarPose<double> start =
      res.groundtruth.empty() ? PlanarPose<double>{} : res.groundtruth.front().pose;
  for (std::size_t m = 0; m < 4; ++m)
    res.metrics[m] = evaluate_track(res.tracks[m], res.groundtruth, res.turns, start, 0.0,
                                    res.duration_s, cfg.gap_s);
  return res;
}

}  // namespace posefuse

#pragma once
/// @file
/// A seeded simulation of seed 001's corridor experiment (the indoor robot
/// whose visual SLAM is lost at a feature-poor corner; docs/reproductions.md),
/// written as a posefuse::RobotLog so that the same fusion code runs on it and
/// on recorded logs.
///
/// **Scenario.** A four-wheel skid-steer robot drives a 14 m x 9 m rectangular
/// corridor counter-clockwise from point 1 (a corner) and comes back to it:
/// world frame = odometry frame (origin and heading of the robot at start,
/// x forward, y left, z up). Corners: 1 = (0, 0), 2 = (14, 0), 3 = (14, 9),
/// 4 = (0, 9). The robot stands still, drives each leg with a trapezoidal
/// speed profile, stops, turns +90° in place with a trapezoidal rate profile,
/// and after the fourth turn is back at pose (0, 0, 0), where it stands still.
///
/// **Sensors** (each on its own clock, with jitter, so no two streams share
/// timestamps; every figure below is a CorridorSimConfig default):
/// * encoders (50 Hz): cumulative ticks of four wheels, quantised (floor).
///   The true wheel radii differ from `wheel_radius_m` by N(0, 0.1 %) each;
///   the true effective (skid) track is 1.5 % wider than `track_width_m` and
///   varies by N(0, 1 %) from turn to turn; every increment slips by N(0, 1 %).
/// * IMU (100 Hz, REP-103 body axes): specific force (longitudinal
///   acceleration, centripetal v·ω, +9.81 on z) with N(0, 0.05) m/s² noise and
///   a constant N(0, 0.05) m/s² bias per axis; gyro ω with N(0, 0.002) rad/s
///   noise and N(0, 0.003) rad/s bias; magnetometer: the Earth's field (30 µT
///   horizontal towards a random magnetic north, 40 µT down) plus a smooth
///   indoor disturbance (8 random 2 µT blobs, 1.5 m wide), distorted by soft
///   iron (I + N(0, 5 %) symmetric) and hard iron (N(0, 10) µT), with
///   N(0, 0.3) µT noise. The log carries no magnetometer calibration.
/// * SLAM (15 Hz): body pose in its map frame. Session 0's map frame is the
///   world frame; tracking starts after 0.5 s. Errors: white N(0, 2 cm) and
///   N(0, 0.3°), plus a Gauss-Markov drift (τ = 10 s, 3 cm, 0.5°). At
///   feature-poor corner 3 it fails the way the seed describes ("it cannot
///   tell the current place from the previous one"): 1.5 m before the corner
///   its pose freezes while still reported as `tracking` for 3 s, then it is
///   `lost` through the turn until the robot is 3 m into leg 3, where it
///   re-initialises (`reinit`) in a new map frame drawn uniformly: yaw in
///   [-π, π), x, y in ±5 m, z in [0, 0.5] m.
/// * ground truth (100 Hz): x, y, yaw.
///
/// Every run with the same config and seed gives the same log (mt19937_64 and
/// a portable Box-Muller; no std::normal_distribution).

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/sim/corridor_config.hpp>
#include <posefuse/sim/detail/rng.hpp>

namespace posefuse::sim {

/// One leg or turn of the drive, for evaluation.
struct CorridorManoeuvre {
  bool turn = false;     ///< true: +90° turn in place; false: straight leg
  double t_start_s = 0;  ///< start (s since t0)
  double t_end_s = 0;    ///< end (s since t0)
};

/// The simulated log and what the simulation knows about it.
struct CorridorSimulation {
  RobotLog log;                                  ///< the log (groundtruth.csv included)
  std::vector<CorridorManoeuvre> manoeuvres;     ///< legs and turns in order
  double t_freeze_s = 0;                         ///< SLAM pose freezes (s since t0)
  double t_lost_s = 0;                           ///< SLAM reports `lost` (s)
  double t_reinit_s = 0;                         ///< SLAM re-initialises (s)
  std::array<double, 3> T_world_map1{};          ///< re-init map frame in world (x, y, yaw)
  double duration_s = 0;                         ///< total duration (s)
};

namespace detail {

/// Trapezoidal profile over distance D: s(t), v(t), a(t) for t in [0, T].
struct Trapezoid {
  double D = 0, vmax = 1, a = 1, ta = 0, tc = 0, T = 0, vpk = 0;
  Trapezoid() = default;
  Trapezoid(double dist, double v, double acc) : D(dist), vmax(v), a(acc) {
    if (D * a < vmax * vmax) {
      vpk = std::sqrt(D * a);
      ta = vpk / a;
      tc = 0;
    } else {
      vpk = vmax;
      ta = vmax / a;
      tc = (D - vmax * vmax / a) / vmax;
    }
    T = 2 * ta + tc;
  }
  /// {s, v, a} at time t.
  [[nodiscard]] std::array<double, 3> at(double t) const {
    if (t <= 0) return {0, 0, 0};
    if (t >= T) return {D, 0, 0};
    if (t < ta) return {0.5 * a * t * t, a * t, a};
    if (t < ta + tc) return {0.5 * a * ta * ta + vpk * (t - ta), vpk, 0};
    const double r = T - t;
    return {D - 0.5 * a * r * r, a * r, -a};
  }
};

struct Segment {
  bool turn = false;
  double t0 = 0;
  Trapezoid prof;
  std::array<double, 3> start{};  // x, y, yaw
  double s0 = 0;                  // distance travelled before the segment
  double track_factor = 1;        // true effective track / nominal, this turn
};

/// Truth at one time: pose, body speed, yaw rate, longitudinal accel, distance.
struct TruthState {
  double x = 0, y = 0, yaw = 0, v = 0, w = 0, acc = 0, s = 0, track_factor = 1;
};

inline TruthState truth_at(const std::vector<Segment>& segs, double t) {
  const Segment* g = &segs.front();
  for (const Segment& c : segs) {
    if (c.t0 <= t) g = &c;
  }
  const auto [q, dq, ddq] = g->prof.at(t - g->t0);
  TruthState st;
  st.track_factor = g->track_factor;
  st.s = g->s0;
  if (g->turn) {
    st.x = g->start[0];
    st.y = g->start[1];
    st.yaw = wrap_angle(g->start[2] + q);
    st.w = dq;
  } else {
    st.x = g->start[0] + q * std::cos(g->start[2]);
    st.y = g->start[1] + q * std::sin(g->start[2]);
    st.yaw = g->start[2];
    st.v = dq;
    st.acc = ddq;
    st.s += q;
  }
  return st;
}

/// Sample times (s) of a stream with a phase offset and uniform jitter.
inline std::vector<double> sample_times(double rate_hz, double phase_s, double jitter_s,
                                        double duration_s, SeededRng& rng) {
  std::vector<double> t;
  const double dt = 1.0 / rate_hz;
  for (double k = 0;; ++k) {
    const double tk = phase_s + k * dt + rng.uniform(-jitter_s, jitter_s);
    if (phase_s + k * dt > duration_s) break;
    t.push_back(std::max(tk, 0.0));
  }
  return t;
}

/// The stamp t0_ns + t_s, rounded to the nanosecond.
/// @throws posefuse::invalid_argument when it does not fit in an int64
///         (t0_ns too close to the end of the range for the drive's duration)
inline std::int64_t to_ns(std::int64_t t0_ns, double t_s) {
  const std::int64_t d = std::int64_t(std::llround(t_s * 1e9));  // t_s >= 0, a few minutes
  if (t0_ns > std::numeric_limits<std::int64_t>::max() - d)
    throw invalid_argument("CorridorSimConfig: t0_ns " + std::to_string(t0_ns) + " + " +
                           std::to_string(t_s) + " s does not fit in int64 nanoseconds");
  return t0_ns + d;
}

/// Unit quaternion (x, y, z, w) of ZYX Euler angles.
inline std::array<double, 4> quat_from_zyx(double yaw, double pitch, double roll) {
  const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2), cp = std::cos(pitch / 2),
               sp = std::sin(pitch / 2), cr = std::cos(roll / 2), sr = std::sin(roll / 2);
  return {sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
          cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy};
}

}  // namespace detail

/// Simulates the corridor run (see the file comment for every error model).
/// @param[in] cfg  scenario and sensor parameters
/// @param[in] seed RNG seed; the same (cfg, seed) gives the same log
/// @return the log, the manoeuvres and the SLAM failure times
/// @throws posefuse::invalid_argument for an invalid config (validate())
[[nodiscard]] inline CorridorSimulation simulate_corridor(const CorridorSimConfig& cfg,
                                                          std::uint64_t seed) {
  validate(cfg);
  using detail::Segment;
  using detail::Trapezoid;
  detail::SeededRng rng(seed);
  constexpr double kPi = std::numbers::pi;
  CorridorSimulation out;
  // --- The drive: still, then 4 x (leg, pause, turn, pause), then still.
  std::vector<Segment> segs;
  double t = 0, s = 0;
  std::array<double, 3> pose{0, 0, 0};
  segs.push_back({false, 0, Trapezoid(0, 1, 1), pose, 0, 1});
  t = cfg.still_start_s;
  double s_corner3 = 0;
  for (int leg = 0; leg < 4; ++leg) {
    const double L = (leg % 2 == 0) ? cfg.leg_a_m : cfg.leg_b_m;
    Segment g{false, t, Trapezoid(L, cfg.cruise_speed_mps, cfg.accel_mps2), pose, s, 1};
    segs.push_back(g);
    out.manoeuvres.push_back({false, t, t + g.prof.T});
    t += g.prof.T + cfg.pause_s;
    s += L;
    pose = {pose[0] + L * std::cos(pose[2]), pose[1] + L * std::sin(pose[2]), pose[2]};
    if (leg == 1) s_corner3 = s;
    const double tf = 1 + cfg.track_error + rng.normal(cfg.track_turn_sigma);
    Segment r{true, t, Trapezoid(kPi / 2, cfg.turn_rate_radps, cfg.turn_accel_radps2), pose, s, tf};
    segs.push_back(r);
    out.manoeuvres.push_back({true, t, t + r.prof.T});
    t += r.prof.T;
    pose[2] = wrap_angle(pose[2] + kPi / 2);
    segs.push_back({false, t, Trapezoid(0, 1, 1), pose, s, 1});
    t += cfg.pause_s;
  }
  out.duration_s = t + cfg.still_end_s;
  const double T = out.duration_s;
  const auto truth = [&segs](double tt) { return detail::truth_at(segs, tt); };
  const auto time_at_distance = [&](double s_target) {  // bisection on s(t)
    double lo = 0, hi = T;
    for (int i = 0; i < 60; ++i) (truth(0.5 * (lo + hi)).s < s_target ? lo : hi) = 0.5 * (lo + hi);
    return hi;
  };
  // --- Fixed sensor errors.
  std::array<double, 4> radius_err{};  // fl, fr, bl, br
  for (double& e : radius_err) e = rng.normal(cfg.radius_error_sigma);
  std::array<double, 3> ba{}, bg{}, hard{};
  for (double& b : ba) b = rng.normal(cfg.accel_bias_sigma);
  for (double& b : bg) b = rng.normal(cfg.gyro_bias_sigma);
  for (double& b : hard) b = rng.normal(cfg.hard_iron_sigma_uT);
  std::array<std::array<double, 3>, 3> soft{};
  for (int i = 0; i < 3; ++i) {
    soft[i][i] = 1 + rng.normal(cfg.soft_iron_sigma);
    for (int j = 0; j < i; ++j) soft[i][j] = soft[j][i] = rng.normal(cfg.soft_iron_sigma);
  }
  const double north = rng.uniform(-kPi, kPi);
  struct Blob { double x, y; std::array<double, 3> m; };
  std::vector<Blob> blobs;
  for (int i = 0; i < cfg.disturbance_blobs; ++i) {
    Blob b{rng.uniform(-1, cfg.leg_a_m + 1), rng.uniform(-1, cfg.leg_b_m + 1), {}};
    for (double& m : b.m) m = rng.normal(cfg.disturbance_uT);
    blobs.push_back(b);
  }
  RobotLog& log = out.log;
  log.params = {cfg.ticks_per_rev, cfg.wheel_radius_m, cfg.track_width_m, cfg.complementary_alpha,
                cfg.fuser_threshold};
  // --- Ground truth.
  for (double tt : detail::sample_times(cfg.truth_rate_hz, 0, 0, T, rng)) {
    const auto st = truth(tt);
    log.groundtruth.push_back({detail::to_ns(cfg.t0_ns, tt), Eigen::Vector3d(st.x, st.y, st.yaw)});
  }
  // --- Encoders: integrate each wheel's angle between samples (1 ms steps);
  // the increment since the previous sample slips by N(0, slip_sigma).
  {
    std::array<double, 4> phi{};  // wheel angles (rad): fl, fr, bl, br
    double t_prev = 0;
    detail::TruthState prev = truth(0);
    for (double tt : detail::sample_times(cfg.wheel_rate_hz, 0.003, cfg.jitter_s, T, rng)) {
      std::array<double, 4> dphi{};
      const int n = std::max(1, int(std::ceil((tt - t_prev) / 1e-3)));
      for (int k = 1; k <= n; ++k) {
        const auto cur = truth(t_prev + (tt - t_prev) * k / n);
        const double ds = cur.s - prev.s, dth = angle_diff(cur.yaw, prev.yaw);
        const double half = 0.5 * cfg.track_width_m * cur.track_factor;
        for (std::size_t wi = 0; wi < 4; ++wi) {
          const double side = (wi % 2 == 0) ? -1.0 : 1.0;  // fl, bl left; fr, br right
          dphi[wi] += (ds + side * half * dth) / (cfg.wheel_radius_m * (1 + radius_err[wi]));
        }
        prev = cur;
      }
      std::array<std::int64_t, 4> ticks{};
      for (std::size_t wi = 0; wi < 4; ++wi) {
        phi[wi] += dphi[wi] * (1 + rng.normal(cfg.slip_sigma));
        ticks[wi] = std::int64_t(std::floor(phi[wi] * cfg.ticks_per_rev / (2 * kPi)));
      }
      log.wheels.push_back({detail::to_ns(cfg.t0_ns, tt), {ticks[0], ticks[1], ticks[2], ticks[3]}});
      t_prev = tt;
    }
  }
  // --- IMU: planar motion, so roll = pitch = 0 and body = Rz(yaw)^T world.
  for (double tt : detail::sample_times(cfg.imu_rate_hz, 0.001, cfg.jitter_s, T, rng)) {
    const auto st = truth(tt);
    ImuSample r;
    r.t_ns = detail::to_ns(cfg.t0_ns, tt);
    const std::array<double, 3> f{st.acc, st.v * st.w, 9.81};
    for (std::size_t i = 0; i < 3; ++i)
      r.accel_mps2(Eigen::Index(i)) = f[i] + ba[i] + rng.normal(cfg.accel_noise);
    const std::array<double, 3> w{0, 0, st.w};
    for (std::size_t i = 0; i < 3; ++i)
      r.gyro_radps(Eigen::Index(i)) = w[i] + bg[i] + rng.normal(cfg.gyro_noise);
    std::array<double, 3> mw{cfg.earth_h_uT * std::cos(north), cfg.earth_h_uT * std::sin(north),
                             -cfg.earth_v_uT};
    for (const Blob& b : blobs) {
      const double d2 = (st.x - b.x) * (st.x - b.x) + (st.y - b.y) * (st.y - b.y);
      const double g = std::exp(-0.5 * d2 / (cfg.disturbance_width_m * cfg.disturbance_width_m));
      for (std::size_t i = 0; i < 3; ++i) mw[i] += g * b.m[i];
    }
    const double c = std::cos(st.yaw), sn = std::sin(st.yaw);
    const std::array<double, 3> mb{c * mw[0] + sn * mw[1], -sn * mw[0] + c * mw[1], mw[2]};
    for (std::size_t i = 0; i < 3; ++i) {
      double m = hard[i] + rng.normal(cfg.mag_noise_uT);
      for (std::size_t j = 0; j < 3; ++j) m += soft[i][j] * mb[j];
      r.mag_uT(Eigen::Index(i)) = m;
    }
    log.imu.push_back(r);
  }
  // --- SLAM: session 0 = world frame; freeze, lost, re-init in a new frame.
  out.t_freeze_s = time_at_distance(s_corner3 - cfg.freeze_before_corner3_m);
  out.t_lost_s = out.t_freeze_s + cfg.frozen_s;
  out.t_reinit_s = time_at_distance(s_corner3 + cfg.reinit_after_corner3_m);
  const std::array<double, 3> m1{rng.uniform(-cfg.reinit_xy_m, cfg.reinit_xy_m),
                                 rng.uniform(-cfg.reinit_xy_m, cfg.reinit_xy_m),
                                 rng.uniform(-kPi, kPi)};
  out.T_world_map1 = m1;
  const double z1 = rng.uniform(0, cfg.reinit_z_m);
  const auto frozen = truth(out.t_freeze_s);
  std::array<double, 3> drift{};  // Gauss-Markov x, y, yaw
  double t_prev = 0;
  bool reinit_done = false;
  for (double tt : detail::sample_times(cfg.slam_rate_hz, 0.017, cfg.jitter_s, T, rng)) {
    const double phi_gm = std::exp(-(tt - t_prev) / cfg.slam_drift_tau_s);
    const std::array<double, 3> sd{cfg.slam_drift_xy, cfg.slam_drift_xy, cfg.slam_drift_yaw};
    for (std::size_t i = 0; i < 3; ++i)
      drift[i] = phi_gm * drift[i] + std::sqrt(1 - phi_gm * phi_gm) * rng.normal(sd[i]);
    t_prev = tt;
    SlamSample r;
    r.t_ns = detail::to_ns(cfg.t0_ns, tt);
    if (tt < cfg.slam_init_s || (tt >= out.t_lost_s && tt < out.t_reinit_s)) {
      r.state = SlamState::kLost;  // pose fields stay (0, 0, 0), identity (0, 0, 0, 1)
      log.slam.push_back(r);
      continue;
    }
    auto st = (tt >= out.t_freeze_s && tt < out.t_lost_s) ? frozen : truth(tt);
    double x = st.x + drift[0] + rng.normal(cfg.slam_sigma_xy);
    double y = st.y + drift[1] + rng.normal(cfg.slam_sigma_xy);
    double yaw = st.yaw + drift[2] + rng.normal(cfg.slam_sigma_yaw);
    double z = rng.normal(cfg.slam_sigma_xy);
    r.state = SlamState::kTracking;
    if (tt >= out.t_reinit_s) {  // express in map 1: T_map1_world * T_world_body
      const double c = std::cos(m1[2]), sn = std::sin(m1[2]);
      const double dx = x - m1[0], dy = y - m1[1];
      x = c * dx + sn * dy;
      y = -sn * dx + c * dy;
      yaw -= m1[2];
      z += z1;
      if (!reinit_done) r.state = SlamState::kReinit;
      reinit_done = true;
    }
    r.position_m = Eigen::Vector3d(x, y, z);
    // One draw per statement (the order of function arguments is unspecified:
    // g++ and clang drew these two in opposite orders); roll first, as the
    // published tables were made.
    const double roll_noise = rng.normal(cfg.slam_sigma_yaw);
    const double pitch_noise = rng.normal(cfg.slam_sigma_yaw);
    const std::array<double, 4> q = detail::quat_from_zyx(wrap_angle(yaw), pitch_noise, roll_noise);
    r.orientation.coeffs() << q[0], q[1], q[2], q[3];  // x, y, z, w
    log.slam.push_back(r);
  }
  return out;
}

}  // namespace posefuse::sim

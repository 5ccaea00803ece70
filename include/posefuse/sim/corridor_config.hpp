#pragma once
/// @file
/// The parameters of the seed-001 corridor simulation (sim/corridor.hpp
/// documents what each one models) and their validation.

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include <posefuse/core/error.hpp>

namespace posefuse::sim {

/// Parameters of simulate_corridor(); defaults are the documented scenario.
struct CorridorSimConfig {
  double leg_a_m = 14.0;            ///< legs 1→2 and 3→4 (m)
  double leg_b_m = 9.0;             ///< legs 2→3 and 4→1 (m)
  double cruise_speed_mps = 0.4;    ///< cruise speed on straights (m/s)
  double accel_mps2 = 0.3;          ///< straight-line acceleration (m/s²)
  double turn_rate_radps = 0.6;     ///< peak in-place turn rate (rad/s)
  double turn_accel_radps2 = 1.0;   ///< turn-rate acceleration (rad/s²)
  double still_start_s = 3.0;       ///< standstill before moving (s)
  double still_end_s = 2.0;         ///< standstill after the last turn (s)
  double pause_s = 0.5;             ///< standstill before and after each turn (s)
  double wheel_rate_hz = 50;        ///< encoder sample rate (Hz)
  double imu_rate_hz = 100;         ///< IMU sample rate (Hz)
  double slam_rate_hz = 15;         ///< SLAM pose rate (Hz)
  double truth_rate_hz = 100;       ///< ground-truth rate (Hz)
  double jitter_s = 0.002;          ///< uniform timestamp jitter, ± (s)
  std::int64_t t0_ns = 1'600'000'000'000'000'000;  ///< clock value of t = 0 (ns)
  double ticks_per_rev = 1320;      ///< encoder ticks per wheel revolution (robot.txt)
  double wheel_radius_m = 0.065;    ///< nominal wheel radius (m, robot.txt)
  double track_width_m = 0.40;      ///< nominal effective track (m, robot.txt)
  double complementary_alpha = 0.98;  ///< written to robot.txt (seed eq 3-4)
  double fuser_threshold = 0.01;      ///< written to robot.txt (seed eq 15, m·rad)
  double radius_error_sigma = 0.001;  ///< relative, fixed per wheel
  double track_error = 0.015;         ///< true effective track / nominal - 1
  double track_turn_sigma = 0.01;     ///< relative, per turn
  double slip_sigma = 0.01;           ///< relative, per encoder increment
  double accel_noise = 0.05;        ///< accelerometer white noise per sample (m/s²)
  double accel_bias_sigma = 0.05;   ///< accelerometer constant bias, per axis (m/s²)
  double gyro_noise = 0.002;        ///< gyro white noise per sample (rad/s)
  double gyro_bias_sigma = 0.003;   ///< gyro constant bias, per axis (rad/s)
  double earth_h_uT = 30;           ///< horizontal Earth field (µT)
  double earth_v_uT = 40;           ///< downward Earth field (µT)
  double mag_noise_uT = 0.3;        ///< magnetometer white noise (µT)
  double hard_iron_sigma_uT = 10;   ///< hard-iron offset, per axis (µT)
  double soft_iron_sigma = 0.05;    ///< soft-iron matrix I + symmetric N(0, σ)
  double disturbance_uT = 2;        ///< indoor field disturbance per blob, per axis (µT)
  double disturbance_width_m = 1.5; ///< blob width (m, 1-σ of a Gaussian)
  int disturbance_blobs = 8;        ///< number of disturbance blobs
  double slam_init_s = 0.5;                         ///< tracking starts (s)
  double slam_sigma_xy = 0.02;      ///< white position noise (m)
  double slam_sigma_yaw = 0.005;    ///< white yaw (and roll/pitch) noise (rad)
  double slam_drift_xy = 0.03;      ///< Gauss-Markov position drift σ (m)
  double slam_drift_yaw = 0.009;    ///< Gauss-Markov yaw drift σ (rad)
  double slam_drift_tau_s = 10;     ///< Gauss-Markov time constant (s)
  double freeze_before_corner3_m = 1.5;  ///< the pose freezes this far before corner 3
  double frozen_s = 3.0;                 ///< frozen but reported `tracking` (s)
  double reinit_after_corner3_m = 3.0;   ///< re-initialisation this far into leg 3
  double reinit_xy_m = 5.0;         ///< new map frame: x, y uniform in ± this (m)
  double reinit_z_m = 0.5;          ///< new map frame: z uniform in [0, this] (m)
};

/// Checks a CorridorSimConfig.
/// @throws posefuse::invalid_argument naming the first field that is not
///         finite, not positive where it must be (lengths, speeds, rates,
///         robot geometry, the fuser threshold, widths, tau), negative where it
///         must not be (durations, sigmas, noise, the map-frame ranges), a
///         jitter of half a sample period or more for any stream (stamps
///         would not increase), alpha outside (0, 1), track_error <= -1, or a
///         SLAM failure outside the drive (freeze before the start, re-init
///         beyond leg 3)
inline void validate(const CorridorSimConfig& c) {
  const auto fail = [](const std::string& why) { throw invalid_argument("CorridorSimConfig: " + why); };
  const std::pair<const char*, double> positive[] = {
      {"leg_a_m", c.leg_a_m}, {"leg_b_m", c.leg_b_m}, {"cruise_speed_mps", c.cruise_speed_mps},
      {"accel_mps2", c.accel_mps2}, {"turn_rate_radps", c.turn_rate_radps},
      {"turn_accel_radps2", c.turn_accel_radps2}, {"wheel_rate_hz", c.wheel_rate_hz},
      {"imu_rate_hz", c.imu_rate_hz}, {"slam_rate_hz", c.slam_rate_hz},
      {"truth_rate_hz", c.truth_rate_hz}, {"ticks_per_rev", c.ticks_per_rev},
      {"wheel_radius_m", c.wheel_radius_m}, {"track_width_m", c.track_width_m},
      {"fuser_threshold", c.fuser_threshold}, {"disturbance_width_m", c.disturbance_width_m},
      {"slam_drift_tau_s", c.slam_drift_tau_s}, {"reinit_after_corner3_m", c.reinit_after_corner3_m}};
  for (const auto& [name, v] : positive)
    if (!std::isfinite(v) || !(v > 0)) fail(std::string(name) + " must be positive and finite");
  const std::pair<const char*, double> non_negative[] = {
      {"still_start_s", c.still_start_s}, {"still_end_s", c.still_end_s}, {"pause_s", c.pause_s},
      {"jitter_s", c.jitter_s}, {"radius_error_sigma", c.radius_error_sigma},
      {"track_turn_sigma", c.track_turn_sigma}, {"slip_sigma", c.slip_sigma},
      {"accel_noise", c.accel_noise}, {"accel_bias_sigma", c.accel_bias_sigma},
      {"gyro_noise", c.gyro_noise}, {"gyro_bias_sigma", c.gyro_bias_sigma},
      {"earth_h_uT", c.earth_h_uT}, {"earth_v_uT", c.earth_v_uT}, {"mag_noise_uT", c.mag_noise_uT},
      {"hard_iron_sigma_uT", c.hard_iron_sigma_uT}, {"soft_iron_sigma", c.soft_iron_sigma},
      {"disturbance_uT", c.disturbance_uT}, {"slam_init_s", c.slam_init_s},
      {"slam_sigma_xy", c.slam_sigma_xy}, {"slam_sigma_yaw", c.slam_sigma_yaw},
      {"slam_drift_xy", c.slam_drift_xy}, {"slam_drift_yaw", c.slam_drift_yaw},
      {"freeze_before_corner3_m", c.freeze_before_corner3_m}, {"frozen_s", c.frozen_s},
      {"reinit_xy_m", c.reinit_xy_m}, {"reinit_z_m", c.reinit_z_m}};
  for (const auto& [name, v] : non_negative)
    if (!std::isfinite(v) || v < 0) fail(std::string(name) + " must be >= 0 and finite");
  for (const auto& [name, hz] : {std::pair<const char*, double>{"wheel_rate_hz", c.wheel_rate_hz},
                                 {"imu_rate_hz", c.imu_rate_hz}, {"slam_rate_hz", c.slam_rate_hz}})
    if (!(c.jitter_s < 0.5 / hz))
      fail("jitter_s must be less than half the sample period of " + std::string(name) +
           " (stamps would not increase)");
  if (!(c.complementary_alpha > 0 && c.complementary_alpha < 1))
    fail("complementary_alpha must lie in (0, 1)");
  if (!std::isfinite(c.track_error) || !(c.track_error > -1)) fail("track_error must be > -1");
  if (c.disturbance_blobs < 0) fail("disturbance_blobs must be >= 0");
  if (!(c.freeze_before_corner3_m < c.leg_a_m + c.leg_b_m))
    fail("freeze_before_corner3_m must be shorter than legs 1 and 2");
  if (!(c.reinit_after_corner3_m < c.leg_a_m)) fail("reinit_after_corner3_m must lie within leg 3");
}

}  // namespace posefuse::sim

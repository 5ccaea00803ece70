#pragma once
/// @file
/// The flags of a program that reads or writes an IMU: the reader's bounds
/// on a reading (posefuse::ImuReadOptions) and the noise densities
/// (posefuse::ImuNoise), the same in every such program.

#include <string>
#include <string_view>
#include <vector>

#include <posefuse/inertial/imu_types.hpp>
#include <posefuse/io/euroc.hpp>

#include "cli.hpp"

namespace posefuse::apps {

/// Declares `--imu-max-gyro` and `--imu-max-accel`, bound to `bounds`.
inline void declare_imu_bounds(Parser& cli, ImuReadOptions& bounds) {
  cli.real_in({.name = "--imu-max-gyro", .value = "RAD/S",
               .help = "largest angular rate accepted per axis: a reading beyond\n"
                       "it is refused at its line (a corrupt or saturated sensor)",
               .unit = "rad/s"},
              bounds.max_abs_angular_rate, 1.0, kMaxAbsAngularRateLimit);
  cli.real_in({.name = "--imu-max-accel", .value = "M/S2",
               .help = "largest specific force accepted per axis (as --imu-max-gyro)", .unit = "m/s^2"},
              bounds.max_abs_specific_force, 10.0, kMaxAbsSpecificForceLimit);
}

/// "NA,NG,WA,WG": the accelerometer and gyroscope noise densities, then their
/// random walks (m/s^2/sqrt(Hz), rad/s/sqrt(Hz), m/s^3/sqrt(Hz),
/// rad/s^2/sqrt(Hz)), each from `lo` to 100.
/// @param[in] text the flag's value
/// @param[in] lo   smallest value accepted: 0 admits a noise-free IMU (a
///                 simulator's), a positive bound keeps an estimator's
///                 information finite
/// @return the noise, with each density and walk where ImuNoise keeps it
/// @throws usage_error for another count, a non-number or a value out of range
[[nodiscard]] inline ImuNoise parse_imu_noise(std::string_view text, double lo) {
  const std::vector<std::string_view> items = split_commas(text, 4, 4, "four comma-separated numbers");
  double x[4];
  for (std::size_t i = 0; i < 4; ++i) {
    x[i] = parse_real(items[i], lo > 0 ? Domain::kPositive : Domain::kNonNegative);
    if (!(x[i] >= lo && x[i] <= 100.0))
      throw usage_error("each value must be from " + num(lo) + " to 100, got '" + std::string(text) + "'");
  }
  return ImuNoise{x[1], x[0], x[3], x[2]};
}

}  // namespace posefuse::apps

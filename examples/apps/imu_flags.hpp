#pragma once
/// @file
/// The flags of a program that reads an IMU: the reader's bounds on a
/// reading (posefuse::ImuReadOptions), the same in every such program.

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

}  // namespace posefuse::apps

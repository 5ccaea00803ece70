// libFuzzer harness: the robot-log folder (read_robot_log and
// read_robot_params of io/robot_log.hpp, with the checks of
// io/robot_log_checks.hpp).
//
// Input: robot.txt, wheels.csv, imu.csv, slam.csv and groundtruth.csv, in
// this order, separated by NUL bytes; a file the input does not reach is
// absent from the folder. Expected rejection: posefuse::io_error. Properties
// of an accepted log: every documented invariant holds (positive parameters,
// alpha in (0, 1), at least two wheel rows and one IMU row, strictly
// increasing t_ns per stream, finite values except in `lost` SLAM rows, unit
// quaternions within 1e-2), and write_robot_log + read_robot_log give back
// the same log bit for bit (NaN in lost rows compares equal to NaN).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/io/robot_log.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;
using posefuse_fuzz::same_number;

constexpr const char* kFiles[5] = {"robot.txt", "wheels.csv", "imu.csv", "slam.csv",
                                   "groundtruth.csv"};

template <class Rows>
void require_increasing(const Rows& rows, const char* name) {
  for (std::size_t i = 1; i < rows.size(); ++i) {
    require(rows[i].t_ns > rows[i - 1].t_ns,
            std::string("read_robot_log returned ") + name + " rows whose t_ns do not increase");
  }
}

bool same_vec(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return same_number(a(0), b(0)) && same_number(a(1), b(1)) && same_number(a(2), b(2));
}

bool same_log(const posefuse::RobotLog& a, const posefuse::RobotLog& b) {
  const auto& p = a.params;
  const auto& q = b.params;
  if (!same_number(p.ticks_per_rev, q.ticks_per_rev) || !same_number(p.wheel_radius_m, q.wheel_radius_m) ||
      !same_number(p.track_width_m, q.track_width_m) ||
      !same_number(p.complementary_alpha, q.complementary_alpha) ||
      !same_number(p.fuser_threshold, q.fuser_threshold))
    return false;
  if (a.wheels != b.wheels) return false;  // integers only
  if (a.imu.size() != b.imu.size() || a.slam.size() != b.slam.size() ||
      a.groundtruth.size() != b.groundtruth.size())
    return false;
  for (std::size_t i = 0; i < a.imu.size(); ++i) {
    const auto& x = a.imu[i];
    const auto& y = b.imu[i];
    if (x.t_ns != y.t_ns || !same_vec(x.accel_mps2, y.accel_mps2) ||
        !same_vec(x.gyro_radps, y.gyro_radps) || !same_vec(x.mag_uT, y.mag_uT))
      return false;
  }
  for (std::size_t i = 0; i < a.slam.size(); ++i) {
    const auto& x = a.slam[i];
    const auto& y = b.slam[i];
    if (x.t_ns != y.t_ns || x.state != y.state || !same_vec(x.position_m, y.position_m)) return false;
    for (Eigen::Index k = 0; k < 4; ++k) {
      if (!same_number(x.orientation.coeffs()(k), y.orientation.coeffs()(k))) return false;
    }
  }
  for (std::size_t i = 0; i < a.groundtruth.size(); ++i) {
    if (a.groundtruth[i].t_ns != b.groundtruth[i].t_ns ||
        !same_vec(a.groundtruth[i].pose, b.groundtruth[i].pose))
      return false;
  }
  return true;
}

void check_accepted(const posefuse::RobotLog& log, const posefuse_fuzz::ScratchDir& dir) {
  const auto& p = log.params;
  for (const double v : {p.ticks_per_rev, p.wheel_radius_m, p.track_width_m, p.complementary_alpha,
                         p.fuser_threshold}) {
    require(std::isfinite(v) && v > 0, "read_robot_log returned a non-positive parameter");
  }
  require(p.complementary_alpha < 1, "read_robot_log returned complementary_alpha >= 1");
  require(log.wheels.size() >= 2, "read_robot_log returned fewer than two wheel rows");
  require(!log.imu.empty(), "read_robot_log returned no IMU row");
  require_increasing(log.wheels, "wheels.csv");
  require_increasing(log.imu, "imu.csv");
  require_increasing(log.slam, "slam.csv");
  require_increasing(log.groundtruth, "groundtruth.csv");
  for (const auto& r : log.imu) {
    require(r.accel_mps2.allFinite() && r.gyro_radps.allFinite() && r.mag_uT.allFinite(),
            "read_robot_log returned a non-finite IMU value");
  }
  for (const auto& r : log.slam) {
    if (r.state == posefuse::SlamState::kLost) continue;
    require(r.position_m.allFinite() && r.orientation.coeffs().allFinite(),
            "read_robot_log returned a non-finite pose in a tracking/reinit SLAM row");
    require(std::abs(r.orientation.norm() - 1.0) < 1e-2,
            "read_robot_log returned a SLAM quaternion that is not unit length within 1e-2");
  }
  for (const auto& r : log.groundtruth) {
    require(r.pose.allFinite(), "read_robot_log returned a non-finite ground-truth pose");
  }
  const auto out = dir / "roundtrip";
  posefuse::write_robot_log(out, log);
  const posefuse::RobotLog back = posefuse::read_robot_log(out);
  require(same_log(log, back), "write_robot_log + read_robot_log changed the log");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir scratch("robot_log");
  const auto dir = scratch / "log";
  std::filesystem::create_directories(dir);
  const auto parts = posefuse_fuzz::split_files(data, size, 5);
  for (std::size_t i = 0; i < 5; ++i) {
    if (i < parts.size()) {
      posefuse_fuzz::write_bytes(dir / kFiles[i], parts[i]);
    } else {
      std::error_code ec;
      std::filesystem::remove(dir / kFiles[i], ec);
    }
  }
  posefuse::RobotLog log;
  try {
    log = posefuse::read_robot_log(dir);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "io_error without a file name");
    return 0;
  }
  check_accepted(log, scratch);
  return 0;
}

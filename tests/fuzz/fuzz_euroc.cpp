// libFuzzer harness: EuRoC csv files (io/euroc.hpp): the IMU file
// (read_euroc_imu) and the state ground truth (read_euroc_groundtruth).
//
// Input: the IMU file, a NUL byte, the ground-truth file (without a NUL the
// whole input is read as both). Expected rejection: posefuse::io_error
// naming the file. Properties of an accepted file: stamps strictly
// increase, every number is finite, the ground truth's trajectory
// validate()s with one stamp t_s = t_ns * 1e-9 per pose, and velocity and
// biases are present together with one value per state.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include <posefuse/core/error.hpp>
#include <posefuse/io/euroc.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;

void imu(const std::filesystem::path& file) {
  std::vector<posefuse::ImuSample> s;
  try {
    s = posefuse::read_euroc_imu(file);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "read_euroc_imu: io_error without a file name");
    return;
  }
  require(!s.empty(), "read_euroc_imu accepted a file without samples");
  for (std::size_t k = 0; k < s.size(); ++k) {
    require(s[k].accel_mps2.allFinite() && s[k].gyro_radps.allFinite(),
            "read_euroc_imu: sample " + std::to_string(k) + " is not finite");
    require(k == 0 || s[k].t_ns > s[k - 1].t_ns, "read_euroc_imu: stamps do not increase");
  }
}

void groundtruth(const std::filesystem::path& file) {
  posefuse::EurocGroundTruth gt;
  try {
    gt = posefuse::read_euroc_groundtruth(file);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "read_euroc_groundtruth: io_error without a file name");
    return;
  }
  require(gt.size() > 0 && gt.trajectory.size() == gt.size(),
          "read_euroc_groundtruth: stamps and poses differ in number");
  try {
    gt.trajectory.validate();
  } catch (const posefuse::invalid_argument& e) {
    posefuse_fuzz::finding(std::string("read_euroc_groundtruth: trajectory fails validate(): ") + e.what());
  }
  for (std::size_t k = 0; k < gt.size(); ++k)
    require(k == 0 || gt.t_ns[k] > gt.t_ns[k - 1], "read_euroc_groundtruth: stamps do not increase");
  const bool v = gt.velocity.has_value();
  require(gt.gyro_bias.has_value() == v && gt.accel_bias.has_value() == v,
          "read_euroc_groundtruth: velocity and biases not present together");
  if (!v) return;
  require(gt.velocity->size() == gt.size() && gt.gyro_bias->size() == gt.size() &&
              gt.accel_bias->size() == gt.size(),
          "read_euroc_groundtruth: one velocity and bias per state");
  for (std::size_t k = 0; k < gt.size(); ++k)
    require((*gt.velocity)[k].allFinite() && (*gt.gyro_bias)[k].allFinite() && (*gt.accel_bias)[k].allFinite(),
            "read_euroc_groundtruth: state " + std::to_string(k) + " is not finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir dir("euroc");
  const auto parts = posefuse_fuzz::split_files(data, size, 2);
  const auto imu_file = dir / "imu0.csv";
  const auto gt_file = dir / "data.csv";
  posefuse_fuzz::write_bytes(imu_file, parts.empty() ? std::string_view() : parts[0]);
  posefuse_fuzz::write_bytes(gt_file, parts.size() > 1 ? parts[1] : (parts.empty() ? std::string_view() : parts[0]));
  imu(imu_file);
  groundtruth(gt_file);
  return 0;
}

// libFuzzer harness: KITTI times.txt files (read_kitti_times, io/kitti.hpp).
//
// Input: the times file. Expected rejection: posefuse::io_error. Properties
// of an accepted file: every stamp is finite and greater than the one before,
// and write_kitti_times + read_kitti_times give back the same stamps bit for
// bit.

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/kitti.hpp>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir dir("kitti_times");
  const auto file = dir / "times.txt";
  posefuse_fuzz::write_bytes(file, std::string_view(reinterpret_cast<const char*>(data), size));
  std::vector<double> t;
  try {
    t = posefuse::read_kitti_times(file);
  } catch (const posefuse::io_error& e) {
    posefuse_fuzz::require(!e.file().empty(), "io_error without a file name");
    return 0;
  }
  for (std::size_t k = 0; k < t.size(); ++k) {
    posefuse_fuzz::require(std::isfinite(t[k]), "read_kitti_times returned a non-finite stamp");
    posefuse_fuzz::require(k == 0 || t[k] > t[k - 1],
                           "read_kitti_times returned stamps that do not increase at index " +
                               std::to_string(k));
  }
  posefuse::Trajectory traj;
  for (const double s : t) traj.push_back(s, Eigen::Isometry3d::Identity());
  const auto file2 = dir / "roundtrip_times.txt";
  posefuse::write_kitti_times(file2, traj);
  const std::vector<double> back = posefuse::read_kitti_times(file2);
  posefuse_fuzz::require(back.size() == t.size(), "write_kitti_times + read_kitti_times changed the count");
  for (std::size_t k = 0; k < t.size(); ++k) {
    posefuse_fuzz::require(posefuse_fuzz::same_number(t[k], back[k]),
                           "write_kitti_times + read_kitti_times changed stamp " + std::to_string(k));
  }
  return 0;
}

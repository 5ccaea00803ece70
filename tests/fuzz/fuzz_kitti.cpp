// libFuzzer harness: KITTI pose files with an optional times.txt
// (io/kitti.hpp, through read_trajectory of io/formats.hpp).
//
// Input: the pose file, optionally followed by a NUL byte and the times
// file. Expected rejections: posefuse::io_error (posefuse::invalid_argument
// never applies here). Properties of an accepted file: the trajectory
// validate()s, every rotation is a rotation, the stamps are the frame indices
// when there is no times file, and write_kitti + write_kitti_times + read
// give back the same trajectory bit for bit (the documented round trip).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/kitti.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;

bool same_trajectory(const posefuse::Trajectory& a, const posefuse::Trajectory& b) {
  if (a.size() != b.size() || a.t_s.size() != b.t_s.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (!posefuse_fuzz::same_number(a.t_s[k], b.t_s[k])) return false;
    for (Eigen::Index i = 0; i < 16; ++i) {
      if (!posefuse_fuzz::same_number(a.poses[k].matrix()(i), b.poses[k].matrix()(i))) return false;
    }
  }
  return true;
}

void check_accepted(const posefuse::Trajectory& traj, bool with_times,
                    const posefuse_fuzz::ScratchDir& dir) {
  try {
    traj.validate();
  } catch (const posefuse::invalid_argument& e) {
    posefuse_fuzz::finding(std::string("read_kitti returned a trajectory that fails validate(): ") +
                           e.what());
  }
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const Eigen::Matrix3d R = traj.poses[k].linear();
    const double residual = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    // The reader keeps a rotation orthonormal to kExactlyOrthonormal and
    // replaces any other by its nearest rotation (residual ~1e-16).
    require(residual <= posefuse::detail::traj_io::kExactlyOrthonormal && R.determinant() > 0,
            "read_kitti returned pose " + std::to_string(k) + " whose rotation is not one (residual " +
                std::to_string(residual) + ")");
    require(traj.poses[k].matrix().row(3) == Eigen::RowVector4d(0, 0, 0, 1),
            "read_kitti returned a pose whose last row is not [0 0 0 1]");
    if (!with_times) {
      require(traj.t_s[k] == static_cast<double>(k),
              "without times.txt the stamps must be the frame indices");
    }
  }
  const auto poses2 = dir / "roundtrip_poses.txt";
  const auto times2 = dir / "roundtrip_times.txt";
  posefuse::write_kitti(poses2, traj);
  posefuse::write_kitti_times(times2, traj);
  const posefuse::Trajectory back = posefuse::read_kitti(poses2, times2);
  require(same_trajectory(traj, back),
          "write_kitti + write_kitti_times + read_kitti changed the trajectory");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir dir("kitti");
  const auto parts = posefuse_fuzz::split_files(data, size, 2);
  const auto poses_file = dir / "poses.txt";
  const auto times_file = dir / "times.txt";
  posefuse_fuzz::write_bytes(poses_file, parts[0]);
  std::optional<std::filesystem::path> times;
  if (parts.size() > 1) {
    posefuse_fuzz::write_bytes(times_file, parts[1]);
    times = times_file;
  }
  posefuse::Trajectory traj;
  try {
    traj = posefuse::read_trajectory(poses_file, posefuse::Format::kKitti, times);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "io_error without a file name");
    return 0;
  }
  check_accepted(traj, times.has_value(), dir);
  return 0;
}

// libFuzzer harness: TUM trajectory files (read_tum of io/tum.hpp, through
// read_trajectory of io/formats.hpp).
//
// Input: the TUM file. Expected rejection: posefuse::io_error. Properties of
// an accepted file: the trajectory validate()s, every rotation is one, and
// write_tum + read_tum give back the stamps and positions bit for bit and
// the rotations to within kRotationRoundTrip (write_tum documents "about
// 1e-16": the rotation goes matrix -> quaternion -> text -> quaternion ->
// matrix, a few roundings per step; 2e6 random rotations needed 7 eps).
// The same input also goes through read_tum_with_covariance with repeated
// stamps kept first: it validate()s, has one covariance per pose when it
// has covariance columns, each symmetric and positive definite in its block.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/tum.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;

/// Largest accepted max |R_back - R| after a write/read round trip.
constexpr double kRotationRoundTrip = 16 * std::numeric_limits<double>::epsilon();

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir dir("tum");
  const auto file = dir / "traj.tum";
  posefuse_fuzz::write_bytes(file, std::string_view(reinterpret_cast<const char*>(data), size));
  try {
    posefuse::ReadOptions options;
    options.duplicates = posefuse::DuplicateStamps::kFirst;
    posefuse::ReadReport report;
    const posefuse::TumWithCovariance c = posefuse::read_tum_with_covariance(file, options, &report);
    c.trajectory.validate();
    require(c.covariance_dim == 0 || c.covariance.size() == c.trajectory.size(),
            "read_tum_with_covariance: covariance count differs from pose count");
    for (const auto& C : c.covariance) {
      require(C == C.transpose(), "read_tum_with_covariance: covariance not symmetric");
      const bool pd = c.covariance_dim == 3 ? posefuse::is_positive_definite(C.topLeftCorner<3, 3>().eval())
                                            : posefuse::is_positive_definite(C);
      require(pd, "read_tum_with_covariance: covariance not positive definite");
    }
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "io_error without a file name");
  } catch (const posefuse::invalid_argument& e) {
    posefuse_fuzz::finding(std::string("read_tum_with_covariance returned an invalid trajectory: ") + e.what());
  }
  posefuse::Trajectory traj;
  try {
    traj = posefuse::read_trajectory(file, posefuse::Format::kTum);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "io_error without a file name");
    return 0;
  }
  try {
    traj.validate();
  } catch (const posefuse::invalid_argument& e) {
    posefuse_fuzz::finding(std::string("read_tum returned a trajectory that fails validate(): ") +
                           e.what());
  }
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const Eigen::Matrix3d R = traj.poses[k].linear();
    const double residual = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    require(residual <= kRotationRoundTrip && R.determinant() > 0,
            "read_tum returned pose " + std::to_string(k) + " whose rotation is not one (residual " +
                std::to_string(residual) + ")");
  }
  const auto file2 = dir / "roundtrip.tum";
  posefuse::write_tum(file2, traj);
  const posefuse::Trajectory back = posefuse::read_tum(file2);
  require(back.size() == traj.size() && back.t_s.size() == traj.t_s.size(),
          "write_tum + read_tum changed the number of poses");
  for (std::size_t k = 0; k < traj.size(); ++k) {
    require(posefuse_fuzz::same_number(traj.t_s[k], back.t_s[k]),
            "write_tum + read_tum changed stamp " + std::to_string(k));
    for (Eigen::Index i = 0; i < 3; ++i) {
      require(posefuse_fuzz::same_number(traj.poses[k].translation()(i), back.poses[k].translation()(i)),
              "write_tum + read_tum changed position " + std::to_string(k));
    }
    const double d = (back.poses[k].linear() - traj.poses[k].linear()).cwiseAbs().maxCoeff();
    require(d <= kRotationRoundTrip, "write_tum + read_tum changed rotation " + std::to_string(k) +
                                         " by " + std::to_string(d / std::numeric_limits<double>::epsilon()) +
                                         " eps");
  }
  return 0;
}

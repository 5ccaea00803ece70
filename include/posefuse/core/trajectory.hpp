#pragma once
/// @file
/// Trajectory: timestamps plus SE(3) poses, the common currency of io/ and eval/.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/plane.hpp>

namespace posefuse {

/// A timed sequence of poses \f$ T_{world,body}(t_k) \f$.
///
/// `stamps[k]` (s) belongs to `poses[k]`. A KITTI file read without its
/// `times.txt` gets the frame indices 0, 1, 2, ... as stamps. The struct is
/// a plain aggregate; call `validate()` to check its invariants.
struct Trajectory {
  /// Timestamps (s), strictly increasing once validated.
  std::vector<double> stamps;
  /// Poses \f$ T_{world,body} \f$: rotation body→world, translation = body origin in world (m).
  std::vector<Eigen::Isometry3d> poses;

  /// Number of poses.
  [[nodiscard]] std::size_t size() const noexcept { return poses.size(); }
  /// True when there is no pose.
  [[nodiscard]] bool empty() const noexcept { return poses.empty(); }

  /// Appends one timed pose (no checks; see `validate()`).
  void push_back(double stamp_s, const Eigen::Isometry3d& T_world_body) {
    stamps.push_back(stamp_s);
    poses.push_back(T_world_body);
  }

  /// The body positions \f$ p_k = t(T_{world,body,k}) \f$ in the world frame (m).
  [[nodiscard]] std::vector<Eigen::Vector3d> positions() const {
    std::vector<Eigen::Vector3d> p;
    p.reserve(poses.size());
    for (const Eigen::Isometry3d& T : poses) p.emplace_back(T.translation());
    return p;
  }

  /// Checks the invariants: as many stamps as poses, every stamp and pose
  /// entry finite, and strictly increasing stamps.
  /// @throws posefuse::invalid_argument naming the first offending index
  void validate() const {
    if (stamps.size() != poses.size()) {
      throw invalid_argument("trajectory has " + std::to_string(stamps.size()) + " stamps but " +
                             std::to_string(poses.size()) + " poses");
    }
    for (std::size_t k = 0; k < poses.size(); ++k) {
      if (!std::isfinite(stamps[k])) {
        throw invalid_argument("trajectory stamp " + std::to_string(k) + " is not finite");
      }
      if (!poses[k].matrix().allFinite()) {
        throw invalid_argument("trajectory pose " + std::to_string(k) + " is not finite");
      }
      if (k > 0 && !(stamps[k] > stamps[k - 1])) {
        throw invalid_argument("trajectory stamps are not strictly increasing at index " +
                               std::to_string(k));
      }
    }
  }
};

/// The sub-trajectory at the given indices, in the given order (indices may
/// repeat, as evo's `reduce_to_ids`).
/// @param[in] traj the trajectory
/// @param[in] ids indices into `traj`
/// @return `{traj.stamps[ids[i]], traj.poses[ids[i]]}` for every i
/// @throws posefuse::invalid_argument when an index is out of range or the
///         trajectory's stamp and pose counts differ
[[nodiscard]] inline Trajectory select(const Trajectory& traj, std::span<const std::size_t> ids) {
  if (traj.stamps.size() != traj.poses.size()) {
    throw invalid_argument("select: trajectory has mismatched stamp and pose counts");
  }
  Trajectory out;
  out.stamps.reserve(ids.size());
  out.poses.reserve(ids.size());
  for (const std::size_t i : ids) {
    if (i >= traj.size()) {
      throw invalid_argument("select: index " + std::to_string(i) + " out of range for " +
                             std::to_string(traj.size()) + " poses");
    }
    out.push_back(traj.stamps[i], traj.poses[i]);
  }
  return out;
}

/// Length of the polyline through the positions,
/// \f$ \sum_k \lVert p_{k+1} - p_k \rVert \f$ (m), as evo's `path_length()`.
[[nodiscard]] inline double path_length(const Trajectory& traj) noexcept {
  double length = 0.0;
  for (std::size_t k = 1; k < traj.poses.size(); ++k) {
    length += (traj.poses[k].translation() - traj.poses[k - 1].translation()).norm();
  }
  return length;
}

/// Projects every position of `traj` onto `plane` (see `project_to_plane`).
/// @param[in] traj the trajectory
/// @param[in] plane the plane to keep (`Plane::kXZ` for KITTI's road plane)
/// @return one 2-D point per pose (m)
[[nodiscard]] inline std::vector<Eigen::Vector2d> project_to_plane(const Trajectory& traj,
                                                                   Plane plane) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(traj.poses.size());
  for (const Eigen::Isometry3d& T : traj.poses) out.push_back(project_to_plane(T, plane));
  return out;
}

}  // namespace posefuse

#pragma once
/// @file
/// Trajectory: timestamps plus SE(3) poses, the one stamped-pose vocabulary
/// of io/, eval/, filters/ and the examples; and its planar counterpart
/// PlanarTrajectory: timestamps plus (x, y, θ) poses, for ground robots.
///
/// **Time convention (the whole library).** A raw sensor sample carries its
/// stamp as an integer `t_ns` (std::int64_t nanoseconds: exact, comparable,
/// the unit of recorded logs). Everything that does arithmetic with time —
/// trajectories, filter steps, interpolation — uses seconds as `double`,
/// spelled `t_s` (a time) and `dt_s` (a step). Converting one to the other is
/// `seconds_from_ns` / `ns_from_seconds` (core/time.hpp).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/core/plane.hpp>

namespace posefuse {

/// A timed sequence of poses \f$ T_{world,body}(t_k) \f$.
///
/// `t_s[k]` (s) belongs to `poses[k]`. A KITTI file read without its
/// `times.txt` gets the frame indices 0, 1, 2, ... as stamps. The struct is
/// a plain aggregate; call `validate()` to check its invariants.
struct Trajectory {
  /// Timestamps (s), strictly increasing once validated.
  std::vector<double> t_s;
  /// Poses \f$ T_{world,body} \f$: rotation body→world, translation = body origin in world (m).
  std::vector<Eigen::Isometry3d> poses;

  /// Number of poses.
  [[nodiscard]] std::size_t size() const noexcept { return poses.size(); }
  /// True when there is no pose.
  [[nodiscard]] bool empty() const noexcept { return poses.empty(); }

  /// Appends one timed pose (no checks; see `validate()`).
  void push_back(double stamp_s, const Eigen::Isometry3d& T_world_body) {
    t_s.push_back(stamp_s);
    poses.push_back(T_world_body);
  }

  /// The body positions \f$ p_k = t(T_{world,body,k}) \f$ in the world frame (m).
  template <class Lazy = void>  // compiled only where called (compile cost, core/lazy.hpp)
  [[nodiscard]] std::vector<Eigen::Vector3d> positions() const {
    std::vector<Eigen::Vector3d> p;
    p.reserve(poses.size());
    for (const detail::dependent_t<Eigen::Isometry3d, Lazy>& T : poses) p.emplace_back(T.translation());
    return p;
  }

  /// Checks the invariants: as many stamps as poses, every stamp and pose
  /// entry finite, and strictly increasing stamps.
  /// @throws posefuse::invalid_argument naming the first offending index
  template <class Lazy = void>  // compiled only where called (compile cost, core/lazy.hpp)
  void validate() const {
    if (t_s.size() != poses.size()) {
      throw invalid_argument("trajectory has " + std::to_string(t_s.size()) + " stamps but " +
                             std::to_string(poses.size()) + " poses");
    }
    for (std::size_t k = 0; k < poses.size(); ++k) {
      if (!std::isfinite(t_s[k])) {
        throw invalid_argument("trajectory stamp " + std::to_string(k) + " is not finite");
      }
      const detail::dependent_t<Eigen::Isometry3d, Lazy>& T = poses[k];
      if (!T.matrix().allFinite()) {
        throw invalid_argument("trajectory pose " + std::to_string(k) + " is not finite");
      }
      if (k > 0 && !(t_s[k] > t_s[k - 1])) {
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
/// @return `{traj.t_s[ids[i]], traj.poses[ids[i]]}` for every i
/// @throws posefuse::invalid_argument when an index is out of range or the
///         trajectory's stamp and pose counts differ
template <class Lazy = void>
[[nodiscard]] Trajectory select(const Trajectory& traj, std::span<const std::size_t> ids) {
  if (traj.t_s.size() != traj.poses.size()) {
    throw invalid_argument("select: trajectory has mismatched stamp and pose counts");
  }
  Trajectory out;
  out.t_s.reserve(ids.size());
  out.poses.reserve(ids.size());
  for (const std::size_t i : ids) {
    if (i >= traj.size()) {
      throw invalid_argument("select: index " + std::to_string(i) + " out of range for " +
                             std::to_string(traj.size()) + " poses");
    }
    out.push_back(traj.t_s[i], traj.poses[i]);
  }
  return out;
}

/// Length of the polyline through the positions,
/// \f$ \sum_k \lVert p_{k+1} - p_k \rVert \f$ (m), as evo's `path_length()`.
template <class Lazy = void>
[[nodiscard]] double path_length(const Trajectory& traj) noexcept {
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
template <class Lazy = void>
[[nodiscard]] std::vector<Eigen::Vector2d> project_to_plane(const Trajectory& traj,
                                                            Plane plane) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(traj.poses.size());
  for (const Eigen::Isometry3d& T : traj.poses) out.push_back(project_to_plane(T, plane));
  return out;
}

/// A timed sequence of planar poses of a body in a 2-D world frame: the
/// planar counterpart of Trajectory, used by ground-robot odometry, fusion
/// and planar metrics (eval/planar_metrics.hpp).
///
/// `poses[k]` = \f$ (x_k, y_k, \theta_k) \f$ — position (m) and heading
/// (rad, counter-clockwise from the world x axis) of the body at `t_s[k]`
/// (s): the layout of `PlanarPose::vector()` (models/planar_pose.hpp) and of
/// PlanarPoseSample (core/samples.hpp). The poses are stored as
/// `Eigen::Vector3d` because this header is in core/, below models/ where
/// PlanarPose lives; `PlanarPose<double>{p(0), p(1), p(2)}` converts one
/// exactly, and `pose.vector()` converts back. Headings are stored as given
/// (not wrapped). A plain aggregate; `validate()` checks its invariants.
struct PlanarTrajectory {
  /// Timestamps (s), strictly increasing once validated.
  std::vector<double> t_s;
  /// Poses (x m, y m, θ rad) of the body in the world frame.
  std::vector<Eigen::Vector3d> poses;

  /// Number of poses.
  [[nodiscard]] std::size_t size() const noexcept { return poses.size(); }
  /// True when there is no pose.
  [[nodiscard]] bool empty() const noexcept { return poses.empty(); }

  /// Appends one timed pose (no checks; see `validate()`).
  /// @param[in] stamp_s time (s)
  /// @param[in] pose (x m, y m, θ rad)
  void push_back(double stamp_s, const Eigen::Vector3d& pose) {
    t_s.push_back(stamp_s);
    poses.push_back(pose);
  }

  /// The position of pose k, (x, y) (m). No bounds check.
  [[nodiscard]] Eigen::Vector2d position(std::size_t k) const { return poses[k].head<2>(); }
  /// The heading of pose k, θ (rad). No bounds check.
  [[nodiscard]] double heading(std::size_t k) const { return poses[k](2); }

  /// All positions (x, y) in the world frame (m), e.g. for a plot.
  [[nodiscard]] std::vector<Eigen::Vector2d> positions() const {
    std::vector<Eigen::Vector2d> p;
    p.reserve(poses.size());
    for (const Eigen::Vector3d& q : poses) p.emplace_back(q.head<2>());
    return p;
  }

  /// Checks the invariants: as many stamps as poses, every stamp and pose
  /// entry finite, and strictly increasing stamps.
  /// @throws posefuse::invalid_argument naming the first offending index
  template <class Lazy = void>
  void validate() const { validate_impl<Lazy>(true); }

  /// Checks the weaker invariants that a *reported* track (what an estimator
  /// output over time) needs: as validate(), but equal consecutive stamps are
  /// allowed (two poses reported at one time; the later one wins).
  /// @throws posefuse::invalid_argument naming the first offending index
  template <class Lazy = void>
  void validate_time_order() const { validate_impl<Lazy>(false); }

 private:
  template <class Lazy = void>  // compiled only where called (compile cost, core/lazy.hpp)
  void validate_impl(bool strict) const {
    if (t_s.size() != poses.size()) {
      throw invalid_argument("planar trajectory has " + std::to_string(t_s.size()) +
                             " stamps but " + std::to_string(poses.size()) + " poses");
    }
    for (std::size_t k = 0; k < poses.size(); ++k) {
      if (!std::isfinite(t_s[k])) {
        throw invalid_argument("planar trajectory stamp " + std::to_string(k) + " is not finite");
      }
      const detail::dependent_t<Eigen::Vector3d, Lazy>& x = poses[k];
      if (!x.allFinite()) {
        throw invalid_argument("planar trajectory pose " + std::to_string(k) + " is not finite");
      }
      if (k > 0 && (strict ? !(t_s[k] > t_s[k - 1]) : t_s[k] < t_s[k - 1])) {
        throw invalid_argument(std::string("planar trajectory stamps are not ") +
                               (strict ? "strictly increasing" : "in time order") + " at index " +
                               std::to_string(k));
      }
    }
  }
};

}  // namespace posefuse

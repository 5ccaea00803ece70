#pragma once
/// @file
/// The selections and transformations evo applies to trajectories before a
/// metric (`evo_ape` / `evo_rpe` options), each a function of a Trajectory:
/// time range (`--t_start/--t_end`), down-sampling (`--downsample`), the
/// motion filter (`--motion_filter`), origin alignment (`--align_origin`)
/// and projection onto a plane (`--project_to_plane`).
///
/// Order in which `evaluate_trajectory` applies them, which is evo's
/// (evo/main_ape.py, main_rpe.py, common_ape_rpe.py): down-sampling and the
/// motion filter on both files, the time range on the reference,
/// association, alignment (Umeyama or origin), projection, metric.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/plane.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/alignment.hpp>

namespace posefuse {

/// The poses with \f$ t_{start} \le t_k \le t_{end} \f$ (either bound
/// optional), as evo's `reduce_to_time_range`. Stamps are the file's own
/// (absolute), in seconds.
/// @param[in] traj the trajectory
/// @param[in] t_start_s optional first stamp kept (s)
/// @param[in] t_end_s optional last stamp kept (s)
/// @return the poses in range, possibly none
/// @throws posefuse::invalid_argument for a non-finite bound or start > end
template <class Lazy = void>
[[nodiscard]] Trajectory reduce_to_time_range(const Trajectory& traj,
                                              std::optional<double> t_start_s,
                                              std::optional<double> t_end_s) {
  if ((t_start_s && !std::isfinite(*t_start_s)) || (t_end_s && !std::isfinite(*t_end_s)))
    throw invalid_argument("time range: bounds must be finite");
  if (t_start_s && t_end_s && *t_start_s > *t_end_s)
    throw invalid_argument("time range: start is after end");
  std::vector<std::size_t> ids;
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const double t = traj.t_s[k];
    if ((!t_start_s || t >= *t_start_s) && (!t_end_s || t <= *t_end_s)) ids.push_back(k);
  }
  return select(traj, ids);
}

/// At most `max_poses` evenly spaced poses, as evo's `downsample`: the
/// indices \f$ \lfloor i (n-1)/(m-1) \rfloor \f$, \f$ i = 0 \dots m-1 \f$
/// (numpy's `linspace(0, n-1, m, dtype=int)`; the last is \f$ n-1 \f$). A
/// trajectory of at most `max_poses` poses is returned unchanged.
/// @throws posefuse::invalid_argument when `max_poses` is 0
template <class Lazy = void>
[[nodiscard]] Trajectory downsample(const Trajectory& traj, std::size_t max_poses) {
  if (max_poses == 0) throw invalid_argument("downsample: cannot keep less than one pose");
  const std::size_t n = traj.size();
  if (n <= max_poses) return traj;
  std::vector<std::size_t> ids(max_poses, 0);
  if (max_poses > 1) {
    const double step = static_cast<double>(n - 1) / static_cast<double>(max_poses - 1);
    for (std::size_t i = 0; i + 1 < max_poses; ++i)
      ids[i] = static_cast<std::size_t>(static_cast<double>(i) * step);
    ids.back() = n - 1;
  }
  return select(traj, ids);
}

/// Keeps pose 0 and then every pose at which the motion accumulated since
/// the last kept pose reaches a threshold: the summed distances between
/// consecutive positions \f$ \ge d \f$ **or** the summed rotation angles
/// between consecutive orientations \f$ \ge \alpha \f$ (both sums restart
/// at a kept pose). This is the rule of evo's `--motion_filter DIST ANGLE`.
/// @param[in] traj the trajectory
/// @param[in] distance_m \f$ d \f$ (m, >= 0)
/// @param[in] angle_rad \f$ \alpha \f$ (rad, >= 0)
/// @return the kept poses
/// @throws posefuse::invalid_argument for a negative or non-finite threshold
template <class Lazy = void>
[[nodiscard]] Trajectory motion_filter(const Trajectory& traj, double distance_m,
                                       double angle_rad) {
  if (!(distance_m >= 0.0) || !(angle_rad >= 0.0) || !std::isfinite(distance_m) ||
      !std::isfinite(angle_rad))
    throw invalid_argument("motion filter: thresholds must be finite and >= 0");
  std::vector<std::size_t> ids;
  if (traj.empty()) return traj;
  ids.push_back(0);
  double distance = 0.0, angle = 0.0;
  for (std::size_t k = 1; k < traj.size(); ++k) {
    const Eigen::Isometry3d& a = traj.poses[k - 1];
    const Eigen::Isometry3d& b = traj.poses[k];
    distance += (b.translation() - a.translation()).norm();
    const Eigen::Matrix3d R = a.linear().transpose() * b.linear();
    const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
    angle += std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
    if (distance >= distance_m || angle >= angle_rad) {
      ids.push_back(k);
      distance = 0.0;
      angle = 0.0;
    }
  }
  return select(traj, ids);
}

/// Moves `est` rigidly so that its first pose equals `ref`'s first pose, as
/// evo's `--align_origin`: \f$ T = Q_0 P_0^{-1} \f$, \f$ P_k \leftarrow T P_k \f$.
/// @param[in] est the estimate (non-empty)
/// @param[in] ref the reference (non-empty)
/// @return the moved estimate and \f$ T \f$ (scale 1)
/// @throws posefuse::invalid_argument when either is empty
template <class Lazy = void>
[[nodiscard]] AlignedTrajectory align_origin(const Trajectory& est, const Trajectory& ref) {
  if (est.empty() || ref.empty()) throw invalid_argument("align_origin: empty trajectory");
  const Eigen::Isometry3d T = ref.poses.front() * est.poses.front().inverse();
  AlignmentResult a;
  a.rotation = T.linear();
  a.translation = T.translation();
  return {apply_alignment(est, a), a};
}

/// Projects every pose (position and orientation) onto a plane as evo's `--project_to_plane`: the
/// coordinate along the plane's normal becomes 0, and the rotation becomes
/// the rotation about the normal by that axis' angle of the static-axes
/// x-y-z Euler decomposition \f$ R = R_z(\gamma) R_y(\beta) R_x(\alpha) \f$
/// (\f$ \gamma \f$ for xy, \f$ \beta \f$ for xz, \f$ \alpha \f$ for yz).
/// @param[in] traj the trajectory
/// @param[in] plane the plane kept
/// @return the projected trajectory (stamps unchanged)
template <class Lazy = void>
[[nodiscard]] Trajectory project_poses_to_plane(const Trajectory& traj, Plane plane) {
  const int normal = plane == Plane::kXY ? 2 : plane == Plane::kXZ ? 1 : 0;
  Trajectory out = traj;
  for (Eigen::Isometry3d& T : out.poses) {
    const Eigen::Matrix3d R = T.linear();
    const double cy = std::hypot(R(0, 0), R(1, 0));
    double angle = 0.0;
    if (normal == 2) {
      angle = cy > 4.0 * std::numeric_limits<double>::epsilon() ? std::atan2(R(1, 0), R(0, 0)) : 0.0;
    } else if (normal == 1) {
      angle = std::atan2(-R(2, 0), cy);
    } else {
      angle = cy > 4.0 * std::numeric_limits<double>::epsilon() ? std::atan2(R(2, 1), R(2, 2))
                                                                 : std::atan2(-R(1, 2), R(1, 1));
    }
    T.translation()(normal) = 0.0;
    T.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(normal)).toRotationMatrix();
  }
  return out;
}

}  // namespace posefuse

#pragma once
/// @file
/// Figures of merit of a planar (ground-robot) track against a reference:
/// position RMSE and largest heading error after association by time, the
/// loop-closure error, and the time without a valid pose.
///
/// A *track* is what an estimator reported over time, a PlanarTrajectory
/// (core/trajectory.hpp) in time order; equal consecutive stamps are allowed
/// (two poses reported at one time). The reference (e.g. ground truth) is
/// interpolated at the track's times (interpolate_at, core/interpolation.hpp:
/// linear in position, shorter arc in heading); track poses outside the
/// reference's time span are not associated. No alignment is applied: both
/// must be in the same world frame.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// Errors of a planar track against a reference (planar_errors()).
struct PlanarErrors {
  /// Track poses inside the reference's time span (the ones compared).
  std::size_t matched = 0;
  /// \f$ \sqrt{\frac1n \sum_k \lVert p_k - g(t_k) \rVert^2} \f$ over the matched
  /// poses (m); NaN when none matched.
  double rmse_m = std::numeric_limits<double>::quiet_NaN();
  /// \f$ \max_k |\mathrm{wrap}(\theta_k - \theta_g(t_k))| \f$ over the matched
  /// poses (rad, in [0, π]); NaN when none matched.
  double max_heading_error_rad = std::numeric_limits<double>::quiet_NaN();
};

/// Position RMSE and largest heading error of `track` against `reference`,
/// each track pose associated with the reference interpolated at its time
/// (see the file comment).
/// @param[in] track the estimator's poses, in time order
/// @param[in] reference the reference poses (ground truth), in time order
/// @return matched count, RMSE (m) and largest heading error (rad); an empty
///         track or reference, or no overlap in time, gives matched = 0 and NaN
/// @throws posefuse::invalid_argument if either trajectory has a non-finite
///         entry, mismatched counts or decreasing stamps (see
///         PlanarTrajectory::validate_time_order)
template <class Lazy = void>
[[nodiscard]] PlanarErrors planar_errors(const PlanarTrajectory& track,
                                         const PlanarTrajectory& reference) {
  track.validate_time_order();
  reference.validate_time_order();
  PlanarErrors out;
  double se = 0, max_heading = 0;
  for (std::size_t k = 0; k < track.size(); ++k) {
    const std::optional<Eigen::Vector3d> g = detail::interpolate_in_order(reference, track.t_s[k]);
    if (!g) continue;
    const Eigen::Vector3d& p = track.poses[k];
    se += (p(0) - (*g)(0)) * (p(0) - (*g)(0)) + (p(1) - (*g)(1)) * (p(1) - (*g)(1));
    max_heading = std::max(max_heading, std::abs(angle_diff(p(2), (*g)(2))));
    ++out.matched;
  }
  if (out.matched > 0) {
    out.rmse_m = std::sqrt(se / double(out.matched));
    out.max_heading_error_rad = max_heading;
  }
  return out;
}

/// Loop-closure error: the distance from the track's last position to the
/// start, \f$ \lVert p_{last} - p_{start} \rVert \f$ (m) — for a run that
/// returns to where it began.
/// @param[in] track the estimator's poses, in time order
/// @param[in] start the start position (world frame, m)
/// @return the distance (m)
/// @throws posefuse::invalid_argument if the track is empty or its last
///         position, or `start`, is not finite
template <class Lazy = void>
[[nodiscard]] double loop_closure_error(const PlanarTrajectory& track,
                                        const Eigen::Vector2d& start) {
  if (track.empty()) throw invalid_argument("loop_closure_error: the track has no pose");
  const Eigen::Vector3d& p = track.poses.back();
  if (!p.allFinite() || !start.allFinite())
    throw invalid_argument("loop_closure_error: the last pose or the start is not finite");
  return std::hypot(p(0) - start(0), p(1) - start(1));
}

/// Time without a valid pose: the summed length of the gaps longer than
/// `max_gap_s` between consecutive reported poses, counting the gap from
/// `t_begin_s` to the first pose and from the last pose to `t_end_s`
/// (poses outside [t_begin_s, t_end_s] shorten no gap twice). An empty track
/// has no pose for `t_end_s - t_begin_s` (when that exceeds `max_gap_s`).
/// @param[in] track the estimator's poses, in time order
/// @param[in] t_begin_s, t_end_s the evaluated span (s), t_begin_s <= t_end_s
/// @param[in] max_gap_s longest gap that still counts as tracking (s, >= 0)
/// @return the time without a pose (s)
/// @throws posefuse::invalid_argument if a time is not finite, t_end_s <
///         t_begin_s, max_gap_s is negative, or the track is invalid (see
///         PlanarTrajectory::validate_time_order)
template <class Lazy = void>
[[nodiscard]] double time_without_pose(const PlanarTrajectory& track, double t_begin_s,
                                       double t_end_s, double max_gap_s) {
  if (!std::isfinite(t_begin_s) || !std::isfinite(t_end_s) || !(t_end_s >= t_begin_s))
    throw invalid_argument("time_without_pose: need finite t_begin_s <= t_end_s");
  if (!std::isfinite(max_gap_s) || !(max_gap_s >= 0))
    throw invalid_argument("time_without_pose: max_gap_s must be finite and >= 0");
  track.validate_time_order();
  double total = 0, prev = t_begin_s;
  for (const double t : track.t_s) {
    if (t - prev > max_gap_s) total += t - prev;
    prev = std::max(prev, t);
  }
  if (t_end_s - prev > max_gap_s) total += t_end_s - prev;
  return total;
}

}  // namespace posefuse

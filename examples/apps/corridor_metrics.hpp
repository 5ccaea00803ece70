#pragma once
/// @file
/// Figures of merit for seed 001's corridor experiment: loop-closure error at
/// the return to the start, RMSE against ground truth, time without a valid
/// pose, and the yaw error after each 90° turn (the seed reports about 1.9°).
///
/// A *track* is the PlanarTrajectory (core/trajectory.hpp) of poses a method
/// reported, in time order, in the world (= odometry) frame; times are
/// seconds since the log's first sample. The generic figures come from the
/// library (eval/planar_metrics.hpp: planar_errors, loop_closure_error,
/// time_without_pose; ground truth interpolated at the method's times,
/// linear in position, along the shorter arc in yaw). What is particular to
/// the seed's experiment stays here: the turns of the drive and the yaw error
/// after each, taken from the last pose the method had reported by then
/// (what a user would have seen).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/planar_metrics.hpp>

namespace posefuse {

/// One in-place or arc turn found in a reference track.
struct TurnEvent {
  double t_start_s{0};  ///< the yaw starts changing (s)
  double t_end_s{0};    ///< the yaw has stopped changing (s)
  double angle_rad{0};  ///< net heading change (rad, counter-clockwise positive)
};

/// Results for one method.
struct CorridorMetrics {
  double loop_closure_error_m = std::numeric_limits<double>::quiet_NaN();  ///< |p_last - p_start| (m)
  double rmse_m = std::numeric_limits<double>::quiet_NaN();   ///< position RMSE vs ground truth (m)
  double time_without_pose_s = 0;  ///< total length of gaps longer than gap_s (s)
  std::vector<double> yaw_error_after_turn_deg;  ///< signed, one per turn (NaN: no pose then)
  double max_yaw_error_deg = std::numeric_limits<double>::quiet_NaN();  ///< max |after-turn error|
  double max_yaw_error_all_deg = std::numeric_limits<double>::quiet_NaN();  ///< max over every pose vs ground truth
  std::size_t poses = 0;  ///< number of poses reported
};

/// The last pose reported at or before `t`, if it is at most `max_age_s` old.
/// @param[in] track poses in time order
/// @param[in] t time (s)
/// @param[in] max_age_s the oldest pose still returned (s)
/// @return (x m, y m, θ rad), or nullopt
[[nodiscard]] inline std::optional<Eigen::Vector3d> pose_at_or_before(const PlanarTrajectory& track,
                                                                    double t, double max_age_s) {
  const auto it = std::upper_bound(track.t_s.begin(), track.t_s.end(), t);
  if (it == track.t_s.begin()) return std::nullopt;
  const auto k = std::size_t(it - track.t_s.begin()) - 1;
  if (t - track.t_s[k] > max_age_s) return std::nullopt;
  return track.poses[k];
}

/// Finds turns in a smooth reference track (ground truth, or encoder dead
/// reckoning): stretches where |dθ/dt| exceeds `rate_threshold` (measured
/// over windows of at least 0.1 s), joined when less than `join_s` apart,
/// kept when the net heading change exceeds `min_angle_rad`.
/// @return the turns in time order
[[nodiscard]] inline std::vector<TurnEvent> detect_turns(const PlanarTrajectory& ref,
                                                         double rate_threshold = 0.1,
                                                         double join_s = 1.0,
                                                         double min_angle_rad = std::numbers::pi / 4) {
  std::vector<TurnEvent> turns;
  std::optional<TurnEvent> cur;
  double angle = 0;
  std::size_t j = 0;
  const std::vector<double>& t = ref.t_s;
  for (std::size_t i = 1; i < ref.size(); ++i) {
    if (t[i] - t[j] < 0.1) continue;
    const double d = angle_diff(ref.heading(i), ref.heading(j));
    const bool turning = std::abs(d) / (t[i] - t[j]) > rate_threshold;
    if (turning) {
      if (cur && t[j] - cur->t_end_s <= join_s) {
        cur->t_end_s = t[i];
        angle += d;
      } else {
        if (cur && std::abs(angle) >= min_angle_rad) turns.push_back({cur->t_start_s, cur->t_end_s, angle});
        cur = TurnEvent{t[j], t[i], 0};
        angle = d;
      }
      cur->angle_rad = angle;
    }
    j = i;
  }
  if (cur && std::abs(angle) >= min_angle_rad) turns.push_back(*cur);
  return turns;
}

/// Evaluates one method's track.
///
/// * loop-closure error: distance from the last reported position to `start`
///   (loop_closure_error; NaN without a pose);
/// * RMSE and `max_yaw_error_all_deg`: over the poses inside the ground
///   truth's time span (planar_errors; NaN without ground truth or overlap);
/// * time without a valid pose: the summed length of the gaps longer than
///   `gap_s` between consecutive poses, counting from `t_begin` to the first
///   pose and from the last pose to `t_end` (time_without_pose);
/// * yaw error after each turn, at `t_end_s + settle_s`, of the last pose
///   reported by then (NaN if it is older than `gap_s`): against ground
///   truth when given, else against the nominal heading (0 plus the sum of
///   the turns' angles rounded to multiples of 90°, i.e. square corners);
/// * max yaw error (`max_yaw_error_deg`): the largest |after-turn error|,
///   with or without ground truth (the figure the seed reports as about
///   1.9°); NaN when no turn has a pose.
/// @param[in] track       the method's poses, time order
/// @param[in] groundtruth ground truth (may be empty)
/// @param[in] turns       turns to evaluate (detect_turns)
/// @param[in] start       the start position (world frame, m)
/// @param[in] t_begin, t_end the evaluated span (s)
/// @param[in] gap_s       longest gap that still counts as having a pose (s)
/// @param[in] settle_s    delay after a turn's end at which its yaw is taken (s)
/// @throws posefuse::invalid_argument for a track or ground truth with
///         non-finite entries or decreasing stamps (eval/planar_metrics.hpp)
[[nodiscard]] inline CorridorMetrics evaluate_track(const PlanarTrajectory& track,
                                                    const PlanarTrajectory& groundtruth,
                                                    const std::vector<TurnEvent>& turns,
                                                    const Eigen::Vector2d& start, double t_begin,
                                                    double t_end, double gap_s = 0.5,
                                                    double settle_s = 0.25) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  CorridorMetrics m;
  m.poses = track.size();
  if (!track.empty()) m.loop_closure_error_m = loop_closure_error(track, start);
  m.time_without_pose_s = time_without_pose(track, t_begin, t_end, gap_s);
  const bool have_gt = !groundtruth.empty();
  if (have_gt) {
    const PlanarErrors e = planar_errors(track, groundtruth);
    if (e.matched > 0) {
      m.rmse_m = e.rmse_m;
      m.max_yaw_error_all_deg = e.max_heading_error_rad * kDeg;
    }
  }
  double nominal = 0;
  double max_turn = 0;
  bool any_turn = false;
  for (const auto& turn : turns) {
    nominal += std::round(turn.angle_rad / (std::numbers::pi / 2)) * (std::numbers::pi / 2);
    const double t = turn.t_end_s + settle_s;
    const auto est = pose_at_or_before(track, t, gap_s);
    const auto g = have_gt ? interpolate_at(groundtruth, t) : std::nullopt;
    double err = std::numeric_limits<double>::quiet_NaN();
    if (est && (g || !have_gt)) err = angle_diff((*est)(2), g ? (*g)(2) : wrap_angle(nominal)) * kDeg;
    m.yaw_error_after_turn_deg.push_back(err);
    if (std::isfinite(err)) {
      max_turn = std::max(max_turn, std::abs(err));
      any_turn = true;
    }
  }
  if (any_turn) m.max_yaw_error_deg = max_turn;
  return m;
}

}  // namespace posefuse

#pragma once
/// @file
/// Figures of merit for seed 001's corridor experiment: loop-closure error at
/// the return to the start, RMSE against ground truth, time without a valid
/// pose, and the yaw error after each 90° turn (the seed reports about 1.9°).
///
/// A *track* is the sequence of poses a method reported, in time order, in
/// the world (= odometry) frame; times are seconds since the log's first
/// sample. Ground truth is interpolated at the method's times (linear in
/// position, along the shorter arc in yaw); the method's pose at a given time
/// is the last one it had reported by then (what a user would have seen).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// A planar pose at a time (s since the log's first sample).
struct StampedPlanarPose {
  double t_s{0};              ///< time (s)
  PlanarPose<double> pose;    ///< x, y (m), theta (rad), world frame
};

/// Poses in time order.
using PlanarTrack = std::vector<StampedPlanarPose>;

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
[[nodiscard]] inline std::optional<PlanarPose<double>> pose_at_or_before(const PlanarTrack& track,
                                                                         double t, double max_age_s) {
  const auto it = std::upper_bound(track.begin(), track.end(), t,
                                   [](double v, const StampedPlanarPose& p) { return v < p.t_s; });
  if (it == track.begin()) return std::nullopt;
  const auto& p = *(it - 1);
  if (t - p.t_s > max_age_s) return std::nullopt;
  return p.pose;
}

/// The track interpolated at `t` (linear in x, y; shorter arc in theta);
/// nullopt outside its time span.
[[nodiscard]] inline std::optional<PlanarPose<double>> interpolate_track(const PlanarTrack& track,
                                                                        double t) {
  if (track.empty() || t < track.front().t_s || t > track.back().t_s) return std::nullopt;
  const auto it = std::lower_bound(track.begin(), track.end(), t,
                                   [](const StampedPlanarPose& p, double v) { return p.t_s < v; });
  if (it == track.begin()) return it->pose;
  const auto& a = *(it - 1);
  const auto& b = *it;
  const double f = (t - a.t_s) / (b.t_s - a.t_s);
  return PlanarPose<double>{a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y),
                            angle_interpolate(a.pose.theta, b.pose.theta, f)};
}

/// Finds turns in a smooth reference track (ground truth, or encoder dead
/// reckoning): stretches where |dθ/dt| exceeds `rate_threshold` (measured
/// over windows of at least 0.1 s), joined when less than `join_s` apart,
/// kept when the net heading change exceeds `min_angle_rad`.
/// @return the turns in time order
[[nodiscard]] inline std::vector<TurnEvent> detect_turns(const PlanarTrack& ref,
                                                         double rate_threshold = 0.1,
                                                         double join_s = 1.0,
                                                         double min_angle_rad = std::numbers::pi / 4) {
  std::vector<TurnEvent> turns;
  std::optional<TurnEvent> cur;
  double angle = 0;
  std::size_t j = 0;
  for (std::size_t i = 1; i < ref.size(); ++i) {
    if (ref[i].t_s - ref[j].t_s < 0.1) continue;
    const double d = angle_diff(ref[i].pose.theta, ref[j].pose.theta);
    const bool turning = std::abs(d) / (ref[i].t_s - ref[j].t_s) > rate_threshold;
    if (turning) {
      if (cur && ref[j].t_s - cur->t_end_s <= join_s) {
        cur->t_end_s = ref[i].t_s;
        angle += d;
      } else {
        if (cur && std::abs(angle) >= min_angle_rad) turns.push_back({cur->t_start_s, cur->t_end_s, angle});
        cur = TurnEvent{ref[j].t_s, ref[i].t_s, 0};
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
/// * loop-closure error: distance from the last reported position to `start`;
/// * RMSE: over the poses inside the ground truth's time span;
/// * time without a valid pose: the summed length of the gaps longer than
///   `gap_s` between consecutive poses, counting from `t_begin` to the first
///   pose and from the last pose to `t_end`;
/// * yaw error after each turn, at `t_end_s + settle_s`, of the last pose
///   reported by then (NaN if it is older than `gap_s`): against ground
///   truth when given, else against the nominal heading (0 plus the sum of
///   the turns' angles rounded to multiples of 90°, i.e. square corners);
/// * max yaw error (`max_yaw_error_deg`): the largest |after-turn error|,
///   with or without ground truth (the figure the seed reports as about
///   1.9°); NaN when no turn has a pose;
/// * `max_yaw_error_all_deg`: the largest yaw error over every pose against
///   ground truth (NaN without ground truth).
/// @param[in] track       the method's poses, time order
/// @param[in] groundtruth ground truth (may be empty)
/// @param[in] turns       turns to evaluate (detect_turns)
/// @param[in] start       the start position (world frame)
[[nodiscard]] inline CorridorMetrics evaluate_track(const PlanarTrack& track,
                                                    const PlanarTrack& groundtruth,
                                                    const std::vector<TurnEvent>& turns,
                                                    const PlanarPose<double>& start, double t_begin,
                                                    double t_end, double gap_s = 0.5,
                                                    double settle_s = 0.25) {
  constexpr double kDeg = 180.0 / std::numbers::pi;
  CorridorMetrics m;
  m.poses = track.size();
  if (!track.empty())
    m.loop_closure_error_m = std::hypot(track.back().pose.x - start.x, track.back().pose.y - start.y);
  double prev = t_begin;
  for (const auto& p : track) {
    if (p.t_s - prev > gap_s) m.time_without_pose_s += p.t_s - prev;
    prev = std::max(prev, p.t_s);
  }
  if (t_end - prev > gap_s) m.time_without_pose_s += t_end - prev;
  const bool have_gt = !groundtruth.empty();
  double se = 0, max_yaw = 0;
  std::size_t n = 0;
  for (const auto& p : track) {
    const auto g = have_gt ? interpolate_track(groundtruth, p.t_s) : std::nullopt;
    if (!g) continue;
    se += (p.pose.x - g->x) * (p.pose.x - g->x) + (p.pose.y - g->y) * (p.pose.y - g->y);
    max_yaw = std::max(max_yaw, std::abs(angle_diff(p.pose.theta, g->theta)) * kDeg);
    ++n;
  }
  if (n > 0) {
    m.rmse_m = std::sqrt(se / double(n));
    m.max_yaw_error_all_deg = max_yaw;
  }
  double nominal = 0;
  double max_turn = 0;
  bool any_turn = false;
  for (const auto& turn : turns) {
    nominal += std::round(turn.angle_rad / (std::numbers::pi / 2)) * (std::numbers::pi / 2);
    const double t = turn.t_end_s + settle_s;
    const auto est = pose_at_or_before(track, t, gap_s);
    const auto g = have_gt ? interpolate_track(groundtruth, t) : std::nullopt;
    double err = std::numeric_limits<double>::quiet_NaN();
    if (est && (g || !have_gt)) err = angle_diff(est->theta, g ? g->theta : wrap_angle(nominal)) * kDeg;
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

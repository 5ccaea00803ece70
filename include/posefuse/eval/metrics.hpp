#pragma once
/// @file
/// Trajectory error metrics: seed 000's planar RMSE, and the absolute and
/// relative pose errors (APE, RPE) defined exactly as evo's
/// `metrics.APE` / `metrics.RPE` (evo/core/metrics.py, filters.py), so that
/// the numbers agree with `evo_ape` / `evo_rpe` to rounding. What a metric
/// measures of an error pose is in eval/pose_relation.hpp, how RPE chooses
/// its pose pairs in eval/rpe_pairs.hpp.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/pose_relation.hpp>
#include <posefuse/eval/rpe_pairs.hpp>
#include <posefuse/eval/statistics.hpp>
#include <posefuse/eval/trajectory_filters.hpp>
#include <posefuse/core/plane.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// Planar position RMSE of seed 000 (Table 1):
/// \f$ \sqrt{\frac1n \sum_k \lVert g_k - e_k \rVert^2} \f$ over road-plane
/// points (see `project_to_plane`). No alignment is applied.
/// @param[in] gt_xy ground-truth road-plane positions (m)
/// @param[in] est_xy estimated road-plane positions (m), same count
/// @return the RMSE (m)
/// @throws posefuse::invalid_argument for different or zero lengths
template <class Lazy = void>
[[nodiscard]] double rmse_2d(std::span<const Eigen::Vector2d> gt_xy,
                             std::span<const Eigen::Vector2d> est_xy) {
  if (gt_xy.size() != est_xy.size()) {
    throw invalid_argument("rmse_2d: " + std::to_string(gt_xy.size()) + " ground-truth but " +
                           std::to_string(est_xy.size()) + " estimated points");
  }
  if (gt_xy.empty()) throw invalid_argument("rmse_2d: no points");
  double sse = 0.0;
  for (std::size_t k = 0; k < gt_xy.size(); ++k) sse += (gt_xy[k] - est_xy[k]).squaredNorm();
  return std::sqrt(sse / static_cast<double>(gt_xy.size()));
}

/// Per-pose (APE) or per-pair (RPE) errors with their statistics.
struct MetricResult {
  std::vector<double> errors;  ///< one error per pose or pair, in `unit_of(relation)`
  Statistics stats;            ///< statistics of `errors`
  AlignmentResult alignment;   ///< similarity applied to the estimate (identity for kNone)
  /// RPE only: the (i, j) index pairs compared; empty for APE.
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
};

/// How the estimate is brought onto the reference before a metric, in
/// evo's order: Umeyama alignment (over the first `n_to_align` pairs) or
/// origin alignment, then projection onto a plane.
struct AlignmentOptions {
  Alignment alignment = Alignment::kNone;  ///< `--align` / `--correct_scale`
  std::size_t n_to_align = 0;              ///< `--n_to_align`: first N pairs only; 0 = all
  bool align_origin = false;               ///< `--align_origin` (excludes `alignment`)
  std::optional<Plane> project_to_plane;   ///< `--project_to_plane`, after alignment
};

namespace detail {

/// The estimate and reference a metric compares: moved and projected
/// copies where `options` asks for them, otherwise the inputs themselves
/// (a 20,000-pose trajectory is 2.5 MB: not copied for nothing).
struct PreparedForMetric {
  AlignmentResult transform;                ///< the similarity applied to the estimate
  std::optional<Trajectory> est_moved;      ///< aligned and/or projected estimate, if any
  std::optional<Trajectory> ref_projected;  ///< projected reference, if projected
  [[nodiscard]] const Trajectory& est(const Trajectory& input) const { return est_moved ? *est_moved : input; }
  [[nodiscard]] const Trajectory& ref(const Trajectory& input) const { return ref_projected ? *ref_projected : input; }
};

/// Aligns and projects as `options` says (see AlignmentOptions); the
/// reference is projected too.
/// @throws posefuse::invalid_argument for Umeyama and origin alignment together
template <class Lazy = void>
PreparedForMetric prepare_for_metric(const Trajectory& ref, const Trajectory& est,
                                     const AlignmentOptions& options) {
  if (options.align_origin && options.alignment != Alignment::kNone)
    throw invalid_argument("alignment: Umeyama alignment and origin alignment exclude each other");
  PreparedForMetric p;
  if (options.align_origin || options.alignment != Alignment::kNone || options.n_to_align > est.size()) {
    // (kNone with too large an n_to_align: align_trajectory's error.)
    AlignedTrajectory aligned = options.align_origin
                                    ? align_origin(est, ref)
                                    : align_trajectory(est, ref, options.alignment, options.n_to_align);
    p.transform = aligned.transform;
    p.est_moved = std::move(aligned.trajectory);
  }
  if (options.project_to_plane) {
    p.est_moved = project_poses_to_plane(p.est(est), *options.project_to_plane);
    p.ref_projected = project_poses_to_plane(ref, *options.project_to_plane);
  }
  return p;
}

template <class Lazy = void>
void check_same_size(const Trajectory& ref, const Trajectory& est, const char* metric) {
  if (ref.size() != est.size() || ref.empty()) {
    throw invalid_argument(std::string(metric) + ": reference has " + std::to_string(ref.size()) +
                           " poses and estimate " + std::to_string(est.size()) +
                           " (need the same, non-zero number: call associate() first)");
  }
}

}  // namespace detail

/// Absolute pose error, as `evo_ape`: per pose k, the error pose
/// \f$ E_k = P_k^{-1} Q_k \f$ (P estimate, Q reference; evo's `ape_base`),
/// measured by `relation`; for kTranslation and kPointDistance
/// \f$ \lVert t(P_k) - t(Q_k) \rVert \f$.
///
/// Equivalences (ref and est already associated, e.g. by `associate`):
/// `ape(ref, est, kTranslation, {kSE3})` = `evo_ape kitti REF EST -a`;
/// `ape(ref, est, kTranslation, {kSim3})` = `evo_ape tum REF EST -as`;
/// `{kScale}` = `-s` alone; `{kSE3, 100}` = `-a --n_to_align 100`;
/// `{.align_origin = true}` = `--align_origin`.
/// @param[in] ref reference trajectory
/// @param[in] est estimated trajectory, pose k registered to `ref` pose k
/// @param[in] relation the measured part of the error pose (not kPointDistanceErrorRatio)
/// @param[in] alignment alignment and projection, applied first
/// @return errors, statistics and the similarity used
/// @throws posefuse::invalid_argument for different or zero sizes, a
///         degenerate alignment, conflicting alignments, or an RPE-only relation
template <class Lazy = void>
[[nodiscard]] MetricResult ape(const Trajectory& ref, const Trajectory& est,
                               PoseRelation relation, const AlignmentOptions& alignment) {
  detail::check_same_size(ref, est, "ape");
  if (relation == PoseRelation::kPointDistanceErrorRatio)
    throw invalid_argument("ape: point_distance_error_ratio is a relative (RPE) measure");
  const detail::PreparedForMetric prepared = detail::prepare_for_metric(ref, est, alignment);
  const Trajectory& est_used = prepared.est(est);
  const Trajectory& ref_used = prepared.ref(ref);
  MetricResult r;
  r.alignment = prepared.transform;
  r.errors.reserve(ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Eigen::Isometry3d& P = est_used.poses[k];
    const Eigen::Isometry3d& Q = ref_used.poses[k];
    r.errors.push_back(relation == PoseRelation::kTranslation ||
                               relation == PoseRelation::kPointDistance
                           ? (P.translation() - Q.translation()).norm()
                           : pose_error(P.inverse() * Q, relation));
  }
  r.stats = compute_statistics(r.errors);
  return r;
}

/// APE with only an Umeyama alignment over all poses (see the overload above).
template <class Lazy = void>
[[nodiscard]] MetricResult ape(const Trajectory& ref, const Trajectory& est,
                               PoseRelation relation = PoseRelation::kTranslation,
                               Alignment alignment = Alignment::kNone) {
  AlignmentOptions options;
  options.alignment = alignment;
  return ape(ref, est, relation, options);
}

/// Options of `rpe` (evo_rpe's command-line options of the same meaning).
struct RpeOptions {
  PoseRelation relation = PoseRelation::kTranslation;  ///< `--pose_relation`
  /// `--delta`: frames (integer >= 1), metres, degrees or radians (> 0)
  double delta = 1.0;
  DeltaUnit delta_unit = DeltaUnit::kFrames;  ///< `--delta_unit`
  Alignment alignment = Alignment::kNone;     ///< `--align` / `--correct_scale`
  /// `--pairs_from_reference`: pick the path pairs on the reference instead
  /// of the (aligned) estimate. evo's default, and ours, is the estimate.
  bool pairs_from_reference = false;
  /// `--all_pairs`: every start pose instead of consecutive pairs. With a
  /// delta in metres or angle, pose i pairs with the j whose accumulated
  /// path (angle) from i is closest to delta, kept when within
  /// `delta * delta_tol` of it.
  bool all_pairs = false;
  double delta_tol = 0.1;       ///< `--delta_tol`: relative tolerance of all-pairs mode
  std::size_t n_to_align = 0;   ///< `--n_to_align` (0 = all)
  bool align_origin = false;    ///< `--align_origin`
  std::optional<Plane> project_to_plane;  ///< `--project_to_plane`
};

/// Relative pose error, as `evo_rpe`:
/// per pair (i, j), \f$ E = (Q_i^{-1} Q_j)^{-1} (P_i^{-1} P_j) \f$
/// (Sturm et al., IROS 2012, eq. 1; P estimate, Q reference), measured by
/// `options.relation` (for the point-distance relations,
/// \f$ |\,\lVert p_j - p_i \rVert - \lVert q_j - q_i \rVert\,| \f$ and its
/// ratio to \f$ \lVert q_j - q_i \rVert \f$ in %). The estimate is aligned
/// first (SE(3) leaves the RPE unchanged; Sim(3) rescales it) and projected
/// if asked, then the pairs are chosen on the aligned estimate (or the
/// reference) by index, path length or rotation angle.
///
/// Angle units (`kDegrees`, `kRadians`): consecutive ids start at pose 0 and
/// follow whenever the summed rotation angles between consecutive poses
/// reach delta. (evo sums differences of rotation-vector norms, which are
/// not rotation angles; the pairs can differ from evo's for this unit.)
///
/// Equivalence: `rpe(ref, est, {kTranslation, 10, kFrames})` =
/// `evo_rpe kitti REF EST --delta 10 --delta_unit f`; with
/// `{kRotationAngleDeg, 100, kMeters, kSim3}` it is
/// `evo_rpe tum REF EST -r angle_deg --delta 100 --delta_unit m -as`.
/// @param[in] ref reference trajectory
/// @param[in] est estimated trajectory, pose k registered to `ref` pose k
/// @param[in] options relation, delta, unit, alignment, pair source
/// @return per-pair errors, statistics, the similarity and the pairs
/// @throws posefuse::invalid_argument for different or zero sizes, a bad
///         delta (non-integer frames, non-positive), a bad tolerance, a
///         degenerate alignment, or when no pair exists for the delta (as
///         evo; also for any delta in frames of at least the number of
///         poses, however large)
template <class Lazy = void>
[[nodiscard]] MetricResult rpe(const Trajectory& ref, const Trajectory& est,
                               const RpeOptions& options = {}) {
  detail::check_same_size(ref, est, "rpe");
  const detail::PreparedForMetric prepared = detail::prepare_for_metric(
      ref, est,
      AlignmentOptions{options.alignment, options.n_to_align, options.align_origin,
                       options.project_to_plane});
  const std::vector<Eigen::Isometry3d>& P = prepared.est(est).poses;
  const std::vector<Eigen::Isometry3d>& Q = prepared.ref(ref).poses;
  MetricResult r;
  r.alignment = prepared.transform;
  if (!(options.delta_tol >= 0.0) || !std::isfinite(options.delta_tol))
    throw invalid_argument("rpe: delta tolerance must be finite and >= 0");
  if (options.delta_unit == DeltaUnit::kFrames) {
    if (!(options.delta >= 1.0) || options.delta != std::floor(options.delta) ||
        !std::isfinite(options.delta)) {
      throw invalid_argument("rpe: delta in frames must be an integer >= 1");
    }
    // A step of n poses or more has no pair; checked in double, because a
    // huge delta (1e300, 2^64) does not fit in a size_t (the cast would be UB).
    if (options.delta < static_cast<double>(P.size())) {
      r.pairs = rpe_pairs_by_index(P.size(), static_cast<std::size_t>(options.delta),
                                   options.all_pairs);
    }
  } else {
    if (!(options.delta > 0.0) || !std::isfinite(options.delta))
      throw invalid_argument("rpe: delta must be positive and finite");
    const bool angles = options.delta_unit != DeltaUnit::kMeters;
    const double delta = options.delta_unit == DeltaUnit::kDegrees
                             ? options.delta * std::numbers::pi / 180.0
                             : options.delta;
    const std::vector<double> step =
        detail::pose_steps(options.pairs_from_reference ? Q : P, angles);
    if (options.all_pairs) {
      std::vector<double> cumulative(step.size(), 0.0);
      for (std::size_t k = 1; k < step.size(); ++k) cumulative[k] = cumulative[k - 1] + step[k];
      r.pairs = detail::all_pairs_by_cumulative(cumulative, delta, delta * options.delta_tol);
    } else {
      r.pairs = detail::consecutive_pairs(step, delta, angles);
    }
  }
  if (r.pairs.empty()) {
    char delta[32];  // shortest round-trip text, locale-free; 24 chars suffice for a double
    const auto printed = std::to_chars(delta, delta + sizeof(delta), options.delta);
    throw invalid_argument("rpe: delta = " + std::string(delta, printed.ptr) + " (" +
                           std::string(to_string(options.delta_unit)) +
                           ") produced an empty index list - try lower values" +
                           (options.all_pairs ? " or a larger --delta-tol" : ""));
  }
  r.errors.reserve(r.pairs.size());
  std::vector<std::pair<std::size_t, std::size_t>> kept;
  for (const auto& [i, j] : r.pairs) {
    if (options.relation == PoseRelation::kPointDistance ||
        options.relation == PoseRelation::kPointDistanceErrorRatio) {
      const double d_ref = (Q[j].translation() - Q[i].translation()).norm();
      const double d_est = (P[j].translation() - P[i].translation()).norm();
      if (options.relation == PoseRelation::kPointDistance) {
        r.errors.push_back(std::abs(d_ref - d_est));
      } else if (d_ref != 0.0) {  // a zero reference distance has no ratio (evo skips it too)
        r.errors.push_back(100.0 * std::abs(d_ref - d_est) / d_ref);
        kept.push_back({i, j});
      }
      continue;
    }
    const Eigen::Isometry3d Q_rel = Q[i].inverse() * Q[j];
    const Eigen::Isometry3d P_rel = P[i].inverse() * P[j];
    r.errors.push_back(pose_error(Q_rel.inverse() * P_rel, options.relation));
  }
  if (options.relation == PoseRelation::kPointDistanceErrorRatio) {
    r.pairs = std::move(kept);
    if (r.pairs.empty())
      throw invalid_argument("rpe: every pair has a zero reference distance, no ratio exists");
  }
  r.stats = compute_statistics(r.errors);
  return r;
}

}  // namespace posefuse

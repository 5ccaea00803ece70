#pragma once
/// @file
/// Trajectory error metrics: seed 000's planar RMSE, and the absolute and
/// relative pose errors (APE, RPE) defined exactly as evo's
/// `metrics.APE` / `metrics.RPE` (evo/core/metrics.py, filters.py), so that
/// the numbers agree with `evo_ape` / `evo_rpe` to rounding.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/statistics.hpp>
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

/// Which part of an error pose \f$ E \f$ a metric measures (evo `--pose_relation`).
enum class PoseRelation {
  kTranslation,       ///< \f$ \lVert t(E) \rVert \f$ (m), evo `trans_part`
  kRotationAngleDeg,  ///< rotation angle of \f$ R(E) \f$ (deg), evo `angle_deg`
  kRotationAngleRad,  ///< rotation angle of \f$ R(E) \f$ (rad), evo `angle_rad`
  kFull,              ///< \f$ \lVert E - I_4 \rVert_F \f$ (unit-less), evo `full`
};

/// Parses "trans" (or "trans_part"), "angle_deg", "angle_rad" or "full".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] PoseRelation parse_pose_relation(std::string_view name) {
  if (name == "trans" || name == "trans_part") return PoseRelation::kTranslation;
  if (name == "angle_deg") return PoseRelation::kRotationAngleDeg;
  if (name == "angle_rad") return PoseRelation::kRotationAngleRad;
  if (name == "full") return PoseRelation::kFull;
  throw invalid_argument("unknown pose relation '" + std::string(name) +
                         "' (expected trans, angle_deg, angle_rad or full)");
}

/// Unit of the errors of a pose relation: "m", "deg", "rad" or "" (unit-less).
[[nodiscard]] constexpr std::string_view unit_of(PoseRelation relation) noexcept {
  switch (relation) {
    case PoseRelation::kTranslation: return "m";
    case PoseRelation::kRotationAngleDeg: return "deg";
    case PoseRelation::kRotationAngleRad: return "rad";
    case PoseRelation::kFull: return "";
  }
  return "";
}

/// Rotation angle \f$ \theta \in [0, \pi] \f$ of a rotation matrix, computed
/// as \f$ \mathrm{atan2}(\lVert \mathrm{vee}(R - R^\top) \rVert / 2,\ (\mathrm{tr} R - 1) / 2) \f$,
/// which stays accurate near 0 and \f$ \pi \f$ (evo: the norm of scipy's
/// `Rotation.from_matrix(R).as_rotvec()`).
/// @param[in] R a rotation matrix
/// @return the angle (rad)
template <class Lazy = void>
[[nodiscard]] double rotation_angle(const Eigen::Matrix3d& R) noexcept {
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
}

/// The error of an error pose \f$ E \f$ under a pose relation (see PoseRelation).
template <class Lazy = void>
[[nodiscard]] double pose_error(const Eigen::Isometry3d& E, PoseRelation relation) noexcept {
  switch (relation) {
    case PoseRelation::kTranslation: return E.translation().norm();
    case PoseRelation::kRotationAngleDeg:
      return rotation_angle(E.linear()) * 180.0 / std::numbers::pi;
    case PoseRelation::kRotationAngleRad: return rotation_angle(E.linear());
    case PoseRelation::kFull: break;
  }
  return (E.matrix() - Eigen::Matrix4d::Identity()).norm();
}

/// Per-pose (APE) or per-pair (RPE) errors with their statistics.
struct MetricResult {
  std::vector<double> errors;  ///< one error per pose or pair, in `unit_of(relation)`
  Statistics stats;            ///< statistics of `errors`
  AlignmentResult alignment;   ///< similarity applied to the estimate (identity for kNone)
  /// RPE only: the (i, j) index pairs compared; empty for APE.
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
};

/// Absolute pose error, as `evo_ape`: per pose k, the error pose
/// \f$ E_k = P_k^{-1} Q_k \f$ (P estimate, Q reference; evo's `ape_base`),
/// measured by `relation`; for kTranslation \f$ \lVert t(P_k) - t(Q_k) \rVert \f$.
///
/// Equivalences (ref and est already associated, e.g. by `associate`):
/// `ape(ref, est, kTranslation, kSE3)` = `evo_ape kitti REF EST -a`;
/// `ape(ref, est, kTranslation, kSim3)` = `evo_ape tum REF EST -as`;
/// `ape(ref, est, kRotationAngleDeg)` = `evo_ape ... -r angle_deg`.
/// @param[in] ref reference trajectory
/// @param[in] est estimated trajectory, pose k registered to `ref` pose k
/// @param[in] relation the measured part of the error pose
/// @param[in] alignment alignment of `est` to `ref` over all poses, applied first
/// @return errors, statistics and the similarity used
/// @throws posefuse::invalid_argument for different or zero sizes, or a
///         degenerate alignment
template <class Lazy = void>
[[nodiscard]] MetricResult ape(const Trajectory& ref, const Trajectory& est,
                               PoseRelation relation = PoseRelation::kTranslation,
                               Alignment alignment = Alignment::kNone) {
  if (ref.size() != est.size() || ref.empty()) {
    throw invalid_argument("ape: reference has " + std::to_string(ref.size()) +
                           " poses and estimate " + std::to_string(est.size()) +
                           " (need the same, non-zero number; associate them first)");
  }
  const AlignedTrajectory aligned = align_trajectory(est, ref, alignment);
  MetricResult r;
  r.alignment = aligned.transform;
  r.errors.reserve(ref.size());
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Eigen::Isometry3d& P = aligned.trajectory.poses[k];
    const Eigen::Isometry3d& Q = ref.poses[k];
    r.errors.push_back(relation == PoseRelation::kTranslation
                           ? (P.translation() - Q.translation()).norm()
                           : pose_error(P.inverse() * Q, relation));
  }
  r.stats = compute_statistics(r.errors);
  return r;
}

/// Unit of the RPE step `delta` (evo `--delta_unit f|m`).
enum class DeltaUnit {
  kFrames,  ///< pose index steps (evo `f`)
  kMeters,  ///< travelled path length (evo `m`)
};

/// Parses "frames" (or "f") and "m" (or "meters").
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] DeltaUnit parse_delta_unit(std::string_view name) {
  if (name == "frames" || name == "f") return DeltaUnit::kFrames;
  if (name == "m" || name == "meters") return DeltaUnit::kMeters;
  throw invalid_argument("unknown delta unit '" + std::string(name) + "' (expected frames or m)");
}

/// Consecutive RPE pairs by index, evo's `filter_pairs_by_index(all_pairs=False)`:
/// ids \f$ 0, \delta, 2\delta, \dots < n \f$ and the pairs of neighbouring ids.
/// @param[in] n number of poses
/// @param[in] delta index step (>= 1)
/// @return pairs \f$ (k\delta, (k+1)\delta) \f$
/// @throws posefuse::invalid_argument when `delta` is 0
template <class Lazy = void>
[[nodiscard]] std::vector<std::pair<std::size_t, std::size_t>> rpe_pairs_by_index(
    std::size_t n, std::size_t delta) {
  if (delta == 0) throw invalid_argument("rpe: delta in frames must be at least 1");
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < n && delta < n - i; i += delta) pairs.emplace_back(i, i + delta);
  return pairs;
}

/// Consecutive RPE pairs by travelled path, evo's
/// `filter_pairs_by_path(all_pairs=False)`: walking the poses from index 0,
/// accumulate \f$ \lVert p_k - p_{k-1} \rVert \f$; every index where the
/// accumulated length reaches \f$ \ge \delta \f$ becomes an id and resets
/// the accumulator to 0; pairs are neighbouring ids. Note that index 0 is
/// an id only when \f$ \delta \le 0 \f$, so the first pair starts at the
/// first pose \f$ \delta \f$ metres along the path, as in evo.
/// @param[in] poses the poses whose positions define the path
/// @param[in] delta_m path step (m, > 0)
/// @return the index pairs
/// @throws posefuse::invalid_argument when `delta_m` is not positive and finite
template <class Lazy = void>
[[nodiscard]] std::vector<std::pair<std::size_t, std::size_t>> rpe_pairs_by_path(
    std::span<const Eigen::Isometry3d> poses, double delta_m) {
  if (!(delta_m > 0.0) || !std::isfinite(delta_m)) {
    throw invalid_argument("rpe: delta in metres must be positive and finite");
  }
  std::vector<std::size_t> ids;
  double path = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (k > 0) path += (poses[k].translation() - poses[k - 1].translation()).norm();
    if (path >= delta_m) {
      ids.push_back(k);
      path = 0.0;
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

/// Options of `rpe` (evo_rpe's command-line options of the same meaning).
struct RpeOptions {
  PoseRelation relation = PoseRelation::kTranslation;  ///< `--pose_relation`
  double delta = 1.0;                         ///< `--delta`: frames (integer >= 1) or metres (> 0)
  DeltaUnit delta_unit = DeltaUnit::kFrames;  ///< `--delta_unit`
  Alignment alignment = Alignment::kNone;     ///< `--align` / `--correct_scale`
  /// `--pairs_from_reference`: pick the path pairs on the reference instead
  /// of the (aligned) estimate. evo's default, and ours, is the estimate.
  bool pairs_from_reference = false;
};

/// Relative pose error over consecutive pairs, as `evo_rpe` (all_pairs off):
/// per pair (i, j), \f$ E = (Q_i^{-1} Q_j)^{-1} (P_i^{-1} P_j) \f$
/// (Sturm et al., IROS 2012, eq. 1; P estimate, Q reference), measured by
/// `options.relation`. The estimate is aligned first (SE(3) leaves the RPE
/// unchanged; Sim(3) rescales it), then the pairs are chosen on the aligned
/// estimate (or the reference) by index or by path length.
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
///         delta (non-integer frames, non-positive), a degenerate alignment,
///         or when no pair exists for the delta (as evo; also for any delta
///         in frames of at least the number of poses, however large)
template <class Lazy = void>
[[nodiscard]] MetricResult rpe(const Trajectory& ref, const Trajectory& est,
                               const RpeOptions& options = {}) {
  if (ref.size() != est.size() || ref.empty()) {
    throw invalid_argument("rpe: reference has " + std::to_string(ref.size()) +
                           " poses and estimate " + std::to_string(est.size()) +
                           " (need the same, non-zero number; associate them first)");
  }
  const AlignedTrajectory aligned = align_trajectory(est, ref, options.alignment);
  const std::vector<Eigen::Isometry3d>& P = aligned.trajectory.poses;
  const std::vector<Eigen::Isometry3d>& Q = ref.poses;
  MetricResult r;
  r.alignment = aligned.transform;
  if (options.delta_unit == DeltaUnit::kFrames) {
    if (!(options.delta >= 1.0) || options.delta != std::floor(options.delta) ||
        !std::isfinite(options.delta)) {
      throw invalid_argument("rpe: delta in frames must be an integer >= 1");
    }
    // A step of n poses or more has no pair; checked in double, because a
    // huge delta (1e300, 2^64) does not fit in a size_t (the cast would be UB).
    if (options.delta < static_cast<double>(P.size())) {
      r.pairs = rpe_pairs_by_index(P.size(), static_cast<std::size_t>(options.delta));
    }
  } else {
    r.pairs = rpe_pairs_by_path(options.pairs_from_reference ? Q : P, options.delta);
  }
  if (r.pairs.empty()) {
    char delta[32];  // shortest round-trip text, locale-free; 24 chars suffice for a double
    const auto printed = std::to_chars(delta, delta + sizeof(delta), options.delta);
    throw invalid_argument("rpe: delta = " + std::string(delta, printed.ptr) +
                           (options.delta_unit == DeltaUnit::kFrames ? " (frames)" : " (m)") +
                           " produced an empty index list - try lower values");
  }
  r.errors.reserve(r.pairs.size());
  for (const auto& [i, j] : r.pairs) {
    const Eigen::Isometry3d Q_rel = Q[i].inverse() * Q[j];
    const Eigen::Isometry3d P_rel = P[i].inverse() * P[j];
    r.errors.push_back(pose_error(Q_rel.inverse() * P_rel, options.relation));
  }
  r.stats = compute_statistics(r.errors);
  return r;
}

}  // namespace posefuse

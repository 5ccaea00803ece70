#pragma once
/// @file
/// Which pose pairs an RPE compares (evo filters.py): by index, by travelled
/// path length or by accumulated rotation angle, consecutive or all pairs.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/eval/pose_relation.hpp>

namespace posefuse {

/// Unit of the RPE step `delta` (evo `--delta_unit f|m|d|r`).
enum class DeltaUnit {
  kFrames,   ///< pose index steps (evo `f`)
  kMeters,   ///< travelled path length (evo `m`)
  kDegrees,  ///< accumulated rotation angle (evo `d`)
  kRadians,  ///< accumulated rotation angle (evo `r`)
};

/// Parses "frames" (or "f"), "m" (or "meters"), "deg" (or "d") and "rad" (or "r").
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] DeltaUnit parse_delta_unit(std::string_view name) {
  if (name == "frames" || name == "f") return DeltaUnit::kFrames;
  if (name == "m" || name == "meters") return DeltaUnit::kMeters;
  if (name == "deg" || name == "d") return DeltaUnit::kDegrees;
  if (name == "rad" || name == "r") return DeltaUnit::kRadians;
  throw invalid_argument("unknown delta unit '" + std::string(name) +
                         "' (expected frames, m, deg or rad)");
}

/// The short name of a delta unit ("frames", "m", "deg", "rad").
[[nodiscard]] constexpr std::string_view to_string(DeltaUnit unit) noexcept {
  switch (unit) {
    case DeltaUnit::kFrames: return "frames";
    case DeltaUnit::kMeters: return "m";
    case DeltaUnit::kDegrees: return "deg";
    case DeltaUnit::kRadians: return "rad";
  }
  return "?";
}

/// RPE pairs by index, evo's `filter_pairs_by_index`: consecutive pairs
/// \f$ (k\delta, (k+1)\delta) \f$, or with `all_pairs` every
/// \f$ (i, i+\delta) \f$.
/// @param[in] n number of poses
/// @param[in] delta index step (>= 1)
/// @param[in] all_pairs every start index instead of every delta-th
/// @return the pairs
/// @throws posefuse::invalid_argument when `delta` is 0
template <class Lazy = void>
[[nodiscard]] std::vector<std::pair<std::size_t, std::size_t>> rpe_pairs_by_index(
    std::size_t n, std::size_t delta, bool all_pairs = false) {
  if (delta == 0) throw invalid_argument("rpe: delta in frames must be at least 1");
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  const std::size_t stride = all_pairs ? 1 : delta;
  for (std::size_t i = 0; i < n && delta < n - i; i += stride) pairs.emplace_back(i, i + delta);
  return pairs;
}

namespace detail {

/// Consecutive pairs from a per-step increment (path length or rotation
/// angle between pose k-1 and k): walking from index 0 the increments are
/// summed, and every index where the sum reaches \f$ \ge \delta \f$ becomes
/// an id and restarts the sum; pairs are neighbouring ids. `first_is_id`
/// makes index 0 an id as well.
template <class Lazy = void>
std::vector<std::pair<std::size_t, std::size_t>> consecutive_pairs(std::span<const double> step,
                                                                   double delta, bool first_is_id) {
  std::vector<std::size_t> ids;
  if (first_is_id && !step.empty()) ids.push_back(0);
  double sum = 0.0;
  for (std::size_t k = 0; k < step.size(); ++k) {
    sum += step[k];
    if (sum >= delta) {
      if (ids.empty() || ids.back() != k) ids.push_back(k);
      sum = 0.0;
    }
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

/// All pairs (i, j), j > i, whose cumulative quantity difference
/// \f$ c_j - c_i \f$ is closest to \f$ \delta \f$ for each i (the first j
/// on a tie) and within \f$ \delta \pm tol \f$ (evo's all-pairs search
/// on a non-decreasing cumulative path).
template <class Lazy = void>
std::vector<std::pair<std::size_t, std::size_t>> all_pairs_by_cumulative(
    std::span<const double> cumulative, double delta, double tol) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t i = 0; i < cumulative.size(); ++i) {
    const double target = cumulative[i] + delta;
    const auto first = cumulative.begin() + static_cast<std::ptrdiff_t>(i) + 1;
    const auto lb = std::lower_bound(first, cumulative.end(), target);
    std::size_t best = cumulative.size();
    double best_diff = 0.0;
    if (lb != first) {
      const double d = std::abs(*(lb - 1) - target);
      // the first index reaching the same value (a flat stretch of the path)
      const auto same = std::lower_bound(first, lb, *(lb - 1));
      best = static_cast<std::size_t>(same - cumulative.begin());
      best_diff = d;
    }
    if (lb != cumulative.end()) {
      const double d = std::abs(*lb - target);
      if (best == cumulative.size() || d < best_diff) {
        best = static_cast<std::size_t>(lb - cumulative.begin());
        best_diff = d;
      }
    }
    if (best < cumulative.size() && best_diff <= tol) pairs.emplace_back(i, best);
  }
  return pairs;
}

/// Per-step increments between consecutive poses: path length (m) or
/// rotation angle (rad) of \f$ T_{k-1}^{-1} T_k \f$; element 0 is 0.
template <class Lazy = void>
std::vector<double> pose_steps(std::span<const Eigen::Isometry3d> poses, bool angles) {
  std::vector<double> step(poses.size(), 0.0);
  for (std::size_t k = 1; k < poses.size(); ++k) {
    step[k] = angles ? rotation_angle(poses[k - 1].linear().transpose() * poses[k].linear())
                     : (poses[k].translation() - poses[k - 1].translation()).norm();
  }
  return step;
}

}  // namespace detail

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
  return detail::consecutive_pairs(detail::pose_steps(poses, false), delta_m, false);
}

}  // namespace posefuse

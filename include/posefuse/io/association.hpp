#pragma once
/// @file
/// Timestamp association of two trajectories, exactly as evo's
/// `sync.associate_trajectories(traj_ref, traj_est, max_diff, offset_2)`
/// with the default nearest-time method (evo/core/sync.py).
///
/// evo walks the stamps of the trajectory with **fewer** poses (on a tie,
/// the estimate, evo's second trajectory), takes for each the first index
/// of the minimum of \f$ |t_{long} + o - t_{short}| \f$ in the longer one,
/// and keeps the pair when that difference is at most `max_diff`. The time
/// offset \f$ o \f$ shifts the estimate: it is added to the longer stamps
/// when the estimate is longer, subtracted when the reference is. Indices
/// of the longer trajectory may repeat. No match at all is an error.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// Matched index pairs: `ref_ids[k]` goes with `est_ids[k]`, in the order
/// of the shorter trajectory.
struct Association {
  std::vector<std::size_t> ref_ids;  ///< indices into the reference
  std::vector<std::size_t> est_ids;  ///< indices into the estimate
  /// Number of matched pairs.
  [[nodiscard]] std::size_t size() const noexcept { return ref_ids.size(); }
};

/// A reference and an estimate reduced to their associated poses
/// (`ref.size() == est.size()`, pose k of one goes with pose k of the other).
struct AssociatedTrajectories {
  Trajectory ref;  ///< reference at the matched indices
  Trajectory est;  ///< estimate at the matched indices
};

namespace detail::traj_io {

/// evo's `matching_time_indices(short, long, max_diff, offset)` on sorted
/// `long` stamps: for each short stamp, the first argmin of
/// |(long + offset) - short|, kept when <= max_diff. Binary search replaces
/// numpy's linear scan; ties resolve to the first index as np.argmin does.
template <class Lazy = void>
void match_nearest(std::span<const double> short_stamps, std::span<const double> long_stamps,
                   double max_diff, double offset, std::vector<std::size_t>& short_ids,
                   std::vector<std::size_t>& long_ids) {
  std::vector<double> shifted(long_stamps.begin(), long_stamps.end());
  for (double& t : shifted) t += offset;  // rounding keeps the order (may create equal values)
  for (std::size_t i = 0; i < short_stamps.size(); ++i) {
    const double t = short_stamps[i];
    const auto lb = std::lower_bound(shifted.begin(), shifted.end(), t);
    std::size_t best = shifted.size();
    double best_diff = 0.0;
    if (lb != shifted.begin()) {
      // |diff| is non-increasing before lb (rounding is monotone): its
      // minimum is at lb-1, and np.argmin wants the first index reaching it.
      best_diff = std::abs(*(lb - 1) - t);
      const auto first = std::partition_point(
          shifted.begin(), lb, [&](double s) { return std::abs(s - t) > best_diff; });
      best = static_cast<std::size_t>(first - shifted.begin());
    }
    if (lb != shifted.end()) {
      const double d = std::abs(*lb - t);
      if (best == shifted.size() || d < best_diff) {
        best = static_cast<std::size_t>(lb - shifted.begin());
        best_diff = d;
      }
    }
    if (best < shifted.size() && best_diff <= max_diff) {
      short_ids.push_back(i);
      long_ids.push_back(best);
    }
  }
}

template <class Lazy = void>
void check_stamps(std::span<const double> stamps, const char* which) {
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    if (!std::isfinite(stamps[k]) || (k > 0 && stamps[k] < stamps[k - 1])) {
      throw invalid_argument(std::string("associate: ") + which +
                             " stamps must be finite and sorted (index " + std::to_string(k) + ")");
    }
  }
}

/// A hint for two stamp sequences that share no time: when their spans (or,
/// for single stamps, their magnitudes) differ by a factor near 1e3, 1e6 or
/// 1e9, one file is probably in ms, µs or ns and the other in s; when the
/// spans agree but the sequences do not overlap, their time origins differ.
/// Empty when nothing stands out.
template <class Lazy = void>
[[nodiscard]] std::string stamp_unit_hint(std::span<const double> ref, std::span<const double> est) {
  if (ref.empty() || est.empty()) return {};
  const auto magnitude = [](std::span<const double> t) {
    const double span = t.back() - t.front();
    return span > 0.0 ? span : std::abs(t.front());
  };
  const double a = magnitude(ref), b = magnitude(est);
  if (a > 0.0 && b > 0.0 && std::isfinite(a) && std::isfinite(b)) {
    const double decades = std::log10(a / b);
    static constexpr const char* kUnit[] = {"s", "ms", "us", "ns"};
    for (int k = 1; k <= 3; ++k) {
      if (std::abs(std::abs(decades) - 3.0 * k) < 0.3) {
        return std::string("; the reference's time span is about 1e") + std::to_string(3 * k) +
               (decades > 0.0 ? " times the estimate's" : " times smaller than the estimate's") +
               ": is one file in " + kUnit[k] + " and the other in s? (stamps must be in seconds)";
      }
    }
  }
  const bool overlap = ref.front() <= est.back() && est.front() <= ref.back();
  if (!overlap) {
    return "; the two time ranges do not overlap (reference " + format_number(ref.front()) +
           " to " + format_number(ref.back()) + " s, estimate " + format_number(est.front()) +
           " to " + format_number(est.back()) +
           " s): different time origins? A constant offset is given with --t-offset";
  }
  return {};
}

}  // namespace detail::traj_io

/// Associates two stamp sequences as evo's `associate_trajectories`
/// (see the file comment for the rule).
/// @param[in] ref_stamps reference stamps (s), finite and non-decreasing
/// @param[in] est_stamps estimate stamps (s), finite and non-decreasing
/// @param[in] max_diff_s largest accepted |time difference| (s), evo's `--t_max_diff` (0.01)
/// @param[in] offset_est_s time offset added to the estimate (s), evo's `--t_offset`
/// @return the matched pairs, in the order of the shorter sequence
/// @throws posefuse::invalid_argument for unsorted or non-finite stamps, a
///         negative or non-finite `max_diff_s`, a non-finite offset, or when
///         no pair matches
template <class Lazy = void>
[[nodiscard]] Association associate(std::span<const double> ref_stamps,
                                    std::span<const double> est_stamps,
                                    double max_diff_s = 0.01, double offset_est_s = 0.0) {
  if (!(max_diff_s >= 0.0) || !std::isfinite(max_diff_s)) {
    throw invalid_argument("associate: max time difference must be finite and >= 0, got " +
                           detail::message_number(max_diff_s));
  }
  if (!std::isfinite(offset_est_s)) {
    throw invalid_argument("associate: time offset must be finite");
  }
  detail::traj_io::check_stamps(ref_stamps, "reference");
  detail::traj_io::check_stamps(est_stamps, "estimate");
  Association a;
  const bool est_longer = est_stamps.size() > ref_stamps.size();
  if (est_longer) {
    detail::traj_io::match_nearest(ref_stamps, est_stamps, max_diff_s, offset_est_s, a.ref_ids,
                                   a.est_ids);
  } else {
    detail::traj_io::match_nearest(est_stamps, ref_stamps, max_diff_s, -offset_est_s, a.est_ids,
                                   a.ref_ids);
  }
  if (a.size() == 0) {
    throw invalid_argument("associate: found no matching timestamps between the reference (" +
                           std::to_string(ref_stamps.size()) + " stamps) and the estimate (" +
                           std::to_string(est_stamps.size()) + " stamps) with max. time diff " +
                           detail::message_number(max_diff_s) + " s and time offset " +
                           detail::message_number(offset_est_s) + " s" +
                           detail::traj_io::stamp_unit_hint(ref_stamps, est_stamps));
  }
  return a;
}

namespace detail::traj_io {

/// `Trajectory::validate()` with equal consecutive stamps allowed (the
/// trajectories of a reader under DuplicateStamps::kKeep).
template <class Lazy = void>
void validate_keeping_repeats(const Trajectory& traj) {
  if (traj.t_s.size() != traj.poses.size()) {
    throw invalid_argument("trajectory has " + std::to_string(traj.t_s.size()) + " stamps but " +
                           std::to_string(traj.poses.size()) + " poses");
  }
  for (std::size_t k = 0; k < traj.poses.size(); ++k) {
    if (!std::isfinite(traj.t_s[k]))
      throw invalid_argument("trajectory stamp " + std::to_string(k) + " is not finite");
    if (!traj.poses[k].matrix().allFinite())
      throw invalid_argument("trajectory pose " + std::to_string(k) + " is not finite");
    if (k > 0 && traj.t_s[k] < traj.t_s[k - 1])
      throw invalid_argument("trajectory stamps decrease at index " + std::to_string(k));
  }
}

}  // namespace detail::traj_io

/// Reduces a reference and an estimate to their associated poses, as
/// `evo_ape tum REF EST --t_max_diff D --t_offset O` does before computing.
/// @param[in] ref reference trajectory (validated)
/// @param[in] est estimated trajectory (validated)
/// @param[in] max_diff_s largest accepted |time difference| (s)
/// @param[in] offset_est_s time offset added to the estimate's stamps (s)
/// @param[in] repeats how the trajectories were read: under
///            DuplicateStamps::kKeep equal consecutive stamps are accepted
///            (evo's behaviour: each repeated stamp of the shorter
///            trajectory pairs with its nearest partner, of a run in the
///            longer one the first pose is used); otherwise stamps must be
///            strictly increasing
/// @return both trajectories at the matched indices; stamps keep their own
///         time frames (the offset is not applied to them)
/// @throws posefuse::invalid_argument when either trajectory fails
///         `validate()`, for bad parameters, or when nothing matches
template <class Lazy = void>
[[nodiscard]] AssociatedTrajectories associate(const Trajectory& ref, const Trajectory& est,
                                               double max_diff_s = 0.01,
                                               double offset_est_s = 0.0,
                                               DuplicateStamps repeats = DuplicateStamps::kError) {
  if (repeats == DuplicateStamps::kKeep) {
    detail::traj_io::validate_keeping_repeats(ref);
    detail::traj_io::validate_keeping_repeats(est);
  } else {
    ref.validate();
    est.validate();
  }
  const Association a = associate(ref.t_s, est.t_s, max_diff_s, offset_est_s);
  return {select(ref, a.ref_ids), select(est, a.est_ids)};
}

}  // namespace posefuse

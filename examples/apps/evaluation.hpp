#pragma once
/// @file
/// The evaluation of `evaluate_trajectory` from the trajectories as read to
/// the numbers and the `--save-results` document: thinning, time range,
/// association (or frame by frame), alignment, the metric and NEES. The
/// program and the Python module (`posefuse.ape` / `posefuse.rpe`) both call
/// `evaluate` and `results_json`, so that they give the same numbers and the
/// same JSON for the same inputs.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <posefuse/eval/consistency.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/eval/trajectory_filters.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace posefuse::apps {

/// Everything that shapes an evaluation's numbers and its JSON document.
struct EvaluationSetup {
  std::string groundtruth_name, estimate_name;  ///< the files as named to the user
  posefuse::Format ref_format = posefuse::Format::kKitti;
  posefuse::Format est_format = posefuse::Format::kKitti;
  /// Formats given explicitly (nothing: detected from the content).
  std::optional<posefuse::Format> ref_format_given, est_format_given;
  bool stamped_by_times = false;  ///< KITTI files were stamped by a times file
  posefuse::DuplicateStamps duplicates = posefuse::DuplicateStamps::kFirst;
  bool metric_rpe = false;
  posefuse::PoseRelation relation = posefuse::PoseRelation::kTranslation;
  posefuse::RpeOptions rpe;  // delta, unit, all pairs, tolerance, pair source
  posefuse::AlignmentOptions align;
  double max_time_diff = 0.01;
  double t_offset = 0.0;
  std::optional<double> t_start, t_end;
  std::optional<std::size_t> downsample;
  std::optional<std::pair<double, double>> motion_filter;  // m, deg

  /// Two KITTI files without times are compared frame by frame.
  [[nodiscard]] bool frame_by_frame() const noexcept {
    return ref_format == posefuse::Format::kKitti && est_format == posefuse::Format::kKitti &&
           !stamped_by_times;
  }
};

/// A file's trajectory and, for a TUM estimate with covariance columns, the
/// covariance of each pose (empty otherwise).
struct LoadedTrajectory {
  posefuse::Trajectory trajectory;
  int covariance_dim = 0;
  std::vector<Eigen::Matrix<double, 6, 6>> covariance;
};

/// The associated poses, the metric and (APE of an estimate with covariance) NEES.
/// Compared frame by frame without thinning, the poses used are the
/// inputs' own (not copied): the trajectories given to `evaluate` must then
/// outlive the Evaluation.
struct Evaluation {
  posefuse::MetricResult result;
  std::optional<posefuse::NeesResult> nees;
  /// The associated (and thinned) reference poses.
  [[nodiscard]] const posefuse::Trajectory& ref_used() const { return ref_input ? *ref_input : ref_kept; }
  /// The associated (and thinned) estimate poses, not aligned.
  [[nodiscard]] const posefuse::Trajectory& est_used() const { return est_input ? *est_input : est_kept; }

  const posefuse::Trajectory* ref_input = nullptr;  ///< the input itself, when used as is
  const posefuse::Trajectory* est_input = nullptr;
  posefuse::Trajectory ref_kept, est_kept;  ///< otherwise the poses used
};

/// The --pose-relation spelling ("trans" for the translation part).
[[nodiscard]] inline std::string_view relation_name(posefuse::PoseRelation r) {
  return r == posefuse::PoseRelation::kTranslation ? "trans" : posefuse::to_string(r);
}

/// The "warning:" lines of a file read under `policy` with `report`
/// (`where`: the file whose lines repeat, for KITTI the times file).
[[nodiscard]] inline std::vector<std::string> duplicate_warnings(const std::string& where,
                                                                 const posefuse::ReadReport& report,
                                                                 posefuse::DuplicateStamps policy) {
  std::vector<std::string> out;
  if (report.duplicates_dropped > 0) {
    out.push_back(where + ":" + std::to_string(report.first_duplicate_line) + ": " +
                  std::to_string(report.duplicates_dropped) +
                  " pose(s) with a repeated timestamp dropped (kept the " +
                  std::string(posefuse::to_string(policy)) +
                  " of each run; --duplicates error refuses them)");
  }
  if (report.duplicates_kept > 0) {
    out.push_back(where + ":" + std::to_string(report.first_duplicate_line) + ": " +
                  std::to_string(report.duplicates_kept) +
                  " pose(s) with a repeated timestamp kept (--duplicates keep: each pairs with "
                  "its nearest partner, as evo)");
  }
  return out;
}

/// "origin" for origin alignment, otherwise the alignment's name.
[[nodiscard]] inline std::string alignment_name(const EvaluationSetup& o) {
  if (o.align.align_origin) return "origin";
  return std::string(posefuse::to_string(o.align.alignment));
}

namespace detail {

inline posefuse::Trajectory thin(const posefuse::Trajectory& traj, const EvaluationSetup& o) {
  posefuse::Trajectory out = traj;
  if (o.downsample) out = posefuse::downsample(out, *o.downsample);
  if (o.motion_filter) {
    out = posefuse::motion_filter(out, o.motion_filter->first,
                                  o.motion_filter->second * std::numbers::pi / 180.0);
  }
  return out;
}

/// NEES of the associated estimate, when its file carried covariances (APE only).
inline std::optional<posefuse::NeesResult> consistency(const EvaluationSetup& o, const LoadedTrajectory& est_file,
                                                       const posefuse::Trajectory& ref_sync,
                                                       const posefuse::Trajectory& est_sync,
                                                       const posefuse::MetricResult& result) {
  if (est_file.covariance_dim == 0 || o.metric_rpe) return std::nullopt;
  // Associated poses keep their file's stamps: find each one's covariance.
  std::vector<Eigen::Matrix<double, 6, 6>> covariance;
  covariance.reserve(est_sync.size());
  const std::vector<double>& stamps = est_file.trajectory.t_s;
  for (const double t : est_sync.t_s) {
    const auto it = std::lower_bound(stamps.begin(), stamps.end(), t);
    covariance.push_back(est_file.covariance[static_cast<std::size_t>(it - stamps.begin())]);
  }
  return posefuse::nees(ref_sync, est_sync, covariance, est_file.covariance_dim, result.alignment);
}

}  // namespace detail

/// Evaluates `est` against `ref` as `o` says, in evo's order:
/// --downsample/--motion-filter, --t-start/--t-end (REF), association
/// (--t-offset) or frame by frame, alignment, --project-to-plane, metric.
/// `stage`, when given, is told before the metric ("APE of N pose pairs").
/// @throws apps::data_error (bad data, naming the files) and
///         apps::usage_error (NEES with --project-to-plane)
inline Evaluation evaluate(const EvaluationSetup& o, const LoadedTrajectory& ref_loaded,
                           const LoadedTrajectory& est_loaded,
                           const std::function<void(const std::string&)>& stage = {}) {
  const posefuse::Trajectory& ref_file = ref_loaded.trajectory;
  const posefuse::Trajectory& est_file = est_loaded.trajectory;
  // Thinned copies only when thinning is asked for; otherwise the poses as
  // read are used (no copy of a possibly large file).
  const bool thinning = o.downsample.has_value() || o.motion_filter.has_value();
  posefuse::Trajectory ref_kept, est_kept;
  if (thinning) {
    ref_kept = detail::thin(ref_file, o);
    est_kept = detail::thin(est_file, o);
  }
  const posefuse::Trajectory* ref = thinning ? &ref_kept : &ref_file;
  const posefuse::Trajectory& est = thinning ? est_kept : est_file;
  Evaluation out;
  if (o.frame_by_frame()) {
    if (ref->size() != est.size()) {
      throw data_error("reference has " + std::to_string(ref->size()) + " poses but estimate " +
                       std::to_string(est.size()) +
                       "; KITTI files without --times are compared frame by frame");
    }
    if (thinning) {
      out.ref_kept = std::move(ref_kept);
      out.est_kept = std::move(est_kept);
    } else {
      out.ref_input = &ref_file;
      out.est_input = &est_file;
    }
  } else {
    if (o.t_start || o.t_end) {
      ref_kept = posefuse::reduce_to_time_range(*ref, o.t_start, o.t_end);
      ref = &ref_kept;
      if (ref->empty()) {
        throw data_error(o.groundtruth_name + ": no pose between --t-start and --t-end (" +
                         shortest(ref_file.t_s.front()) + " to " + shortest(ref_file.t_s.back()) +
                         " s in the file)");
      }
    }
    posefuse::AssociatedTrajectories sync =
        posefuse::associate(*ref, est, o.max_time_diff, o.t_offset, o.duplicates);
    out.ref_kept = std::move(sync.ref);
    out.est_kept = std::move(sync.est);
  }
  const posefuse::Trajectory& ref_used = out.ref_used();
  const posefuse::Trajectory& est_used = out.est_used();
  if (o.align.n_to_align > ref_used.size()) {
    throw data_error("--n-to-align " + std::to_string(o.align.n_to_align) + " but only " +
                     std::to_string(ref_used.size()) + " poses are associated");
  }
  if (stage) stage(std::string(o.metric_rpe ? "RPE" : "APE") + " of " + std::to_string(ref_used.size()) + " pose pairs");
  try {
    out.result = o.metric_rpe ? posefuse::rpe(ref_used, est_used, o.rpe)
                              : posefuse::ape(ref_used, est_used, o.relation, o.align);
  } catch (const posefuse::invalid_argument& e) {
    // The library's reason names its function; say what it means for the files.
    const std::string what = e.what();
    const std::string files = o.groundtruth_name + " and " + o.estimate_name;
    if (what.find("degenerate") != std::string::npos || what.find("no horizontal spread") != std::string::npos)
      throw data_error(files + ": the " + std::to_string(ref_used.size()) +
                       " associated positions are all at one point or on one line, so --align " +
                       std::string(posefuse::to_string(o.align.alignment)) +
                       " has no unique answer (use --align none)");
    if (what.find("not finite") != std::string::npos)
      throw data_error(files + ": an error is not finite (positions too large to be compared)");
    throw data_error(files + ": " + what.substr(what.find(':') == std::string::npos ? 0 : what.find(':') + 2));
  }
  if (o.align.project_to_plane && est_loaded.covariance_dim > 0 && !o.metric_rpe)
    throw usage_error("NEES (an estimate with covariance) cannot be combined with --project-to-plane");
  out.nees = detail::consistency(o, est_loaded, ref_used, est_used, out.result);
  return out;
}

/// The summary members shared by --json and --save-results.
inline void write_summary(JsonWriter& j, const EvaluationSetup& o, const posefuse::MetricResult& r,
                          const std::optional<posefuse::NeesResult>& nees) {
  const posefuse::Statistics& s = r.stats;
  j.member("metric", o.metric_rpe ? "rpe" : "ape")
      .member("groundtruth_format", posefuse::to_string(o.ref_format))
      .member("estimate_format", posefuse::to_string(o.est_format))
      .member("formats_detected", !o.ref_format_given || !o.est_format_given)
      .member("pose_relation", relation_name(o.relation))
      .member("unit", posefuse::unit_of(o.relation))
      .member("alignment", alignment_name(o))
      .member("scale", r.alignment.scale);
  if (o.metric_rpe) {
    j.member("delta", o.rpe.delta).member("delta_unit", posefuse::to_string(o.rpe.delta_unit));
  }
  j.member("count", s.count).member("rmse", s.rmse).member("mean", s.mean).member("median", s.median);
  j.member("std", s.std).member("min", s.min).member("max", s.max).member("sse", s.sse);
  if (nees) {
    j.member("nees_mean", nees->mean).member("nees_dim", nees->dim);
    j.member("nees_lower", nees->lower).member("nees_upper", nees->upper);
    j.member("nees_consistent", nees->consistent());
  }
}

/// The --save-results document: the summary, the options that shaped it,
/// and per pose (APE) or pair (RPE) the stamp(s) and the error.
inline std::string results_json(const EvaluationSetup& o, const Evaluation& e,
                                const std::vector<std::string>& warnings) {
  const posefuse::MetricResult& r = e.result;
  std::ostringstream out;
  JsonWriter j(out);
  j.begin_object();
  write_summary(j, o, r, e.nees);
  j.key("options").begin_object();
  j.member("groundtruth", o.groundtruth_name).member("estimate", o.estimate_name);
  j.member("duplicates", posefuse::to_string(o.duplicates));
  j.member("n_to_align", o.align.n_to_align);
  j.member("project_to_plane",
           o.align.project_to_plane ? posefuse::to_string(*o.align.project_to_plane) : "none");
  j.member("max_time_diff_s", o.max_time_diff).member("t_offset_s", o.t_offset);
  j.member("t_start_s", o.t_start ? *o.t_start : std::nan(""))
      .member("t_end_s", o.t_end ? *o.t_end : std::nan(""));
  j.member("downsample", o.downsample ? static_cast<double>(*o.downsample) : std::nan(""));
  j.member("motion_filter_m", o.motion_filter ? o.motion_filter->first : std::nan(""))
      .member("motion_filter_deg", o.motion_filter ? o.motion_filter->second : std::nan(""));
  if (o.metric_rpe) {
    j.member("all_pairs", o.rpe.all_pairs).member("delta_tol", o.rpe.delta_tol);
    j.member("pairs_from_reference", o.rpe.pairs_from_reference);
  }
  j.end_object();
  j.key("warnings").begin_array();
  for (const std::string& w : warnings) j.value(w);
  j.end_array();
  j.key("errors").begin_array();
  for (const double v : r.errors) j.value(v);
  j.end_array();
  if (e.nees) {
    j.key("nees").begin_array();
    for (const double v : e.nees->nees) j.value(v);
    j.end_array();
  }
  // Stamps of the reference pose each error belongs to (RPE: the pair's end).
  j.key("stamps_s").begin_array();
  if (o.metric_rpe) {
    for (const auto& pair : r.pairs) j.value(e.ref_used().t_s[pair.second]);
  } else {
    for (const double t : e.ref_used().t_s) j.value(t);
  }
  j.end_array();
  j.end_object().finish();
  return out.str();
}

}  // namespace posefuse::apps

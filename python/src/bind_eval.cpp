// posefuse.ape / rpe / align and their results: the pipeline of
// evaluate_trajectory (apps/evaluation.hpp), so that the numbers and
// Result.to_json() equal the program's on the same files and options.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <apps/evaluation.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>

#include "bindings.hpp"
#include "numpy_views.hpp"
#include "trajectory_object.hpp"

namespace posefuse::python {

namespace {

/// An evaluation with the setup and warnings that produced it.
struct ResultObject {
  apps::EvaluationSetup setup;
  apps::Evaluation evaluation;
  std::vector<std::string> warnings;
};

/// The options shared by ape and rpe, as keyword arguments.
struct CommonOptions {
  std::string align = "none";
  std::string pose_relation = "trans";
  std::optional<std::size_t> n_to_align;
  bool align_origin = false;
  std::optional<std::string> project_to_plane;
  double max_time_diff = 0.01;
  double t_offset = 0.0;
  std::optional<double> t_start, t_end;
  std::optional<std::size_t> downsample;
  std::optional<std::pair<double, double>> motion_filter;
};

/// The setup evaluate_trajectory builds from its command line, with the same
/// checks (messages name the keyword arguments instead of the flags).
apps::EvaluationSetup make_setup(const TrajectoryObject& ref, const TrajectoryObject& est,
                                 const CommonOptions& c, bool rpe) {
  apps::EvaluationSetup o;
  o.groundtruth_name = ref.name();
  o.estimate_name = est.name();
  // Trajectories built from arrays are timestamped, like TUM files.
  o.ref_format = ref.format.value_or(posefuse::Format::kTum);
  o.est_format = est.format.value_or(posefuse::Format::kTum);
  if (!ref.format_detected) o.ref_format_given = o.ref_format;
  if (!est.format_detected) o.est_format_given = o.est_format;
  o.stamped_by_times = ref.stamped_by_times || est.stamped_by_times;
  o.duplicates = ref.duplicates == posefuse::DuplicateStamps::kKeep || est.duplicates == posefuse::DuplicateStamps::kKeep
                     ? posefuse::DuplicateStamps::kKeep
                     : ref.duplicates;
  o.metric_rpe = rpe;
  o.relation = posefuse::parse_pose_relation(c.pose_relation);
  o.align.alignment = posefuse::parse_alignment(c.align);
  o.align.align_origin = c.align_origin;
  if (c.project_to_plane) o.align.project_to_plane = posefuse::parse_plane(*c.project_to_plane);
  o.max_time_diff = c.max_time_diff;
  if (!(c.max_time_diff >= 0.0) || !std::isfinite(c.max_time_diff))
    throw posefuse::invalid_argument("max_time_diff must be finite and >= 0");
  if (!std::isfinite(c.t_offset)) throw posefuse::invalid_argument("t_offset must be finite");
  o.t_offset = c.t_offset;
  o.t_start = c.t_start;
  o.t_end = c.t_end;
  if (c.downsample && *c.downsample < 1) throw posefuse::invalid_argument("downsample must be >= 1");
  o.downsample = c.downsample;
  if (c.motion_filter &&
      (!(c.motion_filter->first >= 0.0) || !(c.motion_filter->second >= 0.0) ||
       !std::isfinite(c.motion_filter->first) || !std::isfinite(c.motion_filter->second)))
    throw posefuse::invalid_argument("motion_filter must be (metres, degrees), both finite and >= 0");
  o.motion_filter = c.motion_filter;
  if (!rpe && o.relation == posefuse::PoseRelation::kPointDistanceErrorRatio)
    throw posefuse::invalid_argument("pose_relation='point_distance_error_ratio' is an RPE measure");
  if (o.align.align_origin && o.align.alignment != posefuse::Alignment::kNone)
    throw posefuse::invalid_argument("align_origin=True and align exclude each other");
  if (c.n_to_align) {
    if (o.align.alignment == posefuse::Alignment::kNone)
      throw posefuse::invalid_argument("n_to_align needs align='se3', 'sim3', 'scale' or 'posyaw'");
    if (*c.n_to_align < 3) throw posefuse::invalid_argument("n_to_align must be >= 3");
    o.align.n_to_align = *c.n_to_align;
  }
  if (o.t_start && o.t_end && *o.t_start > *o.t_end) throw posefuse::invalid_argument("t_start is after t_end");
  // resolve_formats of the program: what depends on the formats.
  const bool any_kitti = o.ref_format == posefuse::Format::kKitti || o.est_format == posefuse::Format::kKitti;
  if (any_kitti && o.ref_format != o.est_format && !o.stamped_by_times)
    throw posefuse::invalid_argument(
        "comparing a KITTI file read without times with a " +
        std::string(posefuse::to_string(o.ref_format == posefuse::Format::kKitti ? o.est_format : o.ref_format)) +
        " trajectory needs times= for the KITTI one");
  if (ref.format == posefuse::Format::kKitti && est.format == posefuse::Format::kKitti &&
      ref.stamped_by_times != est.stamped_by_times)
    throw posefuse::invalid_argument("of two KITTI files, either both or neither are read with times=");
  if (o.frame_by_frame() && (o.motion_filter || o.t_start || o.t_end || o.t_offset != 0.0))
    throw posefuse::invalid_argument(
        "motion_filter, t_start, t_end and t_offset need timestamps: read the KITTI files with times= "
        "(KITTI files without it are compared frame by frame)");
  o.rpe.relation = o.relation;
  o.rpe.alignment = o.align.alignment;
  o.rpe.n_to_align = o.align.n_to_align;
  o.rpe.align_origin = o.align.align_origin;
  o.rpe.project_to_plane = o.align.project_to_plane;
  return o;
}

ResultObject run(const TrajectoryObject& ref, const TrajectoryObject& est, apps::EvaluationSetup setup) {
  ResultObject r;
  r.warnings = ref.warnings;
  r.warnings.insert(r.warnings.end(), est.warnings.begin(), est.warnings.end());
  {
    py::gil_scoped_release unlocked;
    r.evaluation = apps::evaluate(setup, ref.loaded, est.loaded);
  }
  r.setup = std::move(setup);
  return r;
}

CommonOptions common(const std::string& align, const std::string& pose_relation,
                     std::optional<std::size_t> n_to_align, bool align_origin,
                     std::optional<std::string> project_to_plane, double max_time_diff, double t_offset,
                     std::optional<double> t_start, std::optional<double> t_end,
                     std::optional<std::size_t> downsample,
                     std::optional<std::pair<double, double>> motion_filter) {
  return {align, pose_relation, n_to_align, align_origin, std::move(project_to_plane), max_time_diff,
          t_offset, t_start, t_end, downsample, motion_filter};
}

ResultObject ape(const TrajectoryObject& ref, const TrajectoryObject& est, const std::string& align,
                 const std::string& pose_relation, std::optional<std::size_t> n_to_align, bool align_origin,
                 std::optional<std::string> project_to_plane, double max_time_diff, double t_offset,
                 std::optional<double> t_start, std::optional<double> t_end, std::optional<std::size_t> downsample,
                 std::optional<std::pair<double, double>> motion_filter) {
  const CommonOptions c = common(align, pose_relation, n_to_align, align_origin, std::move(project_to_plane),
                                 max_time_diff, t_offset, t_start, t_end, downsample, motion_filter);
  return run(ref, est, make_setup(ref, est, c, false));
}

ResultObject rpe(const TrajectoryObject& ref, const TrajectoryObject& est, double delta,
                 const std::string& delta_unit, bool all_pairs, double delta_tol, bool pairs_from_reference,
                 const std::string& align, const std::string& pose_relation, std::optional<std::size_t> n_to_align,
                 bool align_origin, std::optional<std::string> project_to_plane, double max_time_diff,
                 double t_offset, std::optional<double> t_start, std::optional<double> t_end,
                 std::optional<std::size_t> downsample, std::optional<std::pair<double, double>> motion_filter) {
  const CommonOptions c = common(align, pose_relation, n_to_align, align_origin, std::move(project_to_plane),
                                 max_time_diff, t_offset, t_start, t_end, downsample, motion_filter);
  apps::EvaluationSetup o = make_setup(ref, est, c, true);
  if (!(delta > 0.0) || !std::isfinite(delta)) throw posefuse::invalid_argument("delta must be positive and finite");
  if (!(delta_tol >= 0.0) || !std::isfinite(delta_tol))
    throw posefuse::invalid_argument("delta_tol must be finite and >= 0");
  o.rpe.delta = delta;
  o.rpe.delta_unit = posefuse::parse_delta_unit(delta_unit);
  if (o.rpe.delta_unit == posefuse::DeltaUnit::kFrames && (delta < 1.0 || delta != std::floor(delta)))
    throw posefuse::invalid_argument("delta in frames must be an integer >= 1");
  o.rpe.all_pairs = all_pairs;
  o.rpe.delta_tol = delta_tol;
  o.rpe.pairs_from_reference = pairs_from_reference;
  return run(ref, est, std::move(o));
}

/// The similarity as a fresh 4x4 array [[c R, t], [0, 1]].
DoubleArray similarity_matrix(const posefuse::AlignmentResult& a) {
  Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
  S.topLeftCorner<3, 3>() = a.scale * a.rotation;
  S.topRightCorner<3, 1>() = a.translation;
  return matrix_array(S);
}

TrajectoryObject wrap(posefuse::Trajectory t, posefuse::DuplicateStamps duplicates) {
  TrajectoryObject out;
  out.loaded.trajectory = std::move(t);
  out.duplicates = duplicates;
  return out;
}

std::string result_repr(const ResultObject& r) {
  const posefuse::Statistics& s = r.evaluation.result.stats;
  return "<posefuse.Result " + std::string(r.setup.metric_rpe ? "RPE" : "APE") + " " +
         std::string(apps::relation_name(r.setup.relation)) + ", alignment " + apps::alignment_name(r.setup) +
         ": " + std::to_string(s.count) + " values, rmse " + apps::shortest(s.rmse) + " " +
         std::string(posefuse::unit_of(r.setup.relation)) + ">";
}

}  // namespace

void bind_eval(py::module_& m) {
  py::class_<posefuse::AlignmentResult>(m, "Alignment", R"doc(
The similarity y = scale * rotation @ x + translation applied to the
estimate's positions (identity when nothing is aligned); the estimate's
orientations are rotated by rotation.)doc")
      .def_property_readonly("rotation",
                             [](const posefuse::AlignmentResult& a) {
                               require_numpy("Alignment.rotation");
                               return matrix_array(a.rotation);
                             },
                             "(3, 3) rotation, estimate world -> reference world")
      .def_property_readonly("translation",
                             [](const posefuse::AlignmentResult& a) {
                               require_numpy("Alignment.translation");
                               return vector_array(a.translation);
                             },
                             "(3,) translation (m)")
      .def_readonly("scale", &posefuse::AlignmentResult::scale, "scale (1 unless sim3 or scale)")
      .def_property_readonly("matrix",
                             [](const posefuse::AlignmentResult& a) {
                               require_numpy("Alignment.matrix");
                               return similarity_matrix(a);
                             },
                             "(4, 4) [[scale * rotation, translation], [0, 0, 0, 1]]")
      .def(
          "apply",
          [](const posefuse::AlignmentResult& a, const TrajectoryObject& t) {
            return wrap(posefuse::apply_alignment(t.trajectory(), a), t.duplicates);
          },
          py::arg("trajectory"), "the trajectory with the similarity applied")
      .def("__repr__", [](const posefuse::AlignmentResult& a) {
        const Eigen::AngleAxisd aa(a.rotation);
        return "<posefuse.Alignment rotation " + apps::shortest(aa.angle() * 180.0 / std::numbers::pi) +
               " deg, translation (" + apps::shortest(a.translation.x()) + ", " + apps::shortest(a.translation.y()) +
               ", " + apps::shortest(a.translation.z()) + ") m, scale " + apps::shortest(a.scale) + ">";
      });

  py::class_<ResultObject>(m, "Result", R"doc(
An APE or RPE: the statistics of the errors (rmse, mean, median, std
(population, as numpy), min, max, sse, count), the per-pose (APE) or per-pair
(RPE) errors, the alignment, and the associated poses. to_json() is the
document evaluate_trajectory --save-results writes for the same inputs.)doc")
      .def_property_readonly("rmse", [](const ResultObject& r) { return r.evaluation.result.stats.rmse; })
      .def_property_readonly("mean", [](const ResultObject& r) { return r.evaluation.result.stats.mean; })
      .def_property_readonly("median", [](const ResultObject& r) { return r.evaluation.result.stats.median; })
      .def_property_readonly("std", [](const ResultObject& r) { return r.evaluation.result.stats.std; })
      .def_property_readonly("min", [](const ResultObject& r) { return r.evaluation.result.stats.min; })
      .def_property_readonly("max", [](const ResultObject& r) { return r.evaluation.result.stats.max; })
      .def_property_readonly("sse", [](const ResultObject& r) { return r.evaluation.result.stats.sse; })
      .def_property_readonly("count", [](const ResultObject& r) { return r.evaluation.result.stats.count; })
      .def_property_readonly(
          "statistics",
          [](const ResultObject& r) {
            const posefuse::Statistics& s = r.evaluation.result.stats;
            py::dict d;
            d["rmse"] = s.rmse;
            d["mean"] = s.mean;
            d["median"] = s.median;
            d["std"] = s.std;
            d["min"] = s.min;
            d["max"] = s.max;
            d["sse"] = s.sse;
            return d;
          },
          "the statistics as a dict, as evo's get_all_statistics()")
      .def_property_readonly(
          "errors",
          [](const py::object& self) {
            require_numpy("Result.errors");
            return vector_view(self.cast<const ResultObject&>().evaluation.result.errors, self);
          },
          "(K,) errors in unit, read-only view: one per associated pose (APE) or pair (RPE)")
      .def_property_readonly(
          "stamps",
          [](const ResultObject& r) {
            require_numpy("Result.stamps");
            const auto& e = r.evaluation;
            DoubleArray a = new_array({static_cast<py::ssize_t>(e.result.errors.size())});
            auto w = a.mutable_unchecked<1>();
            for (std::size_t k = 0; k < e.result.errors.size(); ++k)
              w(static_cast<py::ssize_t>(k)) =
                  r.setup.metric_rpe ? e.ref_used().t_s[e.result.pairs[k].second] : e.ref_used().t_s[k];
            return a;
          },
          "(K,) the reference stamp of each error (RPE: of the pair's second pose)")
      .def_property_readonly(
          "pairs",
          [](const ResultObject& r) -> py::object {
            require_numpy("Result.pairs");
            const auto& pairs = r.evaluation.result.pairs;
            if (!r.setup.metric_rpe) return py::none();
            py::array_t<std::int64_t> a({static_cast<py::ssize_t>(pairs.size()), py::ssize_t{2}});
            auto w = a.mutable_unchecked<2>();
            for (std::size_t k = 0; k < pairs.size(); ++k) {
              w(static_cast<py::ssize_t>(k), 0) = static_cast<std::int64_t>(pairs[k].first);
              w(static_cast<py::ssize_t>(k), 1) = static_cast<std::int64_t>(pairs[k].second);
            }
            return std::move(a);
          },
          "RPE: (K, 2) indices (i, j) into the associated poses; None for APE")
      .def_property_readonly("alignment", [](const ResultObject& r) { return r.evaluation.result.alignment; },
                             "the Alignment applied to the estimate")
      .def_property_readonly("scale", [](const ResultObject& r) { return r.evaluation.result.alignment.scale; })
      .def_property_readonly("metric", [](const ResultObject& r) { return r.setup.metric_rpe ? "rpe" : "ape"; })
      .def_property_readonly("pose_relation",
                             [](const ResultObject& r) { return std::string(apps::relation_name(r.setup.relation)); })
      .def_property_readonly("unit",
                             [](const ResultObject& r) { return std::string(posefuse::unit_of(r.setup.relation)); })
      .def_property_readonly("ref", [](const ResultObject& r) { return wrap(r.evaluation.ref_used(), r.setup.duplicates); },
                             "the associated reference poses (a Trajectory)")
      .def_property_readonly("est", [](const ResultObject& r) { return wrap(r.evaluation.est_used(), r.setup.duplicates); },
                             "the associated estimate poses, not aligned (a Trajectory)")
      .def_property_readonly("est_aligned",
                             [](const ResultObject& r) {
                               return wrap(posefuse::apply_alignment(r.evaluation.est_used(), r.evaluation.result.alignment),
                                           r.setup.duplicates);
                             },
                             "the associated estimate with the alignment applied")
      .def_property_readonly(
          "nees",
          [](const ResultObject& r) -> py::object {
            if (!r.evaluation.nees) return py::none();
            const posefuse::NeesResult& n = *r.evaluation.nees;
            py::dict d;
            d["mean"] = n.mean;
            d["dim"] = n.dim;
            d["lower"] = n.lower;
            d["upper"] = n.upper;
            d["consistent"] = n.consistent();
            d["values"] = n.nees;
            return std::move(d);
          },
          "APE of a TUM estimate with covariance columns: NEES (dict: mean, dim, lower, upper, consistent, "
          "values); None otherwise")
      .def_readonly("warnings", &ResultObject::warnings, "the readers' warnings")
      .def("to_json", [](const ResultObject& r) { return apps::results_json(r.setup, r.evaluation, r.warnings); },
           "the JSON document of evaluate_trajectory --save-results for the same inputs and options")
      .def("__len__", [](const ResultObject& r) { return r.evaluation.result.errors.size(); })
      .def("__repr__", &result_repr);

  // A Result may use the trajectories' poses as they are (frame by frame):
  // it keeps them alive.
  m.def("ape", &ape, py::keep_alive<0, 1>(), py::keep_alive<0, 2>(), py::arg("ref"), py::arg("est"), py::kw_only(), py::arg("align") = "none",
        py::arg("pose_relation") = "trans", py::arg("n_to_align") = py::none(), py::arg("align_origin") = false,
        py::arg("project_to_plane") = py::none(), py::arg("max_time_diff") = 0.01, py::arg("t_offset") = 0.0,
        py::arg("t_start") = py::none(), py::arg("t_end") = py::none(), py::arg("downsample") = py::none(),
        py::arg("motion_filter") = py::none(), R"doc(
Absolute pose error of est against ref, as evo_ape and evaluate_trajectory.

Steps, in evo's order: downsample (keep at most N evenly spaced poses) and
motion_filter=(metres, degrees) on each trajectory, t_start/t_end (absolute
s, on ref), association by stamps (max_time_diff s, t_offset s added to
est) -- or frame by frame for two KITTI files read without times --, the
alignment over the first n_to_align pairs (all when None), projection to a
plane ('xy', 'xz', 'yz'), the error.

align: 'none', 'se3' (evo -a), 'sim3' (-as), 'scale' (-s) or 'posyaw'
(position and yaw, 4-DoF); align_origin=True: evo --align_origin.
pose_relation: 'trans', 'angle_deg', 'angle_rad', 'full', 'rot_part',
'point_distance'. Returns a Result. Raises InvalidArgument for bad options,
DataError when the trajectories cannot be evaluated so (no matching stamps,
a degenerate alignment, ...).)doc");

  m.def("rpe", &rpe, py::keep_alive<0, 1>(), py::keep_alive<0, 2>(), py::arg("ref"), py::arg("est"), py::kw_only(), py::arg("delta") = 1.0,
        py::arg("delta_unit") = "frames", py::arg("all_pairs") = false, py::arg("delta_tol") = 0.1,
        py::arg("pairs_from_reference") = false, py::arg("align") = "none", py::arg("pose_relation") = "trans",
        py::arg("n_to_align") = py::none(), py::arg("align_origin") = false, py::arg("project_to_plane") = py::none(),
        py::arg("max_time_diff") = 0.01, py::arg("t_offset") = 0.0, py::arg("t_start") = py::none(),
        py::arg("t_end") = py::none(), py::arg("downsample") = py::none(), py::arg("motion_filter") = py::none(),
        R"doc(
Relative pose error of est against ref, as evo_rpe and evaluate_trajectory
--metric rpe: per pair (i, j), E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j).

delta and delta_unit: 'frames' (an integer >= 1), 'm' (path length), 'deg' or
'rad' (accumulated rotation). all_pairs=True: every start pose (with m / deg
/ rad, the partner whose path is closest to delta, within delta * delta_tol).
Pairs are chosen on the aligned estimate, or on ref with
pairs_from_reference=True. pose_relation additionally accepts
'point_distance_error_ratio' (%). The other options are ape's.)doc");

  m.def(
      "align",
      [](const TrajectoryObject& ref, const TrajectoryObject& est, const std::string& method,
         std::optional<std::size_t> n_to_align) {
        const posefuse::Alignment a = posefuse::parse_alignment(method);
        if (n_to_align && *n_to_align < 3) throw posefuse::invalid_argument("n_to_align must be >= 3");
        if (ref.trajectory().size() != est.trajectory().size())
          throw posefuse::invalid_argument("align: reference has " + std::to_string(ref.trajectory().size()) +
                                           " poses and estimate " + std::to_string(est.trajectory().size()) +
                                           " (need the same number: call associate() first)");
        posefuse::AlignedTrajectory aligned =
            posefuse::align_trajectory(est.trajectory(), ref.trajectory(), a, n_to_align.value_or(0));
        return py::make_tuple(aligned.transform, wrap(std::move(aligned.trajectory), est.duplicates));
      },
      py::arg("ref"), py::arg("est"), py::arg("method") = "se3", py::arg("n_to_align") = py::none(), R"doc(
Aligns est to ref (already associated: pose k with pose k), as evo's
align_trajectory: method 'se3', 'sim3', 'scale', 'posyaw' or 'none', over
the first n_to_align pairs (all when None). Returns (Alignment, aligned est).)doc");
}

}  // namespace posefuse::python

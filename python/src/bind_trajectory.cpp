// posefuse.Trajectory, reading and writing KITTI / TUM / EuRoC files, format
// detection and association by stamps.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

#include "bindings.hpp"
#include "numpy_views.hpp"
#include "trajectory_object.hpp"

namespace posefuse::python {

namespace {

/// Quaternions (w, x, y, z) of the rotations of `poses`, a fresh (N, 4) array.
DoubleArray quaternions_wxyz(const std::vector<Eigen::Isometry3d>& poses) {
  DoubleArray a = new_array({static_cast<py::ssize_t>(poses.size()), 4});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Quaterniond q(poses[k].linear());
    const auto i = static_cast<py::ssize_t>(k);
    r(i, 0) = q.w();
    r(i, 1) = q.x();
    r(i, 2) = q.y();
    r(i, 3) = q.z();
  }
  return a;
}

/// The largest |(R^T R - I)_ij| accepted for a rotation given as a matrix.
constexpr double kRotationTolerance = 1e-6;
/// The largest | |q| - 1 | accepted for a quaternion (as the TUM reader).
constexpr double kQuaternionTolerance = 1e-3;

TrajectoryObject from_arrays(const py::object& stamps_obj, const py::object& poses_obj,
                             const py::object& positions_obj, const py::object& quaternions_obj) {
  const DoubleArray stamps = to_double_array(stamps_obj, "stamps");
  check_shape(stamps, {-1}, "stamps", "(N,)");
  const py::ssize_t n = stamps.shape(0);
  if (n == 0) throw py::value_error("a trajectory needs at least one pose (stamps is empty)");
  TrajectoryObject out;
  posefuse::Trajectory& traj = out.loaded.trajectory;
  traj.t_s.assign(stamps.data(), stamps.data() + n);
  traj.poses.assign(static_cast<std::size_t>(n), Eigen::Isometry3d::Identity());
  if (!poses_obj.is_none()) {
    if (!positions_obj.is_none() || !quaternions_obj.is_none())
      throw py::value_error("give either poses or positions (and quaternions), not both");
    const DoubleArray poses = to_double_array(poses_obj, "poses");
    check_shape(poses, {n, 4, 4}, "poses", "(N, 4, 4) with N = len(stamps)");
    const auto p = poses.unchecked<3>();
    for (py::ssize_t k = 0; k < n; ++k) {
      Eigen::Matrix4d& M = traj.poses[static_cast<std::size_t>(k)].matrix();
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) M(i, j) = p(k, i, j);
    }
  } else {
    if (positions_obj.is_none()) throw py::value_error("give poses (N, 4, 4) or positions (N, 3)");
    const DoubleArray positions = to_double_array(positions_obj, "positions");
    check_shape(positions, {n, 3}, "positions", "(N, 3) with N = len(stamps)");
    const auto p = positions.unchecked<2>();
    for (py::ssize_t k = 0; k < n; ++k)
      traj.poses[static_cast<std::size_t>(k)].translation() = Eigen::Vector3d(p(k, 0), p(k, 1), p(k, 2));
    if (!quaternions_obj.is_none()) {
      const DoubleArray quaternions = to_double_array(quaternions_obj, "quaternions");
      check_shape(quaternions, {n, 4}, "quaternions", "(N, 4) (w, x, y, z) with N = len(stamps)");
      const auto q = quaternions.unchecked<2>();
      for (py::ssize_t k = 0; k < n; ++k) {
        const Eigen::Quaterniond qk(q(k, 0), q(k, 1), q(k, 2), q(k, 3));
        const std::string row = "quaternions[" + std::to_string(k) + "]";
        if (!qk.coeffs().allFinite())
          throw py::value_error(row + " = (" + apps::shortest(qk.w()) + ", " + apps::shortest(qk.x()) + ", " +
                                apps::shortest(qk.y()) + ", " + apps::shortest(qk.z()) +
                                ") (w, x, y, z) is not finite");
        // The norm scaled by the largest coefficient: exact for (1e-300, 0, 0, 0), finite at 1e300.
        const double largest = qk.coeffs().cwiseAbs().maxCoeff();
        const double norm = largest == 0.0 ? 0.0 : largest * (qk.coeffs() / largest).norm();
        if (norm == 0.0) throw py::value_error(row + " is zero: a zero quaternion is no rotation");
        if (!(std::abs(norm - 1.0) <= kQuaternionTolerance))
          throw py::value_error(row + " has norm " + apps::shortest(norm) + ", not 1 (within 1e-3)");
        traj.poses[static_cast<std::size_t>(k)].linear() = qk.normalized().toRotationMatrix();
      }
    }
  }
  traj.validate();  // stamps and poses finite, stamps strictly increasing (the C++ messages)
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const Eigen::Matrix4d& M = traj.poses[k].matrix();
    if (M.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
      throw py::value_error("poses[" + std::to_string(k) + "]: the last row must be [0, 0, 0, 1]");
    const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
    const double residual = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (residual > kRotationTolerance)
      throw py::value_error("poses[" + std::to_string(k) + "]: rotation is not orthonormal: max |R^T R - I| = " +
                            apps::shortest(residual) + " (tolerance 1e-6)");
    if (R.determinant() < 0.0)
      throw py::value_error("poses[" + std::to_string(k) + "]: rotation is a reflection (determinant < 0)");
  }
  return out;
}

TrajectoryObject read(const std::filesystem::path& file, const std::string& format_name,
                      const std::optional<std::filesystem::path>& times, const std::string& duplicates) {
  TrajectoryObject out;
  out.source = file.string();
  out.duplicates = posefuse::parse_duplicate_stamps(duplicates);
  if (format_name == "auto") {
    out.format = posefuse::detect_format(file);
    out.format_detected = true;
  } else {
    out.format = posefuse::parse_format(format_name);
  }
  if (times && *out.format != posefuse::Format::kKitti)
    throw posefuse::invalid_argument("times only applies to KITTI files (this one is " +
                                     std::string(posefuse::to_string(*out.format)) + ")");
  posefuse::ReadOptions options;
  options.duplicates = out.duplicates;
  posefuse::ReadReport report;
  {
    py::gil_scoped_release unlocked;
    switch (*out.format) {
      case posefuse::Format::kKitti:
        out.loaded.trajectory = posefuse::read_kitti(file, times, options, &report);
        out.stamped_by_times = times.has_value();
        break;
      case posefuse::Format::kEuroc:
        out.loaded.trajectory = posefuse::read_euroc_groundtruth(file, options, &report).trajectory;
        break;
      case posefuse::Format::kTum: {
        posefuse::TumWithCovariance t = posefuse::read_tum_with_covariance(file, options, &report);
        out.loaded.trajectory = std::move(t.trajectory);
        out.loaded.covariance_dim = t.covariance_dim;
        out.loaded.covariance = std::move(t.covariance);
        break;
      }
    }
  }
  const std::filesystem::path& where = *out.format == posefuse::Format::kKitti && times ? *times : file;
  out.warnings = apps::duplicate_warnings(where.string(), report, out.duplicates);
  for (const std::string& w : out.warnings) {
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 2) != 0) throw py::error_already_set();
  }
  return out;
}

std::string repr(const TrajectoryObject& t) {
  const posefuse::Trajectory& traj = t.trajectory();
  std::string s = "<posefuse.Trajectory " + std::to_string(traj.size()) + " poses, t " +
                  apps::shortest(traj.t_s.front()) + " to " + apps::shortest(traj.t_s.back()) + " s";
  if (t.format) s += ", " + std::string(posefuse::to_string(*t.format)) + " file " + t.source;
  return s + ">";
}

}  // namespace

void bind_trajectory(py::module_& m) {
  py::class_<TrajectoryObject>(m, "Trajectory", R"doc(
A timed sequence of poses T_world_body (rotation body -> world, translation =
body origin in the world, m).

Build one from arrays, or read one with read_trajectory():

    Trajectory(stamps, poses)                      # (N,), (N, 4, 4)
    Trajectory(stamps, positions=p, quaternions=q) # (N,), (N, 3), (N, 4) w, x, y, z

Inputs are converted to float64 (lists and other dtypes are accepted). Stamps
(s) must be finite and strictly increasing, poses finite with orthonormal
rotations, quaternions finite with a norm within 1e-3 of 1 (they are then
normalised); ValueError naming the row otherwise. Quaternions are in the
order (w, x, y, z), as evo's orientations_quat_wxyz; TUM files store them
(x, y, z, w), which read_trajectory handles.

stamps, positions and poses are read-only views on the trajectory's memory
(no copy); quaternions is computed on each access.)doc")
      .def(py::init(&from_arrays), py::arg("stamps"), py::arg("poses") = py::none(), py::kw_only(),
           py::arg("positions") = py::none(), py::arg("quaternions") = py::none())
      .def("__len__", [](const TrajectoryObject& t) { return t.trajectory().size(); })
      .def("__repr__", &repr)
      .def_property_readonly(
          "stamps",
          [](const py::object& self) {
            require_numpy("Trajectory.stamps");
            return vector_view(self.cast<const TrajectoryObject&>().trajectory().t_s, self);
          },
          "(N,) stamps (s), read-only view; for a KITTI file read without times, the frame indices")
      .def_property_readonly(
          "positions",
          [](const py::object& self) {
            require_numpy("Trajectory.positions");
            return positions_view(self.cast<const TrajectoryObject&>().trajectory().poses, self);
          },
          "(N, 3) positions (m), read-only view")
      .def_property_readonly(
          "poses",
          [](const py::object& self) {
            require_numpy("Trajectory.poses");
            return poses_view(self.cast<const TrajectoryObject&>().trajectory().poses, self);
          },
          "(N, 4, 4) homogeneous poses, read-only view")
      .def_property_readonly(
          "quaternions",
          [](const TrajectoryObject& t) {
            require_numpy("Trajectory.quaternions");
            return quaternions_wxyz(t.trajectory().poses);
          },
          "(N, 4) unit quaternions (w, x, y, z), a new array")
      .def_property_readonly(
          "source", [](const TrajectoryObject& t) -> py::object {
            return t.source.empty() ? py::object(py::none()) : py::object(py::str(t.source));
          },
          "the file it was read from (None when built from arrays)")
      .def_property_readonly(
          "format",
          [](const TrajectoryObject& t) -> py::object {
            return t.format ? py::object(py::str(std::string(posefuse::to_string(*t.format)))) : py::object(py::none());
          },
          "'kitti', 'tum' or 'euroc' (None when built from arrays)")
      .def_property_readonly("format_detected", [](const TrajectoryObject& t) { return t.format_detected; },
                             "True when the format was told from the file's content")
      .def_property_readonly("frame_indexed",
                             [](const TrajectoryObject& t) {
                               return t.format == posefuse::Format::kKitti && !t.stamped_by_times;
                             },
                             "True for a KITTI file read without times: its stamps are frame indices, "
                             "and two such trajectories are compared frame by frame")
      .def_property_readonly("duplicates",
                             [](const TrajectoryObject& t) { return std::string(posefuse::to_string(t.duplicates)); },
                             "the repeated-stamp policy it was read with")
      .def_property_readonly("warnings", [](const TrajectoryObject& t) { return t.warnings; },
                             "the reader's warnings (repeated stamps dropped or kept), as evaluate_trajectory prints them")
      .def_property_readonly("covariance_dim", [](const TrajectoryObject& t) { return t.loaded.covariance_dim; },
                             "0, or 3 / 6 for a TUM file with a position / pose covariance per line "
                             "(ape then reports NEES)")
      // evo's names for the same arrays.
      .def_property_readonly("timestamps", [](const py::object& self) { return self.attr("stamps"); },
                             "evo's name of stamps")
      .def_property_readonly("positions_xyz", [](const py::object& self) { return self.attr("positions"); },
                             "evo's name of positions")
      .def_property_readonly("orientations_quat_wxyz", [](const py::object& self) { return self.attr("quaternions"); },
                             "evo's name of quaternions (w, x, y, z)")
      .def_property_readonly("poses_se3", [](const py::object& self) { return self.attr("poses"); },
                             "evo's name of poses");

  m.def(
      "detect_format",
      [](const std::filesystem::path& file) { return std::string(posefuse::to_string(posefuse::detect_format(file))); },
      py::arg("path"), R"doc(
The format of a trajectory file told from its first two data lines: 'kitti'
(12 fields), 'tum' (8, or 14 / 29 with a covariance) or 'euroc' (8 or 17
comma-separated fields, an integer nanosecond stamp first).
Raises FileError ("file:line: reason") when the file fits none or several.)doc");

  m.def("read_trajectory", &read, py::arg("path"), py::arg("format") = "auto", py::arg("times") = py::none(),
        py::arg("duplicates") = "first", R"doc(
Reads a KITTI, TUM or EuRoC trajectory file.

format: 'auto' (told from the content, as evaluate_trajectory), 'kitti',
'tum' or 'euroc'. times: KITTI only, the times.txt stamping each line;
without it the stamps are the frame indices 0, 1, 2, ... and two such files
are compared frame by frame. duplicates: equal consecutive stamps are
'first' (keep the first of each run; the default, as evaluate_trajectory),
'last', 'keep' (keep every pose, as evo: each repeat pairs with its nearest
partner when associated) or 'error'. Dropped or kept repeats are reported
as a UserWarning and in Trajectory.warnings.

Raises FileError (an OSError) whose text is the C++ reader's
"file:line: reason", RepeatedStampError (a FileError) for a repeat under
duplicates='error', InvalidArgument (a ValueError) for a bad format name,
policy, or times with a non-KITTI file.)doc");

  m.def(
      "write_trajectory",
      [](const std::filesystem::path& file, const TrajectoryObject& t, const std::string& format,
         const std::optional<std::filesystem::path>& times) {
        const posefuse::Format f = posefuse::parse_format(format);
        if (times && f != posefuse::Format::kKitti)
          throw posefuse::invalid_argument("times only applies to KITTI files");
        py::gil_scoped_release unlocked;
        posefuse::write_trajectory(file, t.trajectory(), f);
        if (times) posefuse::write_kitti_times(*times, t.trajectory());
      },
      py::arg("path"), py::arg("trajectory"), py::arg("format") = "tum", py::arg("times") = py::none(), R"doc(
Writes a trajectory as 'tum' (the default) or 'kitti' (poses only; give
times= to write the stamps as a KITTI times.txt too). Numbers are the
shortest text that reads back to the same double. EuRoC is read, not
written (InvalidArgument).)doc");

  m.def(
      "associate",
      [](const TrajectoryObject& ref, const TrajectoryObject& est, double max_time_diff, double t_offset) {
        const bool keep = ref.duplicates == posefuse::DuplicateStamps::kKeep ||
                          est.duplicates == posefuse::DuplicateStamps::kKeep;
        posefuse::AssociatedTrajectories sync = posefuse::associate(
            ref.trajectory(), est.trajectory(), max_time_diff, t_offset,
            keep ? posefuse::DuplicateStamps::kKeep : posefuse::DuplicateStamps::kError);
        TrajectoryObject r, e;
        r.loaded.trajectory = std::move(sync.ref);
        e.loaded.trajectory = std::move(sync.est);
        r.duplicates = e.duplicates = keep ? posefuse::DuplicateStamps::kKeep : posefuse::DuplicateStamps::kFirst;
        return py::make_tuple(std::move(r), std::move(e));
      },
      py::arg("ref"), py::arg("est"), py::arg("max_time_diff") = 0.01, py::arg("t_offset") = 0.0, R"doc(
Associates two trajectories by stamps as evo's associate_trajectories: for
each stamp of the shorter one (the estimate on a tie), the nearest stamp of
the other (the first on a tie), kept when |dt| <= max_time_diff (s);
t_offset (s) is added to the estimate's stamps. Returns (ref, est) reduced
to the matched poses (pose k of one goes with pose k of the other; stamps
keep their own time frames). Raises InvalidArgument when nothing matches.)doc");
}

}  // namespace posefuse::python

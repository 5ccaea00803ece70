// posefuse.PoseGraph4Dof / PoseGraphSE3 / PoseGraphSummary, read_g2o and
// write_g2o: the pose graphs of graph/ built from numpy arrays or g2o files.
//
// The 4-DoF graph holds (x, y, z, yaw) with roll and pitch fixed per node; a
// planar (2-D g2o) graph is the 4-DoF graph with z = 0, and arrays of
// (x, y, yaw) poses, 2-vectors dp and 3x3 (x, y, theta) informations are
// accepted for it (graph/g2o_graph.hpp's mapping).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>

#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/g2o_se3.hpp>

#include "bindings.hpp"
#include "math_helpers.hpp"

namespace posefuse::python {
namespace {

namespace py = pybind11;
using namespace math;

RobustKernel kernel(const std::string& loss, double scale) {
  RobustKernel k;
  if (loss == "none") k.type = RobustLoss::kNone;
  else if (loss == "huber") k.type = RobustLoss::kHuber;
  else if (loss == "cauchy") k.type = RobustLoss::kCauchy;
  else throw py::value_error("loss must be 'none', 'huber' or 'cauchy', got '" + loss + "'");
  k.scale = scale;
  return k;
}

PoseGraphOptions options(const std::string& method, int max_iterations, double function_tolerance,
                         double gradient_tolerance, double parameter_tolerance, double initial_lambda,
                         bool planar_fast_path) {
  PoseGraphOptions o;
  if (method == "lm") o.levenberg_marquardt = true;
  else if (method == "gn") o.levenberg_marquardt = false;
  else throw py::value_error("method must be 'lm' (Levenberg-Marquardt) or 'gn' (Gauss-Newton), got '" + method + "'");
  o.max_iterations = max_iterations;
  o.function_tolerance = function_tolerance;
  o.gradient_tolerance = gradient_tolerance;
  o.parameter_tolerance = parameter_tolerance;
  o.initial_lambda = initial_lambda;
  o.planar_fast_path = planar_fast_path;
  o.validate();  // the C++ message naming the option, before the graph is looked at
  return o;
}

// ---- 4-DoF ------------------------------------------------------------------

/// A 4-DoF pose from (x, y, z, yaw) or planar (x, y, yaw).
Pose4Dof pose4(const double* p, py::ssize_t k, double roll, double pitch) {
  Pose4Dof x;
  if (k == 4) {
    x.p = Eigen::Vector3d(p[0], p[1], p[2]);
    x.yaw = p[3];
  } else {
    x.p = Eigen::Vector3d(p[0], p[1], 0.0);
    x.yaw = p[2];
  }
  x.roll = roll;
  x.pitch = pitch;
  return x;
}

/// `obj` as one pose (4,) or (3,) or a stack (n, 4) / (n, 3); returns its width.
py::ssize_t pose_width(const Arr& a, const std::string& what, bool stack) {
  const py::ssize_t nd = stack ? 2 : 1;
  if (a.ndim() != nd || (a.shape(nd - 1) != 4 && a.shape(nd - 1) != 3))
    throw py::value_error(what + ": expected an array of shape " + (stack ? "(N, 4) or (N, 3)" : "(4,) or (3,)") +
                          " ([x, y, z, yaw] or planar [x, y, yaw]), got " + shape_text(a));
  return a.shape(nd - 1);
}

Eigen::Matrix4d information4(const double* p, py::ssize_t k) {
  if (k == 4) return read<4, 4>(p);
  return planar_to_4dof_information(Eigen::Matrix3d(read<3, 3>(p)));
}

Edge4Dof edge4(std::int64_t i, std::int64_t j, const double* dp, py::ssize_t kd, double dyaw, const double* info,
               py::ssize_t ki, const RobustKernel& loss) {
  Edge4Dof e;
  e.from = i;
  e.to = j;
  e.dp = Eigen::Vector3d(dp[0], dp[1], kd == 3 ? dp[2] : 0.0);
  e.dyaw = dyaw;
  e.information = information4(info, ki);
  e.loss = loss;
  return e;
}

void add_node4(PoseGraph4Dof& g, std::int64_t id, const py::object& pose, bool fixed, double roll, double pitch) {
  require_numpy("PoseGraph4Dof.add_node");
  const Arr a = to_array(pose, "PoseGraph4Dof.add_node: pose");
  const py::ssize_t k = pose_width(a, "PoseGraph4Dof.add_node: pose", false);
  g.add_node(id, pose4(a.data(), k, roll, pitch), fixed);
}

void add_nodes4(PoseGraph4Dof& g, const py::object& ids_, const py::object& poses_, const py::object& fixed_,
                const py::object& rp_) {
  require_numpy("PoseGraph4Dof.add_nodes");
  const auto ids = int_array(ids_, -1, "PoseGraph4Dof.add_nodes: ids");
  const py::ssize_t n = ids.shape(0);
  const Arr poses = to_array(poses_, "PoseGraph4Dof.add_nodes: poses");
  const py::ssize_t k = pose_width(poses, "PoseGraph4Dof.add_nodes: poses", true);
  if (poses.shape(0) != n)
    throw py::value_error("PoseGraph4Dof.add_nodes: poses has " + std::to_string(poses.shape(0)) + " rows for " +
                          std::to_string(n) + " ids");
  py::array_t<bool, py::array::c_style | py::array::forcecast> fixed;
  if (!fixed_.is_none()) {
    fixed = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(fixed_);
    if (!fixed || fixed.ndim() != 1 || fixed.shape(0) != n)
      throw py::value_error("PoseGraph4Dof.add_nodes: fixed: expected a bool array of shape (" + std::to_string(n) +
                            ",)");
  }
  Stack rp;
  if (!rp_.is_none()) rp = rows_of(rp_, n, {2}, "PoseGraph4Dof.add_nodes: roll_pitch");
  g.reserve(g.num_nodes() + std::size_t(n), g.num_edges());
  for (py::ssize_t i = 0; i < n; ++i) {
    const double roll = rp_.is_none() ? 0.0 : rp.item(i)[0];
    const double pitch = rp_.is_none() ? 0.0 : rp.item(i)[1];
    g.add_node(ids.at(i), pose4(poses.data() + i * k, k, roll, pitch), fixed_.is_none() ? false : fixed.at(i));
  }
}

std::size_t add_edge4(PoseGraph4Dof& g, std::int64_t i, std::int64_t j, const py::object& dp_, double dyaw,
                      const py::object& info_, const std::string& loss, double scale) {
  require_numpy("PoseGraph4Dof.add_edge");
  const RobustKernel kern = kernel(loss, scale);
  const Arr dp = to_array(dp_, "PoseGraph4Dof.add_edge: dp");
  if (dp.ndim() != 1 || (dp.shape(0) != 3 && dp.shape(0) != 2))
    throw py::value_error("PoseGraph4Dof.add_edge: dp: expected an array of shape (3,) or (2,), got " + shape_text(dp));
  const Arr info = to_array(info_, "PoseGraph4Dof.add_edge: information");
  if (info.ndim() != 2 || !((info.shape(0) == 4 && info.shape(1) == 4) || (info.shape(0) == 3 && info.shape(1) == 3)))
    throw py::value_error("PoseGraph4Dof.add_edge: information: expected an array of shape (4, 4) or (3, 3), got " +
                          shape_text(info));
  return g.add_edge(edge4(i, j, dp.data(), dp.shape(0), dyaw, info.data(), info.shape(0), kern));
}

void add_edges4(PoseGraph4Dof& g, const py::object& i_, const py::object& j_, const py::object& dp_,
                const py::object& dyaw_, const py::object& info_, const std::string& loss, double scale) {
  require_numpy("PoseGraph4Dof.add_edges");
  const RobustKernel kern = kernel(loss, scale);
  const auto from = int_array(i_, -1, "PoseGraph4Dof.add_edges: i");
  const py::ssize_t m = from.shape(0);
  const auto to = int_array(j_, m, "PoseGraph4Dof.add_edges: j");
  const Arr dp = to_array(dp_, "PoseGraph4Dof.add_edges: dp");
  if (dp.ndim() != 2 || dp.shape(0) != m || (dp.shape(1) != 3 && dp.shape(1) != 2))
    throw py::value_error("PoseGraph4Dof.add_edges: dp: expected an array of shape (" + std::to_string(m) + ", 3) or (" +
                          std::to_string(m) + ", 2), got " + shape_text(dp));
  const Stack dyaw = rows_of(dyaw_, m, {}, "PoseGraph4Dof.add_edges: dyaw");
  const Arr info = to_array(info_, "PoseGraph4Dof.add_edges: information");
  const py::ssize_t nd = info.ndim();
  const py::ssize_t ki = nd >= 2 ? info.shape(nd - 1) : 0;
  const bool ok = (nd == 2 || (nd == 3 && info.shape(0) == m)) && (ki == 4 || ki == 3) && info.shape(nd - 2) == ki;
  if (!ok)
    throw py::value_error("PoseGraph4Dof.add_edges: information: expected an array of shape (" + std::to_string(m) +
                          ", 4, 4), (" + std::to_string(m) + ", 3, 3), (4, 4) or (3, 3), got " + shape_text(info));
  g.reserve(g.num_nodes(), g.num_edges() + std::size_t(m));
  for (py::ssize_t e = 0; e < m; ++e)
    g.add_edge(edge4(from.at(e), to.at(e), dp.data() + e * dp.shape(1), dp.shape(1), dyaw.item(e)[0],
                     info.data() + (nd == 3 ? e * ki * ki : 0), ki, kern));
}

py::array_t<double> poses4(const PoseGraph4Dof& g) {
  require_numpy("PoseGraph4Dof.poses");
  auto out = make({py::ssize_t(g.num_nodes())}, {4});
  double* o = out.mutable_data();
  for (const Pose4Dof& x : g.poses()) {
    o[0] = x.p.x(), o[1] = x.p.y(), o[2] = x.p.z(), o[3] = x.yaw;
    o += 4;
  }
  return out;
}

// ---- SE(3) -----------------------------------------------------------------

SE3d se3_arg(const double* p) { return se3_from_matrix(read<4, 4>(p)); }

void add_nodes3(PoseGraphSE3& g, const py::object& ids_, const py::object& poses_, const py::object& fixed_) {
  require_numpy("PoseGraphSE3.add_nodes");
  const auto ids = int_array(ids_, -1, "PoseGraphSE3.add_nodes: ids");
  const py::ssize_t n = ids.shape(0);
  const Stack T = rows_of(poses_, n, {4, 4}, "PoseGraphSE3.add_nodes: poses");
  py::array_t<bool, py::array::c_style | py::array::forcecast> fixed;
  if (!fixed_.is_none()) {
    fixed = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(fixed_);
    if (!fixed || fixed.ndim() != 1 || fixed.shape(0) != n)
      throw py::value_error("PoseGraphSE3.add_nodes: fixed: expected a bool array of shape (" + std::to_string(n) + ",)");
  }
  g.reserve(g.num_nodes() + std::size_t(n), g.num_edges());
  for (py::ssize_t i = 0; i < n; ++i)
    g.add_node(ids.at(i), se3_arg(T.item(i)), fixed_.is_none() ? false : fixed.at(i));
}

void add_edges3(PoseGraphSE3& g, const py::object& i_, const py::object& j_, const py::object& T_,
                const py::object& info_, const std::string& loss, double scale) {
  require_numpy("PoseGraphSE3.add_edges");
  const RobustKernel kern = kernel(loss, scale);
  const auto from = int_array(i_, -1, "PoseGraphSE3.add_edges: i");
  const py::ssize_t m = from.shape(0);
  const auto to = int_array(j_, m, "PoseGraphSE3.add_edges: j");
  const Stack T = rows_of(T_, m, {4, 4}, "PoseGraphSE3.add_edges: measurements");
  const Stack info = stack_of(info_, {6, 6}, "PoseGraphSE3.add_edges: information");
  if (!(info.lead.empty() || (info.lead.size() == 1 && info.lead[0] == m)))
    throw py::value_error("PoseGraphSE3.add_edges: information: expected an array of shape (" + std::to_string(m) +
                          ", 6, 6) or (6, 6), got " + shape_text(info.a));
  g.reserve(g.num_nodes(), g.num_edges() + std::size_t(m));
  for (py::ssize_t e = 0; e < m; ++e) {
    EdgeSE3 ed;
    ed.from = from.at(e);
    ed.to = to.at(e);
    ed.measurement = se3_arg(T.item(e));
    ed.information = read<6, 6>(info.item(e));
    ed.loss = kern;
    g.add_edge(ed);
  }
}

py::array_t<double> poses3(const PoseGraphSE3& g) {
  require_numpy("PoseGraphSE3.poses");
  auto out = make({py::ssize_t(g.num_nodes())}, {4, 4});
  for (std::size_t k = 0; k < g.num_nodes(); ++k) write<4, 4>(out.mutable_data() + k * 16, g.poses()[k].matrix());
  return out;
}

template <class Graph>
py::array_t<std::int64_t> ids_of(const Graph& g) {
  require_numpy("ids");
  py::array_t<std::int64_t> out(py::ssize_t(g.num_nodes()));
  std::copy(g.ids().begin(), g.ids().end(), out.mutable_data());
  return out;
}

template <class Graph>
py::array_t<bool> fixed_of(const Graph& g) {
  require_numpy("fixed");
  py::array_t<bool> out(py::ssize_t(g.num_nodes()));
  for (std::size_t k = 0; k < g.num_nodes(); ++k) out.mutable_at(py::ssize_t(k)) = g.is_fixed(g.ids()[k]);
  return out;
}

const char* loss_name(RobustLoss l) {
  switch (l) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "?";
}

// ---- g2o --------------------------------------------------------------------

py::object read_g2o(const std::filesystem::path& file, const std::string& loss, double scale) {
  const RobustKernel kern = kernel(loss, scale);
  if (g2o_dimension(file) == 2) return py::cast(pose_graph_from_g2o(read_g2o_2d(file), kern));
  return py::cast(pose_graph_from_g2o(read_g2o_3d(file), kern));
}

void write_g2o(const std::filesystem::path& file, const py::object& graph) {
  if (py::isinstance<PoseGraph4Dof>(graph)) {
    const PoseGraph4Dof& g = graph.cast<const PoseGraph4Dof&>();
    if (!g.is_planar())
      throw py::value_error(
          "write_g2o: the 4-DoF graph is not planar (a 2-D g2o file holds x, y, theta: every node at z = 0 with no "
          "roll or pitch, every edge with dp_z = 0 and no z coupling in its information)");
    G2oGraph2d out;
    for (std::size_t k = 0; k < g.num_nodes(); ++k) {
      const Pose4Dof& x = g.poses()[k];
      out.vertices.push_back(G2oVertexSE2{g.ids()[k], x.p.x(), x.p.y(), x.yaw, 0});
      if (g.is_fixed(g.ids()[k])) out.fixed.push_back(g.ids()[k]);
    }
    const int map[3] = {0, 1, 3};
    for (const Edge4Dof& e : g.edges()) {
      G2oEdgeSE2 o;
      o.from = e.from;
      o.to = e.to;
      o.dx = e.dp.x();
      o.dy = e.dp.y();
      o.dtheta = e.dyaw;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) o.information(r, c) = e.information(map[r], map[c]);
      out.edges.push_back(o);
    }
    write_g2o_2d(file, out);
    return;
  }
  if (py::isinstance<PoseGraphSE3>(graph)) {
    const PoseGraphSE3& g = graph.cast<const PoseGraphSE3&>();
    G2oGraph3d out;
    for (std::size_t k = 0; k < g.num_nodes(); ++k) {
      G2oVertexSE3 v;
      v.id = g.ids()[k];
      v.t = g.poses()[k].translation();
      v.q = g.poses()[k].so3().quaternion();
      out.vertices.push_back(v);
      if (g.is_fixed(v.id)) out.fixed.push_back(v.id);
    }
    for (const EdgeSE3& e : g.edges()) {
      G2oEdgeSE3 o;
      o.from = e.from;
      o.to = e.to;
      o.t = e.measurement.translation();
      o.q = e.measurement.so3().quaternion();
      o.information = e.information;
      out.edges.push_back(o);
    }
    write_g2o_3d(file, out);
    return;
  }
  throw py::type_error("write_g2o: graph must be a PoseGraph4Dof or a PoseGraphSE3, got " +
                       std::string(py::str(py::type::handle_of(graph).attr("__name__"))));
}

#define PF_OPTIMIZE_ARGS                                                                                          \
  py::arg("method") = "lm", py::arg("max_iterations") = 100, py::arg("function_tolerance") = 1e-10,               \
      py::arg("gradient_tolerance") = 1e-12, py::arg("parameter_tolerance") = 1e-10, py::arg("initial_lambda") = 1e-5

constexpr const char* kOptimizeDoc =
    "Minimises g2o's chi2 over the free nodes (Levenberg-Marquardt 'lm' or Gauss-Newton 'gn', analytic Jacobians, "
    "block sparse Cholesky); when no node is fixed the first is held. Options as the C++ PoseGraphOptions: "
    "max_iterations (linear solves), function_tolerance (relative cost decrease), gradient_tolerance (largest "
    "gradient entry), parameter_tolerance (step relative to the state), initial_lambda (LM damping). Returns a "
    "PoseGraphSummary; the graph's poses are updated. Raises ValueError naming the option when max_iterations < 1 "
    "or a tolerance or initial_lambda is NaN, infinite or negative, and when the graph is empty or disconnected "
    "from every fixed node (C++ messages).";

}  // namespace

void bind_graph(py::module_& m) {
  py::class_<PoseGraphSummary>(m, "PoseGraphSummary", "What a pose-graph optimisation did (read-only).")
      .def_readonly("initial_cost", &PoseGraphSummary::initial_cost, "g2o chi2 before (without robust losses)")
      .def_readonly("final_cost", &PoseGraphSummary::final_cost, "g2o chi2 after")
      .def_readonly("iterations", &PoseGraphSummary::iterations, "linear solves (accepted and rejected steps)")
      .def_readonly("accepted", &PoseGraphSummary::accepted, "steps that decreased the cost")
      .def_property_readonly(
          "termination", [](const PoseGraphSummary& s) { return std::string(to_string(s.termination)); },
          "why it stopped: 'function_tolerance', 'gradient_tolerance', 'parameter_tolerance', 'max_iterations' or "
          "'no_progress'")
      .def_readonly("solve_time_s", &PoseGraphSummary::solve_time_s, "wall time of optimize() (s)")
      .def_readonly("planar", &PoseGraphSummary::planar, "solved on (x, y, yaw) by the planar path")
      .def("__repr__", [](const PoseGraphSummary& s) {
        return "PoseGraphSummary(initial_cost=" + std::string(py::repr(py::float_(s.initial_cost))) +
               ", final_cost=" + std::string(py::repr(py::float_(s.final_cost))) +
               ", iterations=" + std::to_string(s.iterations) + ", accepted=" + std::to_string(s.accepted) +
               ", termination='" + std::string(to_string(s.termination)) + "', solve_time_s=" +
               std::string(py::repr(py::float_(s.solve_time_s))) + ", planar=" + (s.planar ? "True" : "False") + ")";
      }, "All fields.");

  py::class_<PoseGraph4Dof>(
      m, "PoseGraph4Dof",
      "A 4-DoF pose graph (x, y, z, yaw; roll and pitch held per node), VINS-Mono's global pose graph; a planar g2o "
      "graph is this graph with z = 0. Cost: g2o's chi2, sum of rho(e^T Omega e) with the EDGE_SE2 error extended "
      "to 4-DoF (translation error in the measurement's frame). Node ids are any int64 values.")
      .def(py::init<>(), "An empty graph.")
      .def("add_node", &add_node4, py::arg("id"), py::arg("pose"), py::arg("fixed") = false, py::arg("roll") = 0.0,
           py::arg("pitch") = 0.0,
           "Adds node `id` at pose (4,) [x, y, z, yaw] or planar (3,) [x, y, yaw] (z = 0), with fixed roll and pitch "
           "(rad). Raises ValueError for a duplicate id or a non-finite pose (C++ message).")
      .def("add_nodes", &add_nodes4, py::arg("ids"), py::arg("poses"), py::arg("fixed") = py::none(),
           py::arg("roll_pitch") = py::none(),
           "Adds nodes ids (N,) at poses (N, 4) [x, y, z, yaw] or (N, 3) [x, y, yaw]; fixed (N,) bool, roll_pitch "
           "(N, 2) [roll, pitch]. Nodes before a bad one stay added.")
      .def("add_edge", &add_edge4, py::arg("i"), py::arg("j"), py::arg("dp"), py::arg("dyaw"), py::arg("information"),
           py::arg("loss") = "none", py::arg("loss_scale") = 1.0,
           "Adds edge i -> j measuring j's position in i's frame dp (3,) (or planar (2,)) and the relative yaw dyaw "
           "(rad), with information (4, 4) over [x, y, z, yaw] or planar (3, 3) over [x, y, theta] (unit z), robust "
           "loss 'none' | 'huber' | 'cauchy' with its scale (whitened units). Returns the edge index. Raises "
           "ValueError naming the edge for a missing node, a self edge, a non-finite measurement, an information "
           "that is not finite, symmetric and PSD, or a bad loss scale (C++ messages).")
      .def("add_edges", &add_edges4, py::arg("i"), py::arg("j"), py::arg("dp"), py::arg("dyaw"),
           py::arg("information"), py::arg("loss") = "none", py::arg("loss_scale") = 1.0,
           "Adds M edges: i, j (M,), dp (M, 3) or (M, 2), dyaw (M,), information (M, 4, 4), (M, 3, 3) or one "
           "matrix for all. Edges before a bad one stay added.")
      .def("set_fixed", &PoseGraph4Dof::set_fixed, py::arg("id"), py::arg("fixed") = true, "Holds node `id` fixed (or frees it).")
      .def("is_fixed", &PoseGraph4Dof::is_fixed, py::arg("id"), "True when node `id` is held fixed.")
      .def_property_readonly("num_nodes", &PoseGraph4Dof::num_nodes, "number of nodes")
      .def_property_readonly("num_edges", &PoseGraph4Dof::num_edges, "number of edges")
      .def("__len__", &PoseGraph4Dof::num_nodes, "number of nodes")
      .def_property_readonly("ids", &ids_of<PoseGraph4Dof>, "node ids (N,) int64, insertion order")
      .def_property_readonly("fixed", &fixed_of<PoseGraph4Dof>, "(N,) bool: node held fixed")
      .def_property_readonly("poses", &poses4, "(N, 4) [x, y, z, yaw] in insertion order (a copy)")
      .def_property_readonly(
          "roll_pitch",
          [](const PoseGraph4Dof& g) {
            require_numpy("PoseGraph4Dof.roll_pitch");
            auto out = make({py::ssize_t(g.num_nodes())}, {2});
            for (std::size_t k = 0; k < g.num_nodes(); ++k) {
              out.mutable_data()[2 * k] = g.poses()[k].roll;
              out.mutable_data()[2 * k + 1] = g.poses()[k].pitch;
            }
            return out;
          },
          "(N, 2) [roll, pitch] of every node (held fixed)")
      .def(
          "pose",
          [](const PoseGraph4Dof& g, std::int64_t id) {
            const Pose4Dof& x = g.pose(id);
            return to_numpy<4, 1>(Eigen::Vector4d(x.p.x(), x.p.y(), x.p.z(), x.yaw));
          },
          py::arg("id"), "The pose (4,) [x, y, z, yaw] of node `id` (ValueError when it does not exist).")
      .def(
          "set_pose",
          [](PoseGraph4Dof& g, std::int64_t id, const py::object& pose) {
            require_numpy("PoseGraph4Dof.set_pose");
            const Arr a = to_array(pose, "PoseGraph4Dof.set_pose: pose");
            const py::ssize_t k = pose_width(a, "PoseGraph4Dof.set_pose: pose", false);
            const Pose4Dof& old = g.pose(id);
            g.set_pose(id, pose4(a.data(), k, old.roll, old.pitch));
          },
          py::arg("id"), py::arg("pose"),
          "Moves node `id` to pose (4,) [x, y, z, yaw] or (3,) [x, y, yaw] (z = 0); roll and pitch are kept.")
      .def_property_readonly(
          "edges",
          [](const PoseGraph4Dof& g) {
            require_numpy("PoseGraph4Dof.edges");
            const py::ssize_t ne = py::ssize_t(g.num_edges());
            py::array_t<std::int64_t> from(ne), to(ne);
            auto dp = make({ne}, {3});
            auto dyaw = make({ne}, {});
            auto info = make({ne}, {4, 4});
            py::list loss;
            for (py::ssize_t e = 0; e < ne; ++e) {
              const Edge4Dof& ed = g.edges()[std::size_t(e)];
              from.mutable_at(e) = ed.from;
              to.mutable_at(e) = ed.to;
              write<3, 1>(dp.mutable_data() + 3 * e, ed.dp);
              dyaw.mutable_at(e) = ed.dyaw;
              write<4, 4>(info.mutable_data() + 16 * e, ed.information);
              loss.append(py::make_tuple(loss_name(ed.loss.type), ed.loss.scale));
            }
            py::dict d;
            d["i"] = from, d["j"] = to, d["dp"] = dp, d["dyaw"] = dyaw, d["information"] = info, d["loss"] = loss;
            return d;
          },
          "The edges as a dict of arrays: i, j (M,) int64, dp (M, 3), dyaw (M,), information (M, 4, 4), loss (list "
          "of (name, scale)).")
      .def("cost", &PoseGraph4Dof::cost, "g2o chi2 (with the robust losses) at the current poses.")
      .def("is_planar", &PoseGraph4Dof::is_planar,
           "True when every node is at z = 0 with no roll or pitch and no edge couples z (optimize() then solves "
           "on x, y, yaw).")
      .def("validate", &PoseGraph4Dof::validate,
           "Raises ValueError when the graph is empty or some node has no edge path to a fixed node (C++ message).")
      .def("initialize_rotation_first", py::overload_cast<>(&PoseGraph4Dof::initialize_rotation_first),
           "Rotation-first initialisation (Carlone et al. 2015): chordal yaw, then one linear translation solve; "
           "robust losses ignored. Raises ValueError as validate() or for a singular system.")
      .def(
          "optimize",
          [](PoseGraph4Dof& g, const std::string& method, int max_it, double ft, double gt, double pt, double lam,
             bool planar) {
            const PoseGraphOptions o = options(method, max_it, ft, gt, pt, lam, planar);
            return g.optimize(o);
          },
          PF_OPTIMIZE_ARGS, py::arg("planar_fast_path") = true,
          (std::string(kOptimizeDoc) + " planar_fast_path: solve a planar graph on (x, y, yaw) blocks (same optimum).")
              .c_str())
      .def("__repr__", [](const PoseGraph4Dof& g) {
        return "PoseGraph4Dof(num_nodes=" + std::to_string(g.num_nodes()) + ", num_edges=" + std::to_string(g.num_edges()) +
               ")";
      }, "Sizes of the graph.");

  py::class_<PoseGraphSE3>(
      m, "PoseGraphSE3",
      "An SE(3) pose graph: node poses T_w_b (4x4), relative edges with g2o's EdgeSE3 error [t; q_xyz] of "
      "Z^-1 Xi^-1 Xj and 6x6 information over [x, y, z, qx, qy, qz]. Cost: g2o's chi2.")
      .def(py::init<>(), "An empty graph.")
      .def(
          "add_node",
          [](PoseGraphSE3& g, std::int64_t id, const py::object& T, bool fixed) {
            require_numpy("PoseGraphSE3.add_node");
            g.add_node(id, se3_from_matrix(matrix_arg<4, 4>(T, "PoseGraphSE3.add_node: T")), fixed);
          },
          py::arg("id"), py::arg("T"), py::arg("fixed") = false,
          "Adds node `id` at pose T (4, 4). Raises ValueError for a duplicate id or an invalid pose.")
      .def("add_nodes", &add_nodes3, py::arg("ids"), py::arg("poses"), py::arg("fixed") = py::none(),
           "Adds nodes ids (N,) at poses (N, 4, 4); fixed (N,) bool. Nodes before a bad one stay added.")
      .def(
          "add_edge",
          [](PoseGraphSE3& g, std::int64_t i, std::int64_t j, const py::object& T, const py::object& info,
             const std::string& loss, double scale) {
            require_numpy("PoseGraphSE3.add_edge");
            EdgeSE3 e;
            e.from = i;
            e.to = j;
            e.loss = kernel(loss, scale);
            e.measurement = se3_from_matrix(matrix_arg<4, 4>(T, "PoseGraphSE3.add_edge: T_ij"));
            e.information = matrix_arg<6, 6>(info, "PoseGraphSE3.add_edge: information");
            return g.add_edge(e);
          },
          py::arg("i"), py::arg("j"), py::arg("T_ij"), py::arg("information"), py::arg("loss") = "none",
          py::arg("loss_scale") = 1.0,
          "Adds edge i -> j measuring j's pose in i's frame T_ij (4, 4) with information (6, 6) over [x, y, z, qx, "
          "qy, qz]; robust loss 'none' | 'huber' | 'cauchy'. Returns the edge index. Raises ValueError naming the "
          "edge (C++ messages).")
      .def("add_edges", &add_edges3, py::arg("i"), py::arg("j"), py::arg("measurements"), py::arg("information"),
           py::arg("loss") = "none", py::arg("loss_scale") = 1.0,
           "Adds M edges: i, j (M,), measurements (M, 4, 4), information (M, 6, 6) or one (6, 6) for all.")
      .def("set_fixed", &PoseGraphSE3::set_fixed, py::arg("id"), py::arg("fixed") = true, "Holds node `id` fixed (or frees it).")
      .def("is_fixed", &PoseGraphSE3::is_fixed, py::arg("id"), "True when node `id` is held fixed.")
      .def_property_readonly("num_nodes", &PoseGraphSE3::num_nodes, "number of nodes")
      .def_property_readonly("num_edges", &PoseGraphSE3::num_edges, "number of edges")
      .def("__len__", &PoseGraphSE3::num_nodes, "number of nodes")
      .def_property_readonly("ids", &ids_of<PoseGraphSE3>, "node ids (N,) int64, insertion order")
      .def_property_readonly("fixed", &fixed_of<PoseGraphSE3>, "(N,) bool: node held fixed")
      .def_property_readonly("poses", &poses3, "(N, 4, 4) node poses in insertion order (a copy)")
      .def(
          "pose", [](const PoseGraphSE3& g, std::int64_t id) { return to_numpy<4, 4>(g.pose(id).matrix()); },
          py::arg("id"), "The pose (4, 4) of node `id`.")
      .def(
          "set_pose",
          [](PoseGraphSE3& g, std::int64_t id, const py::object& T) {
            require_numpy("PoseGraphSE3.set_pose");
            g.set_pose(id, se3_from_matrix(matrix_arg<4, 4>(T, "PoseGraphSE3.set_pose: T")));
          },
          py::arg("id"), py::arg("T"), "Moves node `id` to pose T (4, 4).")
      .def_property_readonly(
          "edges",
          [](const PoseGraphSE3& g) {
            require_numpy("PoseGraphSE3.edges");
            const py::ssize_t ne = py::ssize_t(g.num_edges());
            py::array_t<std::int64_t> from(ne), to(ne);
            auto T = make({ne}, {4, 4});
            auto info = make({ne}, {6, 6});
            py::list loss;
            for (py::ssize_t e = 0; e < ne; ++e) {
              const EdgeSE3& ed = g.edges()[std::size_t(e)];
              from.mutable_at(e) = ed.from;
              to.mutable_at(e) = ed.to;
              write<4, 4>(T.mutable_data() + 16 * e, ed.measurement.matrix());
              write<6, 6>(info.mutable_data() + 36 * e, ed.information);
              loss.append(py::make_tuple(loss_name(ed.loss.type), ed.loss.scale));
            }
            py::dict d;
            d["i"] = from, d["j"] = to, d["measurements"] = T, d["information"] = info, d["loss"] = loss;
            return d;
          },
          "The edges as a dict of arrays: i, j (M,) int64, measurements (M, 4, 4), information (M, 6, 6), loss.")
      .def("cost", &PoseGraphSE3::cost, "g2o chi2 (with the robust losses) at the current poses.")
      .def("validate", &PoseGraphSE3::validate,
           "Raises ValueError when the graph is empty or some node has no edge path to a fixed node.")
      .def("initialize_chordal", py::overload_cast<>(&PoseGraphSE3::initialize_chordal),
           "Chordal initialisation (Martinec and Pajdla 2007; Carlone et al. 2015): rotations by the chordal "
           "relaxation projected to SO(3), then one linear translation solve.")
      .def(
          "optimize",
          [](PoseGraphSE3& g, const std::string& method, int max_it, double ft, double gt, double pt, double lam) {
            const PoseGraphOptions o = options(method, max_it, ft, gt, pt, lam, true);
            return g.optimize(o);
          },
          PF_OPTIMIZE_ARGS, kOptimizeDoc)
      .def("__repr__", [](const PoseGraphSE3& g) {
        return "PoseGraphSE3(num_nodes=" + std::to_string(g.num_nodes()) + ", num_edges=" + std::to_string(g.num_edges()) +
               ")";
      }, "Sizes of the graph.");

  m.def("read_g2o", &read_g2o, py::arg("path"), py::arg("loss") = "none", py::arg("loss_scale") = 1.0,
        "Reads a g2o file: VERTEX_SE2 / EDGE_SE2 gives a (planar) PoseGraph4Dof, VERTEX_SE3:QUAT / EDGE_SE3:QUAT a "
        "PoseGraphSE3 (detected from the first vertex or edge line); FIX lines hold nodes fixed; every edge gets the "
        "robust loss. File errors raise with the C++ 'file:line: reason' text.");
  m.def("write_g2o", &write_g2o, py::arg("path"), py::arg("graph"),
        "Writes a graph as a g2o file (a planar PoseGraph4Dof as 2-D, a PoseGraphSE3 as 3-D): vertices, FIX, edges, "
        "numbers as the shortest text that reads back exactly. Robust losses are not written. A graph without nodes "
        "raises ValueError and writes nothing (read_g2o refuses a file without vertices).");
}

}  // namespace posefuse::python

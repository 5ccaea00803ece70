#pragma once
/// @file
/// Planar g2o graphs (io/g2o.hpp) as 4-DoF pose graphs, 3-D ones
/// (io/g2o_se3.hpp) as SE(3) pose graphs, and back.
///
/// A planar graph is the 4-DoF graph with z = 0 and roll = pitch = 0: an
/// `EDGE_SE2` (dx, dy, dθ, Ω₃ in the order x, y, θ) becomes an Edge4Dof with
/// \f$ \Delta p = (dx, dy, 0) \f$ and the 4x4 information
/// \f$ \Omega_4 \f$ that has \f$ \Omega_3 \f$'s entries on the rows and columns
/// (x, y, yaw), 1 at (z, z) and 0 elsewhere on z's row and column.
/// The z residual is identically zero (every node stays at z = 0), so the
/// unit z information never changes the cost, which is then exactly g2o's χ².

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/g2o_se3.hpp>

namespace posefuse {

/// The 4x4 (x, y, z, yaw) information of a planar (x, y, θ) one, unit on z.
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix4d planar_to_4dof_information(const Eigen::Matrix3d& I3) {
  Eigen::Matrix4d I4 = Eigen::Matrix4d::Zero();
  const int map[3] = {0, 1, 3};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) I4(map[r], map[c]) = I3(r, c);
  I4(2, 2) = 1.0;
  return I4;
}

/// The 4-DoF pose graph of a planar g2o graph (`FIX` ids held fixed; with
/// none, optimize() holds the first vertex).
/// @param[in] g the parsed planar g2o graph
/// @param[in] loss robust loss given to every edge
/// @throws posefuse::invalid_argument as PoseGraph4Dof::add_node / add_edge
///         (duplicate vertex ids, an edge naming a missing vertex, ...)
template <class Lazy = void>
[[nodiscard]] PoseGraph4Dof pose_graph_from_g2o(const G2oGraph2d& g, const RobustKernel& loss = {}) {
  PoseGraph4Dof graph;
  graph.reserve(g.vertices.size(), g.edges.size());
  for (const G2oVertexSE2& v : g.vertices)
    graph.add_node(v.id, Pose4Dof{Eigen::Vector3d(v.x, v.y, 0.0), v.theta, 0.0, 0.0});
  for (const std::int64_t id : g.fixed) graph.set_fixed(id);
  for (const G2oEdgeSE2& e : g.edges) {
    Edge4Dof ed;
    ed.from = e.from;
    ed.to = e.to;
    ed.dp = Eigen::Vector3d(e.dx, e.dy, 0.0);
    ed.dyaw = e.dtheta;
    ed.information = planar_to_4dof_information(e.information);
    ed.loss = loss;
    graph.add_edge(ed);
  }
  return graph;
}

/// `g` with every vertex moved to the graph's pose of the same id (x, y, yaw).
/// @throws posefuse::invalid_argument when a vertex id is not in the graph
template <class Lazy = void>
[[nodiscard]] G2oGraph2d with_graph_poses(G2oGraph2d g, const PoseGraph4Dof& graph) {
  for (G2oVertexSE2& v : g.vertices) {
    const Pose4Dof& x = graph.pose(v.id);
    v.x = x.p.x();
    v.y = x.p.y();
    v.theta = x.yaw;
  }
  return g;
}

/// The SE(3) pose graph of a 3-D g2o graph (`FIX` ids held fixed; with
/// @param[in] g the parsed 3-D g2o graph
/// none, optimize() holds the first vertex). Its cost is g2o's χ².
/// @param[in] loss robust loss given to every edge
/// @throws posefuse::invalid_argument as PoseGraphSE3::add_node / add_edge
template <class Lazy = void>
[[nodiscard]] PoseGraphSE3 pose_graph_from_g2o(const G2oGraph3d& g, const RobustKernel& loss = {}) {
  PoseGraphSE3 graph;
  graph.reserve(g.vertices.size(), g.edges.size());
  for (const G2oVertexSE3& v : g.vertices) graph.add_node(v.id, SE3d(v.t, SO3d(v.q)));
  for (const std::int64_t id : g.fixed) graph.set_fixed(id);
  for (const G2oEdgeSE3& e : g.edges) {
    EdgeSE3 ed;
    ed.from = e.from;
    ed.to = e.to;
    ed.measurement = SE3d(e.t, SO3d(e.q));
    ed.information = e.information;
    ed.loss = loss;
    graph.add_edge(ed);
  }
  return graph;
}

/// `g` with every vertex moved to the graph's pose of the same id.
/// @throws posefuse::invalid_argument when a vertex id is not in the graph
template <class Lazy = void>
[[nodiscard]] G2oGraph3d with_graph_poses(G2oGraph3d g, const PoseGraphSE3& graph) {
  for (G2oVertexSE3& v : g.vertices) {
    const SE3d& x = graph.pose(v.id);
    v.t = x.translation();
    v.q = x.so3().quaternion();
  }
  return g;
}

}  // namespace posefuse

#pragma once
/// @file
/// 4-DoF pose-graph optimisation (x, y, z, yaw; roll and pitch held fixed):
/// the global pose graph of VINS-Mono (Qin, Li, Shen, "VINS-Mono: A Robust
/// and Versatile Monocular Visual-Inertial State Estimator", IEEE T-RO 2018,
/// Sec. VIII), where loop closures correct the drift of the four directions
/// a visual-inertial system cannot observe, solved without Ceres:
/// Gauss–Newton or Levenberg–Marquardt with analytic Jacobians, a
/// block-ordered sparse Cholesky and per-edge robust losses, plus the
/// rotation-first initialisation of Carlone et al. 2015.
///
/// This header holds the graph (PoseGraph4Dof: nodes, edges, fixed nodes,
/// input validation, the solver's workspace) and gives everything a user of
/// it needs:
///  * graph/edge_error_4dof.hpp: Pose4Dof, Edge4Dof, the edge error and its
///    Jacobians (edge_error_4dof, edge_error_planar, roll_pitch_rotation);
///  * graph/robust_loss.hpp: RobustLoss, RobustKernel;
///  * graph/pose_graph_options.hpp: PoseGraphOptions, PoseGraphSummary,
///    Termination;
///  * graph/pose_graph_workspace.hpp: PoseGraphWorkspace.
/// The solvers are in graph/detail/ (rotation_first_4dof.hpp,
/// pose_graph_assembly.hpp, levenberg_marquardt.hpp, block_system.hpp).
///
/// **Cost** (g2o's χ²): \f$ F = \sum_k \rho_k(s_k) \f$ over the edges, with
/// \f$ s_k = e_k^\top \Omega_k e_k \f$ and \f$ \rho(s) = s \f$ without a
/// robust loss. Ceres reports \f$ F/2 \f$.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/graph/detail/levenberg_marquardt.hpp>
#include <posefuse/graph/detail/pose_graph_assembly.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/detail/rotation_first_4dof.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/graph/pose_graph_options.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>
#include <posefuse/graph/robust_loss.hpp>

namespace posefuse {

/// PoseGraph4Dof::normal_equations(): the Gauss–Newton system over the free nodes.
struct NormalEquations {
  Eigen::MatrixXd H;               ///< symmetric, B·n x B·n
  Eigen::VectorXd b;               ///< gradient of the cost / 2
  std::vector<std::int64_t> ids;   ///< node id of each block column
  int block_size = 4;              ///< B: 4 ([x, y, z, yaw]) or 3 (planar [x, y, yaw])
};

/// A 4-DoF pose graph: nodes with unique ids, relative edges, fixed nodes.
///
/// Usage: add_node for every pose, add_edge for every measurement, optionally
/// initialize_rotation_first(), then optimize(). Nodes keep their insertion
/// order; ids are any std::int64_t values.
///
/// The graph owns its solver's buffers (a PoseGraphWorkspace): they keep
/// their capacity between solves of this graph, no two graphs share them,
/// and they are freed with the graph or by release_workspace(). A copy of a
/// graph starts with an empty workspace.
class PoseGraph4Dof {
 public:
  /// Reserves storage for `nodes` nodes and `edges` edges (optional; saves
  /// the re-allocations of a graph built node by node).
  void reserve(std::size_t nodes, std::size_t edges) {
    ids_.reserve(nodes);
    poses_.reserve(nodes);
    Qt_.reserve(nodes);
    fixed_.reserve(nodes);
    index_.reserve(nodes);
    edges_.reserve(edges);
    ends_.reserve(edges);
  }

  /// Adds a node.
  /// @param[in] id unique id
  /// @param[in] pose initial pose (roll and pitch stay fixed)
  /// @param[in] fixed held constant by the optimiser
  /// @throws posefuse::invalid_argument for a duplicate id or a non-finite pose
  void add_node(std::int64_t id, const Pose4Dof& pose, bool fixed = false) {
    if (!is_finite(pose)) throw invalid_argument("pose graph: node " + std::to_string(id) + " has a non-finite pose");
    if (!index_.emplace(id, static_cast<int>(ids_.size())).second)
      throw invalid_argument("pose graph: duplicate node id " + std::to_string(id));
    layout_valid_ = false;
    ids_.push_back(id);
    poses_.push_back(pose);
    poses_.back().yaw = wrap_angle(pose.yaw);
    Qt_.push_back(roll_pitch_rotation(pose).transpose());
    fixed_.push_back(fixed ? 1 : 0);
  }

  /// Adds an edge and returns its index.
  /// @throws posefuse::invalid_argument naming the edge when a node is
  ///         missing, both ends are one node, the measurement is not finite,
  ///         the information is not finite, not symmetric or not positive
  ///         semi-definite, or a robust-loss scale is not finite and > 0
  std::size_t add_edge(const Edge4Dof& e) {
    // The message prefix is built only when an edge is refused.
    const auto what = [&] {
      return "pose graph: edge " + std::to_string(edges_.size()) + " (" + std::to_string(e.from) + " -> " +
             std::to_string(e.to) + ")";
    };
    const auto fi = index_.find(e.from);
    const auto ti = index_.find(e.to);
    if (fi == index_.end()) throw invalid_argument(what() + ": node " + std::to_string(e.from) + " does not exist");
    if (ti == index_.end()) throw invalid_argument(what() + ": node " + std::to_string(e.to) + " does not exist");
    if (fi->second == ti->second) throw invalid_argument(what() + ": both ends are the same node");
    if (!e.dp.allFinite() || !std::isfinite(e.dyaw))
      throw invalid_argument(what() + ": the measurement is not finite");
    if (!e.information.allFinite()) throw invalid_argument(what() + ": the information matrix is not finite");
    if (!is_positive_semidefinite(e.information))
      throw invalid_argument(what() + ": the information matrix is not symmetric positive semi-definite");
    if (e.loss.type != RobustLoss::kNone && !(std::isfinite(e.loss.scale) && e.loss.scale > 0))
      throw invalid_argument(what() + ": the robust-loss scale must be finite and > 0");
    layout_valid_ = false;
    edges_.push_back(e);
    ends_.emplace_back(fi->second, ti->second);
    return edges_.size() - 1;
  }

  /// Holds node `id` fixed (or frees it).
  /// @throws posefuse::invalid_argument when the node does not exist
  void set_fixed(std::int64_t id, bool fixed = true) {
    fixed_[std::size_t(node_index(id))] = fixed ? 1 : 0;
    layout_valid_ = false;
  }
  /// True when node `id` is held fixed.
  [[nodiscard]] bool is_fixed(std::int64_t id) const { return fixed_[std::size_t(node_index(id))] != 0; }
  /// Number of nodes.
  [[nodiscard]] std::size_t num_nodes() const noexcept { return poses_.size(); }
  /// Number of edges.
  [[nodiscard]] std::size_t num_edges() const noexcept { return edges_.size(); }
  /// Node ids in insertion order.
  [[nodiscard]] const std::vector<std::int64_t>& ids() const noexcept { return ids_; }
  /// Poses in insertion order.
  [[nodiscard]] const std::vector<Pose4Dof>& poses() const noexcept { return poses_; }
  /// The edges in insertion order.
  [[nodiscard]] const std::vector<Edge4Dof>& edges() const noexcept { return edges_; }
  /// The pose of node `id`.
  /// @throws posefuse::invalid_argument when the node does not exist
  [[nodiscard]] const Pose4Dof& pose(std::int64_t id) const { return poses_[std::size_t(node_index(id))]; }
  /// Replaces the pose of node `id` (roll and pitch included).
  /// @throws posefuse::invalid_argument when the node does not exist or the pose is not finite
  void set_pose(std::int64_t id, const Pose4Dof& pose) {
    const std::size_t k = std::size_t(node_index(id));
    if (!is_finite(pose))
      throw invalid_argument("pose graph: node " + std::to_string(id) + " set to a non-finite pose");
    poses_[k] = pose;
    poses_[k].yaw = wrap_angle(pose.yaw);
    Qt_[k] = roll_pitch_rotation(pose).transpose();
  }

  /// The cost \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$ at the current poses.
  [[nodiscard]] double cost() const {
    double F = 0.0;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const std::size_t i = std::size_t(ends_[k].first), j = std::size_t(ends_[k].second);
      const Edge4Dof& ed = edges_[k];
      const Eigen::Vector4d e =
          edge_error_4dof(poses_[i].p, poses_[i].yaw, Qt_[i], poses_[j].p, poses_[j].yaw, ed.dp, ed.dyaw);
      F += ed.loss.rho(e.dot(ed.information * e));
    }
    return F;
  }

  /// Checks that every node is linked through edges to a fixed node (when
  /// no node is fixed, the first one is taken as fixed, as optimize() does).
  /// @throws posefuse::invalid_argument when the graph is empty, or is
  ///         disconnected: the message names the nodes (up to 10 ids) that
  ///         no edge path links to a fixed node, and how many there are
  void validate() const {
    if (poses_.empty()) throw invalid_argument("pose graph: no nodes");
    const std::vector<char> fixed = effective_fixed();
    std::vector<int> parent(poses_.size());
    for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
    const auto find = [&parent](int x) {
      while (parent[std::size_t(x)] != x) {
        parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
        x = parent[std::size_t(x)];
      }
      return x;
    };
    for (const auto& e : ends_) {
      const int a = find(e.first), b = find(e.second);
      if (a != b) parent[std::size_t(a)] = b;
    }
    std::vector<char> anchored(poses_.size(), 0);
    for (std::size_t i = 0; i < poses_.size(); ++i)
      if (fixed[i]) anchored[std::size_t(find(static_cast<int>(i)))] = 1;
    std::vector<std::int64_t> loose;
    for (std::size_t i = 0; i < poses_.size(); ++i)
      if (!anchored[std::size_t(find(static_cast<int>(i)))]) loose.push_back(ids_[i]);
    if (loose.empty()) return;
    std::string list;
    for (std::size_t k = 0; k < loose.size() && k < 10; ++k) {
      if (k > 0) list += ", ";
      list += std::to_string(loose[k]);
    }
    if (loose.size() > 10) list += ", ...";
    throw invalid_argument("pose graph is disconnected: " + std::to_string(loose.size()) +
                           " node(s) are not linked by any edge path to a fixed node (ids " + list +
                           "); add edges or fix a node in each part");
  }

  /// Rotation-first initialisation (Carlone, Tron, Daniilidis, Dellaert,
  /// "Initialization techniques for 3D SLAM: a survey on rotation estimation
  /// and its use in pose graph optimization", ICRA 2015, chordal relaxation):
  /// 1. yaw: minimise \f$ \sum_k \Omega_{k,\psi\psi} \| v_j - R(\Delta\psi_k) v_i \|^2 \f$
  ///    over unconstrained 2-vectors \f$ v_i \f$ (the first column of
  ///    \f$ R_z(\psi_i) \f$; fixed nodes keep theirs), a sparse linear least
  ///    squares, then \f$ \psi_i = \mathrm{atan2}(v_{i,y}, v_{i,x}) \f$;
  /// 2. translation: with the yaws fixed the cost is quadratic in the
  ///    positions; one exact Newton step minimises it.
  /// Robust losses are ignored here (weights 1). Uses the graph's own workspace.
  /// @throws posefuse::invalid_argument as validate(), or when a linear system is singular
  void initialize_rotation_first() { initialize_rotation_first(workspace_); }

  /// initialize_rotation_first() with the caller's buffers (see PoseGraphWorkspace).
  void initialize_rotation_first(PoseGraphWorkspace& workspace) {
    validate();
    const detail::PoseGraphLayout& L = layout();
    if (L.n == 0) return;
    detail::chordal_yaws(edge_view(), L, poses_, workspace.yaw);
    detail::positions_for_yaws(edge_view(), L, poses_, workspace.planar);
  }

  /// Minimises the cost over the free nodes' x, y, z and yaw.
  ///
  /// Each iteration linearises every edge (analytic Jacobians of
  /// edge_error_4dof), weights it by \f$ \rho'(s) \f$ (IRLS), assembles
  /// \f$ H = \sum J^\top \rho' \Omega J \f$ and \f$ b = \sum J^\top \rho' \Omega e \f$
  /// in 4x4 blocks, and solves \f$ (H + \lambda\,\mathrm{diag}(H)) \Delta = -b \f$
  /// with a block sparse Cholesky (graph/detail/block_system.hpp: 4x4 blocks,
  /// block AMD ordering computed once per graph structure, symbolic analysis
  /// once per call). LM adapts \f$ \lambda \f$ by the gain ratio (Nielsen's
  /// rule); a step is taken only when it lowers the cost. When no node is
  /// fixed, the first is held fixed. Uses the graph's own workspace.
  /// @throws posefuse::invalid_argument as validate() or options.validate() (PoseGraphOptions)
  PoseGraphSummary optimize(const PoseGraphOptions& options = {}) { return optimize(options, workspace_); }

  /// optimize() with the caller's buffers (see PoseGraphWorkspace): the same
  /// result to the last bit, whatever the workspace held before.
  PoseGraphSummary optimize(const PoseGraphOptions& options, PoseGraphWorkspace& workspace) {
    const auto t0 = std::chrono::steady_clock::now();
    validate();
    PoseGraphSummary s = options.planar_fast_path && is_planar() ? optimize_blocks<3>(options, workspace.planar)
                                                                   : optimize_blocks<4>(options, workspace.general);
    s.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
  }

  /// The Gauss–Newton system optimize() solves at the current poses (before
  /// damping): \f$ H = \sum J^\top \rho' \Omega J \f$, \f$ b = \sum J^\top
  /// \rho' \Omega e \f$ over the free nodes, dense. Block column c belongs to
  /// node `ids[c]` (the solver's fill-reducing order); a block is
  /// [x, y, z, yaw], or [x, y, yaw] with `planar` on a planar graph (the
  /// planar path's system). Uses: covariance recovery on small graphs
  /// (\f$ H^{-1} \f$ at the optimum), and checking the assembly against the
  /// edges' Jacobians (tests). Its buffers are its own, freed on return.
  /// @throws posefuse::invalid_argument as validate(), or when `planar` is
  ///         asked of a graph that is not planar
  [[nodiscard]] NormalEquations normal_equations(bool planar = false) {
    validate();
    if (!planar) return normal_equations_blocks<4>();
    if (!is_planar()) throw invalid_argument("pose graph: normal_equations(planar) of a graph that is not planar");
    return normal_equations_blocks<3>();
  }

  /// Frees the graph's solver buffers. optimize() and
  /// initialize_rotation_first() keep their arrays (the Cholesky factor above
  /// all) between calls on this graph, so that solving it again does not
  /// page fresh memory in; destroying the graph frees them too.
  void release_workspace() noexcept { workspace_.release(); }

  /// Bytes the graph's solver buffers hold (their capacity; 0 before the
  /// first solve and after release_workspace()).
  [[nodiscard]] std::size_t workspace_bytes() const noexcept { return workspace_.capacity_bytes(); }

  /// True when the graph is planar: every node at z = 0 with no roll or
  /// pitch, every edge with \f$ \Delta p_z = 0 \f$ and an information
  /// matrix whose z row and column are zero off the diagonal (as
  /// pose_graph_from_g2o builds). Then the z residuals are identically zero
  /// and decouple from x, y and yaw, and optimize() may solve on (x, y, yaw).
  [[nodiscard]] bool is_planar() const noexcept {
    for (const Pose4Dof& x : poses_)
      if (x.p.z() != 0.0 || x.roll != 0.0 || x.pitch != 0.0) return false;
    for (const Edge4Dof& e : edges_) {
      if (e.dp.z() != 0.0) return false;
      for (int r = 0; r < 4; ++r)
        if (r != 2 && (e.information(r, 2) != 0.0 || e.information(2, r) != 0.0)) return false;
    }
    return true;
  }

 private:
  [[nodiscard]] static bool is_finite(const Pose4Dof& x) noexcept {
    return x.p.allFinite() && std::isfinite(x.yaw) && std::isfinite(x.pitch) && std::isfinite(x.roll);
  }

  [[nodiscard]] int node_index(std::int64_t id) const {
    const auto it = index_.find(id);
    if (it == index_.end()) throw invalid_argument("pose graph: node " + std::to_string(id) + " does not exist");
    return it->second;
  }

  [[nodiscard]] std::vector<char> effective_fixed() const {
    std::vector<char> f = fixed_;
    if (!f.empty() && std::find(f.begin(), f.end(), char(1)) == f.end()) f[0] = 1;
    return f;
  }

  /// The variable numbering (block AMD), computed once per graph structure
  /// (the rotation-first start and optimize() share it).
  [[nodiscard]] const detail::PoseGraphLayout& layout() {
    if (!layout_valid_) {
      layout_ = detail::make_pose_graph_layout(effective_fixed(), ends_);
      layout_valid_ = true;
    }
    return layout_;
  }

  [[nodiscard]] detail::PoseGraphEdges edge_view() const noexcept { return {edges_, ends_, Qt_}; }

  /// optimize() on B x B blocks: B = 4 the general path, B = 3 the planar one.
  template <int B>
  PoseGraphSummary optimize_blocks(const PoseGraphOptions& options, detail::SolverBuffers<B>& w) {
    detail::PoseGraphAssembly<B> assembly(edge_view(), w);
    detail::load_state<B>(poses_, w.x);
    PoseGraphSummary s = detail::levenberg_marquardt<B>(assembly, w, layout(), options);
    detail::store_state<B>(w.x, poses_);
    s.planar = B == 3;
    return s;
  }

  template <int B>
  NormalEquations normal_equations_blocks() {
    detail::SolverBuffers<B> w;
    detail::PoseGraphAssembly<B> assembly(edge_view(), w);
    detail::load_state<B>(poses_, w.x);
    assembly.set_trigonometry(w.x);
    const detail::PoseGraphLayout& L = layout();
    NormalEquations out;
    out.block_size = B;
    out.ids.assign(std::size_t(L.n), 0);
    for (std::size_t a = 0; a < poses_.size(); ++a)
      if (L.var[a] >= 0) out.ids[std::size_t(L.var[a])] = ids_[a];
    if (L.n == 0) return out;
    w.sys.build(L.n, L.pairs);
    assembly.linearize(w.x);
    out.H = w.sys.dense();
    out.b = w.sys.b;
    return out;
  }

  std::vector<std::int64_t> ids_;
  std::vector<Pose4Dof> poses_;
  std::vector<Eigen::Matrix3d> Qt_;  ///< \f$ Q_i^\top \f$ per node
  std::vector<char> fixed_;
  std::unordered_map<std::int64_t, int> index_;
  std::vector<Edge4Dof> edges_;
  std::vector<std::pair<int, int>> ends_;  ///< node indices of each edge
  detail::PoseGraphLayout layout_;         ///< cached layout() (valid when layout_valid_)
  bool layout_valid_ = false;
  PoseGraphWorkspace workspace_;           ///< the solver's buffers (scratch, not state)
};

}  // namespace posefuse

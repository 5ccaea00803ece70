#pragma once
/// @file
/// 6-DoF pose-graph optimisation over SE(3): g2o's EdgeSE3 error
/// (graph/edge_error_se3.hpp), solved without Ceres by Gauss–Newton or
/// Levenberg–Marquardt with analytic Jacobians on the 4-DoF graph's block
/// sparse Cholesky with 6x6 blocks (graph/detail/block_system.hpp), per-edge
/// robust losses and fixed nodes, plus a chordal rotation start that does
/// not depend on the odometry (graph/detail/chordal_se3.hpp).
///
/// **Cost** (g2o's χ²): \f$ F = \sum_k \rho_k(s_k) \f$ over the edges, with
/// \f$ s_k = e_k^\top \Omega_k e_k \f$ and \f$ \rho(s) = s \f$ without a
/// robust loss. Ceres reports \f$ F/2 \f$ for the same residuals (see
/// graph/edge_error_se3.hpp for how Ceres's `pose_graph_3d` residual
/// differs).

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

#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/graph/detail/chordal_se3.hpp>
#include <posefuse/graph/detail/levenberg_marquardt.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/detail/pose_graph_se3_assembly.hpp>
#include <posefuse/graph/edge_error_se3.hpp>
#include <posefuse/graph/pose_graph_options.hpp>
#include <posefuse/graph/robust_loss.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse {

/// PoseGraphSE3::normal_equations(): the Gauss–Newton system over the free nodes.
struct NormalEquationsSE3 {
  Eigen::MatrixXd H;              ///< symmetric, 6n x 6n
  Eigen::VectorXd b;              ///< gradient of the cost / 2
  std::vector<std::int64_t> ids;  ///< node id of each 6-column block ([δt; δφ], see pose_graph_plus)
};

/// Buffers for PoseGraphSE3's solvers (as PoseGraphWorkspace for the 4-DoF
/// graph): a program that builds and solves many graphs in turn may hold
/// one and pass it to each solve, so that fresh memory is paged in once.
/// Any workspace, empty or used before, gives the same answer to the last
/// bit; copying one gives an empty one; one solve at a time.
class PoseGraphSE3Workspace {
 public:
  PoseGraphSE3Workspace() = default;
  /// An empty workspace (the buffers are not copied).
  PoseGraphSE3Workspace(const PoseGraphSE3Workspace& /*other*/) noexcept {}
  /// Keeps this workspace's own buffers.
  PoseGraphSE3Workspace& operator=(const PoseGraphSE3Workspace& /*other*/) noexcept { return *this; }
  PoseGraphSE3Workspace(PoseGraphSE3Workspace&&) noexcept = default;
  PoseGraphSE3Workspace& operator=(PoseGraphSE3Workspace&&) noexcept = default;
  ~PoseGraphSE3Workspace() = default;

  /// Bytes of heap storage the buffers hold (capacity); 0 when empty.
  [[nodiscard]] std::size_t capacity_bytes() const noexcept { return buffers_.capacity_bytes(); }
  /// Frees every buffer.
  void release() noexcept { buffers_ = {}; }

 private:
  friend class PoseGraphSE3;
  detail::SolverBuffersSE3 buffers_;
};

/// An SE(3) pose graph: nodes with unique ids, relative edges, fixed nodes.
///
/// Usage: add_node for every pose, add_edge for every measurement, optionally
/// initialize_chordal(), then optimize(). Nodes keep their insertion order.
/// The graph owns its solver's buffers (kept between solves, freed with the
/// graph or by release_workspace(); a copy starts with none).
class PoseGraphSE3 {
 public:
  PoseGraphSE3() = default;

  /// Reserves storage for `nodes` nodes and `edges` edges (optional).
  void reserve(std::size_t nodes, std::size_t edges) {
    ids_.reserve(nodes);
    poses_.reserve(nodes);
    fixed_.reserve(nodes);
    index_.reserve(nodes);
    edges_.reserve(edges);
    ends_.reserve(edges);
  }

  /// Adds a node.
  /// @throws posefuse::invalid_argument for a duplicate id or a non-finite pose
  void add_node(std::int64_t id, const SE3d& pose, bool fixed = false) {
    if (!is_finite(pose)) throw invalid_argument("pose graph: node " + std::to_string(id) + " has a non-finite pose");
    if (!index_.emplace(id, static_cast<int>(ids_.size())).second)
      throw invalid_argument("pose graph: duplicate node id " + std::to_string(id));
    layout_valid_ = false;
    ids_.push_back(id);
    poses_.push_back(pose);
    fixed_.push_back(fixed ? 1 : 0);
  }

  /// Adds an edge and returns its index.
  /// @throws posefuse::invalid_argument naming the edge when a node is
  ///         missing, both ends are one node, the measurement is not finite,
  ///         the information is not finite, not symmetric or not positive
  ///         semi-definite, or a robust-loss scale is not finite and > 0
  std::size_t add_edge(const EdgeSE3& e) {
    const auto what = [&] {
      return "pose graph: edge " + std::to_string(edges_.size()) + " (" + std::to_string(e.from) + " -> " +
             std::to_string(e.to) + ")";
    };
    const auto fi = index_.find(e.from);
    const auto ti = index_.find(e.to);
    if (fi == index_.end()) throw invalid_argument(what() + ": node " + std::to_string(e.from) + " does not exist");
    if (ti == index_.end()) throw invalid_argument(what() + ": node " + std::to_string(e.to) + " does not exist");
    if (fi->second == ti->second) throw invalid_argument(what() + ": both ends are the same node");
    if (!is_finite(e.measurement)) throw invalid_argument(what() + ": the measurement is not finite");
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
  [[nodiscard]] const std::vector<SE3d>& poses() const noexcept { return poses_; }
  /// The edges in insertion order.
  [[nodiscard]] const std::vector<EdgeSE3>& edges() const noexcept { return edges_; }
  /// The pose of node `id`.
  /// @throws posefuse::invalid_argument when the node does not exist
  [[nodiscard]] const SE3d& pose(std::int64_t id) const { return poses_[std::size_t(node_index(id))]; }
  /// Replaces the pose of node `id`.
  /// @throws posefuse::invalid_argument when the node does not exist or the pose is not finite
  void set_pose(std::int64_t id, const SE3d& pose) {
    const std::size_t k = std::size_t(node_index(id));
    if (!is_finite(pose))
      throw invalid_argument("pose graph: node " + std::to_string(id) + " set to a non-finite pose");
    poses_[k] = pose;
  }

  /// The cost \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$ at the current poses.
  [[nodiscard]] double cost() const {
    double F = 0.0;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const EdgeSE3& ed = edges_[k];
      const Vector6d e = edge_error_se3(poses_[std::size_t(ends_[k].first)], poses_[std::size_t(ends_[k].second)],
                                        ed.measurement);
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

  /// Chordal initialisation, independent of the current rotations of the
  /// free nodes (Martinec and Pajdla, CVPR 2007; Carlone, Tron, Daniilidis,
  /// Dellaert, ICRA 2015):
  /// 1. rotations: minimise \f$ \sum_k w_k \| R_j - R_i R_{Z_k} \|_F^2 \f$
  ///    over unconstrained 3x3 matrices (fixed nodes keep theirs;
  ///    \f$ w_k \f$ the mean of the edge's rotation information diagonal),
  ///    a sparse linear least squares, then project each to the nearest
  ///    rotation (SVD);
  /// 2. translations: with the rotations fixed the cost is quadratic in the
  ///    translations; one exact Newton step minimises it.
  /// Robust losses are ignored here (weights 1).
  /// @throws posefuse::invalid_argument as validate(), or when a linear system is singular
  void initialize_chordal() { initialize_chordal(workspace_); }

  /// initialize_chordal() with the caller's buffers (see PoseGraphSE3Workspace).
  void initialize_chordal(PoseGraphSE3Workspace& workspace) {
    validate();
    const detail::PoseGraphLayout& L = layout();
    if (L.n == 0) return;
    detail::chordal_rotations(edge_view(), L, poses_, workspace.buffers_.init);
    detail::translations_for_rotations(edge_view(), L, poses_, workspace.buffers_.init);
  }

  /// Minimises the cost over the free nodes' poses.
  ///
  /// Each iteration linearises every edge (analytic Jacobians of
  /// edge_error_se3), weights it by \f$ \rho'(s) \f$ (IRLS), assembles
  /// \f$ H \f$ and \f$ b \f$ in 6x6 blocks and solves
  /// \f$ (H + \lambda\,\mathrm{diag}(H)) \Delta = -b \f$ with the block
  /// sparse Cholesky (block AMD ordering once per graph structure); the
  /// step is applied by pose_graph_plus. LM and its stopping rules are the
  /// 4-DoF graph's (PoseGraphOptions). When no node is fixed, the first is
  /// held fixed.
  /// @throws posefuse::invalid_argument as validate() or options.validate() (PoseGraphOptions)
  PoseGraphSummary optimize(const PoseGraphOptions& options = {}) { return optimize(options, workspace_); }

  /// optimize() with the caller's buffers (see PoseGraphSE3Workspace): the
  /// same result to the last bit, whatever the workspace held before.
  PoseGraphSummary optimize(const PoseGraphOptions& options, PoseGraphSE3Workspace& workspace) {
    const auto t0 = std::chrono::steady_clock::now();
    validate();
    detail::SolverBuffersSE3& w = workspace.buffers_;
    detail::PoseGraphAssemblySE3 assembly(edge_view(), w);
    detail::load_state_se3(poses_, w.x);
    PoseGraphSummary s = detail::levenberg_marquardt<6>(assembly, w, layout(), options);
    detail::store_state_se3(w.x, poses_);
    s.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
  }

  /// The Gauss–Newton system optimize() solves at the current poses (before
  /// damping), dense; block c belongs to node `ids[c]` (the solver's order).
  /// @throws posefuse::invalid_argument as validate()
  [[nodiscard]] NormalEquationsSE3 normal_equations() {
    validate();
    detail::SolverBuffersSE3 w;
    detail::PoseGraphAssemblySE3 assembly(edge_view(), w);
    detail::load_state_se3(poses_, w.x);
    assembly.set_trigonometry(w.x);
    const detail::PoseGraphLayout& L = layout();
    NormalEquationsSE3 out;
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

  /// Frees the graph's solver buffers.
  void release_workspace() noexcept { workspace_.release(); }
  /// Bytes the graph's solver buffers hold (capacity; 0 before the first solve).
  [[nodiscard]] std::size_t workspace_bytes() const noexcept { return workspace_.capacity_bytes(); }

 private:
  [[nodiscard]] static bool is_finite(const SE3d& x) noexcept {
    return x.translation().allFinite() && x.so3().quaternion().coeffs().allFinite();
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

  [[nodiscard]] const detail::PoseGraphLayout& layout() {
    if (!layout_valid_) {
      layout_ = detail::make_pose_graph_layout(effective_fixed(), ends_);
      layout_valid_ = true;
    }
    return layout_;
  }

  [[nodiscard]] detail::PoseGraphEdgesSE3 edge_view() const noexcept { return {edges_, ends_}; }

  std::vector<std::int64_t> ids_;
  std::vector<SE3d> poses_;
  std::vector<char> fixed_;
  std::unordered_map<std::int64_t, int> index_;
  std::vector<EdgeSE3> edges_;
  std::vector<std::pair<int, int>> ends_;  ///< node indices of each edge
  detail::PoseGraphLayout layout_;
  bool layout_valid_ = false;
  PoseGraphSE3Workspace workspace_;        ///< the solver's buffers (scratch, not state; a copy starts empty)
};

}  // namespace posefuse

#pragma once
/// @file
/// 4-DoF pose-graph optimisation (x, y, z, yaw; roll and pitch held fixed):
/// VINS-Mono's global pose graph (Qin, Li, Shen, "VINS-Mono: A Robust and
/// Versatile Monocular Visual-Inertial State Estimator", IEEE T-RO 2018,
/// Sec. VIII; SPEC.md C) solved without Ceres — Gauss–Newton or
/// Levenberg–Marquardt with analytic Jacobians, a block-ordered sparse
/// Cholesky and per-edge robust losses, plus the rotation-first
/// initialisation of Carlone et al. 2015.
///
/// **Poses.** Node i is \f$ (p_i, \psi_i) \f$ with a fixed roll/pitch
/// rotation \f$ Q_i = R_y(\theta_i) R_x(\phi_i) \f$, so its attitude is
/// \f$ R_i = R_z(\psi_i)\, Q_i \f$ (ZYX, as lie/rotation.hpp). A planar
/// graph is the special case \f$ z = 0, Q_i = I \f$.
///
/// **Edge error** (g2o's EDGE_SE2 error, Kümmerle et al., "g2o: A General
/// Framework for Graph Optimization", ICRA 2011, extended to 4-DoF): an edge
/// i → j measures the position of j in i's frame \f$ \Delta p \f$ and the
/// relative yaw \f$ \Delta\psi \f$;
/// \f[ e_t = R_z(\Delta\psi)^\top \big( R_i^\top (p_j - p_i) - \Delta p \big), \qquad
///     e_\psi = \mathrm{wrap}(\psi_j - \psi_i - \Delta\psi), \f]
/// i.e. the translation error is expressed in the measurement's frame, as
/// \f$ t2v(Z^{-1} X_i^{-1} X_j) \f$ in g2o for planar poses. With
/// \f$ e = [e_t; e_\psi] \f$ and the edge's 4x4 information \f$ \Omega \f$
/// (order x, y, z, yaw), the edge's squared error is \f$ s = e^\top \Omega e \f$.
///
/// **Cost** (g2o's χ²): \f$ F = \sum_k \rho_k(s_k) \f$ with \f$ \rho(s) = s \f$
/// without a robust loss. Ceres reports \f$ F/2 \f$.

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/graph/detail/block_system.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/lie/so2.hpp>

namespace posefuse {

/// A 4-DoF pose: position (m, world), yaw (rad) and the fixed roll and pitch (rad).
struct Pose4Dof {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position in the world frame (m)
  double yaw = 0.0;                             ///< \f$ \psi \f$ about world z (rad)
  double pitch = 0.0;                           ///< \f$ \theta \f$, held fixed (rad)
  double roll = 0.0;                            ///< \f$ \phi \f$, held fixed (rad)
};

/// Robust loss \f$ \rho(s) \f$ of an edge's squared error \f$ s = e^\top\Omega e \f$.
enum class RobustLoss {
  kNone,    ///< \f$ \rho(s) = s \f$
  kHuber,   ///< \f$ \rho(s) = s \f$ for \f$ s \le \delta^2 \f$, else \f$ 2\delta\sqrt{s} - \delta^2 \f$
  kCauchy,  ///< \f$ \rho(s) = c^2 \log(1 + s/c^2) \f$
};

/// A robust loss with its scale (\f$ \delta \f$ or \f$ c \f$, in whitened units).
struct RobustKernel {
  RobustLoss type = RobustLoss::kNone;  ///< which loss
  double scale = 1.0;                   ///< \f$ \delta \f$ (Huber) or \f$ c \f$ (Cauchy), > 0

  /// \f$ \rho(s) \f$.
  [[nodiscard]] double rho(double s) const noexcept {
    switch (type) {
      case RobustLoss::kNone: return s;
      case RobustLoss::kHuber: {
        const double d2 = scale * scale;
        return s <= d2 ? s : 2.0 * scale * std::sqrt(s) - d2;
      }
      case RobustLoss::kCauchy: {
        const double c2 = scale * scale;
        return c2 * std::log1p(s / c2);
      }
    }
    return s;
  }
  /// \f$ \rho'(s) \f$, the iteratively-reweighted least-squares weight (in (0, 1]).
  [[nodiscard]] double weight(double s) const noexcept {
    switch (type) {
      case RobustLoss::kNone: return 1.0;
      case RobustLoss::kHuber: return s <= scale * scale ? 1.0 : scale / std::sqrt(s);
      case RobustLoss::kCauchy: return 1.0 / (1.0 + s / (scale * scale));
    }
    return 1.0;
  }
};

/// A relative 4-DoF measurement between two nodes (ids).
struct Edge4Dof {
  std::int64_t from = 0;                                     ///< node i (the measurement's frame)
  std::int64_t to = 0;                                       ///< node j
  Eigen::Vector3d dp = Eigen::Vector3d::Zero();              ///< \f$ \Delta p \f$: j's position in i's frame (m)
  double dyaw = 0.0;                                         ///< \f$ \Delta\psi = \psi_j - \psi_i \f$ (rad)
  Eigen::Matrix4d information = Eigen::Matrix4d::Identity();  ///< \f$ \Omega \f$, order x, y, z, yaw
  RobustKernel loss;                                         ///< robust loss (none by default)
};

/// The fixed roll/pitch rotation \f$ Q = R_y(\theta) R_x(\phi) \f$ of a pose.
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix3d roll_pitch_rotation(const Pose4Dof& x) {
  return rotation_from_euler_zyx(EulerZYX<double>{x.roll, x.pitch, 0.0});
}

/// \f$ R_z(\psi)^\top v \f$ through SO(2) on the horizontal components.
/// @param[out] J_r_psi if not null, \f$ \partial (R_z(\psi)^\top v) / \partial\psi \f$
template <class Lazy = void>
[[nodiscard]] Eigen::Vector3d rotate_z_inverse(double psi, const Eigen::Vector3d& v,
                                               Eigen::Vector3d* J_r_psi = nullptr) {
  const SO2<double> Rinv = SO2<double>(psi).inverse();
  Eigen::Vector2d J_q_g;
  const Eigen::Vector2d q = Rinv.act(v.head<2>(), &J_q_g);
  // q = R(-ψ) v: d q / d ψ = -(d q / d(-ψ)) = -J_q_g.
  if (J_r_psi) *J_r_psi << -J_q_g, 0.0;
  return Eigen::Vector3d(q.x(), q.y(), v.z());
}

namespace detail {

/// edge_error_4dof from precomputed trigonometry: \f$ (c_i, s_i) \f$ of
/// \f$ \psi_i \f$ and \f$ (c_m, s_m) \f$ of \f$ \Delta\psi \f$ (the optimiser
/// computes them once per node and once per edge instead of twice per edge).
template <class Lazy = void>
[[nodiscard]] Eigen::Vector4d edge_error_4dof_trig(const Eigen::Vector3d& pi, double yaw_i, double ci, double si,
                                                   const Eigen::Matrix3d& Qi_t, const Eigen::Vector3d& pj,
                                                   double yaw_j, const Eigen::Vector3d& dp, double dyaw, double cm,
                                                   double sm, Eigen::Matrix4d* J_e_xi, Eigen::Matrix4d* J_e_xj) {
  const Eigen::Vector3d d = pj - pi;
  const Eigen::Vector3d w(ci * d.x() + si * d.y(), -si * d.x() + ci * d.y(), d.z());  // R_z(ψ_i)^T d
  const Eigen::Vector3d v = Qi_t * w - dp;                                              // R_i^T d - Δp
  Eigen::Vector4d e(cm * v.x() + sm * v.y(), -sm * v.x() + cm * v.y(), v.z(), wrap_angle(yaw_j - yaw_i - dyaw));
  if (J_e_xi || J_e_xj) {
    Eigen::Matrix3d Rzi_t;
    Rzi_t << ci, si, 0.0, -si, ci, 0.0, 0.0, 0.0, 1.0;
    Eigen::Matrix3d Mm;
    Mm << cm, sm, 0.0, -sm, cm, 0.0, 0.0, 0.0, 1.0;
    const Eigen::Matrix3d A = Mm * Qi_t * Rzi_t;  // M R_i^T
    if (J_e_xi) {
      J_e_xi->setZero();
      J_e_xi->topLeftCorner<3, 3>() = -A;
      // d w / d ψ_i = (w_y, -w_x, 0).
      J_e_xi->block<3, 1>(0, 3) = Mm * (Qi_t * Eigen::Vector3d(w.y(), -w.x(), 0.0));
      (*J_e_xi)(3, 3) = -1.0;
    }
    if (J_e_xj) {
      J_e_xj->setZero();
      J_e_xj->topLeftCorner<3, 3>() = A;
      (*J_e_xj)(3, 3) = 1.0;
    }
  }
  return e;
}

/// edge_error_planar from precomputed trigonometry (see edge_error_4dof_trig).
template <class Lazy = void>
[[nodiscard]] Eigen::Vector3d edge_error_planar_trig(const Eigen::Vector2d& pi, double yaw_i, double ci, double si,
                                                     const Eigen::Vector2d& pj, double yaw_j,
                                                     const Eigen::Vector2d& dp, double dyaw, double cm, double sm,
                                                     Eigen::Matrix3d* J_e_xi, Eigen::Matrix3d* J_e_xj) {
  const Eigen::Vector2d d = pj - pi;
  const Eigen::Vector2d w(ci * d.x() + si * d.y(), -si * d.x() + ci * d.y());  // R(ψ_i)^T d
  const Eigen::Vector2d v = w - dp;
  Eigen::Vector3d e(cm * v.x() + sm * v.y(), -sm * v.x() + cm * v.y(), wrap_angle(yaw_j - yaw_i - dyaw));
  if (J_e_xi || J_e_xj) {
    Eigen::Matrix2d Rzi_t, Mm;
    Rzi_t << ci, si, -si, ci;
    Mm << cm, sm, -sm, cm;
    const Eigen::Matrix2d A = Mm * Rzi_t;
    if (J_e_xi) {
      J_e_xi->setZero();
      J_e_xi->topLeftCorner<2, 2>() = -A;
      J_e_xi->block<2, 1>(0, 2) = Mm * Eigen::Vector2d(w.y(), -w.x());
      (*J_e_xi)(2, 2) = -1.0;
    }
    if (J_e_xj) {
      J_e_xj->setZero();
      J_e_xj->topLeftCorner<2, 2>() = A;
      (*J_e_xj)(2, 2) = 1.0;
    }
  }
  return e;
}

}  // namespace detail

/// The 4-DoF edge error \f$ e = [e_t; e_\psi] \f$ (see the file comment) and
/// its Jacobians with respect to \f$ x_i = [p_i; \psi_i] \f$ and \f$ x_j \f$.
/// @param[in] Qi_t \f$ Q_i^\top \f$, node i's fixed roll/pitch rotation transposed
/// @param[out] J_e_xi if not null, \f$ \partial e / \partial [p_i; \psi_i] \f$ (4x4)
/// @param[out] J_e_xj if not null, \f$ \partial e / \partial [p_j; \psi_j] \f$ (4x4)
/// \f[ \frac{\partial e_t}{\partial p_j} = -\frac{\partial e_t}{\partial p_i} = M R_i^\top, \;
///     \frac{\partial e_t}{\partial \psi_i} = M Q_i^\top \frac{d R_z(\psi_i)^\top}{d\psi_i}(p_j - p_i), \;
///     \frac{\partial e_\psi}{\partial \psi_j} = -\frac{\partial e_\psi}{\partial \psi_i} = 1, \f]
/// with \f$ M = R_z(\Delta\psi)^\top \f$.
template <class Lazy = void>
[[nodiscard]] Eigen::Vector4d edge_error_4dof(const Eigen::Vector3d& pi, double yaw_i,
                                              const Eigen::Matrix3d& Qi_t,
                                              const Eigen::Vector3d& pj, double yaw_j,
                                              const Eigen::Vector3d& dp, double dyaw,
                                              Eigen::Matrix4d* J_e_xi = nullptr,
                                              Eigen::Matrix4d* J_e_xj = nullptr) {
  return detail::edge_error_4dof_trig(pi, yaw_i, std::cos(yaw_i), std::sin(yaw_i), Qi_t, pj, yaw_j, dp, dyaw,
                                      std::cos(dyaw), std::sin(dyaw), J_e_xi, J_e_xj);
}

/// The planar edge error (g2o's EDGE_SE2 error,
/// \f$ t2v(Z^{-1} X_i^{-1} X_j) \f$): edge_error_4dof with z = 0 and no roll
/// or pitch, on \f$ x_i = [x_i, y_i, \psi_i] \f$:
/// \f$ e = [R(\Delta\psi)^\top (R(\psi_i)^\top (p_j - p_i) - \Delta p);\ \mathrm{wrap}(\psi_j - \psi_i - \Delta\psi)] \f$.
/// @param[out] J_e_xi if not null, \f$ \partial e / \partial [p_i; \psi_i] \f$ (3x3)
/// @param[out] J_e_xj if not null, \f$ \partial e / \partial [p_j; \psi_j] \f$ (3x3)
template <class Lazy = void>
[[nodiscard]] Eigen::Vector3d edge_error_planar(const Eigen::Vector2d& pi, double yaw_i, const Eigen::Vector2d& pj,
                                                double yaw_j, const Eigen::Vector2d& dp, double dyaw,
                                                Eigen::Matrix3d* J_e_xi = nullptr,
                                                Eigen::Matrix3d* J_e_xj = nullptr) {
  return detail::edge_error_planar_trig(pi, yaw_i, std::cos(yaw_i), std::sin(yaw_i), pj, yaw_j, dp, dyaw,
                                        std::cos(dyaw), std::sin(dyaw), J_e_xi, J_e_xj);
}

/// Why the optimiser stopped.
enum class Termination {
  kFunctionTolerance,   ///< relative cost decrease below the tolerance
  kGradientTolerance,   ///< largest gradient entry below the tolerance
  kParameterTolerance,  ///< step below the tolerance relative to the state
  kMaxIterations,       ///< iteration limit reached
  kNoProgress,          ///< no step decreased the cost (damping exhausted, or a GN step increased it)
};

/// Name of a termination reason ("function_tolerance", ...).
[[nodiscard]] constexpr std::string_view to_string(Termination t) noexcept {
  switch (t) {
    case Termination::kFunctionTolerance: return "function_tolerance";
    case Termination::kGradientTolerance: return "gradient_tolerance";
    case Termination::kParameterTolerance: return "parameter_tolerance";
    case Termination::kMaxIterations: return "max_iterations";
    case Termination::kNoProgress: return "no_progress";
  }
  return "?";
}

/// Optimiser settings.
struct PoseGraphOptions {
  bool levenberg_marquardt = true;    ///< false: undamped Gauss–Newton (stops when a step increases the cost)
  int max_iterations = 100;           ///< linear solves at most
  double function_tolerance = 1e-10;  ///< stop when \f$ (F_k - F_{k+1}) < \mathrm{tol}\, F_k \f$
  double gradient_tolerance = 1e-12;  ///< stop when \f$ \|J^\top W \Omega e\|_\infty < \mathrm{tol} \f$
  double parameter_tolerance = 1e-10;  ///< stop when \f$ \|\Delta\| < \mathrm{tol} (\|x\| + \mathrm{tol}) \f$
  double initial_lambda = 1e-5;       ///< LM damping \f$ \lambda \f$: \f$ H + \lambda\,\mathrm{diag}(H) \f$
  /// Solve a planar graph (PoseGraph4Dof::is_planar()) on (x, y, yaw) with
  /// 3x3 blocks instead of 4x4; the same iterations and optimum up to
  /// rounding (the z rows decouple exactly); 1.4-1.5x faster on the real
  /// g2o files (bench_graph BM_G2o/posefuse vs posefuse_4dof).
  bool planar_fast_path = true;
};

/// What an optimisation did.
struct PoseGraphSummary {
  double initial_cost = 0.0;  ///< \f$ F \f$ before (χ² without robust losses)
  double final_cost = 0.0;    ///< \f$ F \f$ after
  int iterations = 0;         ///< linear solves (accepted and rejected steps)
  int accepted = 0;           ///< steps that decreased the cost
  Termination termination = Termination::kMaxIterations;  ///< why it stopped
  double solve_time_s = 0.0;  ///< wall time of optimize() (s)
  bool planar = false;        ///< solved by the planar (3x3-block) path
};

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
    if (!pose.p.allFinite() || !std::isfinite(pose.yaw) || !std::isfinite(pose.pitch) ||
        !std::isfinite(pose.roll))
      throw invalid_argument("pose graph: node " + std::to_string(id) + " has a non-finite pose");
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
    const int k = node_index(id);
    if (!pose.p.allFinite() || !std::isfinite(pose.yaw) || !std::isfinite(pose.pitch) ||
        !std::isfinite(pose.roll))
      throw invalid_argument("pose graph: node " + std::to_string(id) + " set to a non-finite pose");
    poses_[std::size_t(k)] = pose;
    poses_[std::size_t(k)].yaw = wrap_angle(pose.yaw);
    Qt_[std::size_t(k)] = roll_pitch_rotation(pose).transpose();
  }

  /// The cost \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$ at the current poses.
  [[nodiscard]] double cost() const { return cost_at(poses_); }

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
  /// Robust losses are ignored here (weights 1).
  /// @throws posefuse::invalid_argument as validate(), or when a linear system is singular
  void initialize_rotation_first() {
    validate();
    const Layout& L = layout();
    if (L.n == 0) return;
    // 1. Chordal yaw.
    {
      detail::BlockSystem<2>& sys = workspace<2>().sys;  // reused buffers, see workspace()
      sys.build(L.n, L.pairs);
      sys.set_zero();
      for (std::size_t k = 0; k < edges_.size(); ++k) {
        const int i = ends_[k].first, j = ends_[k].second;
        const double w = std::max(edges_[k].information(3, 3), 0.0);
        const Eigen::Matrix2d Rk = SO2<double>(edges_[k].dyaw).matrix();
        // r = v_j - Rk v_i; J_i = -Rk, J_j = I.
        const Eigen::Vector2d vi = unit(poses_[std::size_t(i)].yaw);
        const Eigen::Vector2d vj = unit(poses_[std::size_t(j)].yaw);
        const Eigen::Vector2d r0 = vj - Rk * vi;  // at the current point
        const Eigen::Matrix2d Hii = w * Eigen::Matrix2d::Identity();
        const Eigen::Matrix2d Hij = -w * Rk.transpose();
        sys.add(k, Hii, Hij, w * Eigen::Matrix2d::Identity(), -w * Rk.transpose() * r0, w * r0);
      }
      const Eigen::VectorXd dx = solve(sys, "yaw initialisation");
      for (std::size_t a = 0; a < poses_.size(); ++a) {
        const int v = L.var[a];
        if (v < 0) continue;
        const Eigen::Vector2d u = unit(poses_[a].yaw) + dx.segment<2>(2 * v);
        if (u.norm() > 1e-12) poses_[a].yaw = wrap_angle(std::atan2(u.y(), u.x()));
      }
    }
    // 2. Linear translation solve.
    {
      detail::BlockSystem<3>& sys = workspace<3>().sys;
      sys.build(L.n, L.pairs);
      sys.set_zero();
      for (std::size_t k = 0; k < edges_.size(); ++k) {
        const int i = ends_[k].first, j = ends_[k].second;
        const Edge4Dof& ed = edges_[k];
        Eigen::Matrix4d Ji, Jj;
        const Eigen::Vector4d e = edge_error_4dof(poses_[std::size_t(i)].p, poses_[std::size_t(i)].yaw,
                                                  Qt_[std::size_t(i)], poses_[std::size_t(j)].p,
                                                  poses_[std::size_t(j)].yaw, ed.dp, ed.dyaw, &Ji, &Jj);
        const Eigen::Matrix3d Jpi = Ji.topLeftCorner<3, 3>(), Jpj = Jj.topLeftCorner<3, 3>();
        const Eigen::Matrix<double, 3, 4> Om = ed.information.topRows<3>();
        const Eigen::Matrix3d Ott = ed.information.topLeftCorner<3, 3>();
        const Eigen::Vector3d g = Om * e;  // Ω_tt e_t + Ω_tψ e_ψ
        sys.add(k, Jpi.transpose() * Ott * Jpi, Jpi.transpose() * Ott * Jpj, Jpj.transpose() * Ott * Jpj,
                Jpi.transpose() * g, Jpj.transpose() * g);
      }
      const Eigen::VectorXd dx = solve(sys, "translation initialisation");
      for (std::size_t a = 0; a < poses_.size(); ++a) {
        const int v = L.var[a];
        if (v >= 0) poses_[a].p += dx.segment<3>(3 * v);
      }
    }
  }

  /// Minimises the cost over the free nodes' x, y, z and yaw.
  ///
  /// Each iteration linearises every edge (analytic Jacobians of
  /// edge_error_4dof), weights it by \f$ \rho'(s) \f$ (IRLS), assembles
  /// \f$ H = \sum J^\top \rho' \Omega J \f$ and \f$ b = \sum J^\top \rho' \Omega e \f$
  /// in 4x4 blocks, and solves \f$ (H + \lambda\,\mathrm{diag}(H)) \Delta = -b \f$
  /// with a block sparse Cholesky (detail/block_system.hpp: 4x4 blocks,
  /// block AMD ordering and symbolic analysis computed once per call). LM adapts
  /// \f$ \lambda \f$ by the gain ratio (Nielsen's rule); a step is taken only
  /// when it lowers the cost. When no node is fixed, the first is held fixed.
  /// @throws posefuse::invalid_argument as validate()
  PoseGraphSummary optimize(const PoseGraphOptions& options = {}) {
    const auto t0 = std::chrono::steady_clock::now();
    validate();
    PoseGraphSummary s = options.planar_fast_path && is_planar() ? optimize_blocks<3>(options)
                                                                   : optimize_blocks<4>(options);
    s.solve_time_s = seconds_since(t0);
    return s;
  }

  /// The Gauss–Newton system optimize() solves at the current poses (before
  /// damping): \f$ H = \sum J^\top \rho' \Omega J \f$, \f$ b = \sum J^\top
  /// \rho' \Omega e \f$ over the free nodes, dense. Block column c belongs to
  /// node `ids[c]` (the solver's fill-reducing order); a block is
  /// [x, y, z, yaw], or [x, y, yaw] with `planar` on a planar graph (the
  /// planar path's system). Uses: covariance recovery on small graphs
  /// (\f$ H^{-1} \f$ at the optimum), and checking the assembly against the
  /// edges' Jacobians (tests).
  /// @throws posefuse::invalid_argument as validate(), or when `planar` is
  ///         asked of a graph that is not planar
  [[nodiscard]] NormalEquations normal_equations(bool planar = false) {
    validate();
    if (!planar) return normal_equations_blocks<4>();
    if (!is_planar()) throw invalid_argument("pose graph: normal_equations(planar) of a graph that is not planar");
    return normal_equations_blocks<3>();
  }

  /// Frees this thread's solver buffers. optimize() and
  /// initialize_rotation_first() keep their arrays (the Cholesky factor above
  /// all, about 1.4 MB for a 3 500-node planar graph) per thread between
  /// calls, because paging fresh memory in cost as much as the solve itself
  /// on a 1 000-node graph; call this to give the memory back.
  static void release_workspace() {
    workspace<2>() = Workspace<2>{};
    workspace<3>() = Workspace<3>{};
    workspace<4>() = Workspace<4>{};
  }

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
  struct Layout {
    int n = 0;                               ///< free nodes
    std::vector<int> var;                    ///< node → block column (-1 fixed)
    std::vector<std::pair<int, int>> pairs;  ///< edge → block columns of its ends
  };

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
  [[nodiscard]] const Layout& layout() {
    if (!layout_valid_) {
      layout_ = compute_layout();
      layout_valid_ = true;
    }
    return layout_;
  }

  [[nodiscard]] Layout compute_layout() const {
    Layout L;
    const std::vector<char> fixed = effective_fixed();
    std::vector<int> free_index(poses_.size(), -1);
    for (std::size_t a = 0; a < poses_.size(); ++a)
      if (!fixed[a]) free_index[a] = L.n++;
    std::vector<std::pair<int, int>> raw;
    raw.reserve(ends_.size());
    for (const auto& e : ends_)
      raw.emplace_back(free_index[std::size_t(e.first)], free_index[std::size_t(e.second)]);
    const std::vector<int> pos = detail::block_amd_order(L.n, raw);
    L.var.assign(poses_.size(), -1);
    for (std::size_t a = 0; a < poses_.size(); ++a)
      if (free_index[a] >= 0) L.var[a] = pos[std::size_t(free_index[a])];
    L.pairs.reserve(ends_.size());
    for (const auto& e : ends_) L.pairs.emplace_back(L.var[std::size_t(e.first)], L.var[std::size_t(e.second)]);
    return L;
  }

  [[nodiscard]] static Eigen::Vector2d unit(double a) { return Eigen::Vector2d(std::cos(a), std::sin(a)); }

  [[nodiscard]] static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  template <int B>
  [[nodiscard]] static Eigen::VectorXd solve(detail::BlockSystem<B>& sys, const char* what) {
    detail::BlockCholesky<B>& chol = workspace<B>().chol;
    chol.analyze(sys);
    const bool factored = chol.factorize(sys);
    Eigen::VectorXd dx;
    if (factored) dx = chol.solve(-sys.b);
    if (!factored || !dx.allFinite())
      throw invalid_argument(std::string("pose graph: ") + what +
                             ": the linear system is singular (information too weak to fix every node)");
    return dx;
  }

  [[nodiscard]] double cost_at(const std::vector<Pose4Dof>& x) const {
    double F = 0.0;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const int i = ends_[k].first, j = ends_[k].second;
      const Edge4Dof& ed = edges_[k];
      const Eigen::Vector4d e = edge_error_4dof(x[std::size_t(i)].p, x[std::size_t(i)].yaw, Qt_[std::size_t(i)],
                                                x[std::size_t(j)].p, x[std::size_t(j)].yaw, ed.dp, ed.dyaw);
      F += ed.loss.rho(e.dot(ed.information * e));
    }
    return F;
  }

  /// The optimiser's state of B per free-or-fixed node: [p; yaw] (B = 4)
  /// or [x, y, yaw] (B = 3, planar).
  template <int B>
  using State = Eigen::Matrix<double, B, 1>;

  /// Per-call buffers of optimize_blocks (capacity kept between calls of
  /// one thread, see detail::graph_workspace).
  template <int B>
  struct Workspace {
    detail::BlockSystem<B> sys;
    detail::BlockCholesky<B> chol;
    std::vector<State<B>> x, trial;
    std::vector<double> c, s;             ///< cos / sin of each node's yaw
    std::vector<double> cm, sm;           ///< cos / sin of each edge's Δψ
    std::vector<Eigen::Matrix3d> info3;   ///< planar information (x, y, yaw)
    Eigen::VectorXd diag, delta, dx;
  };

  /// One workspace per thread and block size: the solver's arrays (the
  /// factor above all) keep their capacity from one optimize() call to the
  /// next, so repeated calls do not page fresh memory in.
  template <int B>
  [[nodiscard]] static Workspace<B>& workspace() {
    static thread_local Workspace<B> w;
    return w;
  }

  template <int B>
  void load_state(std::vector<State<B>>& x) const {
    x.resize(poses_.size());
    for (std::size_t a = 0; a < poses_.size(); ++a) {
      if constexpr (B == 4) x[a] << poses_[a].p, poses_[a].yaw;
      else x[a] << poses_[a].p.x(), poses_[a].p.y(), poses_[a].yaw;
    }
  }

  template <int B>
  void store_state(const std::vector<State<B>>& x) {
    for (std::size_t a = 0; a < poses_.size(); ++a) {
      if constexpr (B == 4) poses_[a].p = x[a].template head<3>();
      else poses_[a].p.template head<2>() = x[a].template head<2>();
      poses_[a].yaw = x[a](B - 1);
    }
  }

  template <int B>
  static void node_trig(const std::vector<State<B>>& x, Workspace<B>& w) {
    w.c.resize(x.size());
    w.s.resize(x.size());
    for (std::size_t a = 0; a < x.size(); ++a) {
      w.c[a] = std::cos(x[a](B - 1));
      w.s[a] = std::sin(x[a](B - 1));
    }
  }

  /// Edge k's error (and Jacobians) at state x, node trigonometry in w.
  template <int B>
  State<B> edge_error_at(std::size_t k, const std::vector<State<B>>& x, const Workspace<B>& w,
                         Eigen::Matrix<double, B, B>* Ji, Eigen::Matrix<double, B, B>* Jj) const {
    const std::size_t i = std::size_t(ends_[k].first), j = std::size_t(ends_[k].second);
    const Edge4Dof& ed = edges_[k];
    if constexpr (B == 4) {
      return detail::edge_error_4dof_trig(x[i].template head<3>(), x[i](3), w.c[i], w.s[i], Qt_[i],
                                          x[j].template head<3>(), x[j](3), ed.dp, ed.dyaw, w.cm[k], w.sm[k], Ji, Jj);
    } else {
      return detail::edge_error_planar_trig(x[i].template head<2>(), x[i](2), w.c[i], w.s[i],
                                            x[j].template head<2>(), x[j](2), ed.dp.template head<2>(), ed.dyaw,
                                            w.cm[k], w.sm[k], Ji, Jj);
    }
  }

  template <int B>
  [[nodiscard]] const Eigen::Matrix<double, B, B>& edge_information(std::size_t k, const Workspace<B>& w) const {
    if constexpr (B == 4) return edges_[k].information;
    else return w.info3[k];
  }

  /// \f$ F \f$ at state x (node trigonometry recomputed into w).
  template <int B>
  [[nodiscard]] double cost_of(const std::vector<State<B>>& x, Workspace<B>& w) const {
    node_trig<B>(x, w);
    double F = 0.0;
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      const State<B> e = edge_error_at<B>(k, x, w, nullptr, nullptr);
      F += edges_[k].loss.rho(e.dot(edge_information<B>(k, w) * e));
    }
    return F;
  }

  /// H and b at state x (node trigonometry must be current in w).
  ///
  /// Uses the Jacobians' structure: \f$ J_j = \mathrm{diag}(A, 1) \f$ and
  /// \f$ J_i = -J_j + \tilde g\, e_\psi^\top \f$ with \f$ \tilde g = [g; 0] \f$
  /// the yaw column of \f$ \partial e_t / \partial \psi_i \f$. With
  /// \f$ W = \rho'\Omega \f$, \f$ H_{jj} = J_j^\top W J_j \f$ and
  /// \f$ u = J_j^\top W \tilde g \f$:
  /// \f$ H_{ij} = -H_{jj} + e_\psi u^\top \f$,
  /// \f$ H_{ii} = H_{jj} - u e_\psi^\top - e_\psi u^\top + (\tilde g^\top W \tilde g)\, e_\psi e_\psi^\top \f$,
  /// \f$ b_i = -b_j + e_\psi (\tilde g^\top W e) \f$: one B x B triple
  /// product per edge instead of five.
  template <int B>
  void assemble(const std::vector<State<B>>& x, Workspace<B>& w) const {
    using Mat = Eigen::Matrix<double, B, B>;
    constexpr int last = B - 1;
    w.sys.set_zero();
    for (std::size_t k = 0; k < edges_.size(); ++k) {
      Mat Ji, Jj;
      const State<B> e = edge_error_at<B>(k, x, w, &Ji, &Jj);
      const Mat& Om = edge_information<B>(k, w);
      const State<B> Oe = Om * e;
      const double wt = edges_[k].loss.weight(e.dot(Oe));
      State<B> g = Ji.col(last);
      g(last) = 0.0;  // g~ = J_i's yaw column + J_j's
      const Mat WJ = wt * (Om * Jj);
      const Mat Hjj = Jj.transpose() * WJ;
      const State<B> u = WJ.transpose() * g;
      const double gWg = wt * g.dot(Om * g);
      Mat Hij = -Hjj;
      Hij.row(last) += u.transpose();
      Mat Hii = Hjj;
      Hii.col(last) -= u;
      Hii.row(last) -= u.transpose();
      Hii(last, last) += gWg;
      const State<B> bj = wt * (Jj.transpose() * Oe);
      State<B> bi = -bj;
      bi(last) += wt * g.dot(Oe);
      w.sys.add(k, Hii, Hij, Hjj, bi, bj);
    }
  }

  template <int B>
  static void apply_step(const Layout& L, const Eigen::VectorXd& dx, std::vector<State<B>>& x) {
    for (std::size_t a = 0; a < x.size(); ++a) {
      const int v = L.var[a];
      if (v < 0) continue;
      x[a] += dx.template segment<B>(B * v);
      x[a](B - 1) = wrap_angle(x[a](B - 1));
    }
  }

  template <int B>
  [[nodiscard]] static double state_norm(const Layout& L, const std::vector<State<B>>& x) {
    double s = 0.0;
    for (std::size_t a = 0; a < x.size(); ++a)
      if (L.var[a] >= 0) s += x[a].squaredNorm();
    return std::sqrt(s);
  }

  /// optimize() on B x B blocks: B = 4 the general path, B = 3 the planar one.
  /// Per-edge constants of a solve: the trigonometry of each edge's Δψ and,
  /// on the planar path, its (x, y, yaw) information.
  template <int B>
  void prepare_edges(Workspace<B>& w) const {
    const std::size_t m = edges_.size();
    w.cm.resize(m);
    w.sm.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      w.cm[k] = std::cos(edges_[k].dyaw);
      w.sm[k] = std::sin(edges_[k].dyaw);
    }
    if constexpr (B == 3) {
      w.info3.resize(m);
      const int map[3] = {0, 1, 3};
      for (std::size_t k = 0; k < m; ++k)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) w.info3[k](r, c) = edges_[k].information(map[r], map[c]);
    }
  }

  template <int B>
  NormalEquations normal_equations_blocks() {
    Workspace<B> w;  // its own buffers: the thread's workspace is left alone
    prepare_edges<B>(w);
    load_state<B>(w.x);
    node_trig<B>(w.x, w);
    const Layout& L = layout();
    NormalEquations out;
    out.block_size = B;
    out.ids.assign(std::size_t(L.n), 0);
    for (std::size_t a = 0; a < poses_.size(); ++a)
      if (L.var[a] >= 0) out.ids[std::size_t(L.var[a])] = ids_[a];
    if (L.n == 0) return out;
    w.sys.build(L.n, L.pairs);
    assemble<B>(w.x, w);
    out.H = w.sys.dense();
    out.b = w.sys.b;
    return out;
  }

  template <int B>
  PoseGraphSummary optimize_blocks(const PoseGraphOptions& options) {
    Workspace<B>& w = workspace<B>();
    PoseGraphSummary s;
    s.planar = B == 3;
    prepare_edges<B>(w);
    load_state<B>(w.x);
    s.initial_cost = s.final_cost = cost_of<B>(w.x, w);  // leaves w.c, w.s at w.x
    const Layout& L = layout();
    if (L.n == 0 || edges_.empty()) {
      s.termination = Termination::kGradientTolerance;
      return s;
    }
    w.sys.build(L.n, L.pairs);
    w.chol.analyze(w.sys);
    double cost_now = s.initial_cost;
    double lambda = options.levenberg_marquardt ? options.initial_lambda : 0.0;
    double nu = 2.0;
    bool relinearise = true;
    s.termination = Termination::kMaxIterations;
    const auto finish = [&] {
      store_state<B>(w.x);
      s.final_cost = cost_now;
      return s;
    };
    while (s.iterations < options.max_iterations) {
      if (relinearise) {
        assemble<B>(w.x, w);
        w.diag = w.sys.diagonal();
        if (w.sys.b.template lpNorm<Eigen::Infinity>() < options.gradient_tolerance) {
          s.termination = Termination::kGradientTolerance;
          break;
        }
        relinearise = false;
      }
      ++s.iterations;
      if (lambda > 0) {
        w.delta.resize(w.diag.size());
        for (Eigen::Index c = 0; c < w.diag.size(); ++c) w.delta(c) = lambda * std::clamp(w.diag(c), 1e-6, 1e32);
        w.sys.add_to_diagonal(w.delta);
      }
      const bool factored = w.chol.factorize(w.sys);
      if (factored) {
        w.dx = -w.sys.b;
        w.chol.solve_in_place(w.dx);
      }
      if (lambda > 0) w.sys.add_to_diagonal(-w.delta);
      if (!factored || !w.dx.allFinite()) {
        if (!options.levenberg_marquardt) {
          s.termination = Termination::kNoProgress;
          break;
        }
        lambda = std::max(lambda, 1e-8) * nu;
        nu *= 2;
        if (lambda > 1e16) {
          s.termination = Termination::kNoProgress;
          break;
        }
        continue;
      }
      const Eigen::VectorXd& dx = w.dx;
      w.trial = w.x;
      apply_step<B>(L, dx, w.trial);
      const double cost_new = cost_of<B>(w.trial, w);  // w.c, w.s now at the trial
      // Predicted decrease of the quadratic model of F = Σ ρ(s): -(2 Δᵀb + Δᵀ H Δ).
      const double predicted = -(2.0 * dx.dot(w.sys.b) + w.sys.quadratic_form(dx));
      // Near the minimum the cost change drops below its rounding error
      // (F ~ 3 moves by 1e-20 when a pose moves by 1e-10): a step whose
      // predicted decrease is at rounding level is taken once (the quadratic
      // model is exact there) and the optimiser stops.
      const double rounding = 64.0 * std::numeric_limits<double>::epsilon() * cost_now;
      const bool polish = std::isfinite(cost_new) && !(cost_new < cost_now) && predicted >= 0 &&
                          predicted <= rounding && cost_new <= cost_now + rounding;
      if (polish) {
        w.x.swap(w.trial);
        ++s.accepted;
        cost_now = std::min(cost_now, cost_new);
        s.termination = Termination::kFunctionTolerance;
        break;
      }
      if (std::isfinite(cost_new) && cost_new < cost_now) {
        const double rho = predicted > 0 ? (cost_now - cost_new) / predicted : 1.0;
        const double decrease = cost_now - cost_new;
        w.x.swap(w.trial);  // the node trigonometry in w is the new state's
        ++s.accepted;
        relinearise = true;
        if (options.levenberg_marquardt) {
          const double f = 2.0 * rho - 1.0;
          lambda *= std::max(1.0 / 3.0, 1.0 - f * f * f);
          lambda = std::max(lambda, 1e-12);
          nu = 2.0;
        }
        const double prev = cost_now;
        cost_now = cost_new;
        if (decrease < options.function_tolerance * prev) {
          s.termination = Termination::kFunctionTolerance;
          break;
        }
        if (dx.norm() < options.parameter_tolerance * (state_norm<B>(L, w.x) + options.parameter_tolerance)) {
          s.termination = Termination::kParameterTolerance;
          break;
        }
      } else {
        node_trig<B>(w.x, w);  // back to the current state's trigonometry
        if (!options.levenberg_marquardt) {
          s.termination = Termination::kNoProgress;
          break;
        }
        // A step that does not lower the cost but is below the parameter
        // tolerance means we are at the minimum to rounding.
        if (dx.norm() < options.parameter_tolerance * (state_norm<B>(L, w.x) + options.parameter_tolerance)) {
          s.termination = Termination::kParameterTolerance;
          break;
        }
        lambda *= nu;
        nu *= 2;
        if (lambda > 1e16) {
          s.termination = Termination::kNoProgress;
          break;
        }
      }
    }
    return finish();
  }

  std::vector<std::int64_t> ids_;
  std::vector<Pose4Dof> poses_;
  std::vector<Eigen::Matrix3d> Qt_;  ///< \f$ Q_i^\top \f$ per node
  std::vector<char> fixed_;
  std::unordered_map<std::int64_t, int> index_;
  std::vector<Edge4Dof> edges_;
  std::vector<std::pair<int, int>> ends_;  ///< node indices of each edge
  Layout layout_;                          ///< cached layout() (valid when layout_valid_)
  bool layout_valid_ = false;
};

}  // namespace posefuse

#pragma once
/// @file
/// An SE(3) pose graph's solver state, buffers, cost and normal equations on
/// 6x6 blocks (not API). The Levenberg–Marquardt loop is the 4-DoF graph's
/// (graph/detail/levenberg_marquardt.hpp), run on these.
///
/// Each node's state is a unit quaternion and a translation; its rotation
/// matrix is computed once per evaluation (set_trigonometry) and each edge's
/// \f$ q_Z^{-1}, R_Z^\top \f$ once per solve. Per edge, H is assembled from
/// \f$ J_j = J_E \f$ and \f$ J_i = -J_E\,\mathrm{Ad} \f$
/// (graph/edge_error_se3.hpp): \f$ H_{jj} = J_E^\top W J_E \f$,
/// \f$ H_{ij} = -\mathrm{Ad}^\top H_{jj} \f$,
/// \f$ H_{ii} = \mathrm{Ad}^\top H_{jj} \mathrm{Ad} \f$,
/// \f$ b_j = J_E^\top W e \f$, \f$ b_i = -\mathrm{Ad}^\top b_j \f$.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <posefuse/graph/detail/block_system.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/edge_error_se3.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse::detail {

/// The optimiser's state of one SE(3) node.
struct NodeStateSE3 {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  ///< unit quaternion
  Eigen::Vector3d t = Eigen::Vector3d::Zero();            ///< translation (m)
};

/// Buffers of an SE(3) solve: the 6x6-block system and its factor, the
/// state, and the 3x3-block systems of the chordal start.
struct SolverBuffersSE3 {
  BlockSystem<6> sys;                      ///< H and b
  BlockCholesky<6> chol;                   ///< factor of (damped) H
  std::vector<NodeStateSE3> x, trial;      ///< current and trial state of every node
  std::vector<Eigen::Matrix3d> R;          ///< rotation matrix of each node at the evaluated state
  std::vector<Eigen::Quaterniond> qz_inv;  ///< \f$ q_Z^{-1} \f$ of each edge
  std::vector<Eigen::Matrix3d> Rz_t;       ///< \f$ R_Z^\top \f$ of each edge
  Eigen::VectorXd diag, delta, dx;         ///< diag(H), the damping added to it, the step
  SolverBuffers<3> init;                   ///< chordal rotations and translations (3x3 blocks)

  /// Bytes of heap storage held (capacity).
  [[nodiscard]] std::size_t capacity_bytes() const noexcept {
    return sys.capacity_bytes() + chol.capacity_bytes() + sizeof(NodeStateSE3) * (x.capacity() + trial.capacity()) +
           sizeof(Eigen::Matrix3d) * (R.capacity() + Rz_t.capacity()) +
           sizeof(Eigen::Quaterniond) * qz_inv.capacity() +
           sizeof(double) * std::size_t(diag.size() + delta.size() + dx.size()) + init.capacity_bytes();
  }
};

/// An SE(3) graph's edges as the solvers read them (references into the graph).
struct PoseGraphEdgesSE3 {
  const std::vector<EdgeSE3>& edges;            ///< the measurements
  const std::vector<std::pair<int, int>>& ends;  ///< node indices (i, j) of each edge
};

/// The state of every node read from the poses (x resized).
template <class Lazy = void>
void load_state_se3(const std::vector<SE3d>& poses, std::vector<NodeStateSE3>& x) {
  x.resize(poses.size());
  for (std::size_t a = 0; a < poses.size(); ++a) x[a] = {poses[a].so3().quaternion(), poses[a].translation()};
}

/// The state written back into the poses.
template <class Lazy = void>
void store_state_se3(const std::vector<NodeStateSE3>& x, std::vector<SE3d>& poses) {
  for (std::size_t a = 0; a < poses.size(); ++a) poses[a] = SE3d(x[a].t, SO3d(x[a].q));
}

/// x ⊞ Δ on the free nodes (pose_graph_plus); fixed nodes untouched. Found
/// by levenberg_marquardt for SE(3) states.
template <int B>
void apply_step(const PoseGraphLayout& L, const Eigen::VectorXd& dx, std::vector<NodeStateSE3>& x) {
  static_assert(B == 6);
  for (std::size_t a = 0; a < x.size(); ++a) {
    const int v = L.var[a];
    if (v < 0) continue;
    const Eigen::Matrix<double, 6, 1> d = dx.segment<6>(6 * v);
    x[a].t += x[a].q * d.head<3>();
    x[a].q = (x[a].q * SO3d::exp(d.tail<3>()).quaternion()).normalized();
  }
}

/// The parameter-tolerance test on SE(3) states: \f$ \|\Delta\| < \mathrm{tol}
/// (\|x_{free}\| + \mathrm{tol}) \f$, \f$ \|x\|^2 = \sum |t|^2 + |q|^2 \f$.
template <int B>
[[nodiscard]] bool step_below_tolerance(const PoseGraphLayout& L, const Eigen::VectorXd& dx,
                                        const std::vector<NodeStateSE3>& x, double tol) {
  static_assert(B == 6);
  double sq = 0.0;
  for (std::size_t a = 0; a < x.size(); ++a)
    if (L.var[a] >= 0) sq += x[a].t.squaredNorm() + x[a].q.squaredNorm();
  return dx.norm() < tol * (std::sqrt(sq) + tol);
}

/// Cost and linearisation of an SE(3) graph's edges (w.sys must be built on
/// the layout before linearize()).
class PoseGraphAssemblySE3 {
 public:
  using Block = Eigen::Matrix<double, 6, 6>;
  using Vec = Eigen::Matrix<double, 6, 1>;

  /// Computes each edge's \f$ q_Z^{-1} \f$ and \f$ R_Z^\top \f$.
  PoseGraphAssemblySE3(const PoseGraphEdgesSE3& g, SolverBuffersSE3& w) : g_(g), w_(w) {
    const std::size_t m = g_.edges.size();
    w_.qz_inv.resize(m);
    w_.Rz_t.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      const Eigen::Quaterniond& qz = g_.edges[k].measurement.so3().quaternion();
      w_.qz_inv[k] = qz.conjugate();
      w_.Rz_t[k] = qz.toRotationMatrix().transpose();
    }
  }

  /// Number of edges.
  [[nodiscard]] std::size_t num_edges() const noexcept { return g_.edges.size(); }

  /// Node rotation matrices at state x (what linearize() reads).
  void set_trigonometry(const std::vector<NodeStateSE3>& x) {
    w_.R.resize(x.size());
    for (std::size_t a = 0; a < x.size(); ++a) w_.R[a] = x[a].q.toRotationMatrix();
  }

  /// \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$ at x; leaves the rotations at x.
  [[nodiscard]] double cost(const std::vector<NodeStateSE3>& x) {
    set_trigonometry(x);
    double F = 0.0;
    for (std::size_t k = 0; k < g_.edges.size(); ++k) {
      const Vec e = error(k, x, nullptr, nullptr);
      F += g_.edges[k].loss.rho(e.dot(g_.edges[k].information * e));
    }
    return F;
  }

  /// H and b of w.sys at x (the rotations must be at x).
  void linearize(const std::vector<NodeStateSE3>& x) {
    w_.sys.set_zero();
    for (std::size_t k = 0; k < g_.edges.size(); ++k) {
      Block JE, Ad;
      const Vec e = error(k, x, &JE, &Ad);
      const Block& Om = g_.edges[k].information;
      const Vec Oe = Om * e;
      const double wt = g_.edges[k].loss.weight(e.dot(Oe));
      // J_E is block diagonal: W J_E column blocks are W's times R_E and D.
      const Eigen::Matrix3d RE = JE.topLeftCorner<3, 3>(), D = JE.bottomRightCorner<3, 3>();
      Block WJ;
      WJ.leftCols<3>().noalias() = wt * (Om.leftCols<3>() * RE);
      WJ.rightCols<3>().noalias() = wt * (Om.rightCols<3>() * D);
      Block Hjj;
      Hjj.topRows<3>().noalias() = RE.transpose() * WJ.topRows<3>();
      Hjj.bottomRows<3>().noalias() = D.transpose() * WJ.bottomRows<3>();
      Vec bj;
      bj.head<3>().noalias() = wt * (RE.transpose() * Oe.head<3>());
      bj.tail<3>().noalias() = wt * (D.transpose() * Oe.tail<3>());
      const Block AdT_H = Ad.transpose() * Hjj;
      const Block Hij = -AdT_H;
      const Block Hii = AdT_H * Ad;
      const Vec bi = -(Ad.transpose() * bj);
      w_.sys.add(k, Hii, Hij, Hjj, bi, bj);
    }
  }

 private:
  Vec error(std::size_t k, const std::vector<NodeStateSE3>& x, Block* JE, Block* Ad) const {
    const std::size_t i = std::size_t(g_.ends[k].first), j = std::size_t(g_.ends[k].second);
    return edge_error_se3_raw(x[i].q, w_.R[i], x[i].t, x[j].q, w_.R[j], x[j].t, w_.qz_inv[k], w_.Rz_t[k],
                              g_.edges[k].measurement.translation(), JE, Ad);
  }

  PoseGraphEdgesSE3 g_;  // references into the graph
  SolverBuffersSE3& w_;
};

}  // namespace posefuse::detail

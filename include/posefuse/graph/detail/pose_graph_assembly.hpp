#pragma once
/// @file
/// A pose graph's cost and normal equations at a state on B x B blocks
/// (not API): B = 4 for [p; yaw], B = 3 for a planar graph's [x, y, yaw].
///
/// The node yaws' cos/sin are computed once per evaluation and each edge's
/// Δψ once per solve (into the SolverBuffers), and H is assembled from one
/// B x B triple product per edge (see PoseGraphAssembly::linearize).

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>

namespace posefuse::detail {

/// The state of every node read from the poses (x resized).
template <int B>
void load_state(const std::vector<Pose4Dof>& poses, std::vector<NodeState<B>>& x) {
  x.resize(poses.size());
  for (std::size_t a = 0; a < poses.size(); ++a) {
    if constexpr (B == 4) x[a] << poses[a].p, poses[a].yaw;
    else x[a] << poses[a].p.x(), poses[a].p.y(), poses[a].yaw;
  }
}

/// The state written back into the poses (roll and pitch, and z on the
/// planar path, are left as they are).
template <int B>
void store_state(const std::vector<NodeState<B>>& x, std::vector<Pose4Dof>& poses) {
  for (std::size_t a = 0; a < poses.size(); ++a) {
    if constexpr (B == 4) poses[a].p = x[a].template head<3>();
    else poses[a].p.template head<2>() = x[a].template head<2>();
    poses[a].yaw = x[a](B - 1);
  }
}

/// Cost and linearisation of a graph's edges, with the buffers `w` for the
/// trigonometry and the block system (w.sys must be built on the layout).
template <int B>
class PoseGraphAssembly {
 public:
  using State = NodeState<B>;
  using Block = Eigen::Matrix<double, B, B>;

  /// Computes the per-edge constants: each edge's Δψ cos/sin and, planar,
  /// its (x, y, yaw) information.
  PoseGraphAssembly(const PoseGraphEdges& g, SolverBuffers<B>& w) : g_(g), w_(w) {
    const std::size_t m = g_.edges.size();
    w_.cm.resize(m);
    w_.sm.resize(m);
    for (std::size_t k = 0; k < m; ++k) {
      w_.cm[k] = std::cos(g_.edges[k].dyaw);
      w_.sm[k] = std::sin(g_.edges[k].dyaw);
    }
    if constexpr (B == 3) {
      w_.info3.resize(m);
      const int map[3] = {0, 1, 3};
      for (std::size_t k = 0; k < m; ++k)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) w_.info3[k](r, c) = g_.edges[k].information(map[r], map[c]);
    }
  }

  /// Number of edges.
  [[nodiscard]] std::size_t num_edges() const noexcept { return g_.edges.size(); }

  /// Node yaws' cos/sin at state x (what linearize() reads).
  void set_trigonometry(const std::vector<State>& x) {
    w_.c.resize(x.size());
    w_.s.resize(x.size());
    for (std::size_t a = 0; a < x.size(); ++a) {
      // Both from one argument into locals: the compiler makes one sincos call.
      const double yaw = x[a](B - 1);
      const double c = std::cos(yaw), s = std::sin(yaw);
      w_.c[a] = c;
      w_.s[a] = s;
    }
  }

  /// \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$ at state x; leaves the
  /// trigonometry at x.
  [[nodiscard]] double cost(const std::vector<State>& x) {
    set_trigonometry(x);
    double F = 0.0;
    for (std::size_t k = 0; k < g_.edges.size(); ++k) {
      const State e = error(k, x, nullptr, nullptr);
      F += g_.edges[k].loss.rho(e.dot(information(k) * e));
    }
    return F;
  }

  /// H and b of w.sys at state x (the trigonometry must be at x).
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
  void linearize(const std::vector<State>& x) {
    constexpr int last = B - 1;
    w_.sys.set_zero();
    for (std::size_t k = 0; k < g_.edges.size(); ++k) {
      Block Ji, Jj;
      const State e = error(k, x, &Ji, &Jj);
      const Block& Om = information(k);
      const State Oe = Om * e;
      const double wt = g_.edges[k].loss.weight(e.dot(Oe));
      State g = Ji.col(last);
      g(last) = 0.0;  // g~ = J_i's yaw column + J_j's
      const Block WJ = wt * (Om * Jj);
      const Block Hjj = Jj.transpose() * WJ;
      const State u = WJ.transpose() * g;
      const double gWg = wt * g.dot(Om * g);
      Block Hij = -Hjj;
      Hij.row(last) += u.transpose();
      Block Hii = Hjj;
      Hii.col(last) -= u;
      Hii.row(last) -= u.transpose();
      Hii(last, last) += gWg;
      const State bj = wt * (Jj.transpose() * Oe);
      State bi = -bj;
      bi(last) += wt * g.dot(Oe);
      w_.sys.add(k, Hii, Hij, Hjj, bi, bj);
    }
  }

 private:
  /// Edge k's error (and Jacobians) at state x.
  State error(std::size_t k, const std::vector<State>& x, Block* Ji, Block* Jj) const {
    const std::size_t i = std::size_t(g_.ends[k].first), j = std::size_t(g_.ends[k].second);
    const Edge4Dof& ed = g_.edges[k];
    if constexpr (B == 4) {
      return edge_error_4dof_trig(x[i].template head<3>(), x[i](3), w_.c[i], w_.s[i], g_.Qt[i],
                                  x[j].template head<3>(), x[j](3), ed.dp, ed.dyaw, w_.cm[k], w_.sm[k], Ji, Jj);
    } else {
      return edge_error_planar_trig(x[i].template head<2>(), x[i](2), w_.c[i], w_.s[i], x[j].template head<2>(),
                                    x[j](2), ed.dp.template head<2>(), ed.dyaw, w_.cm[k], w_.sm[k], Ji, Jj);
    }
  }

  [[nodiscard]] const Block& information(std::size_t k) const {
    if constexpr (B == 4) return g_.edges[k].information;
    else return w_.info3[k];
  }

  PoseGraphEdges g_;  // references into the graph
  SolverBuffers<B>& w_;
};

}  // namespace posefuse::detail

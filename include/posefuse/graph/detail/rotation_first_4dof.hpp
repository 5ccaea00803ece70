#pragma once
/// @file
/// The rotation-first start of a 4-DoF pose graph (not API; the method is
/// documented at PoseGraph4Dof::initialize_rotation_first): a chordal
/// relaxation for the yaws (Carlone, Tron, Daniilidis, Dellaert,
/// "Initialization techniques for 3D SLAM: a survey on rotation estimation
/// and its use in pose graph optimization", ICRA 2015), then the positions
/// that minimise the cost for those yaws.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/graph/detail/block_system.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>
#include <posefuse/lie/so2.hpp>

namespace posefuse::detail {

/// \f$ \Delta = -H^{-1} b \f$ of an assembled system, with the buffers' factor.
/// @throws posefuse::invalid_argument naming `what` when H is singular
template <int B>
[[nodiscard]] Eigen::VectorXd newton_step_or_throw(SolverBuffers<B>& w, const char* what) {
  w.chol.analyze(w.sys);
  const bool factored = w.chol.factorize(w.sys);
  Eigen::VectorXd dx;
  if (factored) dx = w.chol.solve(-w.sys.b);
  if (!factored || !dx.allFinite())
    throw invalid_argument(std::string("pose graph: ") + what +
                           ": the linear system is singular (information too weak to fix every node)");
  return dx;
}

/// Yaws by the chordal relaxation: minimise
/// \f$ \sum_k \Omega_{k,\psi\psi} \| v_j - R(\Delta\psi_k) v_i \|^2 \f$ over
/// free 2-vectors \f$ v_i \f$ (fixed nodes keep theirs), one linear solve
/// from the current yaws, then \f$ \psi_i = \mathrm{atan2}(v_{i,y}, v_{i,x}) \f$.
template <class Lazy = void>
void chordal_yaws(const PoseGraphEdges& g, const PoseGraphLayout& L, std::vector<Pose4Dof>& poses,
                  SolverBuffers<2>& w) {
  const auto unit = [](double a) { return Eigen::Vector2d(std::cos(a), std::sin(a)); };
  w.sys.build(L.n, L.pairs);
  w.sys.set_zero();
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    const int i = g.ends[k].first, j = g.ends[k].second;
    const double wk = std::max(g.edges[k].information(3, 3), 0.0);
    const Eigen::Matrix2d Rk = SO2<double>(g.edges[k].dyaw).matrix();
    // r = v_j - Rk v_i; J_i = -Rk, J_j = I.
    const Eigen::Vector2d vi = unit(poses[std::size_t(i)].yaw);
    const Eigen::Vector2d vj = unit(poses[std::size_t(j)].yaw);
    const Eigen::Vector2d r0 = vj - Rk * vi;  // at the current point
    const Eigen::Matrix2d Hii = wk * Eigen::Matrix2d::Identity();
    const Eigen::Matrix2d Hij = -wk * Rk.transpose();
    w.sys.add(k, Hii, Hij, wk * Eigen::Matrix2d::Identity(), -wk * Rk.transpose() * r0, wk * r0);
  }
  const Eigen::VectorXd dx = newton_step_or_throw(w, "yaw initialisation");
  for (std::size_t a = 0; a < poses.size(); ++a) {
    const int v = L.var[a];
    if (v < 0) continue;
    const Eigen::Vector2d u = unit(poses[a].yaw) + dx.segment<2>(2 * v);
    if (u.norm() > 1e-12) poses[a].yaw = wrap_angle(std::atan2(u.y(), u.x()));
  }
}

/// Positions for the current yaws: the cost is quadratic in them, so one
/// exact Newton step (robust losses ignored) minimises it.
template <class Lazy = void>
void positions_for_yaws(const PoseGraphEdges& g, const PoseGraphLayout& L, std::vector<Pose4Dof>& poses,
                        SolverBuffers<3>& w) {
  w.sys.build(L.n, L.pairs);
  w.sys.set_zero();
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    const std::size_t i = std::size_t(g.ends[k].first), j = std::size_t(g.ends[k].second);
    const Edge4Dof& ed = g.edges[k];
    Eigen::Matrix4d Ji, Jj;
    const Eigen::Vector4d e =
        edge_error_4dof(poses[i].p, poses[i].yaw, g.Qt[i], poses[j].p, poses[j].yaw, ed.dp, ed.dyaw, &Ji, &Jj);
    const Eigen::Matrix3d Jpi = Ji.topLeftCorner<3, 3>(), Jpj = Jj.topLeftCorner<3, 3>();
    const Eigen::Matrix<double, 3, 4> Om = ed.information.topRows<3>();
    const Eigen::Matrix3d Ott = ed.information.topLeftCorner<3, 3>();
    const Eigen::Vector3d r = Om * e;  // Ω_tt e_t + Ω_tψ e_ψ
    w.sys.add(k, Jpi.transpose() * Ott * Jpi, Jpi.transpose() * Ott * Jpj, Jpj.transpose() * Ott * Jpj,
              Jpi.transpose() * r, Jpj.transpose() * r);
  }
  const Eigen::VectorXd dx = newton_step_or_throw(w, "translation initialisation");
  for (std::size_t a = 0; a < poses.size(); ++a) {
    const int v = L.var[a];
    if (v >= 0) poses[a].p += dx.segment<3>(3 * v);
  }
}

}  // namespace posefuse::detail

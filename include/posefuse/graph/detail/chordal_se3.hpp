#pragma once
/// @file
/// The chordal start of an SE(3) pose graph (not API; the method is
/// documented at PoseGraphSE3::initialize_chordal): rotations by the
/// chordal relaxation of Martinec and Pajdla ("Robust rotation and
/// translation estimation in multiview reconstruction", CVPR 2007) as
/// surveyed by Carlone, Tron, Daniilidis, Dellaert ("Initialization
/// techniques for 3D SLAM", ICRA 2015), projected to SO(3), then the
/// translations that minimise the cost for those rotations.

#include <Eigen/Core>
#include <Eigen/SVD>
#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/detail/pose_graph_se3_assembly.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse::detail {

/// Factors the 3x3-block system in w (built and filled).
/// @throws posefuse::invalid_argument naming `what` when it is singular
template <class Lazy = void>
void factor_or_throw(SolverBuffers<3>& w, const char* what) {
  w.chol.analyze(w.sys);
  if (!w.chol.factorize(w.sys))
    throw invalid_argument(std::string("pose graph: ") + what +
                           ": the linear system is singular (information too weak to fix every node)");
}

/// The rotation nearest (Frobenius) to a 3x3 matrix: \f$ U\,\mathrm{diag}(1, 1, \det UV^\top) V^\top \f$.
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix3d project_to_so3(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1.0 : -1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

/// Chordal rotations: minimise \f$ \sum_k w_k \| R_j - R_i R_{Z_k} \|_F^2 \f$
/// over unconstrained 3x3 matrices (fixed nodes keep theirs), with
/// \f$ w_k = \mathrm{tr}(\Omega_{k,rr})/3 \f$ the mean rotation information.
/// The cost separates into the three rows of the matrices, which share one
/// 3x3-block normal matrix: one factorisation, three solves. Each node's
/// matrix is then projected to SO(3).
template <class Lazy = void>
void chordal_rotations(const PoseGraphEdgesSE3& g, const PoseGraphLayout& L, std::vector<SE3d>& poses,
                       SolverBuffers<3>& w) {
  const std::size_t m = g.edges.size();
  std::vector<Eigen::Matrix3d> Rz(m);
  std::vector<double> wk(m);
  std::vector<Eigen::Matrix3d> R(poses.size());
  for (std::size_t a = 0; a < poses.size(); ++a) R[a] = poses[a].so3().matrix();
  w.sys.build(L.n, L.pairs);
  w.sys.set_zero();
  for (std::size_t k = 0; k < m; ++k) {
    Rz[k] = g.edges[k].measurement.so3().matrix();
    wk[k] = std::max(g.edges[k].information.bottomRightCorner<3, 3>().trace() / 3.0, 0.0);
    // Row r of R_j minus row r of R_i R_Z: r = a_j - R_Z^T a_i, J_i = -R_Z^T, J_j = I.
    const Eigen::Matrix3d I = wk[k] * Eigen::Matrix3d::Identity();
    w.sys.add(k, I, -wk[k] * Rz[k], I, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  }
  factor_or_throw(w, "chordal rotation initialisation");
  std::vector<Eigen::Matrix3d> M = R;
  Eigen::VectorXd b(3 * L.n);
  for (int row = 0; row < 3; ++row) {
    b.setZero();
    for (std::size_t k = 0; k < m; ++k) {
      const int vi = L.pairs[k].first, vj = L.pairs[k].second;
      const std::size_t i = std::size_t(g.ends[k].first), j = std::size_t(g.ends[k].second);
      const Eigen::Vector3d r0 = R[j].row(row).transpose() - Rz[k].transpose() * R[i].row(row).transpose();
      if (vi >= 0) b.segment<3>(3 * vi) -= wk[k] * (Rz[k] * r0);
      if (vj >= 0) b.segment<3>(3 * vj) += wk[k] * r0;
    }
    const Eigen::VectorXd dx = w.chol.solve(-b);
    if (!dx.allFinite())
      throw invalid_argument("pose graph: chordal rotation initialisation: the linear system is singular");
    for (std::size_t a = 0; a < poses.size(); ++a)
      if (L.var[a] >= 0) M[a].row(row) += dx.segment<3>(3 * L.var[a]).transpose();
  }
  for (std::size_t a = 0; a < poses.size(); ++a)
    if (L.var[a] >= 0) poses[a] = SE3d(poses[a].translation(), SO3d(project_to_so3(M[a])));
}

/// Translations for the current rotations: the error's translation part is
/// linear in them, so one exact Newton step (robust losses ignored, the
/// rotation residuals held) minimises the cost over them.
template <class Lazy = void>
void translations_for_rotations(const PoseGraphEdgesSE3& g, const PoseGraphLayout& L, std::vector<SE3d>& poses,
                                SolverBuffers<3>& w) {
  w.sys.build(L.n, L.pairs);
  w.sys.set_zero();
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    const std::size_t i = std::size_t(g.ends[k].first), j = std::size_t(g.ends[k].second);
    const EdgeSE3& ed = g.edges[k];
    const Vector6d e = edge_error_se3(poses[i], poses[j], ed.measurement);
    // t_E = R_Z^T (R_i^T (t_j - t_i) - t_Z): d t_E / d t_j = A = R_Z^T R_i^T, d / d t_i = -A.
    const Eigen::Matrix3d A = ed.measurement.so3().matrix().transpose() * poses[i].so3().matrix().transpose();
    const Eigen::Matrix3d Ott = ed.information.topLeftCorner<3, 3>();
    const Eigen::Vector3d r = ed.information.topRows<3>() * e;
    const Eigen::Matrix3d H = A.transpose() * Ott * A;
    w.sys.add(k, H, -H, H, -A.transpose() * r, A.transpose() * r);
  }
  factor_or_throw(w, "translation initialisation");
  const Eigen::VectorXd dx = w.chol.solve(-w.sys.b);
  if (!dx.allFinite())
    throw invalid_argument("pose graph: translation initialisation: the linear system is singular");
  for (std::size_t a = 0; a < poses.size(); ++a)
    if (L.var[a] >= 0) poses[a] = SE3d(poses[a].translation() + dx.segment<3>(3 * L.var[a]), poses[a].so3());
}

}  // namespace posefuse::detail

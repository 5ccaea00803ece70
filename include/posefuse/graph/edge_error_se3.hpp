#pragma once
/// @file
/// The 6-DoF relative-pose edge of an SE(3) pose graph: its error (g2o's
/// `EdgeSE3`) with analytic Jacobians, and the pose increment they refer to.
///
/// **Edge error** (Kümmerle et al., "g2o: A General Framework for Graph
/// Optimization", ICRA 2011, `types_slam3d` EdgeSE3): an edge i → j measures
/// the pose Z of node j in node i's frame. With the error pose
/// \f$ E = Z^{-1} X_i^{-1} X_j = (R_E, t_E) \f$ and its unit quaternion
/// \f$ q_E = (w, v) \f$ taken with \f$ w \ge 0 \f$,
/// \f[ e = [t_E;\ v] \in \mathbb{R}^6, \qquad
///     t_E = R_Z^\top \big( R_i^\top (t_j - t_i) - t_Z \big), \f]
/// and the edge's squared error is \f$ s = e^\top \Omega e \f$ with its 6x6
/// information \f$ \Omega \f$ in the order (x, y, z, qx, qy, qz), as in g2o's
/// files; g2o's χ² is \f$ \sum_k s_k \f$. For a small rotation error of angle
/// θ, \f$ |v| = \sin(\theta/2) \approx \theta/2 \f$. Ceres's `pose_graph_3d`
/// example writes the rotation residual as \f$ 2 v \f$ and the translation
/// error without the \f$ R_Z^\top \f$, and reports half the sum of squares:
/// with the same information, its rotation terms are 4x those here and its
/// cost is half of it.
///
/// **Increment** (the Jacobians' convention, g2o's VertexSE3 to first order):
/// \f$ X \boxplus [\delta t; \delta\phi] = (R\,\mathrm{Exp}(\delta\phi),\ t + R\,\delta t) \f$,
/// i.e. X composed on the right with \f$ (\mathrm{Exp}(\delta\phi), \delta t) \f$.
/// Then \f$ \partial e / \partial \delta_j = J_E \f$ and
/// \f$ \partial e / \partial \delta_i = -J_E\, \mathrm{Ad}(X_j^{-1} X_i) \f$ with
/// \f[ J_E = \begin{bmatrix} R_E & 0 \\ 0 & \tfrac12 (w I + [v]_\times) \end{bmatrix}, \qquad
///     \mathrm{Ad}(R, t) = \begin{bmatrix} R & [t]_\times R \\ 0 & R \end{bmatrix}. \f]

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include <posefuse/graph/robust_loss.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse {

using Matrix6d = Eigen::Matrix<double, 6, 6>;  ///< 6x6 (information, Jacobians)
using Vector6d = Eigen::Matrix<double, 6, 1>;  ///< 6-vector (errors, increments)

/// A relative 6-DoF measurement between two nodes (ids).
struct EdgeSE3 {
  std::int64_t from = 0;                                   ///< node i (the measurement's frame)
  std::int64_t to = 0;                                     ///< node j
  SE3d measurement;                                        ///< Z: pose of j in i's frame
  Matrix6d information = Matrix6d::Identity();             ///< \f$ \Omega \f$, order x, y, z, qx, qy, qz
  RobustKernel loss;                                       ///< robust loss (none by default)
};

namespace detail {

/// \f$ [a]_\times \f$.
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix3d skew3(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

/// The edge error from the raw pieces the optimiser keeps: node rotations
/// as quaternions and matrices, the measurement's \f$ q_Z^{-1} \f$,
/// \f$ R_Z^\top \f$ and \f$ t_Z \f$.
/// @param[out] JE if not null, \f$ J_E \f$ (see the file comment)
/// @param[out] Ad if not null, \f$ \mathrm{Ad}(X_j^{-1} X_i) \f$
template <class Lazy = void>
[[nodiscard]] Vector6d edge_error_se3_raw(const Eigen::Quaterniond& qi, const Eigen::Matrix3d& Ri,
                                          const Eigen::Vector3d& ti, const Eigen::Quaterniond& qj,
                                          const Eigen::Matrix3d& Rj, const Eigen::Vector3d& tj,
                                          const Eigen::Quaterniond& qz_inv, const Eigen::Matrix3d& Rz_t,
                                          const Eigen::Vector3d& tz, Matrix6d* JE, Matrix6d* Ad) {
  Eigen::Quaterniond qE = qz_inv * (qi.conjugate() * qj);
  if (qE.w() < 0.0) qE.coeffs() = -qE.coeffs();
  Vector6d e;
  e.head<3>() = Rz_t * (Ri.transpose() * (tj - ti) - tz);
  e.tail<3>() = qE.vec();
  if (JE) {
    JE->setZero();
    JE->topLeftCorner<3, 3>() = qE.toRotationMatrix();
    JE->bottomRightCorner<3, 3>() = 0.5 * (qE.w() * Eigen::Matrix3d::Identity() + skew3(qE.vec()));
  }
  if (Ad) {
    const Eigen::Matrix3d R = Rj.transpose() * Ri;
    const Eigen::Vector3d t = Rj.transpose() * (ti - tj);
    Ad->topLeftCorner<3, 3>() = R;
    Ad->topRightCorner<3, 3>() = skew3(t) * R;
    Ad->bottomLeftCorner<3, 3>().setZero();
    Ad->bottomRightCorner<3, 3>() = R;
  }
  return e;
}

}  // namespace detail

/// \f$ X \boxplus [\delta t; \delta\phi] = (R\,\mathrm{Exp}(\delta\phi),\ t + R\,\delta t) \f$,
/// the increment the SE(3) graph's Jacobians and optimiser use.
template <class Lazy = void>
[[nodiscard]] SE3d pose_graph_plus(const SE3d& x, const Vector6d& d) {
  return SE3d(x.translation() + x.so3().act(d.head<3>()), x.so3() * SO3d::exp(d.tail<3>()));
}

/// The SE(3) edge error \f$ e = [t_E; v] \f$ of an edge measuring Z between
/// nodes at X_i and X_j (see the file comment), and its Jacobians.
/// @param[in] xi, xj the poses of nodes i and j
/// @param[in] z the edge's measurement, node j in node i's frame
/// @param[out] J_e_xi if not null, \f$ \partial e / \partial \delta_i \f$ (6x6, see pose_graph_plus)
/// @param[out] J_e_xj if not null, \f$ \partial e / \partial \delta_j \f$
template <class Lazy = void>
[[nodiscard]] Vector6d edge_error_se3(const SE3d& xi, const SE3d& xj, const SE3d& z, Matrix6d* J_e_xi = nullptr,
                                      Matrix6d* J_e_xj = nullptr) {
  const Eigen::Quaterniond& qi = xi.so3().quaternion();
  const Eigen::Quaterniond& qj = xj.so3().quaternion();
  const Eigen::Quaterniond& qz = z.so3().quaternion();
  Matrix6d JE, Ad;
  const bool jac = J_e_xi != nullptr || J_e_xj != nullptr;
  const Vector6d e = detail::edge_error_se3_raw(qi, qi.toRotationMatrix(), xi.translation(), qj,
                                                qj.toRotationMatrix(), xj.translation(), qz.conjugate(),
                                                qz.toRotationMatrix().transpose(), z.translation(),
                                                jac ? &JE : nullptr, jac ? &Ad : nullptr);
  if (J_e_xi) *J_e_xi = -JE * Ad;
  if (J_e_xj) *J_e_xj = JE;
  return e;
}

}  // namespace posefuse

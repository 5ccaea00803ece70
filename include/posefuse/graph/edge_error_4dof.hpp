#pragma once
/// @file
/// The 4-DoF pose, the relative measurement between two poses and its error
/// with analytic Jacobians; the planar (x, y, yaw) special case.
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

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include <posefuse/core/angles.hpp>
#include <posefuse/graph/robust_loss.hpp>
#include <posefuse/lie/rotation.hpp>

namespace posefuse {

/// A 4-DoF pose: position (m, world), yaw (rad) and the fixed roll and pitch (rad).
struct Pose4Dof {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position in the world frame (m)
  double yaw = 0.0;                             ///< \f$ \psi \f$ about world z (rad)
  double pitch = 0.0;                           ///< \f$ \theta \f$, held fixed (rad)
  double roll = 0.0;                            ///< \f$ \phi \f$, held fixed (rad)
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
/// @param[in] pi, yaw_i node i's position and yaw
/// @param[in] pj, yaw_j node j's position and yaw
/// @param[in] dp, dyaw the edge's measured position (in node i's yaw frame) and yaw change
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
/// @param[in] pi, yaw_i node i's position and heading
/// @param[in] pj, yaw_j node j's position and heading
/// @param[in] dp, dyaw the edge's measured displacement (in node i's frame) and heading change
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

}  // namespace posefuse

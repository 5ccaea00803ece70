#pragma once
/// @file
/// Small-rotation helpers of the structured pre-integration step
/// (inertial/preintegration.hpp): Exp and the right Jacobian of one IMU step's
/// rotation by their series, and the products by a skew matrix written out
/// column by column. Internal: not part of the public API.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include <posefuse/lie/so3.hpp>

namespace posefuse::detail {

/// \f$ \mathrm{Exp}(\theta) \f$ as a quaternion and \f$ J_r(\theta) = I - a[\theta]_\times + b[\theta]_\times^2 \f$
/// with its coefficients \f$ a = (1 - \cos\theta)/\theta^2 \f$, \f$ b = (\theta - \sin\theta)/\theta^3 \f$,
/// by their Taylor series (to \f$ |\theta|^8 \f$, exact in double) for the small
/// angles of one IMU step, |θ| < 0.05 rad, and by SO3 otherwise. No
/// trigonometric call on the hot path.
template <class Lazy = void>
void small_exp(const Eigen::Vector3d& theta, Eigen::Quaterniond& q, Eigen::Matrix3d& Jr, double& a,
               double& b) {
  const double t2 = theta.squaredNorm();
  if (t2 < 0.05 * 0.05) {
    const double x2 = t2 / 4.0;  // (θ/2)²
    const double c = 1.0 - x2 * (1.0 / 2.0) * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0))));
    const double k = 0.5 * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0)))));
    q = Eigen::Quaterniond(c, k * theta.x(), k * theta.y(), k * theta.z());
    a = 0.5 * (1.0 - t2 * (1.0 / 12.0) * (1.0 - t2 * (1.0 / 30.0) * (1.0 - t2 * (1.0 / 56.0) * (1.0 - t2 * (1.0 / 90.0)))));
    b = (1.0 / 6.0) * (1.0 - t2 * (1.0 / 20.0) * (1.0 - t2 * (1.0 / 42.0) * (1.0 - t2 * (1.0 / 72.0) * (1.0 - t2 * (1.0 / 110.0)))));
  } else {
    q = SO3d::exp(theta).quaternion();
    const double th = std::sqrt(t2);
    a = detail::one_minus_cos_over_x2(th);
    b = detail::x_minus_sin_over_x3(th);
  }
  // J_r = I - a W + b W², W² = θθ^T - |θ|² I.
  Jr.noalias() = (b * theta) * theta.transpose();
  Jr.diagonal().array() += 1.0 - b * t2;
  Jr(0, 1) += a * theta.z();
  Jr(1, 0) -= a * theta.z();
  Jr(0, 2) -= a * theta.y();
  Jr(2, 0) += a * theta.y();
  Jr(1, 2) += a * theta.x();
  Jr(2, 1) -= a * theta.x();
}

/// \f$ -[u]_\times M \f$: the columns \f$ m_j \times u \f$ (27 flops instead of 45).
template <class Lazy = void>
Eigen::Matrix3d neg_skew_times(const Eigen::Vector3d& u, const Eigen::Matrix3d& M) noexcept {
  Eigen::Matrix3d out;
  for (int j = 0; j < 3; ++j) {
    out(0, j) = M(1, j) * u.z() - M(2, j) * u.y();
    out(1, j) = M(2, j) * u.x() - M(0, j) * u.z();
    out(2, j) = M(0, j) * u.y() - M(1, j) * u.x();
  }
  return out;
}

/// \f$ M [u]_\times = M (-[u]_\times)^\top \f$ for an N x 3 matrix M, column by
/// column (\f$ 6N \f$ flops; the columns vectorise when N is even).
template <int N>
Eigen::Matrix<double, N, 3> times_skew(const Eigen::Matrix<double, N, 3>& M,
                                       const Eigen::Vector3d& u) noexcept {
  Eigen::Matrix<double, N, 3> out;
  out.col(0) = M.col(1) * u.z() - M.col(2) * u.y();
  out.col(1) = M.col(2) * u.x() - M.col(0) * u.z();
  out.col(2) = M.col(0) * u.y() - M.col(1) * u.x();
  return out;
}

}  // namespace posefuse::detail

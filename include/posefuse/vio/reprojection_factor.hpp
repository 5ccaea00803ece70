#pragma once
/// @file
/// The reprojection factor of a feature with an inverse depth anchored at
/// its first observation in the window: residual and analytic Jacobians with
/// respect to both keyframe poses, the camera-IMU extrinsic and the inverse
/// depth.
///
/// **Variables.** A keyframe pose \f$ (p_i, R_i) \f$ (body = IMU frame → world),
/// the extrinsic \f$ (p_{bc}, R_{bc}) \f$ (camera → body, \f$ p_b = R_{bc} p_c + p_{bc} \f$)
/// and the inverse depth λ of the feature in the anchor camera i. Poses use
/// the perturbations of ImuState (inertial/imu_factor.hpp):
/// \f$ p \oplus \delta p = p + \delta p \f$, \f$ R \oplus \delta\phi = R\,\mathrm{Exp}(\delta\phi) \f$,
/// tangent \f$ [\delta p, \delta\phi] \f$.
///
/// **Residual** (Qin et al., "VINS-Mono", T-RO 2018, eq 19-20, on the
/// normalised image plane). With \f$ m_i = (x_i, y_i, 1) \f$ and
/// \f$ m_j \f$ the undistorted normalised observations in the anchor and the
/// observing camera:
/// \f[ P_{c_i} = m_i / \lambda, \quad P_{b_i} = R_{bc} P_{c_i} + p_{bc}, \quad
///     P_w = R_i P_{b_i} + p_i, \f]
/// \f[ P_{b_j} = R_j^\top (P_w - p_j), \quad P_{c_j} = R_{bc}^\top (P_{b_j} - p_{bc}), \quad
///     r = S\,\big(\pi(P_{c_j}) - m_j\big), \f]
/// with \f$ \pi(x, y, z) = (x/z, y/z) \f$ and \f$ S = \mathrm{diag}(f_u/\sigma, f_v/\sigma) \f$,
/// so that r is in units of the pixel noise σ.
///
/// **Jacobians** of \f$ P_{c_j} \f$ (then \f$ \partial r = S\,\Pi\,\partial P_{c_j} \f$,
/// \f$ \Pi = [[1/z, 0, -x/z^2], [0, 1/z, -y/z^2]] \f$), with
/// \f$ A = R_{bc}^\top R_j^\top \f$:
/// \f[ \partial/\partial(\delta p_i, \delta\phi_i) = (A,\ -A R_i [P_{b_i}]_\times), \quad
///     \partial/\partial(\delta p_j, \delta\phi_j) = (-A,\ R_{bc}^\top [P_{b_j}]_\times), \f]
/// \f[ \partial/\partial(\delta p_{bc}, \delta\phi_{bc}) =
///     (A R_i - R_{bc}^\top,\ -A R_i R_{bc} [P_{c_i}]_\times + [P_{c_j}]_\times), \quad
///     \partial/\partial\lambda = -A R_i R_{bc}\, m_i / \lambda^2. \f]

#include <Eigen/Core>
#include <cmath>

#include <posefuse/core/error.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// A rigid transform \f$ (p, R) \f$ with the tangent \f$ [\delta p, \delta\phi] \f$
/// of the file comment (a posefuse::Manifold of dimension 6): a keyframe
/// pose (body → world) or the camera-IMU extrinsic (camera → body).
struct RigidPose {
  using Scalar = double;                          ///< scalar type
  static constexpr int Dim = 6;                   ///< tangent dimension
  using Tangent = Eigen::Matrix<double, 6, 1>;    ///< [δp, δφ]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();    ///< translation
  SO3d R;                                         ///< rotation

  /// \f$ x \oplus d \f$.
  [[nodiscard]] RigidPose plus(const Tangent& d) const {
    return RigidPose{p + d.head<3>(), R.plus(d.tail<3>())};
  }
  /// \f$ y \ominus x \f$ (this = y).
  [[nodiscard]] Tangent minus(const RigidPose& x) const {
    Tangent d;
    d << p - x.p, R.minus(x.R);
    return d;
  }
  /// \f$ R q + p \f$.
  [[nodiscard]] Eigen::Vector3d act(const Eigen::Vector3d& q) const { return R.act(q) + p; }
};

/// One observation of an anchored feature in another keyframe (see the file comment).
class ReprojectionFactor {
 public:
  using Residual = Eigen::Vector2d;                     ///< whitened residual (units of σ)
  using PoseJacobian = Eigen::Matrix<double, 2, 6>;     ///< ∂r / ∂[δp, δφ]

  /// @param[in] m_anchor normalised observation (x/z, y/z) in the anchor camera
  /// @param[in] m_obs normalised observation in the observing camera
  /// @param[in] sqrt_info \f$ (f_u/\sigma, f_v/\sigma) \f$, both > 0
  /// @throws posefuse::invalid_argument for non-finite inputs or sqrt_info <= 0
  ReprojectionFactor(const Eigen::Vector2d& m_anchor, const Eigen::Vector2d& m_obs,
                     const Eigen::Vector2d& sqrt_info)
      : mi_(m_anchor.x(), m_anchor.y(), 1.0), mj_(m_obs), s_(sqrt_info) {
    if (!m_anchor.allFinite() || !m_obs.allFinite())
      throw invalid_argument("ReprojectionFactor: observation is not finite");
    if (!(s_.x() > 0 && s_.y() > 0 && s_.allFinite()))
      throw invalid_argument("ReprojectionFactor: sqrt_info must be finite and > 0");
  }

  /// The point in the observing camera, \f$ P_{c_j} \f$ (its z is the depth there).
  [[nodiscard]] Eigen::Vector3d point_in_observer(const RigidPose& Ti, const RigidPose& Tj,
                                                  const RigidPose& T_bc, double inv_depth) const {
    const Eigen::Vector3d Pw = Ti.act(T_bc.act(mi_ / inv_depth));
    return T_bc.R.inverse().act(Tj.R.inverse().act(Pw - Tj.p) - T_bc.p);
  }

  /// The whitened residual r and, for each pointer given, its Jacobian.
  /// @param[in] Ti, Tj, T_bc anchor keyframe pose, observing keyframe pose, extrinsic
  /// @param[in] inv_depth λ in the anchor camera (> 0 for a point in front)
  /// @param[out] J_i, J_j, J_bc, J_lambda the Jacobians of the file comment, or null
  /// The residual is finite only for a point off the observer's z = 0 plane;
  /// callers check point_in_observer(...).z() first.
  [[nodiscard]] Residual residual(const RigidPose& Ti, const RigidPose& Tj, const RigidPose& T_bc,
                                  double inv_depth, PoseJacobian* J_i = nullptr,
                                  PoseJacobian* J_j = nullptr, PoseJacobian* J_bc = nullptr,
                                  Eigen::Vector2d* J_lambda = nullptr) const {
    using M3 = Eigen::Matrix3d;
    const Eigen::Vector3d Pci = mi_ / inv_depth;
    const Eigen::Vector3d Pbi = T_bc.act(Pci);
    const Eigen::Vector3d Pw = Ti.act(Pbi);
    const M3 RjT = Tj.R.matrix().transpose();
    const Eigen::Vector3d Pbj = RjT * (Pw - Tj.p);
    const M3 RbcT = T_bc.R.matrix().transpose();
    const Eigen::Vector3d Pcj = RbcT * (Pbj - T_bc.p);
    const double iz = 1.0 / Pcj.z();
    Residual r(s_.x() * (Pcj.x() * iz - mj_.x()), s_.y() * (Pcj.y() * iz - mj_.y()));
    if (!(J_i || J_j || J_bc || J_lambda)) return r;
    Eigen::Matrix<double, 2, 3> D;  // S Π
    D << s_.x() * iz, 0.0, -s_.x() * Pcj.x() * iz * iz, 0.0, s_.y() * iz, -s_.y() * Pcj.y() * iz * iz;
    const M3 A = RbcT * RjT;
    const Eigen::Matrix<double, 2, 3> DA = D * A;
    const M3 Ri = Ti.R.matrix();
    const Eigen::Matrix<double, 2, 3> DARi = DA * Ri;
    if (J_i) {
      J_i->leftCols<3>() = DA;
      J_i->rightCols<3>() = -DARi * SO3d::hat(Pbi);
    }
    if (J_j) {
      J_j->leftCols<3>() = -DA;
      J_j->rightCols<3>() = D * RbcT * SO3d::hat(Pbj);
    }
    if (J_bc || J_lambda) {
      const Eigen::Matrix<double, 2, 3> DARiRbc = DARi * T_bc.R.matrix();
      if (J_bc) {
        J_bc->leftCols<3>() = DARi - D * RbcT;
        J_bc->rightCols<3>() = -DARiRbc * SO3d::hat(Pci) + D * SO3d::hat(Pcj);
      }
      if (J_lambda) *J_lambda = -DARiRbc * mi_ / (inv_depth * inv_depth);
    }
    return r;
  }

  /// The anchor observation \f$ m_i \f$ (homogeneous, z = 1).
  [[nodiscard]] const Eigen::Vector3d& anchor() const noexcept { return mi_; }
  /// The observation \f$ m_j \f$.
  [[nodiscard]] const Eigen::Vector2d& observation() const noexcept { return mj_; }
  /// \f$ (f_u/\sigma, f_v/\sigma) \f$.
  [[nodiscard]] const Eigen::Vector2d& sqrt_information() const noexcept { return s_; }

 private:
  Eigen::Vector3d mi_;
  Eigen::Vector2d mj_;
  Eigen::Vector2d s_;
};

}  // namespace posefuse

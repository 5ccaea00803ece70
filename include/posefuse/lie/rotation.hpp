#pragma once
/// @file
/// Rotations in 3-D: ZYX Euler angles <-> rotation matrices with the
/// gimbal-lock handling of seed 001 eq 11-13, pose matrix -> position and
/// Euler angles, and matrix-valued shorthands for the SO(3) exponential /
/// logarithm / right Jacobian (implemented by lie/so3.hpp's SO3).
///
/// Convention (REP-103, seed 001 eq 11): a rotation matrix \f$ R \f$ maps
/// vectors from the body frame to the world frame, and
/// \f$ R = R_z(\mathrm{yaw})\,R_y(\mathrm{pitch})\,R_x(\mathrm{roll}) \f$
/// (intrinsic z-y'-x''). All angles are in radians; roll and yaw lie in
/// [-pi, pi], pitch in [-pi/2, pi/2].
///
/// Seed 001 eq 11 prints the same matrix with the symbols rho and theta
/// swapped between eq 11 (rho about z) and eq 13 (theta = atan2(p21, p11));
/// here the names are roll (about x), pitch (about y), yaw (about z).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <limits>
#include <numbers>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// ZYX Euler angles (rad): \f$ R = R_z(\mathrm{yaw}) R_y(\mathrm{pitch}) R_x(\mathrm{roll}) \f$.
template <std::floating_point T = double>
struct EulerZYX {
  T roll{0};   ///< about body x, rad
  T pitch{0};  ///< about body y, rad, in [-pi/2, pi/2]
  T yaw{0};    ///< about world z, rad
};

/// Position and ZYX Euler angles of a pose (seed 001 eq 11: x, y, z = p14, p24, p34).
template <std::floating_point T = double>
struct PositionEuler {
  Eigen::Matrix<T, 3, 1> position;  ///< translation of the pose, in the world frame (m)
  EulerZYX<T> euler;                ///< orientation of the body in the world frame
};

/// Default gimbal-lock tolerance on \f$ \sqrt{p_{11}^2 + p_{21}^2} = |\cos \mathrm{pitch}| \f$:
/// \f$ \sqrt{\epsilon} \f$ balances the generic branch's error
/// (\f$ \epsilon / \cos\mathrm{pitch} \f$) against the locked branch's
/// (\f$ \cos\mathrm{pitch} \f$), about 1.5e-8 for double and 3.5e-4 for float.
template <std::floating_point T>
[[nodiscard]] inline T gimbal_lock_tolerance() noexcept {
  return std::sqrt(std::numeric_limits<T>::epsilon());
}

/// The rotation matrix of ZYX Euler angles (seed 001 eq 11, upper-left 3x3).
/// @param[in] e roll, pitch, yaw in rad
/// @return \f$ R_z(\mathrm{yaw}) R_y(\mathrm{pitch}) R_x(\mathrm{roll}) \f$, body -> world
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 3, 3> rotation_from_euler_zyx(const EulerZYX<T>& e) {
  const T cr = std::cos(e.roll), sr = std::sin(e.roll);
  const T cp = std::cos(e.pitch), sp = std::sin(e.pitch);
  const T cy = std::cos(e.yaw), sy = std::sin(e.yaw);
  Eigen::Matrix<T, 3, 3> R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}

/// ZYX Euler angles of a rotation matrix with seed 001's gimbal-lock cases (eq 12-13).
///
/// \f$ \mathrm{pitch} = \mathrm{atan2}(-p_{31}, \sqrt{p_{11}^2 + p_{21}^2}) \f$ (eq 12).
/// When \f$ \sqrt{p_{11}^2 + p_{21}^2} \le \f$ `lock_tol` (pitch within about
/// `lock_tol` rad of ±90°) only yaw − roll (pitch = +90°) or yaw + roll
/// (pitch = −90°) is observable; roll is set to 0 and
/// \f$ \mathrm{yaw} = \mathrm{atan2}(p_{23}, p_{13}) \f$ (eq 13-b, pitch = +90°) or
/// \f$ \mathrm{yaw} = \mathrm{atan2}(-p_{23}, -p_{13}) \f$ (eq 13-a, pitch = −90°).
/// Otherwise \f$ \mathrm{yaw} = \mathrm{atan2}(p_{21}, p_{11}) \f$,
/// \f$ \mathrm{roll} = \mathrm{atan2}(p_{32}, p_{33}) \f$ (eq 13-c).
/// In every case `rotation_from_euler_zyx(result)` reproduces R to within
/// about `lock_tol` (exactly, up to rounding, away from the lock).
/// @param[in] R rotation matrix (body -> world), assumed orthonormal
/// @param[in] lock_tol threshold on |cos pitch| below which the lock branch is taken
/// @return roll, pitch, yaw in rad
template <class Derived>
[[nodiscard]] inline EulerZYX<typename Derived::Scalar> euler_zyx_from_rotation(
    const Eigen::MatrixBase<Derived>& R,
    typename Derived::Scalar lock_tol = gimbal_lock_tolerance<typename Derived::Scalar>()) {
  using T = typename Derived::Scalar;
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "posefuse: euler_zyx_from_rotation needs a 3x3 matrix");
  const T c = std::sqrt(R(0, 0) * R(0, 0) + R(1, 0) * R(1, 0));  // |cos pitch|
  EulerZYX<T> e;
  e.pitch = std::atan2(-R(2, 0), c);  // eq 12
  if (c <= lock_tol) {
    e.roll = T(0);
    if (R(2, 0) < T(0)) {  // pitch = +90 deg (p31 = -sin pitch = -1), eq 13-b
      e.yaw = std::atan2(R(1, 2), R(0, 2));
    } else {  // pitch = -90 deg, eq 13-a
      e.yaw = std::atan2(-R(1, 2), -R(0, 2));
    }
  } else {  // eq 13-c
    e.yaw = std::atan2(R(1, 0), R(0, 0));
    e.roll = std::atan2(R(2, 1), R(2, 2));
  }
  return e;
}

/// Position and ZYX Euler angles of a homogeneous pose matrix (seed 001 eq 11-13).
/// @param[in] P 4x4 pose of the body in the world frame; its last row is ignored
/// @param[in] lock_tol see euler_zyx_from_rotation
/// @return (p14, p24, p34) and the Euler angles of the upper-left 3x3 block
template <std::floating_point T>
[[nodiscard]] inline PositionEuler<T> position_and_euler(
    const Eigen::Matrix<T, 4, 4>& P, T lock_tol = gimbal_lock_tolerance<T>()) {
  return {P.template block<3, 1>(0, 3), euler_zyx_from_rotation(P.template block<3, 3>(0, 0), lock_tol)};
}

/// Position and ZYX Euler angles of an isometry (seed 001 eq 11-13).
template <std::floating_point T>
[[nodiscard]] inline PositionEuler<T> position_and_euler(
    const Eigen::Transform<T, 3, Eigen::Isometry>& T_w_b, T lock_tol = gimbal_lock_tolerance<T>()) {
  return position_and_euler<T>(T_w_b.matrix(), lock_tol);
}

/// The skew-symmetric (hat) matrix \f$ [v]_\times \f$ with \f$ [v]_\times w = v \times w \f$
/// (SO3::hat).
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 3, 3> skew(const Eigen::Matrix<T, 3, 1>& v) {
  return SO3<T>::hat(v);
}

/// SO(3) exponential (Rodrigues): the rotation matrix of the rotation by
/// |phi| rad about phi/|phi| (SO3::exp; accurate down to |phi| = 0).
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 3, 3> so3_exp(const Eigen::Matrix<T, 3, 1>& phi) {
  return SO3<T>::exp(phi).matrix();
}

/// SO(3) logarithm: the rotation vector (rad) of R, with |result| in [0, pi]
/// (SO3's matrix constructor, then SO3::log through the quaternion, accurate
/// at every angle including pi).
/// @param[in] R rotation matrix, orthonormal within SO3::kDefaultOrthonormalityTolerance
/// @throws posefuse::invalid_argument when R is not finite, not orthonormal or a reflection
template <class Derived>
[[nodiscard]] inline Eigen::Matrix<typename Derived::Scalar, 3, 1> so3_log(
    const Eigen::MatrixBase<Derived>& R) {
  using T = typename Derived::Scalar;
  static_assert(Derived::RowsAtCompileTime == 3 && Derived::ColsAtCompileTime == 3,
                "posefuse: so3_log needs a 3x3 matrix");
  return SO3<T>(typename SO3<T>::Matrix(R)).log();
}

/// Right Jacobian of SO(3): \f$ \exp(\phi + \delta) \approx \exp(\phi) \exp(J_r(\phi) \delta) \f$
/// (SO3::right_jacobian, Solà et al. 2018 eq 143).
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 3, 3> so3_right_jacobian(const Eigen::Matrix<T, 3, 1>& phi) {
  return SO3<T>::right_jacobian(phi);
}

}  // namespace posefuse

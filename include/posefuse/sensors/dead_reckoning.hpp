#pragma once
/// @file
/// Dead reckoning of a planar pose from body motion (seed 001 eq 10), with the
/// 3x3 pose covariance propagated from the per-step (Δs, Δθ) covariance that
/// the wheel-odometry stages attach (itself from per-wheel encoder noise).
/// The pose and its covariance are one Gaussian<PlanarPose<double>>
/// (core/gaussian.hpp), the library's pose-with-covariance type.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/sensors/sample_status.hpp>
#include <posefuse/sensors/wheel_odometry.hpp>

namespace posefuse {

/// The dead-reckoned pose at one sample's time: output of the odometry chain.
struct PlanarPoseEstimate {
  std::int64_t t_ns{0};  ///< stamp of the wheel sample (ns)
  /// Mean (x m, y m, θ rad in [-π, π), world frame) and covariance of
  /// (x, y, θ) (m², m·rad, rad²), as DeadReckoning propagated it.
  Gaussian<PlanarPose<double>> pose;
  SampleStatus status{SampleStatus::kOk};  ///< kNonFinite: motion ignored, pose held
};

/// Odometry-chain stage 3: integrates BodyMotion into a pose (the exact arc
/// by default, or eq 10 as printed) and propagates
/// \f$ P' = J_x P J_x^\top + J_u \Sigma_{\Delta s\Delta\theta} J_u^\top \f$.
/// Input BodyMotion, Output PlanarPoseEstimate.
class DeadReckoning {
 public:
  using Input = BodyMotion;
  using Output = PlanarPoseEstimate;

  /// @param[in] method kExactArc (default, exact for constant v and w over a
  ///            step) or kEuler (eq 10 as printed, first order)
  /// @param[in] start initial pose (world frame)
  /// @param[in] cov0 initial covariance (a 3x3 Eigen matrix or expression, symmetric PSD)
  /// @throws posefuse::invalid_argument if start or cov0 is not finite, or cov0 not symmetric PSD
  ///
  /// A template (Cov is deduced, Eigen::Matrix3d by default) only so that a
  /// file that merely includes this header does not compile the covariance
  /// check (an LDLT), which cost about 2 s per translation unit.
  template <class Cov = Eigen::Matrix3d>
    requires std::is_base_of_v<Eigen::MatrixBase<Cov>, Cov>
  explicit DeadReckoning(Integration method = Integration::kExactArc,
                         const PlanarPose<double>& start = {}, const Cov& cov0 = Cov::Zero())
      : method_(method) {
    reset(start, cov0);
  }

  /// Re-anchors the integration (e.g. onto a fused or re-initialised pose).
  /// @param[in] pose new pose (world frame); theta is wrapped
  /// @param[in] cov its covariance (a 3x3 Eigen matrix or expression, symmetric PSD)
  /// @throws posefuse::invalid_argument if pose or cov is not finite, or cov not
  ///         symmetric PSD (pose and covariance then untouched)
  template <class Derived>
  void reset(const PlanarPose<double>& pose, const Eigen::MatrixBase<Derived>& cov) {
    static_assert(int(Derived::RowsAtCompileTime) == 3 && int(Derived::ColsAtCompileTime) == 3,
                  "posefuse: DeadReckoning::reset needs a 3x3 covariance of (x, y, theta)");
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw invalid_argument("posefuse: DeadReckoning pose must be finite");
    const Eigen::Matrix3d c = cov;
    if (!is_positive_semidefinite(c))
      throw invalid_argument("posefuse: DeadReckoning covariance must be finite, symmetric and PSD");
    pose_ = {pose.x, pose.y, wrap_angle(pose.theta)};
    cov_ = c;
  }

  /// Integrates one step.
  /// @param[in] ds_m arc length, m
  /// @param[in] dtheta_rad heading change, rad
  /// @param[in] cov_u covariance of (ds_m, dtheta_rad)
  /// @return kOk, or kNonFinite (pose and covariance untouched)
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] SampleStatus step(double ds_m, double dtheta_rad, const Eigen::Matrix2d& cov_u) noexcept {
    if (!std::isfinite(ds_m) || !std::isfinite(dtheta_rad) || !cov_u.allFinite())
      return SampleStatus::kNonFinite;
    Eigen::Matrix3d J_x;
    Eigen::Matrix<double, 3, 2> J_u;
    pose_ = unicycle_step(pose_, ds_m, dtheta_rad, method_, &J_x, &J_u);
    cov_ = propagate_pose_covariance(cov_, J_x, J_u, cov_u);
    return SampleStatus::kOk;
  }

  /// Stage call: integrates `m.ds_m`, `m.dtheta_rad` with `m.cov`.
  /// @return pose and covariance after the step, stamped m.t_ns; status kNonFinite
  ///         if the motion was not finite (pose held), else m.status
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] PlanarPoseEstimate operator()(const BodyMotion& m) noexcept {
    const SampleStatus st = step(m.ds_m, m.dtheta_rad, m.cov);
    PlanarPoseEstimate out;
    out.t_ns = m.t_ns;
    out.pose.mean = pose_;
    out.pose.cov = cov_;
    out.status = st == SampleStatus::kOk ? m.status : st;
    return out;
  }

  /// Current pose.
  [[nodiscard]] const PlanarPose<double>& pose() const noexcept { return pose_; }
  /// Current covariance of (x, y, theta).
  [[nodiscard]] const Eigen::Matrix3d& covariance() const noexcept { return cov_; }
  /// Current pose and covariance as one Gaussian.
  [[nodiscard]] Gaussian<PlanarPose<double>> belief() const {
    Gaussian<PlanarPose<double>> g;
    g.mean = pose_;
    g.cov = cov_;
    return g;
  }
  /// The integrator in use.
  [[nodiscard]] Integration method() const noexcept { return method_; }

 private:
  Integration method_;
  PlanarPose<double> pose_;
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
};

}  // namespace posefuse

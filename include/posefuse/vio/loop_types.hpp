#pragma once
/// @file
/// The types of loop closure (vio/loop_closure.hpp): what became of a loop
/// candidate (LoopStatus, LoopResult), the options with their defaults
/// (LoopClosureOptions), and the drift correction \f$ T_{corrected,w} \f$
/// (DriftCorrection: a yaw about z and a translation) with the 4-DoF pose of
/// a rigid pose (pose_4dof).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include <posefuse/core/angles.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/graph/pose_graph_options.hpp>
#include <posefuse/graph/robust_loss.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/vio/pnp.hpp>

namespace posefuse {

/// What became of a loop candidate (vio/loop_closure.hpp's file comment).
enum class LoopStatus {
  kAccepted,               ///< verified; a loop edge was added and the graph re-optimised
  kUnknownQuery,           ///< no keyframe within the tolerance of the query stamp
  kUnknownMatch,           ///< no keyframe within the tolerance of the match stamp
  kTooCloseInTime,         ///< query and match of one sequence closer than min_gap_s
  kTooFewCorrespondences,  ///< fewer shared ids with world points than min_inliers
  kPnpFailed,              ///< PnP + RANSAC found no pose with min_inliers inliers
  kImplausible,            ///< relative pose beyond the yaw or distance bound
};

/// Name of a LoopStatus.
[[nodiscard]] constexpr const char* to_string(LoopStatus s) noexcept {
  switch (s) {
    case LoopStatus::kAccepted: return "accepted";
    case LoopStatus::kUnknownQuery: return "unknown query";
    case LoopStatus::kUnknownMatch: return "unknown match";
    case LoopStatus::kTooCloseInTime: return "too close in time";
    case LoopStatus::kTooFewCorrespondences: return "too few correspondences";
    case LoopStatus::kPnpFailed: return "PnP failed";
    case LoopStatus::kImplausible: return "implausible";
  }
  return "unknown";
}

/// Options of LoopClosure (every default stated).
struct LoopClosureOptions {
  double stamp_tolerance_s = 0.5;     ///< a candidate stamp names the nearest keyframe within this (s)
  double min_gap_s = 10.0;            ///< query and match of one sequence at least this far apart (s)
  int neighbour_keyframes = 2;        ///< world points also from this many keyframes on each side of the match
  int min_inliers = 25;               ///< PnP inliers needed (VINS-Mono: 25)
  /// PnP + RANSAC; its min_inliers is raised to min_inliers. Inlier
  /// threshold 10 px at 460 px focal, VINS-Mono's: the world points come
  /// from the odometry's window and carry centimetres of error.
  PnpOptions pnp = [] {
    PnpOptions p;
    p.inlier_threshold = 10.0 / 460.0;
    return p;
  }();
  double max_relative_yaw_deg = 30.0;     ///< |Δψ| of a loop at most (VINS-Mono: 30°)
  double max_relative_distance_m = 20.0;  ///< |Δp| of a loop at most (VINS-Mono: 20 m)
  double sequential_sigma_m = 0.1;    ///< σ of a sequential edge's translation, each axis (m)
  double sequential_sigma_yaw_rad = 0.01;  ///< σ of a sequential edge's yaw (rad)
  double loop_sigma_m = 0.1;          ///< σ of a loop edge's translation, each axis (m)
  double loop_sigma_yaw_rad = 0.02;   ///< σ of a loop edge's yaw (rad)
  RobustKernel loop_loss{RobustLoss::kCauchy, 1.0};  ///< robust loss of loop edges (whitened units)
  PoseGraphOptions graph;             ///< the pose-graph solver
};

/// A 4-DoF transform \f$ T_{corrected,w} \f$: yaw about z, then translation.
struct DriftCorrection {
  double yaw = 0.0;                             ///< δψ (rad)
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  ///< δt (m)

  /// \f$ R_z(\delta\psi) \f$.
  [[nodiscard]] Eigen::Matrix3d rotation() const {
    return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  }
  /// The corrected pose of an odometry pose.
  [[nodiscard]] SE3d apply(const SE3d& T) const {
    const Eigen::Matrix3d R = rotation();
    return SE3d(R * T.translation() + t, SO3d(Eigen::Quaterniond(R) * T.so3().quaternion()));
  }
  /// The corrected 4-DoF pose of a 4-DoF pose (roll and pitch unchanged).
  [[nodiscard]] Pose4Dof apply(const Pose4Dof& x) const {
    Pose4Dof y = x;
    y.p = rotation() * x.p + t;
    y.yaw = wrap_angle(x.yaw + yaw);
    return y;
  }
  /// The correction taking `from` to `to` (their yaw and position).
  [[nodiscard]] static DriftCorrection between(const Pose4Dof& from, const Pose4Dof& to) {
    DriftCorrection c;
    c.yaw = wrap_angle(to.yaw - from.yaw);
    c.t = to.p - c.rotation() * from.p;
    return c;
  }
};

/// The 4-DoF pose (position, ZYX yaw, pitch, roll) of a rigid pose.
[[nodiscard]] inline Pose4Dof pose_4dof(const SE3d& T) {
  const EulerZYX<double> e = euler_zyx_from_rotation(T.so3().matrix());
  return Pose4Dof{T.translation(), e.yaw, e.pitch, e.roll};
}

/// What became of one candidate.
struct LoopResult {
  LoopStatus status = LoopStatus::kUnknownQuery;  ///< see LoopStatus
  std::string reason;                    ///< a sentence whenever status != kAccepted
  std::int64_t query_id = -1, match_id = -1;     ///< the keyframes (node ids), when found
  std::int64_t t_query_ns = 0, t_match_ns = 0;   ///< their stamps
  int correspondences = 0;               ///< shared ids with a world point
  int inliers = 0;                       ///< PnP inliers
  double rms_residual = 0;               ///< PnP RMS residual (normalised units)
  SE3d T_match_query;                    ///< the verified relative pose (body frames)
  Edge4Dof edge;                         ///< the loop edge (when accepted)
  bool merged = false;                   ///< the query's group was moved into the match's
  PoseGraphSummary summary;              ///< the re-optimisation (when accepted)
  DriftCorrection before, after;         ///< the live sequence's correction around the update
};

/// LoopClosure::shared_id_match(): a keyframe and how many feature ids it shares.
struct SharedIdMatch {
  std::int64_t match_id = -1;  ///< node id
  int shared_ids = 0;          ///< feature ids in common
};

}  // namespace posefuse

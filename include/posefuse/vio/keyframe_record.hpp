#pragma once
/// @file
/// What the estimator hands on when a keyframe leaves its window: the
/// keyframe's pose, the camera–IMU extrinsic, and every feature it observed
/// (id, undistorted normalised coordinates and, where the window had
/// triangulated it, the world point). At that moment the odometry will not
/// move the keyframe again, so the record is what loop closure and maps keep
/// (vio/loop_closure.hpp, vio/vio_map.hpp).
///
/// Frames: \f$ T_{w,b} \f$ is the body (IMU) pose in the odometry's world
/// frame, \f$ T_{b,c} \f$ the camera pose in the body frame; a feature's
/// normalised coordinates are \f$ (x/z, y/z) \f$ in this keyframe's camera and
/// its point \f$ p_w \f$ is in the odometry's world frame.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include <posefuse/lie/se3.hpp>

namespace posefuse {

/// One feature seen by a keyframe.
struct KeyframeFeature {
  std::uint64_t id = 0;                           ///< feature id as given by the tracks
  Eigen::Vector2d m = Eigen::Vector2d::Zero();    ///< normalised coordinates in this keyframe
  bool has_point = false;                         ///< p_w is set (triangulated in the window)
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();  ///< world point (m), when has_point
};

/// A keyframe as it left the window (see the file comment).
struct KeyframeRecord {
  std::int64_t t_ns = 0;                  ///< image stamp (ns)
  SE3d T_w_b;                             ///< body pose in the odometry's world frame
  SE3d T_b_c;                             ///< camera pose in the body frame
  std::vector<KeyframeFeature> features;  ///< in increasing id order
};

}  // namespace posefuse

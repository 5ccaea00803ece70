#pragma once
/// @file
/// Road-plane projection of 3-D poses: keep two axes, drop the third.
///
/// Kept free of any file I/O so that core pipelines (e.g. the seed-000
/// planar EKF) can project poses without pulling in the readers.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// The plane a 3-D position is projected onto, named by the two kept axes
/// in order. KITTI's camera frame is x right, y down, z forward, so its road
/// plane is `kXZ`; a z-up world (EuRoC, ENU) uses `kXY`.
enum class Plane { kXZ, kXY, kYZ };

/// Parses "xz", "xy" or "yz" (lower case, as evo's `--project_to_plane`).
/// @param[in] name the plane's name
/// @return the plane
/// @throws posefuse::invalid_argument for any other text
[[nodiscard]] inline Plane parse_plane(std::string_view name) {
  if (name == "xz") return Plane::kXZ;
  if (name == "xy") return Plane::kXY;
  if (name == "yz") return Plane::kYZ;
  throw invalid_argument("unknown plane '" + std::string(name) + "' (expected xz, xy or yz)");
}

/// The name `parse_plane` accepts for `plane` ("xz", "xy" or "yz").
[[nodiscard]] constexpr std::string_view to_string(Plane plane) noexcept {
  switch (plane) {
    case Plane::kXZ: return "xz";
    case Plane::kXY: return "xy";
    case Plane::kYZ: return "yz";
  }
  return "?";
}

/// Projects a 3-D position onto `plane`: \f$ (p_x, p_z) \f$ for `kXZ`,
/// \f$ (p_x, p_y) \f$ for `kXY`, \f$ (p_y, p_z) \f$ for `kYZ`.
/// @param[in] p_world position in the world frame (m)
/// @param[in] plane the plane to keep
/// @return the two kept coordinates, in the plane's axis order (m)
[[nodiscard]] inline Eigen::Vector2d project_to_plane(const Eigen::Vector3d& p_world,
                                                      Plane plane) noexcept {
  switch (plane) {
    case Plane::kXY: return {p_world.x(), p_world.y()};
    case Plane::kYZ: return {p_world.y(), p_world.z()};
    case Plane::kXZ: break;
  }
  return {p_world.x(), p_world.z()};
}

/// Projects the position of the pose `T_world_body` onto `plane`
/// (orientation is dropped; see the Vector3d overload).
/// @param[in] T_world_body pose of the body in the world frame
/// @param[in] plane the plane to keep
/// @return the body position's two kept coordinates (m)
[[nodiscard]] inline Eigen::Vector2d project_to_plane(const Eigen::Isometry3d& T_world_body,
                                                      Plane plane) noexcept {
  return project_to_plane(Eigen::Vector3d(T_world_body.translation()), plane);
}

}  // namespace posefuse

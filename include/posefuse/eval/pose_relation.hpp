#pragma once
/// @file
/// What an APE or RPE measures of an error pose \f$ E \f$ (evo's
/// `--pose_relation`): the relation names, units and the error of a pose.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>

namespace posefuse {

/// Which part of an error pose \f$ E \f$ a metric measures (evo `--pose_relation`).
enum class PoseRelation {
  kTranslation,       ///< \f$ \lVert t(E) \rVert \f$ (m), evo `trans_part`
  kRotationAngleDeg,  ///< rotation angle of \f$ R(E) \f$ (deg), evo `angle_deg`
  kRotationAngleRad,  ///< rotation angle of \f$ R(E) \f$ (rad), evo `angle_rad`
  kFull,              ///< \f$ \lVert E - I_4 \rVert_F \f$ (unit-less), evo `full`
  kRotationPart,      ///< \f$ \lVert R(E) - I_3 \rVert_F \f$ (unit-less), evo `rot_part`
  /// APE: \f$ \lVert p_k - q_k \rVert \f$ (as kTranslation); RPE:
  /// \f$ |\,\lVert p_j - p_i \rVert - \lVert q_j - q_i \rVert\,| \f$,
  /// distances only, no orientation (m), evo `point_distance`
  kPointDistance,
  /// RPE only: the point-distance error in percent of the reference
  /// distance \f$ \lVert q_j - q_i \rVert \f$ (pairs whose reference
  /// distance is 0 are left out) (%), evo `point_distance_error_ratio`
  kPointDistanceErrorRatio,
};

/// Parses "trans" (or "trans_part"), "angle_deg", "angle_rad", "full",
/// "rot_part", "point_distance" or "point_distance_error_ratio".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] PoseRelation parse_pose_relation(std::string_view name) {
  if (name == "trans" || name == "trans_part") return PoseRelation::kTranslation;
  if (name == "angle_deg") return PoseRelation::kRotationAngleDeg;
  if (name == "angle_rad") return PoseRelation::kRotationAngleRad;
  if (name == "full") return PoseRelation::kFull;
  if (name == "rot_part") return PoseRelation::kRotationPart;
  if (name == "point_distance") return PoseRelation::kPointDistance;
  if (name == "point_distance_error_ratio") return PoseRelation::kPointDistanceErrorRatio;
  throw invalid_argument("unknown pose relation '" + std::string(name) +
                         "' (expected trans, angle_deg, angle_rad, full, rot_part, "
                         "point_distance or point_distance_error_ratio)");
}

/// The evo name of a pose relation ("trans_part", "angle_deg", ...).
[[nodiscard]] constexpr std::string_view to_string(PoseRelation relation) noexcept {
  switch (relation) {
    case PoseRelation::kTranslation: return "trans_part";
    case PoseRelation::kRotationAngleDeg: return "angle_deg";
    case PoseRelation::kRotationAngleRad: return "angle_rad";
    case PoseRelation::kFull: return "full";
    case PoseRelation::kRotationPart: return "rot_part";
    case PoseRelation::kPointDistance: return "point_distance";
    case PoseRelation::kPointDistanceErrorRatio: return "point_distance_error_ratio";
  }
  return "?";
}

/// Unit of the errors of a pose relation: "m", "deg", "rad", "%" or "" (unit-less).
[[nodiscard]] constexpr std::string_view unit_of(PoseRelation relation) noexcept {
  switch (relation) {
    case PoseRelation::kTranslation: return "m";
    case PoseRelation::kPointDistance: return "m";
    case PoseRelation::kRotationAngleDeg: return "deg";
    case PoseRelation::kRotationAngleRad: return "rad";
    case PoseRelation::kPointDistanceErrorRatio: return "%";
    case PoseRelation::kFull: return "";
    case PoseRelation::kRotationPart: return "";
  }
  return "";
}

/// Rotation angle \f$ \theta \in [0, \pi] \f$ of a rotation matrix, computed
/// as \f$ \mathrm{atan2}(\lVert \mathrm{vee}(R - R^\top) \rVert / 2,\ (\mathrm{tr} R - 1) / 2) \f$,
/// which stays accurate near 0 and \f$ \pi \f$ (evo: the norm of scipy's
/// `Rotation.from_matrix(R).as_rotvec()`).
/// @param[in] R a rotation matrix
/// @return the angle (rad)
template <class Lazy = void>
[[nodiscard]] double rotation_angle(const Eigen::Matrix3d& R) noexcept {
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(0.5 * v.norm(), 0.5 * (R.trace() - 1.0));
}

/// The error of an error pose \f$ E \f$ under a pose relation (see
/// PoseRelation; the point-distance relations, which compare distances
/// rather than poses, give \f$ \lVert t(E) \rVert \f$ here).
template <class Lazy = void>
[[nodiscard]] double pose_error(const Eigen::Isometry3d& pose, PoseRelation relation) noexcept {
  // Dependent spelling: compiled only where called (core/lazy.hpp).
  const detail::dependent_t<Eigen::Isometry3d, Lazy>& E = pose;
  switch (relation) {
    case PoseRelation::kTranslation: return E.translation().norm();
    case PoseRelation::kRotationAngleDeg:
      return rotation_angle(E.linear()) * 180.0 / std::numbers::pi;
    case PoseRelation::kRotationAngleRad: return rotation_angle(E.linear());
    case PoseRelation::kRotationPart: return (E.linear() - detail::dependent_t<Eigen::Matrix3d, Lazy>::Identity()).norm();
    case PoseRelation::kPointDistance:
    case PoseRelation::kPointDistanceErrorRatio: return E.translation().norm();
    case PoseRelation::kFull: break;
  }
  return (E.matrix() - detail::dependent_t<Eigen::Matrix4d, Lazy>::Identity()).norm();
}

}  // namespace posefuse

#pragma once
/// @file
/// Feature tracks as the visual-inertial estimator takes them: the types and
/// the csv format are io/feature_tracks.hpp (FeatureObservation, TrackFrame,
/// FeatureTracks, read/write); this header adds reading against a camera
/// (pixels outside its image refused) and the normalised coordinates of an
/// observation.

#include <Eigen/Core>
#include <filesystem>

#include <posefuse/io/feature_tracks.hpp>
#include <posefuse/vio/camera.hpp>

namespace posefuse {

/// Reads a feature-track csv and refuses pixels outside `camera`'s image.
/// @throws posefuse::io_error (file:line) as read_feature_tracks
template <class Lazy = void>
[[nodiscard]] FeatureTracks read_feature_tracks(const std::filesystem::path& file,
                                                const PinholeRadtan& camera) {
  return read_feature_tracks(file, FeatureTrackReadOptions{camera.width, camera.height});
}

/// Normalised coordinates (x/z, y/z) of an observation (camera.undistort;
/// NaN when the distortion cannot be inverted there).
[[nodiscard]] inline Eigen::Vector2d normalised(const PinholeRadtan& camera,
                                                const FeatureObservation& o) noexcept {
  return camera.undistort(o.uv);
}

}  // namespace posefuse

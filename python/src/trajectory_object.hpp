// posefuse.Trajectory as held by the Python module: the C++ trajectory (and,
// for a TUM file with covariance columns, its covariances) plus what the
// evaluation needs to know about where it came from, so that ape/rpe apply
// the rules of evaluate_trajectory (frame by frame for two KITTI files
// without times, association by stamps otherwise) and write the same JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <apps/evaluation.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/read_options.hpp>

namespace posefuse::python {

struct TrajectoryObject {
  apps::LoadedTrajectory loaded;
  std::string source;                        ///< the path as given; empty when built from arrays
  std::optional<posefuse::Format> format;    ///< the file's format; nothing when built from arrays
  bool format_detected = false;              ///< told from the content (format="auto")
  bool stamped_by_times = false;             ///< KITTI stamped by a times file
  /// The policy the file was read with (kFirst for arrays, whose stamps are
  /// strictly increasing).
  posefuse::DuplicateStamps duplicates = posefuse::DuplicateStamps::kFirst;
  std::vector<std::string> warnings;         ///< what the reader reported (repeated stamps)

  [[nodiscard]] const posefuse::Trajectory& trajectory() const noexcept { return loaded.trajectory; }
  /// The name errors and JSON use: the path, or "(arrays)".
  [[nodiscard]] std::string name() const { return source.empty() ? "(arrays)" : source; }
};

}  // namespace posefuse::python

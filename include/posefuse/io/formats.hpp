#pragma once
/// @file
/// One entry point for the trajectory file formats (KITTI, TUM).

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>
#include <posefuse/io/kitti.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/tum.hpp>

namespace posefuse {

/// Trajectory file formats (as evo's `evo_ape kitti|tum`).
enum class Format {
  kKitti,  ///< 12 numbers a line, row-major 3x4 [R|t]; stamps from an optional times.txt
  kTum,    ///< `t tx ty tz qx qy qz qw`
};

/// Parses "kitti" or "tum".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] Format parse_format(std::string_view name) {
  if (name == "kitti") return Format::kKitti;
  if (name == "tum") return Format::kTum;
  throw invalid_argument("unknown trajectory format '" + std::string(name) +
                         "' (expected kitti or tum)");
}

/// The name `parse_format` accepts for `format`.
[[nodiscard]] constexpr std::string_view to_string(Format format) noexcept {
  return format == Format::kKitti ? "kitti" : "tum";
}

/// Reads a trajectory in the given format (see `read_kitti`, `read_tum`).
/// @param[in] file the trajectory file
/// @param[in] format its format
/// @param[in] times_file KITTI only: optional `times.txt`
/// @param[in] options rotation / quaternion tolerances
/// @return the trajectory
/// @throws posefuse::invalid_argument when a times file is given for TUM
/// @throws posefuse::io_error (file:line) for any unreadable or malformed input
template <class Lazy = void>
[[nodiscard]] Trajectory read_trajectory(
    const std::filesystem::path& file, Format format,
    const std::optional<std::filesystem::path>& times_file = std::nullopt,
    const ReadOptions& options = {}) {
  if (format == Format::kTum) {
    if (times_file) throw invalid_argument("a times file only applies to the KITTI format");
    return read_tum(file, options);
  }
  return read_kitti(file, times_file, options);
}

/// Writes a trajectory in the given format; for KITTI only the poses (use
/// `write_kitti_times` for the stamps).
/// @throws posefuse::invalid_argument when `traj` fails `validate()`
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_trajectory(const std::filesystem::path& file, const Trajectory& traj,
                      Format format) {
  if (format == Format::kTum) {
    write_tum(file, traj);
  } else {
    write_kitti(file, traj);
  }
}

}  // namespace posefuse

#pragma once
/// @file
/// One entry point for the trajectory file formats (KITTI, TUM, EuRoC), and
/// their detection by content.

#include <filesystem>
#include <optional>
#include <vector>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/kitti.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/tum.hpp>

namespace posefuse {

/// Trajectory file formats (as evo's `evo_ape kitti|tum|euroc`).
enum class Format {
  kKitti,  ///< 12 numbers a line, row-major 3x4 [R|t]; stamps from an optional times.txt
  kTum,    ///< `t tx ty tz qx qy qz qw`
  kEuroc,  ///< EuRoC state ground truth csv: `t[ns], p xyz, q wxyz[, v, b_w, b_a]` (io/euroc.hpp)
};

/// Parses "kitti", "tum" or "euroc".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] Format parse_format(std::string_view name) {
  if (name == "kitti") return Format::kKitti;
  if (name == "tum") return Format::kTum;
  if (name == "euroc") return Format::kEuroc;
  throw invalid_argument("unknown trajectory format '" + std::string(name) +
                         "' (expected kitti, tum or euroc)");
}

/// The name `parse_format` accepts for `format`.
[[nodiscard]] constexpr std::string_view to_string(Format format) noexcept {
  switch (format) {
    case Format::kKitti: return "kitti";
    case Format::kTum: return "tum";
    case Format::kEuroc: return "euroc";
  }
  return "?";
}

/// Tells a trajectory file's format from its first two data lines (lines
/// neither blank nor starting with '#'; EuRoC's `#timestamp,...` header is
/// such a comment):
///
/// | first data line | format |
/// |---|---|
/// | 12 whitespace-separated fields | KITTI |
/// | 8 whitespace-separated fields (14 or 29: with covariance, see `read_tum_with_covariance`) | TUM |
/// | 8 or 17 comma-separated fields, the first a decimal integer (ns) | EuRoC |
///
/// The second data line, when there is one, must have the same shape. Only
/// the shape is looked at; the reader then checks every value.
/// @param[in] file the trajectory file
/// @return the format
/// @throws posefuse::io_error naming the file (and line) when it cannot be
///         read, has no data line, or its shape fits none of the formats or
///         more than one (e.g. commas and a non-integer first field, or two
///         lines of different shapes): the format is then given explicitly
template <class Lazy = void>
[[nodiscard]] Format detect_format(const std::filesystem::path& file) {
  detail::LineReader reader(file);
  std::string line;
  std::optional<Format> found;
  std::size_t first_line = 0, first_fields = 0;
  const std::string advice = " (give the format explicitly, e.g. --format)";
  for (int seen = 0; seen < 2 && reader.next(line);) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    ++seen;
    const std::size_t n = reader.line_no();
    Format format;
    std::size_t fields = 0;
    if (line.find(',') != std::string::npos) {
      const std::vector<std::string_view> f = detail::split_csv(line);
      fields = f.size();
      const bool integer_stamp = !f[0].empty() && f[0].find_first_not_of("0123456789") == std::string_view::npos;
      if ((fields != 8 && fields != 17) || !integer_stamp) {
        throw io_error(file, n,
                       "cannot tell the format: " + std::to_string(fields) +
                           " comma-separated fields" + (integer_stamp ? "" : " starting with '" + std::string(f[0]) + "'") +
                           "; EuRoC has 8 or 17 with an integer nanosecond stamp first" + advice);
      }
      format = Format::kEuroc;
    } else {
      fields = detail::traj_io::split_whitespace(line).size();
      if (fields == 12) {
        format = Format::kKitti;
      } else if (fields == 8 || fields == 14 || fields == 29) {
        format = Format::kTum;
      } else {
        throw io_error(file, n,
                       "cannot tell the format: " + std::to_string(fields) +
                           " whitespace-separated fields; KITTI has 12, TUM 8 (14 or 29 with a "
                           "covariance)" + advice);
      }
    }
    if (!found) {
      found = format;
      first_line = n;
      first_fields = fields;
    } else if (*found != format || fields != first_fields) {
      throw io_error(file, n,
                     "cannot tell the format: this line looks like " + std::string(to_string(format)) +
                         " (" + std::to_string(fields) + " fields) but line " + std::to_string(first_line) +
                         " like " + std::string(to_string(*found)) + " (" + std::to_string(first_fields) +
                         " fields)" + advice);
    }
  }
  if (!found) throw io_error(file, "no poses (the file has no data lines)");
  return *found;
}

/// Reads a trajectory in the given format (see `read_kitti`, `read_tum`).
/// @param[in] file the trajectory file
/// @param[in] format its format
/// @param[in] times_file KITTI only: optional `times.txt`
/// @param[in] options rotation / quaternion tolerances
/// @return the trajectory
/// @param[out] report optional: poses dropped for a repeated stamp
/// @throws posefuse::invalid_argument when a times file is given for TUM or EuRoC
/// @throws posefuse::io_error (file:line) for any unreadable or malformed input
template <class Lazy = void>
[[nodiscard]] Trajectory read_trajectory(
    const std::filesystem::path& file, Format format,
    const std::optional<std::filesystem::path>& times_file = std::nullopt,
    const ReadOptions& options = {}, ReadReport* report = nullptr) {
  if (format != Format::kKitti && times_file)
    throw invalid_argument("a times file only applies to the KITTI format");
  switch (format) {
    case Format::kTum: return read_tum(file, options, report);
    case Format::kEuroc: return read_euroc_groundtruth(file, options, report).trajectory;
    case Format::kKitti: break;
  }
  return read_kitti(file, times_file, options, report);
}

/// Writes a trajectory in the given format; for KITTI only the poses (use
/// `write_kitti_times` for the stamps).
/// @throws posefuse::invalid_argument when `traj` fails `validate()` or the
///         format is EuRoC (which posefuse reads but does not write)
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_trajectory(const std::filesystem::path& file, const Trajectory& traj,
                      Format format) {
  if (format == Format::kEuroc)
    throw invalid_argument("write_trajectory: EuRoC files are read, not written (use tum)");
  if (format == Format::kTum) {
    write_tum(file, traj);
  } else {
    write_kitti(file, traj);
  }
}

}  // namespace posefuse

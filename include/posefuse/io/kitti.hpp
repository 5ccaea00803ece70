#pragma once
/// @file
/// KITTI odometry pose files (12 numbers a line) and their `times.txt`.
///
/// A KITTI pose line is the row-major 3x4 matrix \f$ [R \mid t] \f$ of
/// \f$ T_{world,cam} \f$: `r11 r12 r13 tx r21 r22 r23 ty r31 r32 r33 tz`
/// (Geiger et al., CVPR 2012, odometry devkit). `times.txt` holds one stamp
/// (s) a line. Blank lines and lines starting with '#' are skipped; line
/// numbers in errors are the file's physical, 1-based lines. A file without
/// any data line is an error, so that an empty input is reported with its
/// name rather than as an empty trajectory.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

namespace detail::traj_io {

/// Values read from a file together with the physical line of each.
template <class T>
struct NumberedRows {
  std::vector<T> values;
  std::vector<std::size_t> lines;
};

template <class Lazy = void>
NumberedRows<Eigen::Isometry3d> read_kitti_rows(const std::filesystem::path& file,
                                                const ReadOptions& options) {
  LineReader reader(file);
  NumberedRows<Eigen::Isometry3d> rows;
  std::string line;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const std::vector<double> v =
        parse_row(line, 12, "KITTI pose: row-major 3x4 [R|t]", file, reader.line_no());
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = checked_rotation(R, options.rotation_tolerance, file, reader.line_no());
    T.translation() = Eigen::Vector3d(v[3], v[7], v[11]);
    check_position(T.translation(), file, reader.line_no());
    rows.values.push_back(T);
    rows.lines.push_back(reader.line_no());
  }
  if (rows.values.empty()) throw io_error(file, "no poses (the file has no data lines)");
  return rows;
}

/// The stamps of a times file, with the line of each. A repeated stamp
/// follows `policy`; `kept` receives, for each stamp kept, the index of its
/// data row in the file (0-based, counting data lines only), so that a
/// caller can drop the matching poses; `all_lines` the line of every data
/// row, kept or not.
template <class Lazy = void>
NumberedRows<double> read_stamp_rows(const std::filesystem::path& file,
                                     DuplicateStamps policy = DuplicateStamps::kError,
                                     ReadReport* report = nullptr,
                                     std::vector<std::size_t>* kept = nullptr,
                                     std::vector<std::size_t>* all_lines = nullptr) {
  LineReader reader(file);
  NumberedRows<double> rows;
  std::string line;
  std::size_t row = 0;
  std::size_t previous_line = 0;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const double t = parse_row(line, 1, "one timestamp in seconds", file, reader.line_no())[0];
    if (all_lines != nullptr) all_lines->push_back(reader.line_no());
    const StampAction action =
        rows.values.empty()
            ? StampAction::kAppend
            : next_stamp_action(t, rows.values.back(), previous_line, policy, report, file,
                                reader.line_no());
    if (action == StampAction::kAppend) {
      rows.values.push_back(t);
      rows.lines.push_back(reader.line_no());
      if (kept != nullptr) kept->push_back(row);
    } else if (action == StampAction::kReplaceLast) {
      rows.lines.back() = reader.line_no();
      if (kept != nullptr) kept->back() = row;
    }
    previous_line = reader.line_no();
    ++row;
  }
  if (rows.values.empty()) throw io_error(file, "no timestamps (the file has no data lines)");
  return rows;
}

}  // namespace detail::traj_io

/// Reads a KITTI `times.txt`: one timestamp (s) a line, strictly increasing.
/// @param[in] file path of the times file
/// @return the stamps in file order
/// @throws posefuse::io_error (file:line) when the file cannot be opened, a
///         line has not exactly one number, a number is unparsable or not
///         finite, a stamp is not greater than the previous one, a read
///         fails or a line is longer than kMaxLineBytes; and (file only)
///         when the path cannot be accessed or the file has no stamp ("no
///         timestamps")
template <class Lazy = void>
[[nodiscard]] std::vector<double> read_kitti_times(const std::filesystem::path& file) {
  return detail::traj_io::read_stamp_rows(file, DuplicateStamps::kError).values;
}

/// Reads a KITTI pose file, optionally with its `times.txt`.
///
/// Rotations are checked against `options.rotation_tolerance` and
/// re-orthonormalised (see ReadOptions). Without `times`, the stamps are
/// the frame indices 0, 1, 2, ... (s), which is also what evo assumes when
/// it treats a KITTI file as a path without timestamps. With `times`, equal
/// consecutive stamps follow `options.duplicates` and the poses of dropped
/// stamps are dropped with them (counted in `report`).
/// @param[in] poses_file path of the pose file
/// @param[in] times_file optional path of the matching `times.txt`
/// @param[in] options rotation tolerance, duplicate-stamp policy
/// @param[out] report optional: poses dropped for a repeated stamp
/// @return the trajectory \f$ T_{world,cam} \f$
/// @throws posefuse::io_error (file:line) when a file cannot be opened, a
///         line has not 12 numbers (the message gives the count found), a
///         number is unparsable or not finite, a rotation is not
///         orthonormal within tolerance or is a reflection, a stamp is
///         smaller than the previous (or equal, under DuplicateStamps::kError),
///         or the times file has a different number of entries
///         (the error names the first line without a partner), a read fails
///         or a line is longer than kMaxLineBytes; and (file only) when a
///         path cannot be accessed or a file has no pose ("no poses") or no
///         stamp ("no timestamps")
template <class Lazy = void>
[[nodiscard]] Trajectory read_kitti(
    const std::filesystem::path& poses_file,
    const std::optional<std::filesystem::path>& times_file = std::nullopt,
    const ReadOptions& options = {}, ReadReport* report = nullptr) {
  detail::traj_io::NumberedRows<Eigen::Isometry3d> rows =
      detail::traj_io::read_kitti_rows(poses_file, options);
  Trajectory traj;
  if (!times_file) {
    traj.poses = std::move(rows.values);
    traj.t_s.resize(traj.poses.size());
    for (std::size_t k = 0; k < traj.t_s.size(); ++k) traj.t_s[k] = static_cast<double>(k);
    return traj;
  }
  ReadReport times_report;
  std::vector<std::size_t> kept, all_lines;
  detail::traj_io::NumberedRows<double> stamps = detail::traj_io::read_stamp_rows(
      *times_file, options.duplicates, &times_report, &kept, &all_lines);
  const std::size_t n_poses = rows.values.size();
  // Counts are compared before duplicates are dropped: line k of the times
  // file goes with data line k of the pose file.
  const std::size_t n_stamps = all_lines.size();
  if (n_stamps > n_poses) {
    // The pose file is the short one (a times file is often shared by the
    // ground truth, the estimate and a control): it is named.
    throw io_error(poses_file, "pose file has " + std::to_string(n_poses) + " poses but " + times_file->string() +
                                   " has " + std::to_string(n_stamps) + " timestamps (line " +
                                   std::to_string(all_lines[n_poses]) +
                                   " of the times file is the first without a pose): is the pose file cut short?");
  }
  if (n_stamps < n_poses) {
    throw io_error(poses_file, rows.lines[n_stamps],
                   "pose file has " + std::to_string(n_poses) + " poses but " +
                       times_file->string() + " has " + std::to_string(n_stamps) +
                       " timestamps; this is the first pose without a timestamp");
  }
  traj.t_s = std::move(stamps.values);
  traj.poses.reserve(kept.size());
  for (const std::size_t k : kept) traj.poses.push_back(rows.values[k]);
  if (report != nullptr) {
    report->duplicates_dropped += times_report.duplicates_dropped;
    report->duplicates_kept += times_report.duplicates_kept;
    if (report->first_duplicate_line == 0) report->first_duplicate_line = times_report.first_duplicate_line;
  }
  return traj;
}

/// Writes the poses of `traj` as a KITTI pose file (stamps are not written;
/// see `write_kitti_times`). Numbers are the shortest text that reads back
/// to the same double, so `read_kitti(write_kitti(traj))` is bit-exact.
/// @param[in] file output path (overwritten)
/// @param[in] traj the trajectory
/// @throws posefuse::invalid_argument when `traj` fails `validate()`
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_kitti(const std::filesystem::path& file, const Trajectory& traj) {
  traj.validate();
  std::ofstream out = detail::traj_io::open_output(file);
  for (const Eigen::Isometry3d& T : traj.poses) {
    const Eigen::Matrix<double, 3, 4> M = T.matrix().topRows<3>();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        if (r + c > 0) out << ' ';
        out << detail::traj_io::format_number(M(r, c));
      }
    }
    out << '\n';
  }
  detail::traj_io::finish_output(out, file);
}

/// Writes the stamps of `traj` as a KITTI `times.txt` (one stamp a line,
/// shortest round-trip text).
/// @throws posefuse::invalid_argument when `traj` fails `validate()`
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_kitti_times(const std::filesystem::path& file, const Trajectory& traj) {
  traj.validate();
  std::ofstream out = detail::traj_io::open_output(file);
  for (const double t : traj.t_s) out << detail::traj_io::format_number(t) << '\n';
  detail::traj_io::finish_output(out, file);
}

}  // namespace posefuse

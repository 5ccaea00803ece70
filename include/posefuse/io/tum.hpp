#pragma once
/// @file
/// TUM RGB-D trajectory files: `t tx ty tz qx qy qz qw` a line.
///
/// Format of the TUM RGB-D benchmark (Sturm et al., IROS 2012): timestamp
/// (s), position of the body in the world (m) and the Hamilton unit
/// quaternion of \f$ R_{world,body} \f$ with the scalar **last**. Fields are
/// separated by whitespace; blank lines and lines starting with '#' are
/// skipped; stamps must increase strictly. A file without any pose is an
/// error (named by its path), not an empty trajectory.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// Reads a TUM trajectory file.
///
/// Quaternions within `options.quaternion_norm_tolerance` of unit norm are
/// normalised (as evo does for every non-zero quaternion). Equal consecutive
/// stamps follow `options.duplicates`; what was dropped is counted in `report`.
/// @param[in] file path of the TUM file
/// @param[in] options quaternion norm tolerance, duplicate-stamp policy
/// @param[out] report optional: poses dropped for a repeated stamp
/// @return the trajectory \f$ T_{world,body}(t) \f$, stamps strictly increasing
/// @throws posefuse::io_error (file:line) when the file cannot be opened, a
///         line has not 8 numbers (the message gives the count found), a
///         number is unparsable or not finite, a quaternion is zero or too
///         far from unit norm, a stamp is smaller than the previous (or
///         equal, under DuplicateStamps::kError), a read fails or a line is
///         longer than kMaxLineBytes; and (file only) when the path cannot
///         be accessed or the file has no pose ("no poses")
template <class Lazy = void>
[[nodiscard]] Trajectory read_tum(const std::filesystem::path& file,
                                  const ReadOptions& options = {},
                                  ReadReport* report = nullptr) {
  detail::LineReader reader(file);
  Trajectory traj;
  std::size_t previous_line = 0;
  std::string line;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<double> v =
        detail::traj_io::parse_row(line, 8, "TUM: t tx ty tz qx qy qz qw", file, n);
    // Eigen's constructor takes (w, x, y, z); the file stores x y z w.
    const Eigen::Quaterniond q = detail::traj_io::checked_quaternion(
        Eigen::Quaterniond(v[7], v[4], v[5], v[6]), options.quaternion_norm_tolerance, file, n);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    const detail::traj_io::StampAction action =
        traj.t_s.empty() ? detail::traj_io::StampAction::kAppend
                         : detail::traj_io::next_stamp_action(v[0], traj.t_s.back(), previous_line,
                                                              options.duplicates, report, file, n);
    if (action == detail::traj_io::StampAction::kAppend) {
      traj.push_back(v[0], T);
    } else if (action == detail::traj_io::StampAction::kReplaceLast) {
      traj.poses.back() = T;
    }
    previous_line = n;
  }
  if (traj.empty()) throw io_error(file, "no poses (the file has no data lines)");
  return traj;
}

/// Writes `traj` as a TUM file. Stamps and positions are written as the
/// shortest text that reads back to the same double (bit-exact round trip);
/// the rotation goes through a unit quaternion (w >= 0), so it reads back
/// equal to about 1e-16, not bit for bit.
/// @param[in] file output path (overwritten)
/// @param[in] traj the trajectory
/// @throws posefuse::invalid_argument when `traj` fails `validate()`
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_tum(const std::filesystem::path& file, const Trajectory& traj) {
  traj.validate();
  std::ofstream out = detail::traj_io::open_output(file);
  out << "# timestamp tx ty tz qx qy qz qw\n";
  for (std::size_t k = 0; k < traj.size(); ++k) {
    const Eigen::Isometry3d& T = traj.poses[k];
    Eigen::Quaterniond q(Eigen::Matrix3d(T.linear()));
    q.normalize();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d p = T.translation();
    out << detail::traj_io::format_number(traj.t_s[k]);
    for (const double x : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) {
      out << ' ' << detail::traj_io::format_number(x);
    }
    out << '\n';
  }
  detail::traj_io::finish_output(out, file);
}

}  // namespace posefuse

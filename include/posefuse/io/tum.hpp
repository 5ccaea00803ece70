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
#include <posefuse/core/gaussian.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// A TUM trajectory whose lines may carry a covariance per pose (see
/// `read_tum_with_covariance`).
struct TumWithCovariance {
  Trajectory trajectory;  ///< the poses, as `read_tum` reads them
  /// 0: no covariance columns; 3: a position covariance per pose; 6: a pose covariance.
  int covariance_dim = 0;
  /// Per pose, a covariance over \f$ [\delta p;\ \delta\theta] \f$: \f$ \delta p \f$
  /// the position error in the world frame (m), \f$ \delta\theta \f$ the
  /// rotation error in the body frame, \f$ R_{true} = R\,\mathrm{Exp}(\delta\theta) \f$
  /// (rad; the right perturbation of lie/lie.hpp). With `covariance_dim`
  /// 3 only the top-left block is set, the rest is zero.
  std::vector<Eigen::Matrix<double, 6, 6>> covariance;
};

namespace detail::traj_io {

template <class Lazy = void>
TumWithCovariance read_tum_rows(const std::filesystem::path& file, const ReadOptions& options,
                                ReadReport* report, bool allow_covariance) {
  detail::LineReader reader(file);
  TumWithCovariance out;
  Trajectory& traj = out.trajectory;
  std::size_t previous_line = 0, columns = 0;
  std::string line;
  while (reader.next(line)) {
    if (is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    if (columns == 0) {
      columns = 8;
      if (allow_covariance) {
        const std::size_t found = split_whitespace(line).size();
        if (found == 14 || found == 29) columns = found;
      }
    }
    const std::vector<double> v = parse_row(
        line, columns,
        columns == 8    ? "TUM: t tx ty tz qx qy qz qw"
        : columns == 14 ? "TUM + position covariance: t tx ty tz qx qy qz qw and 6 upper-triangle "
                          "entries, as the first data line"
                        : "TUM + pose covariance: t tx ty tz qx qy qz qw and 21 upper-triangle "
                          "entries, as the first data line",
        file, n);
    // Eigen's constructor takes (w, x, y, z); the file stores x y z w.
    const Eigen::Quaterniond q = checked_quaternion(
        Eigen::Quaterniond(v[7], v[4], v[5], v[6]), options.quaternion_norm_tolerance, file, n);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    check_position(T.translation(), file, n);
    Eigen::Matrix<double, 6, 6> C = Eigen::Matrix<double, 6, 6>::Zero();
    if (columns > 8) {
      const int dim = columns == 14 ? 3 : 6;
      std::size_t c = 8;
      for (int i = 0; i < dim; ++i)
        for (int j = i; j < dim; ++j) C(i, j) = C(j, i) = v[c++];
      const bool definite = dim == 3 ? is_positive_definite(C.topLeftCorner<3, 3>().eval())
                                     : is_positive_definite(C);
      if (!definite) throw io_error(file, n, "covariance is not positive definite");
    }
    const StampAction action =
        traj.t_s.empty() ? StampAction::kAppend
                         : next_stamp_action(v[0], traj.t_s.back(), previous_line,
                                             options.duplicates, report, file, n);
    if (action == StampAction::kAppend) {
      traj.push_back(v[0], T);
      if (columns > 8) out.covariance.push_back(C);
    } else if (action == StampAction::kReplaceLast) {
      traj.poses.back() = T;
      if (columns > 8) out.covariance.back() = C;
    }
    previous_line = n;
  }
  if (traj.empty()) throw io_error(file, "no poses (the file has no data lines)");
  out.covariance_dim = columns == 14 ? 3 : columns == 29 ? 6 : 0;
  return out;
}

}  // namespace detail::traj_io

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
  return detail::traj_io::read_tum_rows(file, options, report, false).trajectory;
}

/// Reads a TUM file whose lines may carry a covariance after the pose, the
/// same number of columns on every line (set by the first data line):
/// 8 (no covariance), 14 (`t tx ty tz qx qy qz qw` then the upper triangle
/// of the 3x3 position covariance, row by row: xx xy xz yy yz zz; m²) or 29
/// (then the upper triangle of the 6x6 covariance of
/// \f$ [\delta p;\ \delta\theta] \f$, row by row, 21 numbers; see
/// TumWithCovariance for the frames). This is posefuse's format for
/// estimates with uncertainty (e.g. a filter's output), used by
/// `evaluate_trajectory` for NEES.
/// @throws posefuse::io_error (file:line) as `read_tum`, and when a line's
///         column count differs from the first data line's or its
///         covariance is not positive definite
template <class Lazy = void>
[[nodiscard]] TumWithCovariance read_tum_with_covariance(const std::filesystem::path& file,
                                                         const ReadOptions& options = {},
                                                         ReadReport* report = nullptr) {
  return detail::traj_io::read_tum_rows(file, options, report, true);
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

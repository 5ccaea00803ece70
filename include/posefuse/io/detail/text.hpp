#pragma once
/// @file
/// Line-oriented text parsing shared by the trajectory readers and writers
/// (not API): tokenising, strict number parsing and round-trip formatting,
/// and the rotation / quaternion checks, all reporting posefuse::io_error
/// with the file and 1-based line. Lines are read by detail::LineReader
/// (line_reader.hpp: length cap, read errors).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/io/detail/message_number.hpp>

/// Internals of the trajectory readers/writers; nested so that other io
/// headers (e.g. robot_log.hpp) can keep their own detail helpers.
namespace posefuse::detail::traj_io {

/// Opens `file` for writing (truncating it), locale-free (see open_output_file).
/// @throws posefuse::io_error when it cannot be opened
template <class Lazy = void>
[[nodiscard]] std::ofstream open_output(const std::filesystem::path& file) {
  return open_output_file(file);
}

/// Flushes `out` and reports a failed write.
/// @throws posefuse::io_error when any write to `file` failed
template <class Lazy = void>
void finish_output(std::ofstream& out, const std::filesystem::path& file) {
  out.flush();
  if (!out) throw io_error(file, "write failed");
}

[[nodiscard]] constexpr bool is_space(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r' || c == '\n';
}

/// True for a line that is empty, all whitespace, or a '#' comment.
template <class Lazy = void>
[[nodiscard]] bool is_blank_or_comment(std::string_view line) noexcept {
  for (const char c : line) {
    if (is_space(c)) continue;
    return c == '#';
  }
  return true;
}

/// Splits a line at runs of whitespace; the views point into `line`.
template <class Lazy = void>
[[nodiscard]] std::vector<std::string_view> split_whitespace(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

/// Parses a whole token as a finite double (decimal or scientific; a
/// leading '+' is accepted).
/// @throws posefuse::io_error naming file, line and 1-based column
template <class Lazy = void>
[[nodiscard]] double parse_number(std::string_view token, const std::filesystem::path& file,
                                  std::size_t line, std::size_t column) {
  std::string_view digits = token;
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') {
    digits.remove_prefix(1);
  }
  double value = 0.0;
  const char* const end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, value);
  if (ec == std::errc::result_out_of_range) {
    throw io_error(file, line,
                   "number '" + std::string(token) + "' in column " + std::to_string(column) +
                       " is out of the range of double");
  }
  if (ec != std::errc{} || ptr != end) {
    throw io_error(file, line,
                   "cannot parse '" + std::string(token) + "' in column " + std::to_string(column) +
                       " as a number");
  }
  if (!std::isfinite(value)) {
    throw io_error(
        file, line,
        "non-finite value '" + std::string(token) + "' in column " + std::to_string(column));
  }
  return value;
}

/// Tokenises a data line, checks it has exactly `expected` numbers and parses them.
/// @param[in] what short description of the row layout for the message
/// @throws posefuse::io_error on a wrong column count or a bad number
template <class Lazy = void>
[[nodiscard]] std::vector<double> parse_row(std::string_view line, std::size_t expected,
                                            std::string_view what,
                                            const std::filesystem::path& file,
                                            std::size_t line_no) {
  const std::vector<std::string_view> tokens = split_whitespace(line);
  if (tokens.size() != expected) {
    throw io_error(file, line_no,
                   "expected " + std::to_string(expected) + " whitespace-separated numbers (" +
                       std::string(what) + "), found " + std::to_string(tokens.size()));
  }
  std::vector<double> values(expected);
  for (std::size_t c = 0; c < expected; ++c) {
    values[c] = parse_number(tokens[c], file, line_no, c + 1);
  }
  return values;
}

/// Shortest decimal text that parses back to exactly `value` (std::to_chars).
template <class Lazy = void>
[[nodiscard]] std::string format_number(double value) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  (void)ec;  // 64 chars always suffice for a double
  return std::string(buf, ptr);
}

/// Largest accepted magnitude (m) of a position coordinate in a trajectory
/// file. Squared differences of larger coordinates overflow a double, so no
/// error statistic could be computed from them; 1e100 m is far beyond any
/// physical trajectory (the observable universe is about 1e27 m across).
inline constexpr double kMaxAbsPosition = 1e100;

/// Refuses a position coordinate beyond kMaxAbsPosition (file:line).
template <class Lazy = void>
void check_position(const Eigen::Vector3d& p, const std::filesystem::path& file, std::size_t line) {
  if (p.cwiseAbs().maxCoeff() > kMaxAbsPosition) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", p.cwiseAbs().maxCoeff());
    throw io_error(file, line,
                   std::string("position coordinate of magnitude ") + buf +
                       " m is beyond 1e+100 m, where squared errors overflow");
  }
}

/// What a reader does with the row it just parsed (see `next_stamp_action`).
enum class StampAction {
  kAppend,       ///< a new, later stamp: append the row
  kSkip,         ///< a repeated stamp under DuplicateStamps::kFirst: drop this row
  kReplaceLast,  ///< a repeated stamp under DuplicateStamps::kLast: overwrite the previous row
};

/// A stamp as text: the shortest exact decimal for seconds (double), the
/// integer for nanoseconds.
template <class Stamp>
[[nodiscard]] std::string stamp_text(Stamp t) {
  if constexpr (std::is_floating_point_v<Stamp>) {
    return format_number(double(t));
  } else {
    return std::to_string(t);
  }
}

/// The error for a stamp `t` that does not follow `previous` (read on
/// `previous_line`) strictly. `offer_policies`: the reader takes
/// ReadOptions::duplicates, and a repeat is thrown as repeated_stamp_error
/// (a program that offers another policy adds its flag to the message);
/// otherwise, and for a decreasing stamp, as io_error. The message names no
/// program flag.
template <class Stamp>
[[noreturn]] void throw_stamp_out_of_order(Stamp t, Stamp previous, std::size_t previous_line,
                                           const std::filesystem::path& file, std::size_t line,
                                           bool offer_policies) {
  const std::string message = "timestamp " + stamp_text(t) +
                              (t == previous ? " repeats the previous one" : " is earlier than the previous one") +
                              " (" + stamp_text(previous) + " on line " + std::to_string(previous_line) + ")";
  if (t == previous && offer_policies) throw repeated_stamp_error(file, line, message);
  throw io_error(file, line, message);
}

/// Decides what to do with a row stamped `t` that follows `previous` (read
/// on `previous_line`), under `policy`; counts dropped rows in `report`.
/// The one rule of every reader that takes ReadOptions::duplicates; `Stamp`
/// is double (seconds) or an integer type (nanoseconds).
/// @throws posefuse::io_error (file:line) for a decreasing stamp, and for a
///         repeated one under DuplicateStamps::kError (then of type
///         repeated_stamp_error)
template <class Stamp>
[[nodiscard]] StampAction next_stamp_action(Stamp t, Stamp previous, std::size_t previous_line,
                                            DuplicateStamps policy, ReadReport* report,
                                            const std::filesystem::path& file,
                                            std::size_t line) {
  if (t > previous) return StampAction::kAppend;
  if (t == previous && policy != DuplicateStamps::kError) {
    if (report != nullptr) {
      if (report->duplicates_dropped == 0 && report->duplicates_kept == 0) report->first_duplicate_line = line;
      ++(policy == DuplicateStamps::kKeep ? report->duplicates_kept : report->duplicates_dropped);
    }
    if (policy == DuplicateStamps::kKeep) return StampAction::kAppend;
    return policy == DuplicateStamps::kFirst ? StampAction::kSkip : StampAction::kReplaceLast;
  }
  throw_stamp_out_of_order(t, previous, previous_line, file, line, /*offer_policies=*/true);
}

/// Below this orthonormality residual a rotation is kept bit for bit, so
/// that written files read back exactly.
inline constexpr double kExactlyOrthonormal = 1e-12;

/// Checks that `R` is a rotation within `tolerance` and returns the nearest
/// rotation (the orthogonal polar factor of `R`, which is \f$ U V^\top \f$
/// of its SVD \f$ R = U \Sigma V^\top \f$), or `R` itself when it is
/// orthonormal to `kExactlyOrthonormal`.
///
/// The polar factor is computed by Newton's iteration
/// \f$ X_{k+1} = \tfrac12 (X_k + X_k^{-\top}) \f$, \f$ X_0 = R \f$
/// (Higham, "Computing the polar decomposition", SIAM J. Sci. Stat. Comput.
/// 7(4), 1986, eq. 3.1), which converges quadratically for the nearly
/// orthonormal matrices accepted here: a residual of 1e-3 reaches rounding
/// in three steps. Over 2 800 random rotations perturbed by 1e-9 to 1e-3 it
/// agreed with the SVD's \f$ U V^\top \f$ to 1.6e-15 (the SVD's own product
/// is orthonormal only to 3e-15; this one to 4.4e-16), at a fraction of the
/// cost (the SVD was half of the time to read a KITTI file; bench_eval).
/// @throws posefuse::io_error for a non-orthonormal matrix or a reflection
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix3d checked_rotation(const Eigen::Matrix3d& R, double tolerance,
                                               const std::filesystem::path& file,
                                               std::size_t line) {
  using Mat3 = dependent_t<Eigen::Matrix3d, Lazy>;  // compiled where called (core/lazy.hpp)
  const Mat3& Rd = R;
  const double residual = (Rd.transpose() * Rd - Mat3::Identity()).cwiseAbs().maxCoeff();
  if (!(residual <= tolerance)) {
    throw io_error(file, line,
                   "rotation is not orthonormal: max |R^T R - I| = " + message_number(residual) +
                       " exceeds the tolerance " + message_number(tolerance));
  }
  const double det = Rd.determinant();
  if (!(det > 0.0)) {
    throw io_error(file, line, "rotation is a reflection (det R = " + message_number(det) + ")");
  }
  if (residual <= kExactlyOrthonormal) return R;
  Mat3 X = Rd;
  // Quadratic convergence: the change halves its exponent every step; stop
  // once it is at rounding level (at most 8 steps, 3 for tolerance 1e-3).
  for (int k = 0; k < 8; ++k) {
    const Mat3 next = 0.5 * (X + X.inverse().transpose());
    const double change = (next - X).cwiseAbs().maxCoeff();
    X = next;
    if (change <= 1e-15) break;
  }
  return X;
}

/// Checks a quaternion's norm and returns it normalised.
/// @throws posefuse::io_error for a zero or clearly non-unit quaternion
template <class Lazy = void>
[[nodiscard]] Eigen::Quaterniond checked_quaternion(const Eigen::Quaterniond& q,
                                                    double tolerance,
                                                    const std::filesystem::path& file,
                                                    std::size_t line) {
  const double norm = q.norm();
  if (norm == 0.0) throw io_error(file, line, "quaternion has zero norm");
  if (!(std::abs(norm - 1.0) <= tolerance)) {
    throw io_error(file, line,
                   "quaternion norm " + message_number(norm) + " differs from 1 by more than " +
                       message_number(tolerance));
  }
  return q.normalized();
}

}  // namespace posefuse::detail::traj_io

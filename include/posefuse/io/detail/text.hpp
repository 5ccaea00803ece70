#pragma once
/// @file
/// Line-oriented text parsing shared by the trajectory readers and writers
/// (not API): tokenising, strict number parsing and round-trip formatting,
/// and the rotation / quaternion checks, all reporting posefuse::io_error
/// with the file and 1-based line. Lines are read by detail::LineReader
/// (line_reader.hpp: length cap, read errors).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/line_reader.hpp>

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

/// Below this orthonormality residual a rotation is kept bit for bit, so
/// that written files read back exactly.
inline constexpr double kExactlyOrthonormal = 1e-12;

/// Checks that `R` is a rotation within `tolerance` and returns the nearest
/// rotation \f$ U V^\top \f$ (from \f$ R = U \Sigma V^\top \f$), or `R`
/// itself when it is orthonormal to `kExactlyOrthonormal`.
/// @throws posefuse::io_error for a non-orthonormal matrix or a reflection
// A template with nothing to deduce, so that the SVD is compiled only where
// a reader is used, not in every file including an io/ header.
template <class Lazy = void>
[[nodiscard]] Eigen::Matrix3d checked_rotation(const Eigen::Matrix3d& R, double tolerance,
                                               const std::filesystem::path& file,
                                               std::size_t line) {
  const double residual = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(residual <= tolerance)) {
    throw io_error(file, line,
                   "rotation is not orthonormal: max |R^T R - I| = " + format_number(residual) +
                       " exceeds the tolerance " + format_number(tolerance));
  }
  const double det = R.determinant();
  if (!(det > 0.0)) {
    throw io_error(file, line, "rotation is a reflection (det R = " + format_number(det) + ")");
  }
  if (residual <= kExactlyOrthonormal) return R;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
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
                   "quaternion norm " + format_number(norm) + " differs from 1 by more than " +
                       format_number(tolerance));
  }
  return q.normalized();
}

}  // namespace posefuse::detail::traj_io

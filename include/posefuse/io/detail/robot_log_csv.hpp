#pragma once
/// @file
/// CSV machinery of the robot-log reader and writer (not API): line
/// splitting, strict field parsing with file:line errors, round-trip number
/// formatting. Split out of robot_log.hpp to keep that header short.

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/io/detail/line_reader.hpp>

namespace posefuse {

namespace detail {

template <class Lazy = void>
std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c;
  return r;
}

/// Reads a text file as (line number, trimmed content) pairs, skipping blank
/// and `#` lines.
/// @throws posefuse::io_error for a missing or inaccessible file, a read
///         error, or a line longer than kMaxLineBytes
template <class Lazy = void>
std::vector<std::pair<std::size_t, std::string>> read_content_lines(
    const std::filesystem::path& file) {
  if (checked_status(file).type() == std::filesystem::file_type::not_found)
    throw io_error(file, "required file is missing");
  LineReader in(file);
  std::vector<std::pair<std::size_t, std::string>> lines;
  std::string line;
  while (in.next(line)) {
    const std::string_view t = trim_blanks(line);
    if (t.empty() || t.front() == '#') continue;
    lines.emplace_back(in.line_no(), std::string(t));
  }
  return lines;
}

/// A cursor over one CSV data line that parses its fields in order.
class CsvLine {
 public:
  CsvLine(const std::filesystem::path& file, std::size_t line, std::string_view text,
          std::span<const std::string_view> names)
      : file_(file), line_(line), names_(names), fields_(split_csv(text)) {
    if (fields_.size() != names.size()) {
      std::string expected;
      for (std::string_view n : names) (expected += expected.empty() ? "" : ",") += n;
      throw io_error(file, line, "expected " + std::to_string(names.size()) + " columns (" +
                                     expected + "), got " + std::to_string(fields_.size()));
    }
  }
  std::int64_t integer() {
    const std::string_view f = next();
    std::string_view g = f;
    if (!g.empty() && g.front() == '+') g.remove_prefix(1);
    std::int64_t v = 0;
    const auto [ptr, ec] = std::from_chars(g.data(), g.data() + g.size(), v);
    if (g.empty() || ec != std::errc{} || ptr != g.data() + g.size()) fail("an integer", f);
    return v;
  }
  double real(bool allow_non_finite = false) {
    const std::string_view f = next();
    if (allow_non_finite && f.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::string_view g = f;
    if (!g.empty() && g.front() == '+') g.remove_prefix(1);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(g.data(), g.data() + g.size(), v);
    if (g.empty() || ec != std::errc{} || ptr != g.data() + g.size()) fail("a number", f);
    if (!allow_non_finite && !std::isfinite(v))
      throw io_error(file_, line_, "column '" + std::string(names_[i_ - 1]) +
                                       "' is not finite ('" + std::string(f) + "')");
    return v;
  }
  std::string_view text() { return next(); }
  [[noreturn]] void error(const std::string& reason) const { throw io_error(file_, line_, reason); }
  [[noreturn]] void fail(const char* what, std::string_view f) const {
    throw io_error(file_, line_, "column '" + std::string(names_[i_ - 1]) + "' is not " + what +
                                     " ('" + std::string(f) + "')");
  }

 private:
  std::string_view next() { return fields_[i_++]; }
  const std::filesystem::path& file_;
  std::size_t line_;
  std::span<const std::string_view> names_;
  std::vector<std::string_view> fields_;
  std::size_t i_ = 0;
};

/// True when a line is the file's column names (an uncommented header).
template <class Lazy = void>
bool is_column_header(std::string_view text, std::span<const std::string_view> names) {
  const auto f = split_csv(text);
  if (f.size() != names.size()) return false;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (lower(f[i]) != names[i]) return false;
  }
  return true;
}

/// Parses every data line of a CSV file with `row(CsvLine&) -> Record`, and
/// checks that t_ns increases strictly; `lines`, when given, receives each
/// record's 1-based line number.
template <class Record, class RowFn>
std::vector<Record> read_csv(const std::filesystem::path& file,
                             std::span<const std::string_view> names, RowFn row,
                             std::vector<std::size_t>* lines = nullptr) {
  std::vector<Record> out;
  std::size_t prev_line = 0;
  for (const auto& [n, text] : read_content_lines(file)) {
    if (out.empty() && is_column_header(text, names)) continue;
    CsvLine c(file, n, text, names);
    Record r = row(c);
    if (!out.empty() && r.t_ns <= out.back().t_ns)
      throw io_error(file, n, "t_ns " + std::to_string(r.t_ns) +
                                  " does not increase (previous row, line " +
                                  std::to_string(prev_line) + ", has " +
                                  std::to_string(out.back().t_ns) + ")");
    out.push_back(r);
    if (lines != nullptr) lines->push_back(n);
    prev_line = n;
  }
  return out;
}

template <class Lazy = void>
std::string fmt(double v) {
  std::array<char, 64> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);  // shortest round-trip
  return std::string(buf.data(), r.ptr);
}

/// Opens `file` for writing, locale-free (see open_output_file).
template <class Lazy = void>
std::ofstream open_for_writing(const std::filesystem::path& file) {
  return open_output_file(file);
}

inline constexpr std::array<std::string_view, 5> kWheelCols{"t_ns", "fl", "fr", "bl", "br"};
inline constexpr std::array<std::string_view, 10> kImuCols{"t_ns", "ax", "ay", "az", "gx",
                                                           "gy",   "gz", "mx", "my", "mz"};
inline constexpr std::array<std::string_view, 9> kSlamCols{"t_ns", "state", "x",  "y", "z",
                                                           "qx",   "qy",    "qz", "qw"};
inline constexpr std::array<std::string_view, 4> kTruthCols{"t_ns", "x", "y", "yaw"};

}  // namespace detail

}  // namespace posefuse

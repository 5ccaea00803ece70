#pragma once
/// @file
/// The text readers' shared tokenising: blanks trimmed, a comma-separated
/// line split into fields, an integer nanosecond stamp parsed with file:line
/// errors. Not API.

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <posefuse/core/error.hpp>

namespace posefuse::detail {

/// `s` without leading spaces and tabs and without trailing spaces, tabs and
/// carriage returns.
[[nodiscard]] constexpr std::string_view trim_blanks(std::string_view s) noexcept {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

/// Splits a csv line at commas, each field trimmed (trim_blanks); views into `line`.
template <class Lazy = void>
[[nodiscard]] std::vector<std::string_view> split_csv(std::string_view line) {
  std::vector<std::string_view> out;
  for (;;) {
    const std::size_t comma = line.find(',');
    out.push_back(trim_blanks(line.substr(0, comma)));
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return out;
}

/// Parses an integer nanosecond stamp.
/// @throws posefuse::io_error naming file, line and column 1
template <class Lazy = void>
[[nodiscard]] std::int64_t parse_stamp(std::string_view token, const std::filesystem::path& file,
                                       std::size_t line) {
  std::int64_t v = 0;
  const char* const end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (ec == std::errc::result_out_of_range)
    throw io_error(file, line, "timestamp '" + std::string(token) + "' does not fit in int64 ns");
  if (ec != std::errc{} || ptr != end || token.empty())
    throw io_error(file, line,
                   "cannot parse '" + std::string(token) +
                       "' in column 1 as an integer timestamp in nanoseconds");
  return v;
}

}  // namespace posefuse::detail

#pragma once
/// @file
/// The library's exception types.
///
/// posefuse reports three kinds of failure differently (docs/design.md,
/// "Errors"): bad configuration throws posefuse::invalid_argument, unreadable
/// or malformed files throw posefuse::io_error naming the file and line, and
/// data failures on a per-sample hot path return a [[nodiscard]] status
/// (core/status.hpp).

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace posefuse {

/// A configuration value that the library cannot work with (negative
/// variance, zero track width, mismatched lengths, ...).
class invalid_argument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// A file that cannot be read or is malformed. what() reads
/// `"<file>:<line>: <reason>"` (or `"<file>: <reason>"` when no line applies).
class io_error : public std::runtime_error {
 public:
  io_error(const std::filesystem::path& file, std::size_t line, const std::string& reason)
      : std::runtime_error(format(file, line, reason)), file_(file), line_(line) {}
  io_error(const std::filesystem::path& file, const std::string& reason)
      : io_error(file, 0, reason) {}

  /// The file the error is about.
  [[nodiscard]] const std::filesystem::path& file() const noexcept { return file_; }
  /// 1-based line number, or 0 when the error is not about one line.
  [[nodiscard]] std::size_t line() const noexcept { return line_; }

 private:
  static std::string format(const std::filesystem::path& file, std::size_t line,
                            const std::string& reason) {
    // Appended piece by piece: `s + ":" + ...` trips GCC 12's -Wrestrict
    // false positive in optimised builds.
    std::string s = file.string();
    if (line > 0) {
      s.append(":");
      s.append(std::to_string(line));
    }
    s.append(": ");
    s.append(reason);
    return s;
  }
  std::filesystem::path file_;
  std::size_t line_;
};

}  // namespace posefuse

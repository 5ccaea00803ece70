#pragma once
/// @file
/// Line-by-line reading of the text files of every io/ reader (not API):
/// 1-based line numbers, a cap on the line length, read errors told apart
/// from the end of the file, and file-system errors (a name too long, no
/// permission) reported as posefuse::io_error naming the path.

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <ios>
#include <istream>
#include <locale>
#include <string>
#include <system_error>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// Longest line (bytes, without its line end) any io/ reader accepts: 1 MiB.
/// A KITTI pose line is about 200 bytes, a robot-log row under 300; a longer
/// line means the wrong file (e.g. `/dev/zero` or a binary), which is then
/// rejected after reading about 1 MiB instead of the whole file.
inline constexpr std::size_t kMaxLineBytes = std::size_t(1) << 20;

namespace detail {

/// The status of `file` (file_type::not_found when it does not exist).
/// @throws posefuse::io_error naming `file` when its status cannot be
///         determined, e.g. a path component longer than the system allows
///         (ENAMETOOLONG) or a folder without search permission
template <class Lazy = void>
[[nodiscard]] std::filesystem::file_status checked_status(
    const std::filesystem::path& file) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(file, ec);
  if (st.type() == std::filesystem::file_type::none)
    throw io_error(file, "cannot access: " + ec.message());
  return st;
}

/// Reads a text file line by line, counting 1-based line numbers, stripping
/// a trailing '\r' (files written on Windows) and a UTF-8 byte-order mark
/// at the start of the file.
class LineReader {
 public:
  /// @throws posefuse::io_error when the file cannot be accessed or opened,
  ///         or is a folder
  explicit LineReader(const std::filesystem::path& file) : file_(file) {
    if (std::filesystem::is_directory(checked_status(file)))
      throw io_error(file, "cannot open file for reading: it is a folder");
    in_.open(file, std::ios::in | std::ios::binary);
    if (!in_) throw io_error(file, "cannot open file for reading");
  }

  /// Reads the next line into `line`; false at the end of the file.
  /// @throws posefuse::io_error (file:line) on a read error (badbit), which
  ///         is never taken for the end of the file, and for a line longer
  ///         than kMaxLineBytes
  bool next(std::string& line) {
    line.clear();
    // Chunks through istream::getline: it stops at '\n', at the end of the
    // file, or when the chunk is full (failbit without eofbit), so that a
    // line without an end is never read further than the cap.
    char chunk[4096];
    bool any = false;  // a character (or the line end) was extracted
    for (;;) {
      in_.getline(chunk, sizeof(chunk));
      const auto got = static_cast<std::size_t>(in_.gcount());
      if (in_.bad()) throw io_error(file_, line_no_ + 1, "read error");
      if (got > 0) any = true;
      if (!in_.fail()) {  // the line end was extracted (counted in `got`), or the end of the file
        line.append(chunk, in_.eof() ? got : got - 1);
        break;
      }
      if (in_.eof()) break;     // nothing more to read
      line.append(chunk, got);  // a full chunk: the line goes on
      if (line.size() > kMaxLineBytes) {
        throw io_error(file_, line_no_ + 1,
                       "line longer than " + std::to_string(kMaxLineBytes) + " bytes");
      }
      in_.clear(in_.rdstate() & ~std::ios::failbit);
    }
    if (line.size() > kMaxLineBytes) {
      throw io_error(file_, line_no_ + 1,
                     "line longer than " + std::to_string(kMaxLineBytes) + " bytes");
    }
    if (!any) return false;
    ++line_no_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // A UTF-8 byte-order mark (EF BB BF) that some editors put at the start
    // of a file is not part of the first field.
    if (line_no_ == 1 && line.starts_with("\xEF\xBB\xBF")) line.erase(0, 3);
    return true;
  }
  /// 1-based number of the line last read.
  [[nodiscard]] std::size_t line_no() const noexcept { return line_no_; }
  [[nodiscard]] const std::filesystem::path& file() const noexcept { return file_; }

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::size_t line_no_ = 0;
};

/// Opens `file` for writing (truncating it) with the classic "C" locale, so
/// that nothing written depends on the global locale (no digit grouping).
/// @throws posefuse::io_error when it cannot be opened
template <class Lazy = void>
[[nodiscard]] std::ofstream open_output_file(const std::filesystem::path& file) {
  std::ofstream out;
  out.imbue(std::locale::classic());
  out.open(file, std::ios::out | std::ios::binary | std::ios::trunc);
  if (!out) throw io_error(file, "cannot open file for writing");
  return out;
}

}  // namespace detail

}  // namespace posefuse

#pragma once
/// @file
/// Output files of an example program, written all together at the end of a
/// run and never left half-written.
///
/// Each file is written to a temporary file in the same folder
/// (`.<name>.tmp.<pid>.<n>`), its stream checked after a flush, and only then
/// renamed into place (rename(2) within one folder is atomic). A program
/// first computes everything, then adds its outputs to one OutputFiles and
/// commits it: every file is written to its temporary first, and only when
/// all of them succeeded are they renamed, so a failing output (a full disk,
/// `--svg /dev/full`) leaves no other output of the run behind either.
///
/// Targets that exist and are not regular files (a device, a FIFO), and any
/// path under /dev or /proc (`/dev/stdout` may lead to the very file the
/// shell redirected standard output to), cannot be replaced by a rename; they
/// are written in place, after the temporaries succeeded and before any
/// rename. Any other symbolic link is followed: the file it points to is
/// replaced and the link kept.
///
/// Not guarded against: a crash or power loss between the renames (some of
/// the run's files are then new, the rest old, none partial), and fsync is
/// not called.

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>
#include <unistd.h>

#include <posefuse/core/error.hpp>

#include "cli.hpp"

namespace posefuse::apps {

namespace detail {

/// A fresh hidden name beside `target`: `.<name>.tmp.<pid>.<n>`.
[[nodiscard]] inline std::filesystem::path temporary_beside(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  return target.parent_path() / ("." + target.filename().string() + ".tmp." +
                                 std::to_string(::getpid()) + "." + std::to_string(counter++));
}

/// True for a normalised absolute path under /dev or /proc.
[[nodiscard]] inline bool is_system_path(const std::filesystem::path& p) {
  auto it = p.begin();
  if (it == p.end() || *it != "/" || ++it == p.end()) return false;
  return *it == "dev" || *it == "proc";
}

/// `path` made absolute, normalised, without a trailing separator, and with
/// a symbolic link resolved to the file it points to (not under /dev, /proc).
[[nodiscard]] inline std::filesystem::path resolve_target(const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::absolute(path, ec);
  if (ec) throw io_error(path, "cannot resolve the path: " + ec.message());
  p = p.lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  if (is_system_path(p)) return p;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(p, ec))) {
    const std::filesystem::path real = std::filesystem::weakly_canonical(p, ec);
    if (ec) throw io_error(path, "cannot follow the symbolic link: " + ec.message());
    p = real;
  }
  return p;
}

/// Calls `write(file)`; an io_error about `file` (or a file inside it) is
/// rethrown about `shown` (or the same file inside `shown`), so messages name
/// the output the user asked for, not its temporary.
inline void write_as(const std::function<void(const std::filesystem::path&)>& write,
                     const std::filesystem::path& file, const std::filesystem::path& shown) {
  try {
    write(file);
  } catch (const io_error& e) {
    const std::filesystem::path rel = e.file().lexically_relative(file);
    if (rel.empty() || *rel.begin() == "..") throw;  // about another file
    std::string reason = e.what();
    std::string prefix = e.file().string();
    if (e.line() > 0) prefix += ":" + std::to_string(e.line());
    prefix += ": ";
    if (reason.rfind(prefix, 0) == 0) reason.erase(0, prefix.size());
    throw io_error(rel == "." ? shown : shown / rel, e.line(), reason);
  }
}

}  // namespace detail

/// Writes `content` to `file` through a checked stream: opened, written,
/// flushed, closed, each step checked (the caller handles temporaries).
/// @throws posefuse::io_error naming `file` when any step fails
inline void write_text_file(const std::filesystem::path& file, std::string_view content) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw io_error(file, "cannot open for writing");
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
  out.flush();
  if (!out) throw io_error(file, "write failed");
  out.close();
  if (out.fail()) throw io_error(file, "write failed on close");
}

/// The output files of one run; see the file comment.
class OutputFiles {
 public:
  /// Writes a file (to the path it is given), e.g. `posefuse::write_trajectory`.
  using FileWriter = std::function<void(const std::filesystem::path&)>;

  /// Adds a file whose content is known.
  /// @param[in] file    where it goes
  /// @param[in] content its bytes
  /// @throws posefuse::invalid_argument when `file` is already an output of this run
  void add(const std::filesystem::path& file, std::string content) {
    add_with(file, [text = std::move(content)](const std::filesystem::path& p) {
      write_text_file(p, text);
    });
  }

  /// Adds a file written by `write(path)`, which must throw (io_error) on failure.
  /// @throws posefuse::invalid_argument when `file` is already an output of this run
  void add_with(const std::filesystem::path& file, FileWriter write) {
    push(file, std::move(write), false);
  }

  /// Adds a folder whose files `write(folder)` creates (e.g.
  /// `posefuse::write_robot_log`). It writes into a temporary sibling folder;
  /// on commit each of its files replaces the one of the same name in
  /// `folder` (created when absent); other files of `folder` are kept.
  /// @throws posefuse::invalid_argument when `folder` is already an output of this run
  void add_folder(const std::filesystem::path& folder, FileWriter write) {
    push(folder, std::move(write), true);
  }

  /// The outputs added so far.
  [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }

  /// Writes every output; see the file comment for the order.
  /// @throws posefuse::io_error naming the output that failed; then no
  ///         output has been replaced, unless a rename itself failed
  void commit() {
    namespace fs = std::filesystem;
    for (Entry& e : entries_) {
      std::error_code ec;
      const fs::file_status st = fs::status(e.target, ec);
      if (e.folder) {
        if (fs::exists(st) && !fs::is_directory(st))
          throw io_error(e.shown, "exists and is not a folder");
      } else {
        if (fs::is_directory(st)) throw io_error(e.shown, "is a folder");
        e.in_place = detail::is_system_path(e.target) || (fs::exists(st) && !fs::is_regular_file(st));
      }
    }
    try {
      for (Entry& e : entries_) {  // 1. temporaries
        if (e.in_place) continue;
        e.temporary = detail::temporary_beside(e.target);
        if (e.folder) {
          std::error_code ec;
          if (!std::filesystem::create_directory(e.temporary, ec) || ec)
            throw io_error(e.shown, "cannot create a temporary folder beside it: " +
                                        (ec ? ec.message() : std::string("exists")));
        }
        detail::write_as(e.write, e.temporary, e.shown);
      }
      for (Entry& e : entries_)  // 2. devices, pipes, /dev/stdout
        if (e.in_place) detail::write_as(e.write, e.target, e.shown);
    } catch (...) {
      discard();
      throw;
    }
    for (Entry& e : entries_) {  // 3. renames
      if (e.in_place) continue;
      std::error_code ec;
      if (!e.folder) {
        fs::rename(e.temporary, e.target, ec);
        if (ec) {
          discard();
          throw io_error(e.shown, "cannot rename the written file into place: " + ec.message());
        }
        e.temporary.clear();
        continue;
      }
      fs::create_directories(e.target, ec);
      if (ec) {
        discard();
        throw io_error(e.shown, "cannot create folder: " + ec.message());
      }
      for (const fs::directory_entry& f : fs::directory_iterator(e.temporary)) {
        fs::rename(f.path(), e.target / f.path().filename(), ec);
        if (ec) {
          discard();
          throw io_error(e.target / f.path().filename(), "cannot rename into place: " + ec.message());
        }
      }
      fs::remove(e.temporary, ec);
      e.temporary.clear();
    }
    entries_.clear();
  }

  /// Removes any temporaries left by a failed commit.
  ~OutputFiles() { discard(); }

  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;

 private:
  struct Entry {
    std::filesystem::path shown;   ///< as the user gave it (messages)
    std::filesystem::path target;  ///< resolved
    FileWriter write;
    bool folder = false;
    bool in_place = false;
    std::filesystem::path temporary;
  };

  void push(const std::filesystem::path& file, FileWriter write, bool folder) {
    const std::filesystem::path target = detail::resolve_target(file);
    for (const Entry& e : entries_)
      if (e.target == target && !writes_no_file(target))
        throw invalid_argument(file.string() + " is given as two outputs of one run");
    entries_.push_back({file, target, std::move(write), folder, false, {}});
  }

  void discard() noexcept {
    for (Entry& e : entries_) {
      if (e.temporary.empty()) continue;
      std::error_code ec;
      std::filesystem::remove_all(e.temporary, ec);
      e.temporary.clear();
    }
  }

  std::vector<Entry> entries_;
};

}  // namespace posefuse::apps

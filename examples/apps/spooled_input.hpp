#pragma once
/// @file
/// Input that can be read only once (a named pipe, `<(command)`), for a
/// program that reads a file twice (format detection, then the reader): such
/// input is copied once into a private temporary file that the readers then
/// open; messages are turned back to name the path as given.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>

namespace posefuse::apps {

/// Copies of the inputs that are not regular files; removed with the object.
class SpooledInputs {
 public:
  SpooledInputs() = default;
  SpooledInputs(const SpooledInputs&) = delete;
  SpooledInputs& operator=(const SpooledInputs&) = delete;
  ~SpooledInputs() {
    std::error_code ec;
    if (!dir_.empty()) std::filesystem::remove_all(dir_, ec);
  }

  /// The path to read `given` from: `given` itself when it is a regular file
  /// (or missing, a folder: the reader reports those), else a copy of its
  /// whole content read once.
  /// @throws posefuse::io_error naming `given` when it cannot be read or copied
  [[nodiscard]] std::filesystem::path readable(const std::filesystem::path& given) {
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(given, ec);
    if (ec || std::filesystem::is_regular_file(st) || std::filesystem::is_directory(st) ||
        !std::filesystem::exists(st))
      return given;
    for (const auto& [from, copy] : copies_)
      if (from == given) return copy;
    if (dir_.empty()) {
      std::string pattern = (std::filesystem::temp_directory_path() / "posefuse-input-XXXXXX").string();
      if (::mkdtemp(pattern.data()) == nullptr) throw io_error(given, "cannot create a temporary copy");
      dir_ = pattern;
    }
    const std::filesystem::path copy = dir_ / std::to_string(copies_.size());
    std::ifstream in(given, std::ios::binary);
    if (!in) throw io_error(given, "cannot open file for reading");
    std::ofstream out(copy, std::ios::binary);
    out << in.rdbuf();
    out.flush();
    if (in.bad() || !out) throw io_error(given, "cannot read it into a temporary copy");
    copies_.emplace_back(given, copy);
    return copy;
  }

  /// `text` with every copy's path replaced by the path as given.
  [[nodiscard]] std::string shown(std::string text) const {
    for (const auto& [from, copy] : copies_) {
      const std::string c = copy.string(), f = from.string();
      for (std::size_t at = text.find(c); at != std::string::npos; at = text.find(c, at + f.size()))
        text.replace(at, c.size(), f);
    }
    return text;
  }

  /// The path as given for a path `readable` returned.
  [[nodiscard]] std::filesystem::path shown(const std::filesystem::path& path) const {
    for (const auto& [from, copy] : copies_)
      if (copy == path) return from;
    return path;
  }

 private:
  std::filesystem::path dir_;
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> copies_;
};

}  // namespace posefuse::apps

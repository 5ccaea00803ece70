#pragma once
// The one configurable path to the real datasets (layout: docs/programs.md).
// Order: the POSEFUSE_DATA_DIR environment variable, else the CMake cache
// variable POSEFUSE_DATA_DIR baked in at build time.
#include <cstdlib>
#include <filesystem>
#include <string>

namespace posefuse::test {

inline std::filesystem::path data_dir() {
  if (const char* env = std::getenv("POSEFUSE_DATA_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return POSEFUSE_DEFAULT_DATA_DIR;
}

/// The folder `data_dir()/relative`, or an empty path when it does not exist.
inline std::filesystem::path dataset(const std::string& relative) {
  std::filesystem::path p = data_dir() / relative;
  return std::filesystem::is_directory(p) ? p : std::filesystem::path{};
}

}  // namespace posefuse::test

/// Skips the current Catch2 test case visibly when a dataset is missing.
/// Catch2 v2 has no SKIP(): the case passes with a WARN line naming the
/// missing folder, which is printed even on success.
#define POSEFUSE_REQUIRE_DATASET(var, relative)                                       \
  const std::filesystem::path var = ::posefuse::test::dataset(relative);              \
  if (var.empty()) {                                                                  \
    WARN("SKIPPED: dataset '" << (relative) << "' not found under "                   \
                              << ::posefuse::test::data_dir()                         \
                              << " (set POSEFUSE_DATA_DIR to run this test)");        \
    return;                                                                           \
  }

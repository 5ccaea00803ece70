#pragma once
// Runs an example program for end-to-end tests: captures exit status, stdout
// and stderr; finds examples in the build tree (POSEFUSE_EXAMPLES_DIR).
// Also a strict JSON reader (RFC 8259) to check the programs' --json output.
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <sys/wait.h>
#include <variant>
#include <vector>

#include <apps/json_read.hpp>

#include "support/temp_dir.hpp"

namespace posefuse::test {

struct Run {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `exe args` through the shell, with stdout/stderr captured in `dir`.
inline Run run(const std::filesystem::path& exe, const std::string& args, const TempDir& dir) {
  const auto out = dir.path() / "stdout.txt", err = dir.path() / "stderr.txt";
  const std::string cmd =
      "'" + exe.string() + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// Number of '\n' in `s`.
inline std::size_t count_lines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

/// The strict JSON reader of the example programs (apps/json_read.hpp).
using Json = posefuse::apps::JsonValue;

/// The path of a built example, or an empty path when it was not built.
inline std::filesystem::path example(const std::string& name) {
  const std::filesystem::path exe = std::filesystem::path(POSEFUSE_EXAMPLES_DIR) / name;
  return std::filesystem::exists(exe) ? exe : std::filesystem::path{};
}

}  // namespace posefuse::test

/// Skips the current test case visibly when an example program is not built.
#define POSEFUSE_REQUIRE_EXAMPLE(var, name)                                                   \
  const std::filesystem::path var = ::posefuse::test::example(name);                          \
  if (var.empty()) {                                                                          \
    WARN("SKIPPED: example '" << (name) << "' not built (POSEFUSE_BUILD_EXAMPLES=ON)");      \
    return;                                                                                   \
  }

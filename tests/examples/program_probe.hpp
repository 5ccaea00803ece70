#pragma once
// One row of a program-contract table (docs/programs.md): a program, its
// arguments, the exit status it must give, the text its stderr must (and
// must not) contain, and the files it must not leave behind. Arguments and
// texts use {dir} for the scratch folder. A program that is not built is
// skipped visibly.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace posefuse::test {

struct Probe {
  std::string program, args;
  int status;
  std::vector<std::string> contains, absent;
  /// Files (with {dir}) that must not exist after the run: outputs of a
  /// refused run.
  std::vector<std::string> not_written{};
};

/// `text` with every {dir} replaced by the scratch folder.
inline std::string expand(std::string text, const TempDir& dir) {
  const std::string key = "{dir}";
  for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key))
    text.replace(at, key.size(), dir.path().string());
  return text;
}

/// Runs one probe and checks it: the status; for a failure, exactly one
/// error line on stderr starting with "<program>: ", ending in
/// "(try --help)" exactly for a usage error (documented `warning:` lines the
/// run printed before failing are allowed ahead of it); the texts; the files
/// not written.
inline void check(const Probe& p, const TempDir& dir) {
  const std::filesystem::path exe = example(p.program);
  if (exe.empty()) {
    WARN("SKIPPED: example '" << p.program << "' not built");
    return;
  }
  const Run r = run(exe, expand(p.args, dir), dir);
  INFO(p.program << " " << p.args << "\nstderr: " << r.err);
  CHECK(r.status == p.status);
  if (p.status != 0) {
    // Leading warning lines, then the one error line.
    std::string error = r.err;
    while (error.rfind("warning: ", 0) == 0 && error.find('\n') != std::string::npos)
      error.erase(0, error.find('\n') + 1);
    CHECK(count_lines(error) == 1);
    CHECK(error.rfind(p.program + ": ", 0) == 0);
    CHECK((p.status == 2) == (error.find("(try --help)") != std::string::npos));
  }
  for (const std::string& c : p.contains) CHECK(r.err.find(expand(c, dir)) != std::string::npos);
  for (const std::string& a : p.absent) CHECK(r.err.find(a) == std::string::npos);
  for (const std::string& f : p.not_written) CHECK_FALSE(std::filesystem::exists(expand(f, dir)));
}

}  // namespace posefuse::test

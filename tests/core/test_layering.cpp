// The library's one-way layering (docs/design.md): a header under
// include/posefuse/<folder>/ may include headers of its own folder and of
// folders of a lower rank, never of a higher rank and never of a sibling of
// the same rank. This test reads every header and fails on any arrow that
// runs up or sideways, naming the file and line.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Rank of each folder of include/posefuse/. Equal ranks are siblings.
const std::map<std::string, int>& ranks() {
  static const std::map<std::string, int> r{
      {"core", 0},                                           // Eigen and the standard library only
      {"lie", 1},                                            // SO2 SE2 SO3 SE3
      {"models", 2}, {"io", 2}, {"eval", 2},                 // siblings: none includes another
      {"filters", 3},                                        // estimators over models
      {"sensors", 4},                                        // raw samples -> model inputs (may run filters)
      {"fusion", 5}, {"inertial", 5}, {"graph", 5},           // estimators over sensors
      {"vio", 6},                                            // the visual-inertial estimator
      // Beside the recommended API, above all of it: the conformance harness
      // and test references, the simulators, and the seed documents'
      // formulas reproduced as printed.
      {"testing", 7}, {"sim", 7}, {"seed", 7},
      {"frontend", 7},  // the image front end (needs OpenCV): images -> feature tracks for vio/
  };
  return r;
}

struct Arrow {
  std::string file;
  int line;
  std::string from, to;
};

fs::path include_root() { return fs::path(POSEFUSE_SOURCE_DIR) / "include" / "posefuse"; }

// Calls f(path, line_no, text) for every line of every file under
// include/posefuse (lines numbered from 1).
template <class F>
void for_each_library_line(F f) {
  for (const auto& entry : fs::recursive_directory_iterator(include_root())) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path());
    std::string text;
    int line_no = 0;
    while (std::getline(in, text)) f(entry.path(), ++line_no, text);
  }
}

// Folder of a header relative to include/posefuse ("" for the umbrella).
std::string folder_of(const fs::path& rel) {
  return rel.has_parent_path() ? rel.begin()->string() : std::string();
}

std::vector<Arrow> arrows_breaking_layers(std::vector<std::string>& unknown_folders) {
  std::vector<Arrow> bad;
  const std::regex include_re(R"(^\s*#\s*include\s*<posefuse/([a-z_]+)/)");
  for (const auto& entry : fs::recursive_directory_iterator(include_root())) {
    if (!entry.is_regular_file() || entry.path().extension() != ".hpp") continue;
    const fs::path rel = fs::relative(entry.path(), include_root());
    const std::string from = folder_of(rel);
    if (from.empty()) continue;  // posefuse.hpp includes everything by design
    if (!ranks().count(from)) {
      unknown_folders.push_back(from);
      continue;
    }
    std::ifstream in(entry.path());
    std::string text;
    int line_no = 0;
    while (std::getline(in, text)) {
      ++line_no;
      std::smatch m;
      if (!std::regex_search(text, m, include_re)) continue;
      const std::string to = m[1].str();
      if (to == from) continue;
      const auto it = ranks().find(to);
      if (it == ranks().end()) {
        unknown_folders.push_back(to);
        continue;
      }
      if (it->second >= ranks().at(from)) bad.push_back({rel.string(), line_no, from, to});
    }
  }
  return bad;
}

}  // namespace

TEST_CASE("Layering: no header includes a layer above it or a sibling", "[core][layering]") {
  REQUIRE(fs::is_directory(include_root()));
  std::vector<std::string> unknown;
  const std::vector<Arrow> bad = arrows_breaking_layers(unknown);
  for (const Arrow& a : bad)
    UNSCOPED_INFO(a.file << ":" << a.line << ": " << a.from << " (rank " << ranks().at(a.from)
                         << ") includes " << a.to << " (rank " << ranks().at(a.to) << ")");
  CHECK(bad.empty());
  // A new folder must be given a rank here before it can be used.
  for (const std::string& f : unknown) UNSCOPED_INFO("folder without a rank: " << f);
  CHECK(unknown.empty());
}

TEST_CASE("Layering: the seed programs' code is not in the library", "[core][layering]") {
  // Runners and experiment metrics live in examples/apps/ (the simulators the
  // library's own tests use are library code, in include/posefuse/sim/).
  CHECK_FALSE(fs::exists(include_root() / "apps"));
  for (const char* gone :
       {"fusion/corridor_runner.hpp", "fusion/corridor_metrics.hpp", "filters/trajectory_correction.hpp"}) {
    INFO(gone);
    CHECK_FALSE(fs::exists(include_root() / gone));
  }
  // And no library header reaches into examples/apps.
  const std::regex apps_re(R"(^\s*#\s*include\s*[<"]apps/)");
  for_each_library_line([&](const fs::path& file, int line_no, const std::string& text) {
    INFO(file.string() << ":" << line_no);
    CHECK_FALSE(std::regex_search(text, apps_re));
  });
}

TEST_CASE("Layering: headers name only documents that are in the repository", "[core][layering]") {
  // A comment that sends the reader to a file must send them to one they
  // have: any `something.md` named in a header must exist, relative to the
  // repository root, and no header may point outside the repository.
  const fs::path root(POSEFUSE_SOURCE_DIR);
  const std::regex doc_re(R"(([A-Za-z0-9_./-]+)\.md\b)");
  const std::regex outside_re(R"(\.\./shared|\.\./\.\./)");
  int named = 0;
  for_each_library_line([&](const fs::path& file, int line_no, const std::string& text) {
    INFO(fs::relative(file, root).string() << ":" << line_no << ": " << text);
    CHECK_FALSE(std::regex_search(text, outside_re));
    for (std::sregex_iterator it(text.begin(), text.end(), doc_re), end; it != end; ++it) {
      ++named;
      const std::string doc = (*it)[1].str() + ".md";
      INFO("names " << doc);
      CHECK(fs::is_regular_file(root / doc));
    }
  });
  // The check above must have something to check: the headers do point to docs/.
  CHECK(named > 0);
}

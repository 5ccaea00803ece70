// The corridor_fusion example end to end: table, JSON, SVG, --write-log then
// --log gives the same figures, and bad input exits non-zero with one line.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace {

/// The text after `"key": ` following the object of `method`.
std::string json_field(const std::string& json, const std::string& method, const std::string& key) {
  const std::size_t m = json.find("\"" + method + "\": {");
  REQUIRE(m != std::string::npos);
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = json.find(tag, m);
  REQUIRE(at != std::string::npos);
  return json.substr(at + tag.size(), json.find_first_of(",}", at + tag.size()) - at - tag.size());
}

}  // namespace

TEST_CASE("corridor_fusion: prints the table, the per-turn yaw errors and an SVG",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto svg = dir.path() / "paths.svg";
  const auto r = posefuse::test::run(exe, "--seed 1 --svg '" + svg.string() + "'", dir);
  REQUIRE(r.status == 0);
  for (const char* s : {"slam_only", "odometry_only", "seed_fuser", "gated_fuser", "loop closure (m)",
                        "yaw error after each 90-degree turn", "lost"})
    CHECK(r.out.find(s) != std::string::npos);
  const std::string text = posefuse::test::slurp(svg);
  CHECK(text.rfind("<svg", 0) == 0);
  CHECK(text.find("ground truth") != std::string::npos);
  CHECK(text.find("</svg>") != std::string::npos);
}

TEST_CASE("corridor_fusion: --json, and --write-log then --log gives the same figures",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto log = dir.path() / "log";
  const auto sim = posefuse::test::run(exe, "--seed 3 --json --write-log '" + log.string() + "'", dir);
  REQUIRE(sim.status == 0);
  const auto rec = posefuse::test::run(exe, "--json --log '" + log.string() + "'", dir);
  REQUIRE(rec.status == 0);
  for (const char* m : {"slam_only", "odometry_only", "seed_fuser", "gated_fuser"}) {
    for (const char* k : {"loop_closure_error", "max_yaw_error_deg", "rmse"}) {
      INFO(m << "." << k);
      CHECK(json_field(sim.out, m, k) == json_field(rec.out, m, k));
    }
  }
  CHECK(std::stod(json_field(sim.out, "slam_only", "loop_closure_error")) > 1.5);
  CHECK(std::stod(json_field(sim.out, "gated_fuser", "loop_closure_error")) < 1.0);
}

TEST_CASE("corridor_fusion: bad input exits non-zero with a one-line reason",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto bad = dir.path() / "bad";
  std::filesystem::create_directories(bad);
  std::ofstream(bad / "robot.txt") << "ticks_per_rev 1320\nwheel_radius 0.065\n";
  struct Case {
    std::string args, expect;
  };
  const Case cases[] = {
      {"--frobnicate", "unknown option"},
      {"--seed", "needs a value"},
      {"--seed -3", "non-negative integer"},
      {"--seed 1 --log x", "exclude each other"},
      {"--log '" + (dir.path() / "missing").string() + "'", "log folder does not exist"},
      {"--log '" + bad.string() + "'", "robot.txt:2: unknown key 'wheel_radius'"},
  };
  for (const auto& c : cases) {
    const auto r = posefuse::test::run(exe, c.args, dir);
    INFO(c.args << " -> " << r.err);
    CHECK(r.status != 0);
    CHECK(r.err.find(c.expect) != std::string::npos);
    CHECK(r.err.find('\n') == r.err.size() - 1);  // exactly one line
    CHECK(r.out.empty());
  }
  const auto help = posefuse::test::run(exe, "--help", dir);
  CHECK(help.status == 0);
  CHECK(help.out.find("--write-log") != std::string::npos);
}

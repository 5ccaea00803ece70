// The corridor_fusion example end to end: table, JSON (valid, round-trip
// numbers), SVG, --write-log then --log gives the same figures; usage errors
// exit 2, bad data and unwritable outputs exit 1, each with one line, and a
// failed run leaves no output behind.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace {

using posefuse::test::Json;

/// The text after `"key": ` following the object of `method`.
std::string json_field(const std::string& json, const std::string& method, const std::string& key) {
  const std::size_t m = json.find("\"" + method + "\": {");
  REQUIRE(m != std::string::npos);
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = json.find(tag, m);
  REQUIRE(at != std::string::npos);
  return json.substr(at + tag.size(), json.find_first_of(",}", at + tag.size()) - at - tag.size());
}

/// The lines of `text` from the first starting with "method" through the
/// second starting with "gated_fuser" (the corridor table), each with
/// `prefix` removed and trailing spaces dropped.
std::vector<std::string> table_block(const std::string& text, const std::string& prefix = "") {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string line;
  int gated = 0;
  while (std::getline(in, line) && gated < 2) {
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) line.pop_back();
    if (line.rfind(prefix, 0) == 0) line = line.substr(prefix.size());
    else if (prefix.rfind(line, 0) == 0 && line.find_first_not_of(' ') != std::string::npos &&
             prefix.find_first_not_of(' ', line.size()) == std::string::npos)
      line.clear();  // the prefix without its trailing spaces: an empty line
    if (out.empty() && line.rfind("method          loop closure", 0) != 0) continue;
    out.push_back(line);
    gated += line.rfind("gated_fuser", 0) == 0;
  }
  return out;
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
  CHECK(text.find(">x (m)</text>") != std::string::npos);
  CHECK(text.find("gated_fuser (loop closure ") != std::string::npos);
  CHECK(text.find("nan") == std::string::npos);
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
  // The whole document is valid JSON with the documented members.
  const Json j = Json::parse(sim.out);
  CHECK(j["source"].string() == "simulation, seed 3");
  CHECK(j["turns"].number() == 4);
  CHECK(j["turns_from_groundtruth"].boolean());
  for (const char* m : {"slam_only", "odometry_only", "seed_fuser", "gated_fuser"}) {
    const Json& x = j["methods"][m];
    CHECK(x["yaw_error_after_turn_deg"].array().size() == 4);
    CHECK(x["poses"].number() > 0);
    CHECK(x["time_without_pose_s"].is_number());
  }
  CHECK(j["methods"]["gated_fuser"]["loop_closure_error"].number() ==
        Json::parse(rec.out)["methods"]["gated_fuser"]["loop_closure_error"].number());
  for (const char* k : {"valid", "lost", "reinit", "tilted"}) CHECK(j["slam"][k].is_number());
  CHECK(j["gated_fuser"]["anchors"].number() >= 1);
  CHECK(j["magnetometer_note"].is_string());
  CHECK(j["warnings"].is_array());
}

TEST_CASE("corridor_fusion: bad input exits 2 (usage) or 1 (data) with a one-line reason",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto bad = dir.path() / "bad";
  std::filesystem::create_directories(bad);
  std::ofstream(bad / "robot.txt") << "ticks_per_rev 1320\nwheel_radius 0.065\n";
  struct Case {
    std::string args, expect;
    int status;
  };
  const Case cases[] = {
      {"--frobnicate", "unknown option", 2},
      {"--seed", "needs a value", 2},
      {"--seed -3", "non-negative integer", 2},
      {"--seed 99999999999999999999999", "out of range", 2},  // not wrapped to 2^64 - 1
      {"--seed 1x", "non-negative integer", 2},
      {"--seed 1 --log x", "exclude each other", 2},
      {"--seed 1 --seed 2", "given more than once", 2},
      {"--log x --write-log y", "cannot be used with --log", 2},
      {"--json extra", "unexpected argument 'extra'", 2},
      {"--log '" + (dir.path() / "missing").string() + "'", "log folder does not exist", 1},
      {"--log '" + bad.string() + "'", "robot.txt:2: unknown key 'wheel_radius'", 1},
      {"--svg /dev/full", "/dev/full: write failed", 1},
      {"--svg '" + (dir.path() / "no" / "p.svg").string() + "'", "no/p.svg: cannot open", 1},
  };
  for (const auto& c : cases) {
    const auto r = posefuse::test::run(exe, c.args, dir);
    INFO(c.args << " -> " << r.err);
    CHECK(r.status == c.status);
    CHECK(r.err.find(c.expect) != std::string::npos);
    CHECK(r.err.rfind("corridor_fusion: ", 0) == 0);
    CHECK(r.err.find('\n') == r.err.size() - 1);  // exactly one line
    CHECK((r.err.find("(try --help)") != std::string::npos) == (c.status == 2));
    CHECK(r.out.empty());
  }
  const auto help = posefuse::test::run(exe, "--help", dir);
  CHECK(help.status == 0);
  CHECK(help.out.find("--write-log") != std::string::npos);
  CHECK(help.out.find("--seed N") != std::string::npos);
}

TEST_CASE("corridor_fusion: a failing --svg leaves no --write-log behind",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto log = dir.path() / "log";
  const auto r = posefuse::test::run(exe, "--write-log '" + log.string() + "' --svg /dev/full", dir);
  CHECK(r.status == 1);
  CHECK(r.err.find("/dev/full") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(log));
  for (const auto& f : std::filesystem::directory_iterator(dir.path()))  // no temporaries
    CHECK(f.path().filename().string().find(".tmp.") == std::string::npos);
}

TEST_CASE("corridor_fusion: docs/reproductions-seed001.md's table and the example's comment are its output",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto r = posefuse::test::run(exe, "", dir);
  REQUIRE(r.status == 0);
  const auto printed = table_block(r.out);
  REQUIRE(printed.size() == 12);
  const std::filesystem::path root = std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
  const std::string page = posefuse::test::slurp(root / "docs" / "reproductions-seed001.md");
  const std::size_t sec = page.find("# Seed 001");
  REQUIRE(sec != std::string::npos);
  CHECK(table_block(page.substr(sec)) == printed);
  const std::string example = posefuse::test::slurp(root / "examples" / "corridor_fusion.cpp");
  CHECK(table_block(example, "//   ") == printed);
}

TEST_CASE("corridor_fusion: --json reports warnings, tilted SLAM poses and the magnetometer",
          "[fusion][examples][corridor]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "corridor_fusion");
  posefuse::test::TempDir dir("corridor-example");
  const auto log = dir.path() / "log";
  const auto clean = posefuse::test::run(exe, "--seed 2 --json --write-log '" + log.string() + "'", dir);
  REQUIRE(clean.status == 0);
  CHECK(clean.out.find("\"warnings\": []") != std::string::npos);
  CHECK(clean.out.find("\"tilted\": 0") != std::string::npos);
  CHECK(clean.out.find("\"magnetometer_calibrated\": true") != std::string::npos);
  CHECK(clean.out.find("\"magnetometer_note\": \"horizontal hard/soft-iron") != std::string::npos);
  CHECK(clean.out.find("\"max_yaw_error_all_deg\": ") != std::string::npos);
  // The IMU stops halfway (imu.csv cut), ground truth starts 2 m off.
  for (const char* name : {"imu.csv", "groundtruth.csv"}) {
    std::istringstream in(posefuse::test::slurp(log / name));
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    std::ofstream out(log / name, std::ios::trunc);
    const bool imu = std::string(name) == "imu.csv";
    for (std::size_t i = 0; i < (imu ? lines.size() / 2 : lines.size()); ++i) {
      if (!imu && lines[i][0] != '#') {
        const std::size_t c = lines[i].find(',');
        const std::size_t d = lines[i].find(',', c + 1);
        out << lines[i].substr(0, c + 1) << std::stod(lines[i].substr(c + 1, d - c - 1)) + 2.0
            << lines[i].substr(d) << '\n';
      } else {
        out << lines[i] << '\n';
      }
    }
  }
  const auto json = posefuse::test::run(exe, "--json --log '" + log.string() + "'", dir);
  REQUIRE(json.status == 0);
  INFO(json.out);
  const std::size_t w = json.out.find("\"warnings\": [");
  REQUIRE(w != std::string::npos);
  CHECK(json.out.find("groundtruth.csv: the first pose is (2.00 m", w) != std::string::npos);
  CHECK(json.out.find("imu.csv: no attitude younger than", w) != std::string::npos);
  CHECK(json.out.find("\"magnetometer_calibrated\": false") != std::string::npos);
  const auto table = posefuse::test::run(exe, "--log '" + log.string() + "'", dir);
  REQUIRE(table.status == 0);
  // Warnings go to standard error, one `warning:` line each; the table on
  // standard output has none.
  CHECK(table.err.find("warning: ") == 0);
  CHECK(table.err.find("groundtruth.csv: the first pose is (2.00 m") != std::string::npos);
  CHECK(table.out.find("warning: ") == std::string::npos);
  CHECK(json.err.find("warning: ") == 0);
  CHECK(table.err.find("ground truth in the odometry frame") != std::string::npos);
}

// The example programs' shared helpers: the flag parser and run_main
// (apps/cli.hpp), the JSON writer (apps/json.hpp), the SVG writer
// (apps/svg.hpp) and the write-then-rename output files (apps/output_file.hpp).
#include <catch2/catch.hpp>

#include <apps/cli.hpp>
#include <apps/imu_flags.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/svg.hpp>

#include <algorithm>
#include <charconv>
#include <clocale>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

#include "examples/program_probe.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

namespace apps = posefuse::apps;
namespace fs = std::filesystem;
using posefuse::test::Json;

namespace {

apps::CommandLine command(std::vector<std::string> args) {
  return {"prog", std::move(args)};
}

/// The usage_error message of parsing `args` with `parser`, or "" when it parsed.
template <class P>
std::string usage_message(P& parser, std::vector<std::string> args) {
  std::ostringstream help;
  try {
    (void)parser.parse(command(std::move(args)), help);
  } catch (const apps::usage_error& e) {
    return e.what();
  }
  return "";
}

/// Redirects file descriptor 2 to a file while it lives; `text()` ends it.
class StderrCapture {
 public:
  StderrCapture() : file_(dir_.path() / "stderr.txt") {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int fd = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    ::dup2(fd, 2);
    ::close(fd);
  }
  std::string text() {
    restore();
    return posefuse::test::slurp(file_);
  }
  ~StderrCapture() { restore(); }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
    saved_ = -1;
  }
  posefuse::test::TempDir dir_{"stderr"};
  fs::path file_;
  int saved_ = -1;
};

/// Runs run_main with `body` as program "prog"; returns (exit code, stderr).
template <class Body>
std::pair<int, std::string> run_main_with(Body body, std::vector<const char*> args = {"prog"}) {
  StderrCapture cap;
  const int code = apps::run_main(static_cast<int>(args.size()), args.data(), body);
  return {code, cap.text()};
}

/// Names of the files in `dir`.
std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

// ---------------------------------------------------------------------------
// Parser

TEST_CASE("apps::Parser: every kind of flag sets its target", "[examples][cli]") {
  std::string name = "none";
  std::optional<fs::path> file;
  std::vector<fs::path> inputs;
  double sigma = 0.5;
  std::optional<std::uint64_t> seed;
  int count = 3;
  bool verbose = false, quiet = false;
  std::string mode;
  apps::Parser cli("prog", "[options]", "A test program.");
  cli.text({.name = "--name", .value = "TEXT", .help = "a name"}, name);
  cli.output({.name = "--file", .value = "FILE", .help = "a file"}, file);
  cli.inputs({.name = "--input", .value = "FILE", .help = "inputs (repeat)"}, inputs);
  cli.real({.name = "--sigma", .value = "S", .help = "noise", .unit = "m"}, sigma, apps::Domain::kPositive);
  cli.integer({.name = "--seed", .value = "N", .help = "seed"}, seed, std::uint64_t{0});
  cli.integer({.name = "--count", .value = "K", .help = "count"}, count, 1, 10);
  cli.flag({.name = "--verbose", .help = "talk"}, verbose);
  cli.flag({.name = "--quiet", .help = "hush"}, quiet);
  cli.custom({.name = "--mode", .value = "a|b", .help = "mode", .default_text = "a"},
             [&](std::string_view v) {
               if (v != "a" && v != "b") throw posefuse::invalid_argument("expected a or b");
               mode = std::string(v);
             });
  std::ostringstream help;
  REQUIRE(cli.parse(command({"--name", "x y", "--file=out.txt", "--input", "a", "--input", "b",
                             "--sigma", "1e308", "--seed", "18446744073709551615", "--count=10",
                             "--verbose", "--mode", "b"}),
                    help));
  CHECK(help.str().empty());
  CHECK(name == "x y");
  REQUIRE(file);
  CHECK(*file == "out.txt");
  CHECK(inputs == std::vector<fs::path>{"a", "b"});
  CHECK(sigma == 1e308);  // finite and > 0: accepted as the flag requires
  REQUIRE(seed);
  CHECK(*seed == std::numeric_limits<std::uint64_t>::max());
  CHECK(count == 10);
  CHECK(verbose);
  CHECK_FALSE(quiet);
  CHECK(mode == "b");
  CHECK(cli.given("--sigma"));
  CHECK_FALSE(cli.given("--quiet"));
  // Defaults stay when a flag is absent.
  double s2 = 0.25;
  apps::Parser other("prog", "", "");
  other.real({.name = "--sigma", .value = "S", .help = "noise"}, s2);
  REQUIRE(other.parse(command({}), help));
  CHECK(s2 == 0.25);
}

TEST_CASE("apps::Parser: --help prints the generated usage and nothing is parsed",
          "[examples][cli]") {
  double q = 1.0;
  bool json = false;
  std::optional<std::uint64_t> seed;
  apps::Parser cli("prog", "[--seed N] [options]", "Does things.");
  cli.real({.name = "--cv-q", .value = "Q", .help = "acceleration noise", .unit = "m^2/s^3"}, q,
           apps::Domain::kPositive);
  cli.integer({.name = "--seed", .value = "N", .help = "RNG seed", .default_text = "1"}, seed,
              std::uint64_t{0});
  cli.flag({.name = "--json", .help = "print JSON\nsecond line"}, json);
  cli.epilogue("Exit status: 0, 1, 2.");
  for (const char* h : {"--help", "-h"}) {
    std::ostringstream out;
    // --help wins even over an unknown flag and a bad value before it.
    CHECK_FALSE(cli.parse(command({"--bogus", "--cv-q", "-1", h}), out));
    CHECK(out.str() == cli.help());
  }
  CHECK(q == 1.0);
  const std::string h = cli.help();
  CHECK(h ==
        "usage: prog [--seed N] [options]\n"
        "\n"
        "Does things.\n"
        "\n"
        "  --cv-q Q  acceleration noise (default 1 m^2/s^3)\n"
        "  --seed N  RNG seed (default 1)\n"
        "  --json    print JSON\n"
        "            second line\n"
        "  --help    print this help and exit\n"
        "\n"
        "Exit status: 0, 1, 2.\n");
}

TEST_CASE("apps::Parser: each usage mistake is a usage_error naming it", "[examples][cli]") {
  double var = 1.0, offset = 0.0, tol = 0.01;
  std::optional<std::uint64_t> seed;
  int k = 5;
  std::optional<fs::path> file;
  bool json = false;
  std::string mode = "a";
  apps::Parser cli("prog", "", "");
  cli.real({.name = "--var", .value = "V", .help = "variance"}, var, apps::Domain::kPositive);
  cli.real({.name = "--offset", .value = "X", .help = "offset"}, offset);
  cli.real({.name = "--tol", .value = "S", .help = "tolerance"}, tol, apps::Domain::kNonNegative);
  cli.integer({.name = "--seed", .value = "N", .help = "seed"}, seed, std::uint64_t{0});
  cli.integer({.name = "--k", .value = "K", .help = "k"}, k, -3, 7);
  cli.input({.name = "--file", .value = "FILE", .help = "file"}, file);
  cli.flag({.name = "--json", .help = "json"}, json);
  cli.custom({.name = "--mode", .value = "a|b", .help = "mode"}, [&](std::string_view v) {
    if (v != "a" && v != "b") throw posefuse::invalid_argument("unknown mode '" + std::string(v) + "'");
    mode = std::string(v);
  });
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--bogus"}, "unknown option '--bogus'"},
      {{"--bogus=3"}, "unknown option '--bogus'"},
      {{"extra"}, "unexpected argument 'extra'"},
      {{"-v"}, "unexpected argument '-v'"},
      {{"--"}, "unexpected argument '--'"},
      {{"--var"}, "--var needs a value (V)"},
      {{"--file", "--json"}, "--file needs a value (FILE)"},
      {{"--json=1"}, "--json takes no value"},
      {{"--json", "--json"}, "--json is given more than once"},
      {{"--var", "1", "--var", "2"}, "--var is given more than once"},
      {{"--var", "0"}, "--var: expected a finite number > 0, got '0'"},
      {{"--var", "-1"}, "--var: expected a finite number > 0, got '-1'"},
      {{"--var", "-0"}, "--var: expected a finite number > 0, got '-0'"},
      {{"--var", "inf"}, "--var: expected a finite number > 0, got 'inf'"},
      {{"--var", "nan"}, "--var: expected a finite number > 0, got 'nan'"},
      {{"--var", "1e400"}, "--var: expected a finite number > 0, got '1e400' (out of the range of a double)"},
      {{"--offset", "abc"}, "--offset: expected a finite number, got 'abc'"},
      {{"--offset", " 1"}, "--offset: expected a finite number, got ' 1'"},
      {{"--offset", "1 "}, "--offset: expected a finite number, got '1 '"},
      {{"--offset", "+1"}, "--offset: expected a finite number, got '+1'"},
      {{"--offset", "1,5"}, "--offset: expected a finite number, got '1,5'"},
      {{"--offset", "0x10"}, "--offset: expected a finite number, got '0x10'"},
      {{"--offset="}, "--offset: expected a finite number, got ''"},
      {{"--tol", "-0.1"}, "--tol: expected a finite number >= 0, got '-0.1'"},
      {{"--seed", "-3"}, "--seed: expected a non-negative integer, got '-3'"},
      {{"--seed", "99999999999999999999999"},
       "--seed: expected a non-negative integer, got '99999999999999999999999' (out of range)"},
      {{"--seed", "18446744073709551616"},
       "--seed: expected a non-negative integer, got '18446744073709551616' (out of range)"},
      {{"--seed", "1.5"}, "--seed: expected a non-negative integer, got '1.5'"},
      {{"--seed", "1e3"}, "--seed: expected a non-negative integer, got '1e3'"},
      {{"--seed", "+4"}, "--seed: expected a non-negative integer, got '+4'"},
      {{"--k", "8"}, "--k: expected an integer from -3 to 7, got '8' (out of range)"},
      {{"--k", "-4"}, "--k: expected an integer from -3 to 7, got '-4' (out of range)"},
      {{"--file="}, "--file: expected a path, got ''"},
      {{"--mode", "c"}, "--mode: unknown mode 'c'"},
  };
  for (const Case& c : cases) {
    INFO(c.args.front() << (c.args.size() > 1 ? " " + c.args[1] : std::string()));
    CHECK(usage_message(cli, c.args) == c.message);
  }
  // A failed parse of --seed leaves the target as it was (no wrap-around to 2^64 - 1).
  seed.reset();
  CHECK_FALSE(usage_message(cli, {"--seed", "99999999999999999999999"}).empty());
  CHECK_FALSE(seed.has_value());
  // Accepted edge values.
  CHECK(usage_message(cli, {"--var", "4.9e-324", "--tol", "0", "--k", "-3", "--offset", "-1e308"}).empty());
  CHECK(var == 4.9e-324);
  CHECK(tol == 0.0);
  CHECK(k == -3);
  CHECK(offset == -1e308);
  CHECK(usage_message(cli, {"--file=--odd-name"}).empty());  // the = form takes any value
  REQUIRE(file);
  CHECK(*file == "--odd-name");
}

TEST_CASE("apps::Parser: an output naming an input or another output is a usage error",
          "[examples][cli][outputs]") {
  const posefuse::test::TempDir dir("cli-roles");
  const fs::path in = dir.write("in.csv", "1\n");
  fs::create_directory(dir.path() / "sub");
  fs::create_symlink(in, dir.path() / "link.csv");
  const auto parse = [&](std::vector<std::string> args) {
    std::optional<fs::path> input, out, svg;
    std::vector<fs::path> more;
    std::string loops;
    apps::Parser cli("prog", "", "");
    cli.input({.name = "--in", .value = "FILE", .help = "input"}, input);
    cli.inputs({.name = "--more", .value = "FILE", .help = "inputs"}, more);
    cli.output({.name = "--out", .value = "FILE", .help = "output"}, out);
    cli.output({.name = "--svg", .value = "FILE", .help = "plot"}, svg);
    cli.custom({.name = "--loops", .value = "FILE|auto", .help = "a file or auto",
                .role = apps::PathRole::kInput, .keywords = {"auto"}},
               [&](std::string_view v) { loops = std::string(v); });
    for (std::string& a : args) a = posefuse::test::expand(a, dir);
    std::ostringstream help;
    return cli.parse(command(args), help);
  };
  const auto refused = [&](std::vector<std::string> args) {
    try {
      (void)parse(std::move(args));
    } catch (const apps::usage_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string d = dir.path().string();
  // Spellings of one file: ./, dir/../, a symbolic link, a trailing separator.
  CHECK(refused({"--in", "{dir}/in.csv", "--out", "{dir}/./in.csv"}) ==
        "--out " + d + "/./in.csv is the input of --in; it would be overwritten");
  CHECK(refused({"--in", "{dir}/in.csv", "--svg", "{dir}/sub/../in.csv"}).find("--svg") == 0);
  CHECK(refused({"--in", "{dir}/link.csv", "--out", "{dir}/in.csv"}).find("is the input of --in") != std::string::npos);
  CHECK(refused({"--more", "{dir}/x.csv", "--more", "{dir}/in.csv", "--out", "{dir}/in.csv"}).find("--more") !=
        std::string::npos);
  CHECK(refused({"--in", "{dir}/sub", "--out", "{dir}/sub/"}).find("is the input of --in") != std::string::npos);
  // Outputs that do not exist yet are compared as paths.
  CHECK(refused({"--out", "{dir}/new.csv", "--svg", "{dir}/./new.csv"}) ==
        "--out " + d + "/new.csv and --svg " + d + "/./new.csv name the same file; one would overwrite the other");
  // A custom flag with a role: its keywords are not paths.
  CHECK(refused({"--loops", "{dir}/in.csv", "--out", "{dir}/in.csv"}).find("is the input of --loops") !=
        std::string::npos);
  CHECK(refused({"--loops", "auto", "--out", "auto"}).empty());
  // Distinct files, and devices (which replace no file), are accepted.
  CHECK(refused({"--in", "{dir}/in.csv", "--out", "{dir}/out.csv", "--svg", "{dir}/out.svg"}).empty());
  CHECK(refused({"--out", "/dev/null", "--svg", "/dev/null"}).empty());
  CHECK(refused({"--in", "/dev/null", "--out", "/dev/null"}).empty());
}

TEST_CASE("apps::Parser: real_in bounds a value and says so in --help", "[examples][cli]") {
  double rate = 20;
  apps::Parser cli("prog", "", "");
  cli.real_in({.name = "--rate", .value = "HZ", .help = "frame rate", .unit = "Hz"}, rate, 0.1, 1000.0);
  std::ostringstream help;
  CHECK(cli.help().find("frame rate; 0.1 to 1000 (default 20 Hz)") != std::string::npos);
  REQUIRE(cli.parse(command({"--rate", "1000"}), help));
  CHECK(rate == 1000);
  for (const char* bad : {"2e6", "0.09", "-1", "nan", "inf"}) {
    INFO(bad);
    CHECK_THROWS_AS(cli.parse(command({"--rate", bad}), help), apps::usage_error);
  }
  try {
    (void)cli.parse(command({"--rate", "2e6"}), help);
  } catch (const apps::usage_error& e) {
    CHECK(std::string(e.what()) == "--rate: expected a number from 0.1 to 1000, got '2e6'");
  }
  CHECK(apps::num(104.99993599999999) == "105");
  CHECK(apps::num(1e-9) == "1e-09");
}

TEST_CASE("apps::Parser: declaring a flag twice or a bad name is a programming error",
          "[examples][cli]") {
  bool a = false;
  apps::Parser cli("prog", "", "");
  cli.flag({.name = "--a", .help = "a"}, a);
  CHECK_THROWS_AS(cli.flag({.name = "--a", .help = "again"}, a), std::logic_error);
  CHECK_THROWS_AS(cli.flag({.name = "--help", .help = "mine"}, a), std::logic_error);
  CHECK_THROWS_AS(cli.flag({.name = "-b", .help = "short"}, a), std::logic_error);
  CHECK_THROWS_AS(cli.flag({.name = "--b=c", .help = "eq"}, a), std::logic_error);
}

TEST_CASE("apps::split_commas: items in order, empty ones kept, the count bounded", "[examples][cli]") {
  using V = std::vector<std::string_view>;
  CHECK(apps::split_commas("a,b,c", 1, 5, "x") == V{"a", "b", "c"});
  CHECK(apps::split_commas("", 1, 1, "x") == V{""});
  CHECK(apps::split_commas("a,,b,", 1, 5, "x") == V{"a", "", "b", ""});
  CHECK_THROWS_WITH(apps::split_commas("1,2,3", 2, 2, "DIST,ANGLE"), "expected DIST,ANGLE, got '1,2,3'");
  CHECK_THROWS_WITH(apps::split_commas("1", 2, 2, "DIST,ANGLE"), "expected DIST,ANGLE, got '1'");
}

TEST_CASE("apps::parse_imu_noise: four values in [lo, 100], stored where ImuNoise keeps them", "[examples][cli]") {
  const posefuse::ImuNoise n = apps::parse_imu_noise("1,2,3,4", 1e-8);
  CHECK(n.accel_noise_density == 1.0);
  CHECK(n.gyro_noise_density == 2.0);
  CHECK(n.accel_random_walk == 3.0);
  CHECK(n.gyro_random_walk == 4.0);
  CHECK(apps::parse_imu_noise("0,0,0,0", 0.0).gyro_noise_density == 0.0);  // a noise-free simulator
  CHECK_THROWS_AS(apps::parse_imu_noise("0,0,0,0", 1e-8), apps::usage_error);
  CHECK_THROWS_WITH(apps::parse_imu_noise("1,2,3", 0.0), "expected four comma-separated numbers, got '1,2,3'");
  CHECK_THROWS_WITH(apps::parse_imu_noise("1,2,3,101", 0.0), "each value must be from 0 to 100, got '1,2,3,101'");
  CHECK_THROWS_AS(apps::parse_imu_noise("1,2,x,4", 0.0), apps::usage_error);
}

TEST_CASE("apps::parse_real does not depend on the C locale", "[examples][cli]") {
  // std::from_chars ignores the locale; strtod would read "0,5" under de_DE.
  const char* previous = std::setlocale(LC_NUMERIC, nullptr);
  const std::string saved = previous ? previous : "C";
  const bool german = std::setlocale(LC_NUMERIC, "de_DE.UTF-8") != nullptr;
  CHECK(apps::parse_real("0.5") == 0.5);
  CHECK_THROWS_AS(apps::parse_real("0,5"), apps::usage_error);
  std::setlocale(LC_NUMERIC, saved.c_str());
  if (!german) WARN("de_DE.UTF-8 locale not installed: checked under the C locale only");
}

TEST_CASE("apps::run_main maps outcomes to exit codes with one line on stderr",
          "[examples][cli]") {
  SECTION("success returns the body's code; a void body returns 0") {
    const auto [code, err] = run_main_with([](const apps::CommandLine& c) {
      return c.program == "prog" && c.args.size() == 2 && c.args[1] == "b" ? 0 : 7;
    }, {"/some/dir/prog", "a", "b"});
    CHECK(code == 0);
    CHECK(err.empty());
    const auto [code2, err2] = run_main_with([](const apps::CommandLine&) {});
    CHECK(code2 == 0);
    CHECK(err2.empty());
  }
  SECTION("usage_error: exit 2, the reason and 'try --help'") {
    const auto [code, err] = run_main_with([](const apps::CommandLine&) -> int {
      throw apps::usage_error("unknown option '--x'");
    });
    CHECK(code == apps::kExitUsage);
    CHECK(code == 2);
    CHECK(err == "prog: unknown option '--x' (try --help)\n");
  }
  SECTION("io_error: exit 1, naming file:line") {
    const auto [code, err] = run_main_with([](const apps::CommandLine&) -> int {
      throw posefuse::io_error("data/est.txt", 17, "expected 12 numbers");
    });
    CHECK(code == apps::kExitData);
    CHECK(code == 1);
    CHECK(err == "prog: data/est.txt:17: expected 12 numbers\n");
  }
  SECTION("data_error and other exceptions: exit 1, one line even for a multi-line message") {
    const auto [code, err] = run_main_with([](const apps::CommandLine&) -> int {
      throw apps::data_error("RMSE is not finite\nsecond line");
    });
    CHECK(code == 1);
    CHECK(err == "prog: RMSE is not finite second line\n");
    const auto [code2, err2] = run_main_with([](const apps::CommandLine&) -> int {
      throw posefuse::invalid_argument("poses differ in number");
    });
    CHECK(code2 == 1);
    CHECK(err2 == "prog: poses differ in number\n");
    const auto [code3, err3] = run_main_with([](const apps::CommandLine&) -> int { throw 42; });
    CHECK(code3 == 1);
    CHECK(err3 == "prog: unknown error\n");
  }
}

// ---------------------------------------------------------------------------
// JSON

TEST_CASE("apps::JsonWriter: strings are fully escaped", "[examples][json]") {
  using W = apps::JsonWriter;
  CHECK(W::quote("plain") == "\"plain\"");
  CHECK(W::quote("a\"b\\c/d") == "\"a\\\"b\\\\c/d\"");
  CHECK(W::quote("\b\f\n\r\t") == "\"\\b\\f\\n\\r\\t\"");
  CHECK(W::quote(std::string("\x00\x01\x1f\x7f", 4)) == "\"\\u0000\\u0001\\u001f\\u007f\"");
  CHECK(W::quote("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80") == "\"caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80\"");
  CHECK(W::quote("bad \xFF end") == "\"bad \\ufffd end\"");
  CHECK(W::quote("\xC0\xAF") == "\"\\ufffd\\ufffd\"");          // overlong '/'
  CHECK(W::quote("\xED\xA0\x80") == "\"\\ufffd\\ufffd\\ufffd\"");  // a surrogate
  CHECK(W::quote("\xE2\x82") == "\"\\ufffd\\ufffd\"");          // truncated
  // Every byte value round-trips through a strict reader to valid JSON.
  std::string all;
  for (int c = 0; c < 128; ++c) all += static_cast<char>(c);
  const Json j = Json::parse(W::quote(all));
  CHECK(j.string() == all);
}

TEST_CASE("apps::JsonWriter: numbers round-trip and non-finite ones are null", "[examples][json]") {
  using W = apps::JsonWriter;
  CHECK(W::number(std::numeric_limits<double>::quiet_NaN()) == "null");
  CHECK(W::number(std::numeric_limits<double>::infinity()) == "null");
  CHECK(W::number(-std::numeric_limits<double>::infinity()) == "null");
  CHECK(W::number(0.1) == "0.1");
  CHECK(W::number(1.0) == "1");
  CHECK(W::number(-2.5e-300) == "-2.5e-300");
  CHECK(W::number(1e300) == "1e+300");
  std::mt19937_64 rng(20240611);
  std::uniform_int_distribution<std::uint64_t> bits;
  int checked = 0;
  while (checked < 2000) {
    double v;
    const std::uint64_t b = bits(rng);
    std::memcpy(&v, &b, sizeof v);
    if (!std::isfinite(v)) continue;
    const std::string s = W::number(v);
    const Json j = Json::parse(s);  // valid JSON number grammar
    CHECK(j.number() == v);         // and the same double, bit for bit
    ++checked;
  }
  std::ostringstream out;
  W w(out);
  w.begin_array().value(std::numeric_limits<std::uint64_t>::max()).value(std::int64_t{-5})
      .value(std::numeric_limits<double>::quiet_NaN()).value(true).null().end_array().finish();
  CHECK(out.str() == "[18446744073709551615, -5, null, true, null]\n");
}

TEST_CASE("apps::JsonWriter: block and inline layouts give valid JSON", "[examples][json]") {
  std::ostringstream out;
  using L = apps::JsonWriter::Layout;
  apps::JsonWriter w(out);
  w.begin_object();
  w.member("name", "a \"b\"").member("n", std::size_t{3}).member("ok", false);
  w.key("empty_block").begin_array(L::kBlock).end_array();
  w.key("empty").begin_object().end_object();
  w.key("list").begin_array(L::kBlock);
  w.begin_object(L::kInline).member("x", 1.5).key("v").begin_array().value(1).value(2).end_array().end_object();
  w.value("s");
  w.end_array();
  w.key("inline").begin_object(L::kInline).member("deep", std::string("y")).key("o").begin_object().end_object().end_object();
  w.end_object().finish();
  CHECK(out.str() ==
        "{\n"
        "  \"name\": \"a \\\"b\\\"\",\n"
        "  \"n\": 3,\n"
        "  \"ok\": false,\n"
        "  \"empty_block\": [],\n"
        "  \"empty\": {},\n"
        "  \"list\": [\n"
        "    {\"x\": 1.5, \"v\": [1, 2]},\n"
        "    \"s\"\n"
        "  ],\n"
        "  \"inline\": {\"deep\": \"y\", \"o\": {}}\n"
        "}\n");
  const Json j = Json::parse(out.str());
  CHECK(j["name"].string() == "a \"b\"");
  CHECK(j["list"][0]["v"][1].number() == 2);
  CHECK(j["inline"]["o"].object().empty());
}

TEST_CASE("apps::JsonWriter: misuse throws logic_error", "[examples][json]") {
  std::ostringstream out;
  {
    apps::JsonWriter w(out);
    w.begin_object();
    CHECK_THROWS_AS(w.value(1), std::logic_error);  // no key
  }
  {
    apps::JsonWriter w(out);
    w.begin_array();
    CHECK_THROWS_AS(w.key("k"), std::logic_error);  // key in an array
    CHECK_THROWS_AS(w.end_object(), std::logic_error);
    CHECK_THROWS_AS(w.finish(), std::logic_error);  // still open
  }
  {
    apps::JsonWriter w(out);
    w.begin_object().key("k");
    CHECK_THROWS_AS(w.key("again"), std::logic_error);
    CHECK_THROWS_AS(w.end_object(), std::logic_error);  // key without value
  }
  {
    apps::JsonWriter w(out);
    w.value(1);
    CHECK_THROWS_AS(w.value(2), std::logic_error);  // two top-level values
    CHECK_NOTHROW(w.finish());
  }
  {
    apps::JsonWriter w(out);
    CHECK_THROWS_AS(w.finish(), std::logic_error);  // empty document
  }
}

TEST_CASE("The test's JSON reader rejects what is not JSON", "[examples][json]") {
  // The end-to-end tests rely on this reader; it must be strict.
  for (const char* bad : {"", "{", "[1,]", "{\"a\":1,}", "{'a':1}", "nan", "NaN", "-nan", "inf",
                          "01", "1.", ".5", "+1", "1e", "\"a\nb\"", "\"\\x\"", "[1] [2]",
                          "{\"a\":1,\"a\":2}", "tru", "nul"}) {
    INFO(bad);
    CHECK_THROWS(Json::parse(bad));
  }
  CHECK(Json::parse(" {\"a\": [1, -0.5e-3, true, false, null, \"\\u00e9\"]} ")["a"][1].number() ==
        -0.5e-3);
}

// ---------------------------------------------------------------------------
// SVG

TEST_CASE("apps::svg: non-finite coordinates are refused, text is escaped", "[examples][svg]") {
  namespace svg = apps::svg;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  using Points = std::vector<svg::Point>;
  svg::Plot p("t");
  CHECK_THROWS_AS(p.line("raw", Points{{0, 0}, {1, nan}}, {}), posefuse::invalid_argument);
  CHECK_THROWS_WITH(p.line("raw", Points{{0, 0}, {inf, 1}}, {}),
                    Catch::Contains("'raw'") && Catch::Contains("index 1"));
  CHECK_THROWS_AS(p.line("v", std::vector<Eigen::Vector2d>{Eigen::Vector2d(nan, 0)}, {}),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(p.markers("m", {{-inf, 0}}, svg::Marker::kCircle, {}), posefuse::invalid_argument);
  CHECK_THROWS_AS(p.include({nan, 0}), posefuse::invalid_argument);
  CHECK_THROWS_AS(svg::coordinate(nan), posefuse::invalid_argument);
  CHECK_THROWS_AS(svg::Document(0, 10), posefuse::invalid_argument);
  CHECK_THROWS_AS(svg::Document(10, nan), posefuse::invalid_argument);
  svg::Document d(100, 100);
  CHECK_THROWS_AS(d.line({0, 0}, {nan, 1}, {}), posefuse::invalid_argument);
  CHECK_THROWS_AS(d.plot(p, {0, 0, 50, 50}), posefuse::invalid_argument);  // too small
  CHECK(svg::escape("<a & 'b' \"c\">") == "&lt;a &amp; &apos;b&apos; &quot;c&quot;&gt;");
  CHECK(svg::escape("x\x01y") == "x\xEF\xBF\xBDy");
  CHECK(svg::escape("\xFF") == "\xEF\xBF\xBD");
  CHECK(svg::escape("\xC2\xB2") == "\xC2\xB2");  // "²" kept
  CHECK(svg::coordinate(-0.001) == "0.00");
  CHECK(svg::coordinate(12.345) == "12.35");
}

TEST_CASE("apps::svg: a plot has title, axes with units, legend and equal aspect", "[examples][svg]") {
  namespace svg = apps::svg;
  svg::Plot p("paths <A&B>");
  p.x_axis("x", "m").y_axis("z", "m").equal_aspect();
  using Points = std::vector<svg::Point>;
  p.line("truth", Points{{0, 0}, {10, 5}}, {"#000000", 2.0, {}});
  p.line("", Points{{0, 5}, {10, 0}}, {"red", 1.0, "4,2"});  // no legend entry
  p.markers("start", {{0, 0}}, svg::Marker::kSquare, {"blue", 1.0, {}});
  CHECK(p.legend_entries() == 2);
  svg::Document d(600, 400);
  d.plot(p, {0, 0, 600, 400});
  const std::string s = d.str();
  CHECK(s.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"600.00\" height=\"400.00\"", 0) == 0);
  CHECK(s.size() > 7);
  CHECK(s.substr(s.size() - 7) == "</svg>\n");
  CHECK(s.find("paths &lt;A&amp;B&gt;") != std::string::npos);
  CHECK(s.find(">x (m)</text>") != std::string::npos);
  CHECK(s.find(">z (m)</text>") != std::string::npos);
  CHECK(s.find(">truth</text>") != std::string::npos);
  CHECK(s.find(">start</text>") != std::string::npos);
  CHECK(s.find("stroke-dasharray=\"4,2\"") != std::string::npos);
  CHECK(s.find("nan") == std::string::npos);
  CHECK(s.find("inf") == std::string::npos);
  // Equal aspect: the first data polyline spans 10 x 5 m, so 2:1 in pixels.
  const std::size_t at = s.find("<polyline");
  REQUIRE(at != std::string::npos);
  const std::size_t pts = s.find("points=\"", at) + 8;
  const std::string list = s.substr(pts, s.find('"', pts) - pts);
  double x0, y0, x1, y1;
  REQUIRE(std::sscanf(list.c_str(), "%lf,%lf %lf,%lf", &x0, &y0, &x1, &y1) == 4);
  CHECK((x1 - x0) / (y0 - y1) == Approx(2.0).epsilon(1e-3));  // y up: y1 above y0
}

// ---------------------------------------------------------------------------
// Output files

TEST_CASE("apps::OutputFiles: write-then-rename, all or nothing", "[examples][output]") {
  posefuse::test::TempDir dir("outputs");
  const fs::path a = dir.path() / "a.txt", b = dir.path() / "b.svg";

  SECTION("files appear complete and no temporary is left") {
    apps::OutputFiles files;
    files.add(a, "alpha\n");
    files.add_with(b, [](const fs::path& p) { apps::write_text_file(p, "<svg/>\n"); });
    CHECK(listing(dir.path()).empty());  // nothing before commit
    files.commit();
    CHECK(posefuse::test::slurp(a) == "alpha\n");
    CHECK(posefuse::test::slurp(b) == "<svg/>\n");
    CHECK(listing(dir.path()) == std::vector<std::string>{"a.txt", "b.svg"});
  }
  SECTION("a failing output leaves the others unwritten and old files intact") {
    (void)dir.write("a.txt", "old content\n");
    apps::OutputFiles files;
    files.add(a, "new content\n");
    files.add(dir.path() / "missing" / "c.txt", "never\n");
    CHECK_THROWS_WITH(files.commit(), Catch::Contains("missing/c.txt") &&
                                          Catch::Contains("cannot open for writing"));
    CHECK(posefuse::test::slurp(a) == "old content\n");
    CHECK(listing(dir.path()) == std::vector<std::string>{"a.txt"});
  }
  SECTION("a writer that fails half-way leaves no partial file; its message names the output") {
    apps::OutputFiles files;
    files.add_with(a, [](const fs::path& p) {
      std::ofstream(p) << "half of the";
      throw posefuse::io_error(p, 2, "disk full");
    });
    CHECK_THROWS_WITH(files.commit(), a.string() + ":2: disk full");
    CHECK(listing(dir.path()).empty());
  }
  SECTION("/dev/full: a write error, and the device is not replaced") {
    apps::OutputFiles files;
    files.add(dir.path() / "ok.txt", "fine\n");
    files.add("/dev/full", std::string(1 << 16, 'x'));
    CHECK_THROWS_WITH(files.commit(), Catch::Contains("/dev/full") && Catch::Contains("write failed"));
    struct stat st {};
    REQUIRE(::stat("/dev/full", &st) == 0);
    CHECK(S_ISCHR(st.st_mode));
    CHECK(listing(dir.path()).empty());  // ok.txt was not renamed into place either
  }
  SECTION("/dev/null is written in place") {
    apps::OutputFiles files;
    files.add("/dev/null", "discarded\n");
    CHECK_NOTHROW(files.commit());
    struct stat st {};
    REQUIRE(::stat("/dev/null", &st) == 0);
    CHECK(S_ISCHR(st.st_mode));
  }
  SECTION("a symbolic link is followed and kept") {
    (void)dir.write("real.txt", "old\n");
    fs::create_symlink("real.txt", dir.path() / "link.txt");
    apps::OutputFiles files;
    files.add(dir.path() / "link.txt", "new\n");
    files.commit();
    CHECK(fs::is_symlink(dir.path() / "link.txt"));
    CHECK(posefuse::test::slurp(dir.path() / "real.txt") == "new\n");
  }
  SECTION("the same path twice and a folder as a file are refused") {
    apps::OutputFiles files;
    files.add(a, "1");
    CHECK_THROWS_AS(files.add(dir.path() / "." / "a.txt", "2"), posefuse::invalid_argument);
    apps::OutputFiles onto_folder;
    onto_folder.add(dir.path(), "x");
    CHECK_THROWS_WITH(onto_folder.commit(), Catch::Contains("is a folder"));
  }
  SECTION("a folder output: its files replace those of the same name, others are kept") {
    const fs::path log = dir.path() / "log";
    fs::create_directories(log);
    (void)dir.write("log/wheels.csv", "old\n");
    (void)dir.write("log/notes.txt", "mine\n");
    apps::OutputFiles files;
    files.add_folder(log, [](const fs::path& d) {
      apps::write_text_file(d / "wheels.csv", "new\n");
      apps::write_text_file(d / "imu.csv", "imu\n");
    });
    files.commit();
    CHECK(posefuse::test::slurp(log / "wheels.csv") == "new\n");
    CHECK(posefuse::test::slurp(log / "imu.csv") == "imu\n");
    CHECK(posefuse::test::slurp(log / "notes.txt") == "mine\n");
    CHECK(listing(dir.path()) == std::vector<std::string>{"log"});
  }
  SECTION("a folder output that fails is not created, and names the file inside it") {
    const fs::path log = dir.path() / "new_log";
    apps::OutputFiles files;
    files.add_folder(log, [](const fs::path& d) {
      apps::write_text_file(d / "robot.txt", "ok\n");
      throw posefuse::io_error(d / "imu.csv", "write failed");
    });
    CHECK_THROWS_WITH(files.commit(), (log / "imu.csv").string() + ": write failed");
    CHECK(listing(dir.path()).empty());
  }
}

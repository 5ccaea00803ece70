// The recorded-log folder format (issue 3 item 7): round trip through the
// simulator, and file:line errors for malformed input.
#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/sim/corridor.hpp>

namespace fs = std::filesystem;

namespace {

// A scratch folder removed at the end of the test.
class Scratch {
 public:
  Scratch() {
    static std::atomic<int> n{0};
    path_ = fs::temp_directory_path() /
            ("posefuse-robotlog-" + std::to_string(::getpid()) + "-" + std::to_string(n++) + "-" +
             std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(path_);
  }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return path_; }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name, std::ios::binary) << text;
  }

 private:
  fs::path path_;
};

const char* kRobot =
    "# robot\nticks_per_rev 1320\nwheel_radius_m 0.065\ntrack_width_m 0.4\n"
    "complementary_alpha 0.98\nfuser_threshold 0.01\n";
// Rows 0.1 s apart (t_ns in nanoseconds, as the format requires).
const char* kWheels =
    "# t_ns,fl,fr,bl,br\n100000000,0,0,0,0\n200000000,5,6,5,6\n300000000,10,12,10,12\n";
const char* kImu = "# t_ns,ax,ay,az,gx,gy,gz,mx,my,mz\n150000000,0,0,9.81,0,0,0,30,0,-40\n";
const char* kSlam = "# t_ns,state,x,y,z,qx,qy,qz,qw\n120000000,lost,0,0,0,0,0,0,1\n"
                    "220000000,tracking,0.1,0,0,0,0,0,1\n";

// A valid minimal log in `d`, then `name` replaced by `text`.
void minimal_log(const Scratch& d, const std::string& name = "", const std::string& text = "") {
  d.write("robot.txt", kRobot);
  d.write("wheels.csv", kWheels);
  d.write("imu.csv", kImu);
  d.write("slam.csv", kSlam);
  if (!name.empty()) d.write(name, text);
}

// The message of the io_error read_robot_log throws.
std::string error_of(const Scratch& d) {
  try {
    (void)posefuse::read_robot_log(d.path());
  } catch (const posefuse::io_error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("RobotLog: a minimal log reads back with every field", "[sim][io][robot_log]") {
  Scratch d;
  minimal_log(d);
  const auto log = posefuse::read_robot_log(d.path());
  CHECK(log.params.ticks_per_rev == 1320);
  CHECK(log.params.track_width_m == 0.4);
  REQUIRE(log.wheels.size() == 3);
  CHECK(log.wheels[2].ticks.fr == 12);
  REQUIRE(log.imu.size() == 1);
  CHECK(log.imu[0].mag_uT.z() == -40);
  REQUIRE(log.slam.size() == 2);
  CHECK(log.slam[0].state == posefuse::SlamState::kLost);
  CHECK(log.slam[1].position_m.x() == 0.1);
  CHECK(log.slam[1].orientation.w() == 1.0);
  CHECK(log.groundtruth.empty());
}

TEST_CASE("RobotLog: the simulator's log round-trips bit-identically", "[sim][io][robot_log]") {
  Scratch d;
  const auto sim = posefuse::sim::simulate_corridor({}, 3);
  posefuse::write_robot_log(d.path(), sim.log);
  for (const char* f : {"robot.txt", "wheels.csv", "imu.csv", "slam.csv", "groundtruth.csv"})
    CHECK(fs::is_regular_file(d.path() / f));
  const auto back = posefuse::read_robot_log(d.path());
  CHECK(back == sim.log);
  // Without ground truth the file is not written (and a stale one is removed).
  auto no_gt = sim.log;
  no_gt.groundtruth.clear();
  posefuse::write_robot_log(d.path(), no_gt);
  CHECK_FALSE(fs::exists(d.path() / "groundtruth.csv"));
  CHECK(posefuse::read_robot_log(d.path()) == no_gt);
}

TEST_CASE("RobotLog: liberal about headers, spaces, CRLF, case and lost rows", "[sim][io][robot_log]") {
  Scratch d;
  minimal_log(d, "slam.csv",
              "t_ns,state,x,y,z,qx,qy,qz,qw\r\n"  // uncommented column names
              "\r\n"
              "120000000 , LOST , nan,nan,nan,nan,nan,nan,nan\r\n"  // lost poses may be NaN
              "130000000,lost,,,,,,,\r\n"                            // ... or empty
              "220000000,Tracking, 0.1 ,0,0,0,0,0,1\r\n"
              "320000000,reinit,+5,0,0,0,0,0.7071068,0.7071068\r\n");
  d.write("robot.txt", std::string(kRobot) + "# trailing comment\n");
  const auto log = posefuse::read_robot_log(d.path());
  REQUIRE(log.slam.size() == 4);
  CHECK(log.slam[2].state == posefuse::SlamState::kTracking);
  CHECK(log.slam[3].state == posefuse::SlamState::kReinit);
  CHECK(log.slam[3].position_m.x() == 5.0);
  CHECK(log.slam[3].orientation.z() == 0.7071068);  // the file's column order is x, y, z, w
}

TEST_CASE("RobotLog: malformed files name file and line", "[sim][io][robot_log]") {
  struct Case {
    const char* file;
    const char* text;
    const char* where;  // "<file>:<line>"
    const char* what;   // part of the reason
  };
  const Case cases[] = {
      {"wheels.csv", "# h\n100,0,0,0,0\n200,1,2,3\n", "wheels.csv:3", "expected 5 columns"},
      {"wheels.csv", "100,0,0,0,0\n200,1,x,3,4\n", "wheels.csv:2", "column 'fr' is not an integer"},
      {"wheels.csv", "100,0,0,0,0\n100,1,1,1,1\n", "wheels.csv:2", "does not increase"},
      {"wheels.csv", "100,0,0,0,0\n200,1,1,1,1\n150,2,2,2,2\n", "wheels.csv:3", "does not increase"},
      {"imu.csv", "# h\n\n150,0,0,nan,0,0,0,30,0,-40\n", "imu.csv:3", "column 'az' is not finite"},
      {"imu.csv", "150,0,0,9.8,0,0,0,30,0,inf\n", "imu.csv:1", "column 'mz' is not finite"},
      {"imu.csv", "150,0,0,9.8,0,0,0,30,0,-40,7\n", "imu.csv:1", "expected 10 columns"},
      {"imu.csv", "150,0,0,9.8,0,0,0,30,0,1e999\n", "imu.csv:1", "column 'mz' is not a number"},
      {"slam.csv", "120,lost,0,0,0,0,0,0,1\n220,flying,0,0,0,0,0,0,1\n", "slam.csv:2",
       "column 'state' is not tracking, lost or reinit"},
      {"slam.csv", "220,tracking,0,0,0,0,0,0,2\n", "slam.csv:1", "not unit length"},
      {"slam.csv", "220,tracking,nan,0,0,0,0,0,1\n", "slam.csv:1", "column 'x' is not finite"},
      {"groundtruth.csv", "0,0,0,0\n10,1,2\n", "groundtruth.csv:2", "expected 4 columns"},
      {"robot.txt", "ticks_per_rev 1320\nwheel_radius_m -0.065\n", "robot.txt:2",
       "must be positive"},
      {"robot.txt", "ticks_per_rev 1320\nwheel_diameter_m 0.13\n", "robot.txt:2", "unknown key"},
      {"robot.txt", "ticks_per_rev 1320\nticks_per_rev 1000\n", "robot.txt:2", "duplicate key"},
      {"robot.txt", "ticks_per_rev abc\n", "robot.txt:1", "not a number"},
      {"robot.txt", "ticks_per_rev\n", "robot.txt:1", "expected 'key value'"},
      {"robot.txt",
       "ticks_per_rev 1320\nwheel_radius_m 0.065\ntrack_width_m 0.4\ncomplementary_alpha 1.5\n",
       "robot.txt:4", "(0, 1)"},
  };
  for (const auto& c : cases) {
    Scratch d;
    minimal_log(d, c.file, c.text);
    const std::string msg = error_of(d);
    INFO(c.file << ": " << msg);
    CHECK(msg.find(std::string(c.where) + ": ") != std::string::npos);
    CHECK(msg.find(c.what) != std::string::npos);
  }
}

TEST_CASE("RobotLog: missing files and keys are reported", "[sim][io][robot_log]") {
  for (const char* f : {"robot.txt", "wheels.csv", "imu.csv", "slam.csv"}) {
    Scratch d;
    minimal_log(d);
    fs::remove(d.path() / f);
    const std::string msg = error_of(d);
    INFO(msg);
    CHECK(msg.find(std::string(f) + ": required file is missing") != std::string::npos);
  }
  Scratch d;
  minimal_log(d, "robot.txt", "ticks_per_rev 1320\nwheel_radius_m 0.065\ntrack_width_m 0.4\n"
                              "complementary_alpha 0.98\n");
  CHECK(error_of(d).find("robot.txt: missing required key 'fuser_threshold'") != std::string::npos);
  minimal_log(d, "wheels.csv", "# only one row\n100,0,0,0,0\n");
  CHECK(error_of(d).find("wheels.csv: needs at least two data rows") != std::string::npos);
  CHECK_THROWS_AS(posefuse::read_robot_log(d.path() / "nope"), posefuse::io_error);
}

TEST_CASE("RobotLog: logs that parse but cannot be right are rejected, naming the file",
          "[sim][io][robot_log]") {
  struct Case {
    const char* file;
    const char* text;
    const char* where;  // "<file>:<line>: " or "<file>: "
    const char* what;   // part of the reason
  };
  const Case cases[] = {
      // A 16-bit counter wrapping around on fl: 5 -> -32760 in 0.1 s.
      {"wheels.csv", "# t_ns,fl,fr,bl,br\n100000000,0,0,0,0\n200000000,5,6,5,6\n300000000,-32760,12,10,12\n",
       "wheels.csv:4: ", "fl jumps from 5 to -32760 ticks in 0.1000 s"},
      {"wheels.csv", "100000000,0,0,0,0\n200000000,0,0,0,70000\n", "wheels.csv:2: ",
       "wrap-around or reset"},
      // Upside-down IMU (z down) and an IMU mounted on its side (gravity on x).
      {"imu.csv", "150000000,0,0,-9.81,0,0,0,30,0,-40\n", "imu.csv: ",
       "expected specific force +9.81 on z at rest, z up (REP-103)"},
      {"imu.csv", "150000000,9.8,0,0.3,0,0,0,30,0,-40\n", "imu.csv: ", "gravity is mostly on x/y"},
      // Another unit or epoch: slam.csv in microseconds, imu.csv in seconds.
      {"slam.csv", "120000,lost,0,0,0,0,0,0,1\n220000,tracking,0.1,0,0,0,0,0,1\n", "slam.csv: ",
       "nanoseconds on the same clock"},
      {"imu.csv", "0,0,0,9.81,0,0,0,30,0,-40\n1,0,0,9.81,0,0,0,30,0,-40\n", "imu.csv: ",
       "overlap by 0 %"},
      // Squeezed into a thousandth of the wheels' span (ms written as µs, say).
      {"groundtruth.csv", "100000000,0,0,0\n100100000,0,0,0\n100200000,0,0,0\n",
       "groundtruth.csv: ", "t_ns spans"},
      // Camera-frame poses: rotated 90 deg about x.
      {"slam.csv", "120000000,tracking,0,0,0,0.7071068,0,0,0.7071068\n"
                   "220000000,tracking,0,0,0.1,0.7071068,0,0,0.7071068\n",
       "slam.csv: ", "2 of 2 poses tilted more than 20 deg from z-up; expected robot body poses "
                     "in a z-up map frame (REP-103)"},
  };
  for (const auto& c : cases) {
    Scratch d;
    minimal_log(d, c.file, c.text);
    const std::string msg = error_of(d);
    INFO(c.file << ": " << msg);
    CHECK(msg.find((d.path() / c.where).string()) == 0);
    CHECK(msg.find(c.what) != std::string::npos);
  }
  // One tilted pose of three is not an error but a warning.
  Scratch d;
  minimal_log(d, "slam.csv", "120000000,tracking,0,0,0,0.7071068,0,0,0.7071068\n"
                             "170000000,tracking,0,0,0,0,0,0,1\n220000000,tracking,0.1,0,0,0,0,0,1\n");
  const auto log = posefuse::read_robot_log(d.path());
  const auto w = posefuse::check_robot_log(log, d.path());
  REQUIRE(w.size() == 1);
  CHECK(w[0].find("slam.csv: 1 valid poses are tilted") != std::string::npos);
}

TEST_CASE("RobotLog: doubtful encoders and ground truth give warnings", "[sim][io][robot_log]") {
  const auto sim = posefuse::sim::simulate_corridor({}, 1);
  CHECK(posefuse::check_robot_log(sim.log).empty());
  const auto warned = [](const std::vector<std::string>& w, const char* part) {
    return std::any_of(w.begin(), w.end(),
                       [&](const std::string& s) { return s.find(part) != std::string::npos; });
  };
  {  // The left side counts backwards: the path spins instead of driving.
    auto log = sim.log;
    for (auto& r : log.wheels) r.ticks.fl = -r.ticks.fl, r.ticks.bl = -r.ticks.bl;
    const auto w = posefuse::check_robot_log(log);
    CHECK(warned(w, "wheels.csv: the encoder path turns"));
    CHECK(warned(w, "does one side count backwards"));
  }
  {  // One wheel counts backwards.
    auto log = sim.log;
    for (auto& r : log.wheels) r.ticks.br = -r.ticks.br;
    CHECK(warned(posefuse::check_robot_log(log), "wheels.csv: the right wheels disagree"));
  }
  {  // Every wheel counts backwards.
    auto log = sim.log;
    for (auto& r : log.wheels)
      r.ticks = {-r.ticks.fl, -r.ticks.fr, -r.ticks.bl, -r.ticks.br};
    CHECK(warned(posefuse::check_robot_log(log), "wheels.csv: the encoder path runs mostly backwards"));
  }
  {  // Ground truth in another frame.
    auto log = sim.log;
    for (auto& g : log.groundtruth) g.pose.x() += 2.0;
    CHECK(warned(posefuse::check_robot_log(log, "d"), "groundtruth.csv: the first pose is (2.00 m"));
    log = sim.log;
    for (auto& g : log.groundtruth) g.pose(2) += 0.2;
    CHECK(warned(posefuse::check_robot_log(log), "ground truth in the odometry frame"));
  }
}

TEST_CASE("RobotLog: checks of counters and stamps at the ends of the int64 range do not overflow",
          "[sim][io][robot_log][overflow]") {
  constexpr std::int64_t lo = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int64_t>::max();
  const posefuse::RobotLogParams p{1320, 0.065, 0.4, 0.98, 0.01};
  // Regression: these tick and stamp differences overflowed int64 (undefined behaviour).
  const std::vector<posefuse::WheelSample> wrap{{0, {lo, 0, 0, 0}}, {100'000'000, {hi, 0, 0, 0}}};
  CHECK_THROWS_WITH(posefuse::check_wheel_increments(wrap, p, "wheels.csv"),
                    Catch::Contains("fl jumps from " + std::to_string(lo) + " to " +
                                    std::to_string(hi) + " ticks in 0.1000 s"));
  const std::vector<posefuse::WheelSample> far{{lo + 1, {0, 0, 0, 0}}, {hi, {10, 10, 10, 10}}};
  CHECK_NOTHROW(posefuse::check_wheel_increments(far, p, "wheels.csv"));  // 10 ticks in 585 years
  // The path warnings on the wrapped counter: finite numbers, the left side disagreeing.
  const auto w = posefuse::wheel_path_warnings(wrap, p, "wheels.csv");
  CHECK(std::any_of(w.begin(), w.end(), [](const std::string& s) {
    return s.find("wheels.csv: the left wheels disagree") != std::string::npos &&
           s.find("nan") == std::string::npos && s.find("inf") == std::string::npos;
  }));
  // Counters near the ends that move normally raise nothing.
  std::vector<posefuse::WheelSample> near_end;
  for (std::int64_t k = 0; k < 100; ++k)
    near_end.push_back({k * 20'000'000, {hi - 1000 + k, hi - 1000 + k, lo + k, lo + k}});
  CHECK_NOTHROW(posefuse::check_wheel_increments(near_end, p, "wheels.csv"));
}

TEST_CASE("RobotLog: numbers in messages are never truncated", "[sim][io][robot_log]") {
  // Regression: num_text printed through a 64-byte snprintf buffer, so the
  // 306 characters of 1e300 with 4 decimals were cut to 63.
  std::string expected(400, '\0');
  expected.resize(std::size_t(std::snprintf(expected.data(), expected.size(), "%.4f", 1e300)));
  REQUIRE(expected.size() == 306);
  CHECK(posefuse::detail::num_text(1e300, 4) == expected);
  CHECK(posefuse::detail::num_text(-1e300, 1).size() == 304);  // '-', 301 digits, ".0"
  CHECK(posefuse::detail::num_text(0.1, 4) == "0.1000");
  CHECK(posefuse::detail::num_text(-2.5e-7, 2) == "-0.00");
  // Through a check: a wheel radius of 1e300 m appears in full, and the
  // reason after it survives.
  const posefuse::RobotLogParams p{1320, 1e300, 0.4, 0.98, 0.01};
  const std::vector<posefuse::WheelSample> w{{0, {0, 0, 0, 0}}, {100'000'000, {5, 0, 0, 0}}};
  CHECK_THROWS_WITH(posefuse::check_wheel_increments(w, p, "wheels.csv"),
                    Catch::Contains("wheel_radius_m " + expected + " (more than 10 m/s)") &&
                        Catch::EndsWith("or t_ns not in nanoseconds?"));
}

namespace {

// A digit-grouping numpunct facet ("1,700,000,000"), so that the test needs
// no system locale to be installed.
struct GroupingNumpunct : std::numpunct<char> {
  char do_thousands_sep() const override { return ','; }
  std::string do_grouping() const override { return "\3"; }
};

}  // namespace

TEST_CASE("RobotLog: writing does not depend on the global locale", "[sim][io][robot_log]") {
  // Regression: the int64 columns went through operator<< with the global
  // locale, so a grouping locale wrote "1,700,000,000,..." into the CSV.
  Scratch d;
  const auto sim = posefuse::sim::simulate_corridor({}, 3);
  const std::locale old =
      std::locale::global(std::locale(std::locale::classic(), new GroupingNumpunct));
  std::ostringstream probe;
  probe << std::int64_t{1234567};
  const bool grouping = probe.str() == "1,234,567";
  try {
    posefuse::write_robot_log(d.path(), sim.log);
  } catch (...) {
    std::locale::global(old);
    throw;
  }
  std::locale::global(old);
  REQUIRE(grouping);
  CHECK(posefuse::read_robot_log(d.path()) == sim.log);
}

TEST_CASE("RobotLog: empty, unreadable, endless and over-long inputs name the file",
          "[sim][io][robot_log][errors]") {
  {  // An empty groundtruth.csv was read as "no ground truth" in silence.
    Scratch d;
    minimal_log(d, "groundtruth.csv", "# t_ns,x,y,yaw\n");
    CHECK(error_of(d) == (d.path() / "groundtruth.csv").string() +
                             ": has no data rows (remove the file when there is no ground truth)");
  }
  {  // A line over the cap is not read to its end.
    Scratch d;
    minimal_log(d, "wheels.csv",
                std::string(kWheels) + "#" + std::string(posefuse::kMaxLineBytes, ' ') + "\n");
    CHECK(error_of(d) == (d.path() / "wheels.csv").string() + ":5: line longer than " +
                             std::to_string(posefuse::kMaxLineBytes) + " bytes");
  }
  if (fs::exists("/proc/self/mem")) {  // reading it fails with EIO
    Scratch d;
    minimal_log(d);
    fs::remove(d.path() / "imu.csv");
    fs::create_symlink("/proc/self/mem", d.path() / "imu.csv");
    CHECK(error_of(d) == (d.path() / "imu.csv").string() + ":1: read error");
  }
  if (fs::exists("/dev/zero")) {
    Scratch d;
    minimal_log(d);
    fs::remove(d.path() / "slam.csv");
    fs::create_symlink("/dev/zero", d.path() / "slam.csv");
    CHECK(error_of(d) == (d.path() / "slam.csv").string() + ":1: line longer than " +
                             std::to_string(posefuse::kMaxLineBytes) + " bytes");
    fs::remove(d.path() / "slam.csv");
    fs::create_directory(d.path() / "slam.csv");
    CHECK(error_of(d) ==
          (d.path() / "slam.csv").string() + ": cannot open file for reading: it is a folder");
  }
}

TEST_CASE("RobotLog: a path component longer than the system allows is an io_error",
          "[sim][io][robot_log][errors]") {
  // Regression: ENAMETOOLONG escaped from std::filesystem::is_directory as
  // std::filesystem::filesystem_error.
  Scratch d;
  const fs::path dir = d.path() / std::string(300, 'a') / "log";
  const auto named = [&](const auto& f) {
    try {
      f();
    } catch (const posefuse::io_error& e) {
      return e.file() == dir && std::string(e.what()).rfind(dir.string() + ": ", 0) == 0;
    }
    return false;
  };
  CHECK(named([&] { (void)posefuse::read_robot_log(dir); }));
  CHECK(named([&] { posefuse::write_robot_log(dir, posefuse::sim::simulate_corridor({}, 1).log); }));
  // A too-long name inside an existing folder.
  const fs::path file = d.path() / (std::string(300, 'b') + ".txt");
  CHECK_THROWS_WITH(posefuse::read_robot_params(file),
                    Catch::StartsWith(file.string() + ": cannot access:"));
}

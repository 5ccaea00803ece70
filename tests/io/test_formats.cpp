// KITTI / TUM readers and writers: bit-exact round trips, and one test per
// malformed input checking that the io_error names the file and the line.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <locale>
#include <random>
#include <sstream>
#include <string>

#include <posefuse/io/formats.hpp>

#include "support/data_path.hpp"
#include "support/synthetic_trajectory.hpp"
#include "support/temp_dir.hpp"

namespace {

using posefuse::io_error;
using posefuse::test::TempDir;

// Runs f, which must throw posefuse::io_error, and returns the exception.
template <class F>
io_error expect_io_error(F&& f) {
  try {
    f();
  } catch (const io_error& e) {
    return e;
  }
  FAIL("expected posefuse::io_error");
  return io_error("", "unreachable");
}

// The error must name the file (full path) and the 1-based line, and contain `reason`.
void check_error(const io_error& e, const std::filesystem::path& file, std::size_t line,
                 const std::string& reason) {
  const std::string what = e.what();
  INFO(what);
  CHECK(e.file() == file);
  CHECK(e.line() == line);
  const std::string prefix =
      line > 0 ? file.string() + ":" + std::to_string(line) + ": " : file.string() + ": ";
  CHECK(what.rfind(prefix, 0) == 0);
  CHECK(what.find(reason) != std::string::npos);
}

const std::string kIdentityRow = "1 0 0 0 0 1 0 0 0 0 1 0\n";

// A digit-grouping numpunct facet ("1,234,567"), so that the test needs no
// system locale to be installed.
struct GroupingNumpunct : std::numpunct<char> {
  char do_thousands_sep() const override { return ','; }
  std::string do_grouping() const override { return "\3"; }
};

// Installs a grouping global locale for its lifetime, then restores the old one.
class GroupingGlobalLocale {
 public:
  GroupingGlobalLocale()
      : old_(std::locale::global(std::locale(std::locale::classic(), new GroupingNumpunct))) {}
  ~GroupingGlobalLocale() { std::locale::global(old_); }
  GroupingGlobalLocale(const GroupingGlobalLocale&) = delete;
  GroupingGlobalLocale& operator=(const GroupingGlobalLocale&) = delete;

 private:
  std::locale old_;
};

posefuse::Trajectory random_trajectory(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> dt(1e-3, 0.5);
  posefuse::Trajectory traj;
  double t = 1.6e9 + 0.123456789;  // Unix-like stamps need all 17 digits
  for (std::size_t k = 0; k < n; ++k) {
    traj.push_back(t, posefuse::test::random_pose(rng, 100.0));
    t += dt(rng);
  }
  return traj;
}

}  // namespace

TEST_CASE("Formats: KITTI writer and reader round-trip bit-exactly", "[io][kitti]") {
  TempDir dir("kitti-rt");
  posefuse::Trajectory traj = random_trajectory(200, 7);
  traj.poses[3].translation() = Eigen::Vector3d(5e-324, -0.0, 1e100);  // extremes survive (1e100 m: the largest accepted)
  posefuse::write_kitti(dir.path() / "poses.txt", traj);
  posefuse::write_kitti_times(dir.path() / "times.txt", traj);
  const posefuse::Trajectory back =
      posefuse::read_kitti(dir.path() / "poses.txt", dir.path() / "times.txt");
  REQUIRE(back.size() == traj.size());
  for (std::size_t k = 0; k < traj.size(); ++k) {
    CHECK(back.t_s[k] == traj.t_s[k]);
    CHECK(back.poses[k].matrix() == traj.poses[k].matrix());
  }
}

TEST_CASE("Formats: KITTI without times gets frame-index stamps", "[io][kitti]") {
  TempDir dir("kitti-idx");
  const auto file = dir.write("p.txt", kIdentityRow + kIdentityRow + "\n" + kIdentityRow);
  const posefuse::Trajectory traj = posefuse::read_kitti(file);
  REQUIRE(traj.size() == 3);
  CHECK(traj.t_s == std::vector<double>{0.0, 1.0, 2.0});
  CHECK(traj.poses[2].isApprox(Eigen::Isometry3d::Identity(), 0.0));
}

TEST_CASE("Formats: TUM round trip is bit-exact in stamps and positions", "[io][tum]") {
  TempDir dir("tum-rt");
  const posefuse::Trajectory traj = random_trajectory(200, 11);
  posefuse::write_tum(dir.path() / "t.tum", traj);
  const posefuse::Trajectory back = posefuse::read_tum(dir.path() / "t.tum");
  REQUIRE(back.size() == traj.size());
  for (std::size_t k = 0; k < traj.size(); ++k) {
    CHECK(back.t_s[k] == traj.t_s[k]);
    CHECK(back.poses[k].translation() == traj.poses[k].translation());
    // Rotations pass through a quaternion: equal to a few ulp, not bit for bit.
    CHECK((back.poses[k].linear() - traj.poses[k].linear()).cwiseAbs().maxCoeff() < 2e-15);
  }
}

TEST_CASE("Formats: TUM reader skips comments, blank lines and CRLF", "[io][tum]") {
  TempDir dir("tum-ok");
  const double c = std::cos(0.25), s = std::sin(0.25);  // 0.5 rad about z
  const std::string text = "# stamp x y z qx qy qz qw\r\n\r\n  1.0 1 2 3 0 0 " + std::to_string(s) +
                           " " + std::to_string(c) + "\r\n\t2.5\t4 5 6  0 0 0 1.00001\r\n";
  const posefuse::Trajectory traj = posefuse::read_tum(dir.write("a.tum", text));
  REQUIRE(traj.size() == 2);
  CHECK(traj.t_s[1] == 2.5);
  CHECK(traj.poses[0].translation() == Eigen::Vector3d(1, 2, 3));
  CHECK(Eigen::AngleAxisd(traj.poses[0].linear()).angle() == Approx(0.5).margin(1e-6));
  // The near-unit quaternion was normalised.
  CHECK(traj.poses[1].linear().isApprox(Eigen::Matrix3d::Identity(), 1e-15));
}

TEST_CASE("Formats: KITTI reader re-orthonormalises nearly orthonormal rotations", "[io][kitti]") {
  TempDir dir("kitti-orth");
  const auto file = dir.write("p.txt", "1.0002 0 0 0 0 0.9999 0 0 0 0 1 0\n");
  const posefuse::Trajectory traj = posefuse::read_kitti(file);
  const Eigen::Matrix3d R = traj.poses[0].linear();
  CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15);
  CHECK(R.isApprox(Eigen::Matrix3d::Identity(), 1e-15));
  // A stricter tolerance rejects the same file.
  posefuse::ReadOptions strict;
  strict.rotation_tolerance = 1e-4;
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(file, std::nullopt, strict); }),
              file, 1, "not orthonormal");
}

TEST_CASE("Formats: missing or unwritable files name the path", "[io][errors]") {
  TempDir dir("missing");
  const auto missing = dir.path() / "nope.txt";
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(missing); }), missing, 0,
              "cannot open");
  check_error(expect_io_error([&] { (void)posefuse::read_tum(missing); }), missing, 0,
              "cannot open");
  check_error(expect_io_error([&] { (void)posefuse::read_tum(dir.path()); }), dir.path(), 0,
              "cannot open");
  const auto kitti = dir.write("p.txt", kIdentityRow);
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(kitti, missing); }), missing, 0,
              "cannot open");
  const auto out = dir.path() / "no_such_dir" / "out.txt";
  const posefuse::Trajectory traj = posefuse::read_kitti(kitti);
  check_error(expect_io_error([&] { posefuse::write_kitti(out, traj); }), out, 0,
              "cannot open file for writing");
  check_error(expect_io_error([&] { posefuse::write_tum(out, traj); }), out, 0,
              "cannot open file for writing");
}

TEST_CASE("Formats: a read error is reported, not taken for the end of the file", "[io][errors]") {
  // Reading /proc/self/mem at offset 0 fails with EIO (badbit): the readers
  // returned an empty trajectory for it, as for an empty file.
  const std::filesystem::path mem = "/proc/self/mem";
  if (!std::filesystem::exists(mem)) {
    WARN("SKIPPED: no " << mem);
    return;
  }
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(mem); }), mem, 1, "read error");
  check_error(expect_io_error([&] { (void)posefuse::read_tum(mem); }), mem, 1, "read error");
  check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(mem); }), mem, 1,
              "read error");
}

TEST_CASE("Formats: a line longer than kMaxLineBytes fails fast, naming file:line",
          "[io][errors]") {
  static_assert(posefuse::kMaxLineBytes == 1 << 20);
  TempDir dir("long-line");
  // A comment of exactly the cap is still read (and skipped); one byte more is an error.
  const std::string at_cap = "#" + std::string(posefuse::kMaxLineBytes - 1, 'x') + "\n";
  const auto ok = dir.write("ok.txt", kIdentityRow + at_cap + kIdentityRow);
  CHECK(posefuse::read_kitti(ok).size() == 2);
  const std::string too_long = "#" + std::string(posefuse::kMaxLineBytes, 'x') + "\n";
  const std::string reason = "line longer than 1048576 bytes";
  const auto kitti = dir.write("k.txt", kIdentityRow + too_long + kIdentityRow);
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(kitti); }), kitti, 2, reason);
  const auto tum = dir.write("t.tum", "0 0 0 0 0 0 0 1\r\n" + too_long);
  check_error(expect_io_error([&] { (void)posefuse::read_tum(tum); }), tum, 2, reason);
  // Without a line end at all (the last line of a file).
  const auto times = dir.write("times.txt", "0\n" + std::string(posefuse::kMaxLineBytes + 1, '1'));
  check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(times); }), times, 2, reason);
  // An endless file without line ends stops after about a MiB.
  const std::filesystem::path zero = "/dev/zero";
  if (std::filesystem::exists(zero)) {
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(zero); }), zero, 1, reason);
  }
}

TEST_CASE("Formats: a file without any data line is an error naming the file", "[io][errors]") {
  TempDir dir("empty");
  const auto empty = dir.write("empty.txt", "");
  const auto comments = dir.write("comments.txt", "# only a comment\n\n   \r\n");
  for (const auto& file : {empty, comments}) {
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(file); }), file, 0, "no poses");
    check_error(expect_io_error([&] { (void)posefuse::read_tum(file); }), file, 0, "no poses");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(file); }), file, 0,
                "no timestamps");
    check_error(
        expect_io_error([&] { (void)posefuse::read_trajectory(file, posefuse::Format::kTum); }),
        file, 0, "no poses");
  }
  // An empty times.txt is named, not the pose file.
  const auto poses = dir.write("p.txt", kIdentityRow);
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, empty); }), empty, 0,
              "no timestamps");
}

TEST_CASE("Formats: a path component longer than the system allows is an io_error",
          "[io][errors]") {
  // ENAMETOOLONG escaped from std::filesystem::is_directory as
  // std::filesystem::filesystem_error.
  TempDir dir("long-name");
  const auto file = dir.path() / std::string(300, 'a') / "x.txt";
  const auto last = dir.path() / (std::string(300, 'b') + ".txt");
  const posefuse::Trajectory traj = random_trajectory(3, 9);
  for (const auto& p : {file, last}) {
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(p); }), p, 0, "");
    check_error(expect_io_error([&] { (void)posefuse::read_tum(p); }), p, 0, "");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(p); }), p, 0, "");
    const auto times = dir.write("times.txt", "0\n1\n2\n");
    const auto poses = dir.write("poses.txt", kIdentityRow + kIdentityRow + kIdentityRow);
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, p); }), p, 0, "");
    check_error(expect_io_error([&] { posefuse::write_kitti(p, traj); }), p, 0,
                "cannot open file for writing");
    check_error(expect_io_error([&] { posefuse::write_tum(p, traj); }), p, 0,
                "cannot open file for writing");
    check_error(expect_io_error([&] { posefuse::write_kitti_times(p, traj); }), p, 0,
                "cannot open file for writing");
  }
  check_error(expect_io_error([&] { (void)posefuse::read_tum(file); }), file, 0,
              "cannot access: File name too long");
}

TEST_CASE("Formats: writers do not depend on the global locale", "[io][locale]") {
  TempDir dir("locale");
  posefuse::Trajectory traj = random_trajectory(20, 13);
  traj.poses[1].translation() = Eigen::Vector3d(1234567.0, -7654321.5, 1e22);
  const GroupingGlobalLocale grouping;
  std::ostringstream probe;
  probe << 1234567;
  REQUIRE(probe.str() == "1,234,567");  // the global locale groups digits
  posefuse::write_kitti(dir.path() / "p.txt", traj);
  posefuse::write_kitti_times(dir.path() / "t.txt", traj);
  posefuse::write_tum(dir.path() / "a.tum", traj);
  const posefuse::Trajectory kitti =
      posefuse::read_kitti(dir.path() / "p.txt", dir.path() / "t.txt");
  const posefuse::Trajectory tum = posefuse::read_tum(dir.path() / "a.tum");
  REQUIRE(kitti.size() == traj.size());
  REQUIRE(tum.size() == traj.size());
  for (std::size_t k = 0; k < traj.size(); ++k) {
    CHECK(kitti.t_s[k] == traj.t_s[k]);
    CHECK(kitti.poses[k].matrix() == traj.poses[k].matrix());
    CHECK(tum.t_s[k] == traj.t_s[k]);
    CHECK(tum.poses[k].translation() == traj.poses[k].translation());
  }
}

TEST_CASE("Formats: KITTI malformed lines report file:line and the reason", "[io][kitti][errors]") {
  TempDir dir("kitti-bad");
  struct Case {
    const char* name;
    std::string line;
    const char* reason;
  };
  const Case cases[] = {
      {"too few", "1 0 0 0 0 1 0 0 0 0 1\n", "expected 12 whitespace-separated numbers"},
      {"too many", "1 0 0 0 0 1 0 0 0 0 1 0 7\n", "found 13"},
      {"commas", "1,0,0,0,0,1,0,0,0,0,1,0\n", "found 1"},
      {"letters", "1 0 0 0 0 abc 0 0 0 0 1 0\n", "cannot parse 'abc' in column 6 as a number"},
      {"trailing junk", "1 0 0 0.5m 0 1 0 0 0 0 1 0\n", "cannot parse '0.5m' in column 4"},
      {"nan", "1 0 0 nan 0 1 0 0 0 0 1 0\n", "non-finite value 'nan' in column 4"},
      {"inf", "1 0 0 0 0 1 0 0 0 0 1 -inf\n", "non-finite value '-inf' in column 12"},
      {"overflow", "1 0 0 1e999 0 1 0 0 0 0 1 0\n", "out of the range of double"},
      {"scaled", "2 0 0 0 0 2 0 0 0 0 2 0\n", "rotation is not orthonormal"},
      {"sheared", "1 0.1 0 0 0 1 0 0 0 0 1 0\n", "rotation is not orthonormal"},
      {"reflection", "1 0 0 0 0 1 0 0 0 0 -1 0\n", "reflection"},
  };
  for (const Case& c : cases) {
    SECTION(c.name) {
      // Two good lines, a comment and a blank line before the bad one: line 5.
      const auto file =
          dir.write("poses.txt", kIdentityRow + "# comment\n\n" + kIdentityRow + c.line);
      check_error(expect_io_error([&] { (void)posefuse::read_kitti(file); }), file, 5, c.reason);
    }
  }
}

TEST_CASE("Formats: KITTI times.txt errors name the right file and line", "[io][kitti][errors]") {
  TempDir dir("times-bad");
  const auto poses = dir.write("poses.txt", kIdentityRow + kIdentityRow + kIdentityRow);
  SECTION("not increasing") {
    const auto times = dir.write("times.txt", "0.0\n0.1\n0.1\n");
    // The library names no program flag: only the programs that have one add it.
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), times, 3,
                "timestamp 0.1 repeats the previous one (0.1 on line 2)");
    CHECK_THROWS_AS(posefuse::read_kitti(poses, times), posefuse::repeated_stamp_error);
    CHECK(std::string(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }).what())
              .find("--duplicates") == std::string::npos);
  }
  SECTION("decreasing, also via read_kitti_times") {
    const auto times = dir.write("times.txt", "0.0\n0.2\n0.1\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(times); }), times, 3,
                "timestamp 0.1 is earlier than the previous one (0.2 on line 2)");
  }
  SECTION("two numbers on a line") {
    const auto times = dir.write("times.txt", "0.0\n0.1 0.2\n0.3\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), times, 2,
                "expected 1 whitespace-separated numbers (one timestamp in seconds), found 2");
  }
  SECTION("unparsable") {
    const auto times = dir.write("times.txt", "0.0\n0.1\nzero\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), times, 3,
                "cannot parse 'zero'");
  }
  SECTION("fewer stamps than poses: names the first pose without a stamp") {
    const auto times = dir.write("times.txt", "0.0\n0.1\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), poses, 3,
                "pose file has 3 poses but");
  }
  SECTION("more stamps than poses: names the pose file, cut short, and the first stamp without a pose") {
    const auto times = dir.write("times.txt", "0.0\n0.1\n0.2\n\n0.3\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), poses, 0,
                "pose file has 3 poses but " + times.string() +
                    " has 4 timestamps (line 5 of the times file is the first without a pose)");
  }
}

TEST_CASE("Formats: TUM malformed lines report file:line and the reason", "[io][tum][errors]") {
  TempDir dir("tum-bad");
  const std::string good = "0.0 0 0 0 0 0 0 1\n# note\n0.1 1 0 0 0 0 0 1\n";
  struct Case {
    const char* name;
    std::string line;
    const char* reason;
  };
  const Case cases[] = {
      {"seven columns", "0.2 1 0 0 0 0 1\n",
       "expected 8 whitespace-separated numbers (TUM: t tx ty tz qx qy qz qw), found 7"},
      {"csv", "0.2,1,0,0,0,0,0,1\n", "found 1"},
      {"bad number", "0.2 1 0 0 0 0 0 one\n", "cannot parse 'one' in column 8"},
      {"nan stamp", "nan 1 0 0 0 0 0 1\n", "non-finite value 'nan' in column 1"},
      {"equal stamp", "0.1 1 0 0 0 0 0 1\n",
       "timestamp 0.1 repeats the previous one (0.1 on line 3)"},
      {"earlier stamp", "0.05 1 0 0 0 0 0 1\n", "timestamp 0.05 is earlier than the previous one (0.1 on line 3)"},
      {"zero quaternion", "0.2 1 0 0 0 0 0 0\n", "quaternion has zero norm"},
      {"non-unit quaternion", "0.2 1 0 0 0 0 0 2\n", "quaternion norm 2 differs from 1"},
  };
  for (const Case& c : cases) {
    SECTION(c.name) {
      const auto file = dir.write("t.tum", good + c.line);
      check_error(expect_io_error([&] { (void)posefuse::read_tum(file); }), file, 4, c.reason);
    }
  }
}

TEST_CASE("Formats: parse_format and read_trajectory dispatch", "[io]") {
  CHECK(posefuse::parse_format("kitti") == posefuse::Format::kKitti);
  CHECK(posefuse::parse_format("tum") == posefuse::Format::kTum);
  CHECK(posefuse::to_string(posefuse::Format::kTum) == "tum");
  CHECK_THROWS_AS(posefuse::parse_format("csv"), posefuse::invalid_argument);
  TempDir dir("dispatch");
  const posefuse::Trajectory traj = random_trajectory(5, 3);
  posefuse::write_trajectory(dir.path() / "a.tum", traj, posefuse::Format::kTum);
  posefuse::write_trajectory(dir.path() / "a.kitti", traj, posefuse::Format::kKitti);
  CHECK(posefuse::read_trajectory(dir.path() / "a.tum", posefuse::Format::kTum).t_s ==
        traj.t_s);
  CHECK(posefuse::read_trajectory(dir.path() / "a.kitti", posefuse::Format::kKitti).size() == 5);
  CHECK_THROWS_AS(posefuse::read_trajectory(dir.path() / "a.tum", posefuse::Format::kTum,
                                            dir.path() / "a.kitti"),
                  posefuse::invalid_argument);
}

TEST_CASE("Formats: writers refuse invalid trajectories", "[io][errors]") {
  TempDir dir("invalid");
  posefuse::Trajectory traj = random_trajectory(3, 5);
  traj.t_s[2] = traj.t_s[1];
  CHECK_THROWS_AS(posefuse::write_tum(dir.path() / "x.tum", traj), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::write_kitti_times(dir.path() / "t.txt", traj),
                  posefuse::invalid_argument);
}

TEST_CASE("Formats: real KITTI 06 files read with default tolerances", "[io][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "kitti/06");
  for (const char* name : {"groundtruth.txt", "orbslam2_stereo.txt", "cvo_vo.txt"}) {
    INFO(name);
    const posefuse::Trajectory traj = posefuse::read_kitti(dir / name, dir / "times.txt");
    CHECK(traj.size() == 1101);
    CHECK_NOTHROW(traj.validate());
    for (const Eigen::Isometry3d& T : traj.poses) {
      const Eigen::Matrix3d R = T.linear();
      REQUIRE((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
    }
  }
  const posefuse::Trajectory mono = posefuse::read_tum(dir / "orbslam2_mono.tum");
  CHECK(mono.size() == 1101);
  CHECK(mono.t_s.front() == 0.0);
  // CVO's rotations drift to |R^T R - I| = 4.1e-4; a 1e-4 tolerance rejects them.
  posefuse::ReadOptions strict;
  strict.rotation_tolerance = 1e-4;
  CHECK_THROWS_AS(posefuse::read_kitti(dir / "cvo_vo.txt", std::nullopt, strict),
                  posefuse::io_error);
}

// ---------------------------------------------------------------------------
// Input policy (evaluation issue): repeated stamps, byte-order marks, cheap
// re-orthonormalisation.

TEST_CASE("Formats: TUM repeated stamps follow the duplicate policy and are reported",
          "[io][tum][duplicates]") {
  TempDir dir("tum-dup");
  // Lines 3 and 4 repeat line 2's stamp with other positions (x = 2, 3).
  const auto file = dir.write("d.tum",
                              "# t x y z qx qy qz qw\n"
                              "0.1 1 0 0 0 0 0 1\n"
                              "0.1 2 0 0 0 0 0 1\n"
                              "0.1 3 0 0 0 0 0 1\n"
                              "0.2 4 0 0 0 0 0 1\n"
                              "0.3 5 0 0 0 0 0 1\n"
                              "0.3 6 0 0 0 0 0 1\n");
  posefuse::ReadOptions options;
  SECTION("error (the library default) names the first repeat") {
    check_error(expect_io_error([&] { (void)posefuse::read_tum(file); }), file, 3,
                "timestamp 0.1 repeats the previous one (0.1 on line 2)");
  }
  SECTION("first keeps the first pose of each run") {
    options.duplicates = posefuse::DuplicateStamps::kFirst;
    posefuse::ReadReport report;
    const posefuse::Trajectory traj = posefuse::read_tum(file, options, &report);
    REQUIRE(traj.size() == 3);
    CHECK(traj.t_s == std::vector<double>{0.1, 0.2, 0.3});
    CHECK(traj.poses[0].translation().x() == 1.0);
    CHECK(traj.poses[1].translation().x() == 4.0);
    CHECK(traj.poses[2].translation().x() == 5.0);
    CHECK(report.duplicates_dropped == 3);
    CHECK(report.first_duplicate_line == 3);
  }
  SECTION("last keeps the last pose of each run") {
    options.duplicates = posefuse::DuplicateStamps::kLast;
    posefuse::ReadReport report;
    const posefuse::Trajectory traj = posefuse::read_tum(file, options, &report);
    REQUIRE(traj.size() == 3);
    CHECK(traj.poses[0].translation().x() == 3.0);
    CHECK(traj.poses[1].translation().x() == 4.0);
    CHECK(traj.poses[2].translation().x() == 6.0);
    CHECK(report.duplicates_dropped == 3);
  }
  SECTION("keep keeps every pose, equal stamps and all (as evo reads)") {
    options.duplicates = posefuse::DuplicateStamps::kKeep;
    posefuse::ReadReport report;
    const posefuse::Trajectory traj = posefuse::read_tum(file, options, &report);
    REQUIRE(traj.size() == 6);
    CHECK(traj.t_s == std::vector<double>{0.1, 0.1, 0.1, 0.2, 0.3, 0.3});
    CHECK(traj.poses[1].translation().x() == 2.0);
    CHECK(report.duplicates_kept == 3);
    CHECK(report.duplicates_dropped == 0);
    CHECK(report.first_duplicate_line == 3);
  }
  SECTION("a decreasing stamp stays an error under every policy") {
    const auto bad = dir.write("b.tum", "0.1 1 0 0 0 0 0 1\n0.1 2 0 0 0 0 0 1\n0.05 3 0 0 0 0 0 1\n");
    for (const auto policy : {posefuse::DuplicateStamps::kFirst, posefuse::DuplicateStamps::kLast,
                              posefuse::DuplicateStamps::kKeep}) {
      options.duplicates = policy;
      check_error(expect_io_error([&] { (void)posefuse::read_tum(bad, options); }), bad, 3,
                  "timestamp 0.05 is earlier than the previous one (0.1 on line 2)");
    }
  }
  SECTION("policy names parse and print") {
    CHECK(posefuse::parse_duplicate_stamps("first") == posefuse::DuplicateStamps::kFirst);
    CHECK(posefuse::parse_duplicate_stamps("last") == posefuse::DuplicateStamps::kLast);
    CHECK(posefuse::parse_duplicate_stamps("error") == posefuse::DuplicateStamps::kError);
    CHECK(posefuse::to_string(posefuse::DuplicateStamps::kLast) == "last");
    CHECK(posefuse::parse_duplicate_stamps("keep") == posefuse::DuplicateStamps::kKeep);
    CHECK(posefuse::to_string(posefuse::DuplicateStamps::kKeep) == "keep");
    CHECK_THROWS_AS(posefuse::parse_duplicate_stamps("all"), posefuse::invalid_argument);
  }
}

TEST_CASE("Formats: KITTI times with repeated stamps drop the matching poses",
          "[io][kitti][duplicates]") {
  TempDir dir("kitti-dup");
  // Pose k has tx = k, so the kept poses can be identified.
  std::string poses_text;
  for (int k = 0; k < 5; ++k) poses_text += "1 0 0 " + std::to_string(k) + " 0 1 0 0 0 0 1 0\n";
  const auto poses = dir.write("p.txt", poses_text);
  const auto times = dir.write("t.txt", "0.0\n0.1\n0.1\n# note\n0.2\n0.2\n");
  posefuse::ReadOptions options;
  options.duplicates = posefuse::DuplicateStamps::kFirst;
  posefuse::ReadReport report;
  posefuse::Trajectory traj = posefuse::read_kitti(poses, times, options, &report);
  REQUIRE(traj.size() == 3);
  CHECK(traj.t_s == std::vector<double>{0.0, 0.1, 0.2});
  CHECK(traj.poses[1].translation().x() == 1.0);
  CHECK(traj.poses[2].translation().x() == 3.0);
  CHECK(report.duplicates_dropped == 2);
  CHECK(report.first_duplicate_line == 3);

  options.duplicates = posefuse::DuplicateStamps::kLast;
  traj = posefuse::read_kitti(poses, times, options);
  REQUIRE(traj.size() == 3);
  CHECK(traj.poses[1].translation().x() == 2.0);
  CHECK(traj.poses[2].translation().x() == 4.0);

  // Counts are compared line for line, before anything is dropped.
  const auto short_times = dir.write("s.txt", "0.0\n0.1\n0.1\n0.2\n");
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, short_times, options); }),
              poses, 5, "pose file has 5 poses but");
}

TEST_CASE("Formats: a UTF-8 byte-order mark does not break the first number", "[io][bom]") {
  TempDir dir("bom");
  const std::string bom = "\xEF\xBB\xBF";
  const auto tum = dir.write("b.tum", bom + "0.5 1 2 3 0 0 0 1\n0.6 1 2 3 0 0 0 1\n");
  const posefuse::Trajectory t = posefuse::read_tum(tum);
  REQUIRE(t.size() == 2);
  CHECK(t.t_s[0] == 0.5);
  const auto tum_comment = dir.write("c.tum", bom + "# header\n0.5 1 2 3 0 0 0 1\n");
  CHECK(posefuse::read_tum(tum_comment).size() == 1);
  const auto kitti = dir.write("b.txt", bom + kIdentityRow);
  CHECK(posefuse::read_kitti(kitti).size() == 1);
  const auto times = dir.write("t.txt", bom + "1.25\n");
  CHECK(posefuse::read_kitti_times(times) == std::vector<double>{1.25});
  // Only at the start of the file: elsewhere it is a bad number.
  const auto middle = dir.write("m.tum", "0.5 1 2 3 0 0 0 1\n" + bom + "0.6 1 2 3 0 0 0 1\n");
  check_error(expect_io_error([&] { (void)posefuse::read_tum(middle); }), middle, 2,
              "cannot parse");
}

TEST_CASE("Formats: the polar re-orthonormalisation equals the SVD's nearest rotation",
          "[io][kitti]") {
  std::mt19937_64 rng(20261202);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> size(-9.0, -3.0);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3d axis_angle(n01(rng), n01(rng), n01(rng));
    const Eigen::Matrix3d R0 =
        Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).toRotationMatrix();
    Eigen::Matrix3d noise;
    for (int i = 0; i < 9; ++i) noise(i / 3, i % 3) = n01(rng);
    const Eigen::Matrix3d R = R0 + std::pow(10.0, size(rng)) * noise;
    const double residual = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(residual <= 1e-3) || residual <= posefuse::detail::traj_io::kExactlyOrthonormal) continue;
    const Eigen::Matrix3d polar = posefuse::detail::traj_io::checked_rotation(R, 1e-3, "x", 1);
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d nearest = svd.matrixU() * svd.matrixV().transpose();
    INFO("trial " << trial << ", residual " << residual);
    // Both are the same matrix up to each algorithm's rounding (the SVD's
    // own product is orthonormal only to about 3e-15); Newton's result is
    // orthonormal to about one ulp.
    CHECK((polar - nearest).cwiseAbs().maxCoeff() < 4e-15);
    CHECK((polar.transpose() * polar - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15);
    CHECK(polar.determinant() > 0.0);
  }
}

TEST_CASE("Formats: detect_format tells KITTI, TUM and EuRoC apart and refuses to guess",
          "[io][detect]") {
  TempDir dir("detect");
  using posefuse::Format;
  const std::string euroc8 = "1403715273262142976,0.87,2.18,0.94,0.07,-0.82,-0.11,-0.55\n";
  const std::string euroc17 =
      "1403715273262142976, 0.87, 2.18, 0.94, 0.07, -0.82, -0.11, -0.55, 0, 0, 0, 0, 0, 0, 0, 0, 0\n";
  CHECK(posefuse::detect_format(dir.write("k.txt", kIdentityRow + kIdentityRow)) == Format::kKitti);
  CHECK(posefuse::detect_format(dir.write("t.tum", "# t x y z qx qy qz qw\n0 0 0 0 0 0 0 1\n")) == Format::kTum);
  CHECK(posefuse::detect_format(dir.write("c.tum", "0 0 0 0 0 0 0 1 1 0 0 1 0 1\n")) == Format::kTum);
  CHECK(posefuse::detect_format(dir.write("e.csv", "#timestamp,p_RS_R_x [m],...\n" + euroc8 + euroc8)) == Format::kEuroc);
  CHECK(posefuse::detect_format(dir.write("f.csv", euroc17)) == Format::kEuroc);
  CHECK(posefuse::detect_format(dir.write("bom.txt", "\xEF\xBB\xBF" + kIdentityRow)) == Format::kKitti);
  const struct {
    const char* name;
    std::string text;
    std::size_t line;
    const char* reason;
  } refused[] = {
      {"csv with a non-integer stamp", "1.5,0,0,0,1,0,0,0\n", 1, "starting with '1.5'"},
      {"csv of another width", "1,2,3\n", 1, "3 comma-separated fields"},
      {"7 numbers", "# x\n0 0 0 0 0 0 1\n", 2, "7 whitespace-separated fields"},
      {"a TUM line, then a KITTI line", "0 0 0 0 0 0 0 1\n" + kIdentityRow, 2,
       "looks like kitti (12 fields) but line 1 like tum (8 fields)"},
      {"a TUM line, then a covariance line", "0 0 0 0 0 0 0 1\n0 0 0 0 0 0 0 1 1 0 0 1 0 1\n", 2,
       "(14 fields) but line 1 like tum (8 fields)"},
  };
  for (const auto& c : refused) {
    SECTION(c.name) {
      const auto file = dir.write("r.txt", c.text);
      check_error(expect_io_error([&] { (void)posefuse::detect_format(file); }), file, c.line, c.reason);
      check_error(expect_io_error([&] { (void)posefuse::detect_format(file); }), file, c.line,
                  "give the format explicitly");
    }
  }
  const auto empty = dir.write("empty.txt", "# nothing\n\n");
  check_error(expect_io_error([&] { (void)posefuse::detect_format(empty); }), empty, 0, "no poses");
  CHECK(posefuse::parse_format("euroc") == Format::kEuroc);
  CHECK(posefuse::to_string(Format::kEuroc) == "euroc");
}

TEST_CASE("Formats: EuRoC ground truth through read_trajectory, with the duplicate policy",
          "[io][euroc][duplicates]") {
  TempDir dir("euroc-dup");
  const auto file = dir.write("gt.csv",
                              "#timestamp,px,py,pz,qw,qx,qy,qz\n"
                              "1000000000,1,0,0,1,0,0,0\n"
                              "1000000000,2,0,0,1,0,0,0\n"
                              "1500000000,3,0,0,1,0,0,0\n");
  check_error(expect_io_error([&] { (void)posefuse::read_trajectory(file, posefuse::Format::kEuroc); }),
              file, 3, "repeats the previous one");
  posefuse::ReadOptions options;
  options.duplicates = posefuse::DuplicateStamps::kLast;
  posefuse::ReadReport report;
  const posefuse::Trajectory t =
      posefuse::read_trajectory(file, posefuse::Format::kEuroc, std::nullopt, options, &report);
  REQUIRE(t.size() == 2);
  CHECK(t.t_s == std::vector<double>{1.0, 1.5});
  CHECK(t.poses[0].translation().x() == 2.0);
  CHECK(report.duplicates_dropped == 1);
  CHECK(report.first_duplicate_line == 3);
  options.duplicates = posefuse::DuplicateStamps::kFirst;
  CHECK(posefuse::read_trajectory(file, posefuse::Format::kEuroc, std::nullopt, options).poses[0].translation().x() == 1.0);
  CHECK_THROWS_AS(posefuse::read_trajectory(file, posefuse::Format::kEuroc, file), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::write_trajectory(dir.path() / "o.csv", t, posefuse::Format::kEuroc),
                  posefuse::invalid_argument);
}

TEST_CASE("Formats: positions beyond 1e100 m are refused at their line", "[io][errors]") {
  TempDir dir("huge-position");
  const auto tum = dir.write("huge.tum", "0 0 0 0 0 0 0 1\n0.1 1e200 0 0 0 0 0 1\n");
  check_error(expect_io_error([&] { (void)posefuse::read_tum(tum); }), tum, 2,
              "position coordinate of magnitude 1e+200 m is beyond 1e+100 m");
  const auto kitti = dir.write("huge.txt", kIdentityRow + "1 0 0 0 0 1 0 -1e101 0 0 1 0\n");
  check_error(expect_io_error([&] { (void)posefuse::read_kitti(kitti); }), kitti, 2, "1e+101 m is beyond");
  const auto euroc = dir.write("huge.csv", "#t,p,q\n1000,0,0,0,1,0,0,0\n2000,0,0,1e150,1,0,0,0\n");
  check_error(expect_io_error([&] { (void)posefuse::read_euroc_groundtruth(euroc); }), euroc, 3, "1e+150 m");
  // 1e100 itself is accepted.
  const auto edge = dir.write("edge.tum", "0 1e100 0 0 0 0 0 1\n");
  CHECK(posefuse::read_tum(edge).poses[0].translation().x() == 1e100);
}

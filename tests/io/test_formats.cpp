// KITTI / TUM readers and writers: bit-exact round trips, and one test per
// malformed input checking that the io_error names the file and the line.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
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
  traj.poses[3].translation() = Eigen::Vector3d(5e-324, -0.0, 1e308);  // extremes survive too
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
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), times, 3,
                "not greater than the previous one (0.1 on line 2)");
  }
  SECTION("decreasing, also via read_kitti_times") {
    const auto times = dir.write("times.txt", "0.0\n0.2\n0.1\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti_times(times); }), times, 3,
                "not greater");
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
  SECTION("more stamps than poses: names the first stamp without a pose") {
    const auto times = dir.write("times.txt", "0.0\n0.1\n0.2\n\n0.3\n");
    check_error(expect_io_error([&] { (void)posefuse::read_kitti(poses, times); }), times, 5,
                "times file has 4 timestamps but");
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
       "timestamp 0.1 is not greater than the previous one (0.1 on line 3)"},
      {"earlier stamp", "0.05 1 0 0 0 0 0 1\n", "not greater than the previous"},
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
  CHECK_THROWS_AS(posefuse::parse_format("euroc"), posefuse::invalid_argument);
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

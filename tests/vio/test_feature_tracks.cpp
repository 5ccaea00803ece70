// Feature-track csv (io/feature_tracks.hpp, vio/feature_tracks.hpp) and IMU
// gap checks (io/imu_gaps.hpp): round trip, header and comments, and a
// file:line error for every malformed row, stamp going back, repeated id,
// NaN and pixel outside the image; the real V1_01_easy IMU when present.
#include <catch2/catch.hpp>

#include <limits>
#include <string>

#include <posefuse/io/imu_gaps.hpp>
#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/vio/feature_tracks.hpp>

#include "support/data_path.hpp"
#include "support/io_error.hpp"
#include "support/temp_dir.hpp"

using posefuse::test::io_error_of;

TEST_CASE("Feature tracks: csv rows grouped into frames, header and comments", "[vio][tracks]") {
  posefuse::test::TempDir dir("tracks");
  const auto f = dir.write("t.csv",
                           "# from some front end\n"
                           "t_ns, feature_id, u, v\n"
                           "1000,0,102.5,33.25\r\n"
                           "1000, 7 ,640.125,301\n"
                           "\n"
                           "2000,0,-0.5,479.5\n"
                           "3000,18446744073709551615,1e2,2E1\n");
  const posefuse::FeatureTracks t = posefuse::read_feature_tracks(f, posefuse::sim::synthetic_camera());
  REQUIRE(t.size() == 3);
  CHECK(t[0].t_ns == 1000);
  REQUIRE(t[0].features.size() == 2);
  CHECK(t[0].features[1].id == 7);
  CHECK(t[0].features[1].uv == Eigen::Vector2d(640.125, 301));
  CHECK(t[1].features[0].uv == Eigen::Vector2d(-0.5, 479.5));
  CHECK(t[2].features[0].id == std::numeric_limits<std::uint64_t>::max());
  CHECK(t[2].features[0].uv == Eigen::Vector2d(100, 20));
}

TEST_CASE("Feature tracks: write then read is exact", "[vio][tracks]") {
  posefuse::test::TempDir dir("tracks");
  posefuse::sim::TrackSimConfig c;
  c.features_per_frame = 40;
  const posefuse::sim::SimulatedTracks s =
      posefuse::sim::simulate_feature_tracks(posefuse::sim::synthetic_flight(), 1.0, posefuse::sim::synthetic_camera(), c);
  const auto f = dir.path() / "out.csv";
  posefuse::write_feature_tracks(f, s.tracks);
  const posefuse::FeatureTracks back = posefuse::read_feature_tracks(f);
  REQUIRE(back.size() == s.tracks.size());
  for (std::size_t k = 0; k < back.size(); ++k) {
    CHECK(back[k].t_ns == s.tracks[k].t_ns);
    REQUIRE(back[k].features.size() == s.tracks[k].features.size());
    for (std::size_t i = 0; i < back[k].features.size(); ++i) {
      CHECK(back[k].features[i].id == s.tracks[k].features[i].id);
      CHECK(back[k].features[i].uv == s.tracks[k].features[i].uv);  // bit for bit
    }
  }
  // The writer refuses what the reader would refuse.
  posefuse::FeatureTracks bad = s.tracks;
  bad[1].t_ns = bad[0].t_ns;
  CHECK_THROWS_AS(posefuse::write_feature_tracks(f, bad), posefuse::invalid_argument);
  bad = s.tracks;
  bad[0].features[0].uv.x() = std::nan("");
  CHECK_THROWS_AS(posefuse::write_feature_tracks(f, bad), posefuse::invalid_argument);
  bad = s.tracks;
  bad[0].features[1].id = bad[0].features[0].id;
  CHECK_THROWS_AS(posefuse::write_feature_tracks(f, bad), posefuse::invalid_argument);
}

TEST_CASE("Feature tracks: malformed rows are file:line errors", "[vio][tracks]") {
  posefuse::test::TempDir dir("tracks");
  const posefuse::PinholeRadtan cam = posefuse::sim::synthetic_camera();
  const auto err = [&](const std::string& rows) {
    const auto f = dir.write("t.csv", "t_ns,feature_id,u,v\n1000,1,10,20\n" + rows);
    return io_error_of([&] { (void)posefuse::read_feature_tracks(f, cam); });
  };
  CHECK_THAT(err("2000,1,10\n"), Catch::Contains("t.csv:3: expected 4 comma-separated fields"));
  CHECK_THAT(err("2000,1,10,20,5\n"), Catch::Contains("t.csv:3: expected 4 comma-separated fields"));
  CHECK_THAT(err("900,2,10,20\n"), Catch::Contains("t.csv:3: timestamp 900 is earlier than the previous one (1000 on line 2)"));
  CHECK_THAT(err("2000,2,10,20\n\n1500,3,1,1\n"),
             Catch::Contains("t.csv:5: timestamp 1500 is earlier than the previous one (2000 on line 3)"));
  CHECK_THAT(err("1000,1,11,21\n"), Catch::Contains("t.csv:3: feature id 1 repeats within the image at 1000 ns (line 2)"));
  CHECK_THAT(err("2000,-1,10,20\n"), Catch::Contains("t.csv:3: cannot parse '-1' in column 2 as a feature id"));
  CHECK_THAT(err("2000,1.5,10,20\n"), Catch::Contains("t.csv:3: cannot parse '1.5' in column 2"));
  CHECK_THAT(err("2000,18446744073709551616,10,20\n"), Catch::Contains("t.csv:3: cannot parse '18446744073709551616'"));
  CHECK_THAT(err("2000.5,1,10,20\n"), Catch::Contains("t.csv:3: cannot parse '2000.5' in column 1"));
  CHECK_THAT(err("2000,1,nan,20\n"), Catch::Contains("t.csv:3: non-finite value 'nan' in column 3"));
  CHECK_THAT(err("2000,1,10,inf\n"), Catch::Contains("t.csv:3: non-finite value 'inf' in column 4"));
  CHECK_THAT(err("2000,1,10,abc\n"), Catch::Contains("t.csv:3: cannot parse 'abc' in column 4"));
  CHECK_THAT(err("2000,1,751.6,20\n"), Catch::Contains("t.csv:3: pixel (751.6, 20) is outside the 752x480 image"));
  CHECK_THAT(err("2000,1,10,-0.6\n"), Catch::Contains("t.csv:3: pixel (10, -0.6) is outside"));
  CHECK_THAT(err("t_ns,feature_id,u,v\n"), Catch::Contains("t.csv:3: cannot parse 't_ns' in column 1"));
  // Without a camera, pixels are not checked.
  CHECK_NOTHROW(posefuse::read_feature_tracks(dir.write("t2.csv", "1,1,-100,5000\n")));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_feature_tracks(dir.write("e.csv", "# only\nt_ns,feature_id,u,v\n")); }),
             Catch::Contains("e.csv: no feature observations"));
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_feature_tracks(dir.path() / "missing.csv"); }),
             Catch::Contains("missing.csv"));
}

TEST_CASE("IMU gaps: reported, or refused at the line after the gap", "[vio][imu]") {
  posefuse::test::TempDir dir("gaps");
  const auto f = dir.write("imu.csv",
                           "#timestamp,wx,wy,wz,ax,ay,az\n"
                           "0,0,0,0,0,0,9.81\n"
                           "5000000,0,0,0,0,0,9.81\n"
                           "10000000,0,0,0,0,0,9.81\n"
                           "\n"
                           "40000000,0,0,0,0,0,9.81\n"
                           "45000000,0,0,0,0,0,9.81\n");
  const std::vector<posefuse::ImuSample> s = posefuse::read_euroc_imu(f);
  const std::vector<posefuse::ImuGap> gaps = posefuse::find_imu_gaps(s, 20'000'000);
  REQUIRE(gaps.size() == 1);
  CHECK(gaps[0].index == 3);
  CHECK(gaps[0].t_before_ns == 10'000'000);
  CHECK(gaps[0].length_ns() == 30'000'000);
  CHECK(posefuse::find_imu_gaps(s, 30'000'000).empty());  // the limit itself is accepted
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu_checked(f, 20'000'000); }),
             Catch::Contains("imu.csv:6: gap of 30 ms after line 4 (the limit is 20 ms)"));
  CHECK(posefuse::read_euroc_imu_checked(f, 30'000'000) == s);
  CHECK_THROWS_AS(posefuse::find_imu_gaps(s, 0), posefuse::invalid_argument);
  // The reader's other checks still apply.
  const auto back = dir.write("back.csv", "0,0,0,0,0,0,9.81\n5,0,0,0,0,0,nan\n");
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu_checked(back, 20'000'000); }),
             Catch::Contains("back.csv:2: non-finite value 'nan'"));
}

TEST_CASE("IMU gaps: the real V1_01_easy IMU has none above 20 ms", "[vio][imu][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  const std::vector<posefuse::ImuSample> s = posefuse::read_euroc_imu_checked(d / "imu0.csv", 20'000'000);
  CHECK(s.size() == 29120);
  // Its intervals are 5 ms to within a microsecond: a 5.001 ms limit passes, 4.999 ms does not.
  CHECK(posefuse::find_imu_gaps(s, 5'001'000).empty());
  CHECK(posefuse::find_imu_gaps(s, 4'999'000).size() > 29000);
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_euroc_imu_checked(d / "imu0.csv", 4'999'000); }),
             Catch::Contains("imu0.csv:3: gap of "));
}

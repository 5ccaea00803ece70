// Feature tracks with pixels a little outside the image: dropped and counted
// within FeatureTrackReadOptions::drop_margin_px, refused beyond it (and
// always without a margin).
#include <catch2/catch.hpp>

#include <string>

#include <posefuse/io/feature_tracks.hpp>

#include "support/io_error.hpp"
#include "support/temp_dir.hpp"

using posefuse::test::io_error_of;

TEST_CASE("Feature tracks: pixels just outside the image are dropped within a stated margin", "[io][tracks]") {
  posefuse::test::TempDir dir("tracks-margin");
  const auto f = dir.write("t.csv",
                           "t_ns,feature_id,u,v\n1000,0,-0.51,148.821\n1000,1,10,10\n2000,0,752.4,20\n"
                           "2000,1,20,-1.2\n3000,1,30,30\n");
  // No margin: the first pixel outside is refused at its line.
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_feature_tracks(f, {752, 480}); }),
             Catch::Contains("t.csv:2: pixel (-0.51, 148.821) is outside the 752x480 image"));
  // A 1 px margin: three observations dropped (lines 2, 4, 5), every frame kept.
  const posefuse::FeatureTrackRead r = posefuse::read_feature_tracks_counted(f, {752, 480, 1.0});
  CHECK(r.dropped == 3);
  CHECK(r.first_dropped_line == 2);
  CHECK(r.worst_outside_px == Approx(0.9));
  REQUIRE(r.tracks.size() == 3);
  CHECK(r.tracks[0].features.size() == 1);
  CHECK(r.tracks[0].features[0].id == 1);
  CHECK(r.tracks[1].features.empty());
  CHECK(r.tracks[2].features.size() == 1);
  // Beyond the margin: refused, naming the margin.
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_feature_tracks_counted(f, {752, 480, 0.6}); }),
             Catch::Contains("t.csv:4: pixel (752.4, 20) is outside the 752x480 image") &&
                 Catch::Contains("by 0.9 px, more than the 0.6 px margin"));
  CHECK_THROWS_AS(posefuse::read_feature_tracks_counted(f, {752, 480, -1.0}), posefuse::invalid_argument);
}

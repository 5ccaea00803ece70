// Loop-candidate csv: round trip, sorting, one test per malformation naming
// file:line; the recurring-id oracle on hand-made tracks.
#include <catch2/catch.hpp>

#include <string>

#include <posefuse/io/loop_candidates.hpp>

#include "support/io_error.hpp"
#include "support/temp_dir.hpp"

using posefuse::LoopCandidate;
using posefuse::test::io_error_of;

TEST_CASE("loop candidates: read, sorted, round trip", "[io][loop]") {
  posefuse::test::TempDir dir("loopcand");
  const auto f = dir.write("c.csv",
                           "t_ns_query,t_ns_match\n# comment\n\n300, 100\n200,50\r\n300,20\n");
  const std::vector<LoopCandidate> c = posefuse::read_loop_candidates(f);
  REQUIRE(c.size() == 3);
  CHECK(c[0].t_query_ns == 200);
  CHECK(c[0].t_match_ns == 50);
  CHECK(c[1].t_query_ns == 300);
  CHECK(c[1].t_match_ns == 20);
  CHECK(c[2].t_match_ns == 100);
  const auto g = dir.path() / "out.csv";
  posefuse::write_loop_candidates(g, c);
  const std::vector<LoopCandidate> d = posefuse::read_loop_candidates(g);
  REQUIRE(d.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(d[k].t_query_ns == c[k].t_query_ns);
    CHECK(d[k].t_match_ns == c[k].t_match_ns);
  }
  CHECK(posefuse::read_loop_candidates(dir.write("empty.csv", "t_ns_query,t_ns_match\n")).empty());
  CHECK_THROWS_AS(posefuse::write_loop_candidates(g, {LoopCandidate{5, 5, 0}}), posefuse::invalid_argument);
}

TEST_CASE("loop candidates: malformed files are file:line errors", "[io][loop]") {
  posefuse::test::TempDir dir("loopcand");
  const struct {
    const char* text;
    const char* expected;
  } cases[] = {
      {"t_ns_query,t_ns_match\n10,5\n30\n", ":3: expected 2 comma-separated fields (t_ns_query, t_ns_match), found 1"},
      {"10,5,1\n", ":1: expected 2 comma-separated fields"},
      {"10,5\nx,1\n", ":2: cannot parse 'x' in column 1"},
      {"10,y\n", ":1: cannot parse 'y' in column 2"},
      {"10,1.5\n", ":1: cannot parse '1.5' in column 2"},
      {"10,10\n", ":1: the match 10 ns is not earlier than the query 10 ns"},
      {"10,20\n", ":1: the match 20 ns is not earlier than the query 10 ns"},
      {"99999999999999999999,1\n", ":1: timestamp '99999999999999999999' does not fit in int64 ns"},
  };
  int k = 0;
  for (const auto& c : cases) {
    INFO(c.text);
    const auto f = dir.write("bad" + std::to_string(k++) + ".csv", c.text);
    const std::string what = io_error_of([&] { (void)posefuse::read_loop_candidates(f); });
    CHECK_THAT(what, Catch::StartsWith(f.string()) && Catch::Contains(c.expected));
  }
  CHECK_THAT(io_error_of([&] { (void)posefuse::read_loop_candidates(dir.path() / "missing.csv"); }),
             Catch::Contains("missing.csv: cannot open"));
}

TEST_CASE("loop candidates: the recurring-id oracle", "[io][loop]") {
  // Frames every 1 s; ids 0..39 seen at t = 0..2 s, then again at t = 30 s
  // (a revisit), ids 100.. elsewhere.
  posefuse::FeatureTracks t;
  const auto frame = [](std::int64_t s, std::uint64_t first, int n) {
    posefuse::TrackFrame f;
    f.t_ns = s * 1'000'000'000;
    for (int i = 0; i < n; ++i) f.features.push_back({first + std::uint64_t(i), Eigen::Vector2d(1, 1)});
    return f;
  };
  for (std::int64_t s = 0; s < 3; ++s) t.push_back(frame(s, 0, 40));
  for (std::int64_t s = 3; s < 30; ++s) t.push_back(frame(s, 100 + 50 * std::uint64_t(s), 40));
  t.push_back(frame(30, 5, 35));   // 35 of the first place's ids
  t.push_back(frame(31, 10, 20));  // too few shared
  posefuse::RecurringIdOptions o;
  o.min_gap_s = 20;
  o.min_shared_ids = 30;
  const std::vector<LoopCandidate> c = posefuse::loop_candidates_from_recurring_ids(t, o);
  REQUIRE(c.size() == 1);
  CHECK(c[0].t_query_ns == 30'000'000'000);
  CHECK(c[0].t_match_ns == 0);  // all three early frames share 35: the earliest is kept
  CHECK(c[0].shared_ids == 35);
  // Within the gap nothing is proposed, however many ids are shared.
  o.min_gap_s = 31;
  CHECK(posefuse::loop_candidates_from_recurring_ids(t, o).empty());
  o.min_gap_s = -1;
  CHECK_THROWS_AS(posefuse::loop_candidates_from_recurring_ids(t, o), posefuse::invalid_argument);
}

// Tests for core/stream_merge.hpp: every sample once, in time order, stable
// ties, any number of streams, bad input rejected before anything is visited.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/stream_merge.hpp>

using posefuse::for_each_in_time_order;
using posefuse::Overloaded;

namespace {
struct Tick {
  std::int64_t t_ns;
  int id;
};
struct Tock {
  std::int64_t t_ns;
  double value;
};
}  // namespace

TEST_CASE("StreamMerge: three sample types visited once each, by t_ns, ties by stream order",
          "[core][stream_merge]") {
  std::vector<posefuse::ImuSample> imu(3);
  imu[0].t_ns = 10;
  imu[1].t_ns = 20;
  imu[2].t_ns = 40;
  const std::vector<posefuse::WheelSample> wheels{{5, {}}, {20, {}}, {30, {}}};
  std::vector<posefuse::SlamSample> slam(2);
  slam[0].t_ns = 20;
  slam[1].t_ns = 50;
  std::string order;
  std::vector<std::int64_t> stamps;
  const std::size_t n = for_each_in_time_order(
      Overloaded{[&](const posefuse::ImuSample& s) { order += 'i', stamps.push_back(s.t_ns); },
                 [&](const posefuse::WheelSample& s) { order += 'w', stamps.push_back(s.t_ns); },
                 [&](const posefuse::SlamSample& s) { order += 's', stamps.push_back(s.t_ns); }},
      imu, wheels, slam);
  CHECK(n == 8);
  // At t = 20 all three streams have a sample: IMU (first argument), wheels, SLAM.
  CHECK(order == "wiiwswis");
  CHECK(stamps == std::vector<std::int64_t>{5, 10, 20, 20, 20, 30, 40, 50});
  // The argument order decides ties, not the types.
  order.clear();
  stamps.clear();
  (void)for_each_in_time_order(
      Overloaded{[&](const posefuse::ImuSample&) { order += 'i'; },
                 [&](const posefuse::WheelSample&) { order += 'w'; },
                 [&](const posefuse::SlamSample&) { order += 's'; }},
      slam, wheels, imu);
  CHECK(order == "wiswiwis");  // t = 20: slam, wheels, imu
}

TEST_CASE("StreamMerge: equal stamps within one stream keep the stream's order",
          "[core][stream_merge]") {
  const std::vector<Tick> a{{1, 0}, {1, 1}, {1, 2}, {3, 3}};
  const std::vector<Tock> b{{1, 10.0}, {2, 20.0}};
  std::vector<int> ids;
  (void)for_each_in_time_order(Overloaded{[&](const Tick& t) { ids.push_back(t.id); },
                                          [&](const Tock& t) { ids.push_back(int(t.value)); }},
                               a, b);
  CHECK(ids == std::vector<int>{0, 1, 2, 10, 20, 3});
}

TEST_CASE("StreamMerge: two streams of one type are told apart by their index",
          "[core][stream_merge]") {
  const std::vector<Tick> left{{2, 0}, {4, 1}};
  const std::array<Tick, 3> right{{{1, 100}, {4, 101}, {9, 102}}};
  std::vector<std::pair<std::size_t, int>> seen;
  const auto visit = [&]<std::size_t I>(const Tick& t, std::integral_constant<std::size_t, I>) {
    seen.emplace_back(I, t.id);
  };
  (void)for_each_in_time_order(visit, left, std::span<const Tick>(right));
  const std::vector<std::pair<std::size_t, int>> want{{1, 100}, {0, 0}, {0, 1}, {1, 101}, {1, 102}};
  CHECK(seen == want);
}

TEST_CASE("StreamMerge: random streams come out sorted and complete", "[core][stream_merge]") {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<std::int64_t> step(0, 30);
  std::vector<Tick> a, b, c;
  std::int64_t ta = -1000, tb = 5, tc = std::numeric_limits<std::int64_t>::min();
  for (int k = 0; k < 500; ++k) {
    a.push_back({ta += step(rng), k});
    b.push_back({tb += step(rng), 1000 + k});
    if (k < 3) c.push_back({tc + k, 2000 + k});  // far in the past: all first
  }
  std::vector<std::int64_t> t;
  std::vector<int> ids;
  (void)for_each_in_time_order(
      [&](const Tick& s) {
        t.push_back(s.t_ns);
        ids.push_back(s.id);
      },
      a, b, c);
  REQUIRE(t.size() == 1003);
  CHECK(std::is_sorted(t.begin(), t.end()));
  CHECK(ids[0] == 2000);
  CHECK(ids[2] == 2002);
  std::sort(ids.begin(), ids.end());
  CHECK(std::adjacent_find(ids.begin(), ids.end()) == ids.end());  // each once
}

TEST_CASE("StreamMerge: empty streams and a stream out of time order", "[core][stream_merge]") {
  const std::vector<Tick> none;
  int calls = 0;
  CHECK(for_each_in_time_order([&](const Tick&) { ++calls; }, none, none) == 0);
  CHECK(calls == 0);
  const std::vector<Tick> good{{1, 0}, {2, 1}};
  const std::vector<Tick> bad{{1, 0}, {5, 1}, {3, 2}};
  CHECK_THROWS_AS(for_each_in_time_order([&](const Tick&) { ++calls; }, good, bad),
                  posefuse::invalid_argument);
  CHECK_THROWS_WITH(for_each_in_time_order([&](const Tick&) { ++calls; }, good, bad),
                    Catch::Contains("stream 1 is not in time order: sample 2 has t_ns 3 after 5"));
  CHECK(calls == 0);  // checked before the first sample is visited
}

// The corridor simulation: geometry, determinism, sensor models, SLAM failure.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <set>
#include <posefuse/sim/corridor.hpp>
#include <posefuse/core/time.hpp>

using posefuse::sim::CorridorSimConfig;
using posefuse::SlamState;
using posefuse::sim::simulate_corridor;

namespace {
const posefuse::sim::CorridorSimulation& sim1() {
  static const auto s = simulate_corridor({}, 1);
  return s;
}
double t_of(const CorridorSimConfig& c, std::int64_t t_ns) { return posefuse::seconds_between(t_ns, c.t0_ns); }
}  // namespace

TEST_CASE("Corridor sim: the same seed gives the same log, another seed another", "[sim]") {
  const auto a = simulate_corridor({}, 7);
  const auto b = simulate_corridor({}, 7);
  const auto c = simulate_corridor({}, 8);
  CHECK(a.log == b.log);
  CHECK_FALSE(a.log == c.log);
}

TEST_CASE("Corridor sim: 14 m x 9 m counter-clockwise loop back to the start", "[sim]") {
  const auto& s = sim1();
  const auto& gt = s.log.groundtruth;
  REQUIRE(gt.size() > 1000);
  CHECK(gt.front().pose.x() == 0.0);
  CHECK(gt.front().pose(2) == 0.0);
  CHECK(std::abs(gt.back().pose.x()) < 1e-9);
  CHECK(std::abs(gt.back().pose.y()) < 1e-9);
  CHECK(std::abs(gt.back().pose(2)) < 1e-9);
  // Corners at the end of each leg: 2 = (14, 0), 3 = (14, 9), 4 = (0, 9).
  REQUIRE(s.manoeuvres.size() == 8);
  const double corners[3][2] = {{14, 0}, {14, 9}, {0, 9}};
  for (int k = 0; k < 3; ++k) {
    const double t = s.manoeuvres[std::size_t(2 * k)].t_end_s;
    const auto it = std::lower_bound(gt.begin(), gt.end(), t, [&](const auto& g, double v) {
      return t_of(CorridorSimConfig{}, g.t_ns) < v;
    });
    REQUIRE(it != gt.end());
    CHECK(it->pose.x() == Approx(corners[k][0]).margin(1e-3));
    CHECK(it->pose.y() == Approx(corners[k][1]).margin(1e-3));
  }
  // Counter-clockwise: every turn is +90°, and x, y stay inside the rectangle.
  for (const auto& m : s.manoeuvres) CHECK(m.t_end_s > m.t_start_s);
  for (const auto& g : gt) {
    CHECK(g.pose.x() > -1e-6);
    CHECK(g.pose.x() < 14 + 1e-6);
    CHECK(g.pose.y() > -1e-6);
    CHECK(g.pose.y() < 9 + 1e-6);
  }
}

TEST_CASE("Corridor sim: asynchronous streams with strictly increasing, unshared stamps", "[sim]") {
  const auto& L = sim1().log;
  std::set<std::int64_t> wheel_t, imu_t;
  for (std::size_t i = 1; i < L.wheels.size(); ++i) CHECK(L.wheels[i].t_ns > L.wheels[i - 1].t_ns);
  for (std::size_t i = 1; i < L.imu.size(); ++i) CHECK(L.imu[i].t_ns > L.imu[i - 1].t_ns);
  for (std::size_t i = 1; i < L.slam.size(); ++i) CHECK(L.slam[i].t_ns > L.slam[i - 1].t_ns);
  for (const auto& w : L.wheels) wheel_t.insert(w.t_ns);
  for (const auto& m : L.imu) imu_t.insert(m.t_ns);
  int shared = 0;
  for (const auto& sl : L.slam) shared += int(wheel_t.count(sl.t_ns) + imu_t.count(sl.t_ns));
  for (const auto& m : L.imu) shared += int(wheel_t.count(m.t_ns));
  CHECK(shared == 0);
  // Rates: about 50, 100 and 15 Hz over the run.
  const double T = sim1().duration_s;
  CHECK(double(L.wheels.size()) / T == Approx(50).epsilon(0.02));
  CHECK(double(L.imu.size()) / T == Approx(100).epsilon(0.02));
  CHECK(double(L.slam.size()) / T == Approx(15).epsilon(0.02));
}

TEST_CASE("Corridor sim: encoders count a full turn; the IMU reads gravity and a field", "[sim]") {
  const auto& s = sim1();
  const CorridorSimConfig c;
  const auto& w = s.log.wheels.back().ticks;
  const double m_per_tick = 2 * std::numbers::pi * c.wheel_radius_m / c.ticks_per_rev;
  const double left = 0.5 * double(w.fl + w.bl) * m_per_tick;
  const double right = 0.5 * double(w.fr + w.br) * m_per_tick;
  CHECK(0.5 * (left + right) == Approx(46.0).epsilon(0.01));  // 2 x (14 + 9) m
  // Heading from the encoders: 2π, off by the effective-track error (1.5 %
  // + N(0, 1 %) per turn) and the wheel-radius errors on the straights.
  const double heading = (right - left) / c.track_width_m;
  CHECK(heading > 2 * std::numbers::pi);
  CHECK(heading < 2 * std::numbers::pi * 1.06);
  // At rest (first second): specific force ~ (0, 0, 9.81), gyro ~ bias.
  double az = 0, gz = 0, mnorm = 0;
  int n = 0;
  for (const auto& m : s.log.imu) {
    if (t_of(c, m.t_ns) > 1.0) break;
    az += m.accel_mps2.z();
    gz += m.gyro_radps.z();
    mnorm += m.mag_uT.norm();
    ++n;
  }
  CHECK(az / n == Approx(9.81).margin(0.2));
  CHECK(std::abs(gz / n) < 0.015);
  CHECK(mnorm / n > 25);
  CHECK(mnorm / n < 90);
}

TEST_CASE("Corridor sim: SLAM freezes before corner 3, is lost, and re-initialises later",
          "[sim]") {
  const auto& s = sim1();
  const CorridorSimConfig c;
  CHECK(s.t_freeze_s < s.manoeuvres[3].t_start_s);  // before the turn at corner 3
  CHECK(s.t_lost_s > s.t_freeze_s);
  CHECK(s.t_reinit_s > s.manoeuvres[3].t_end_s);     // after it
  int reinit = 0, lost_after_freeze = 0, frozen = 0;
  double fx = 0, fy = 0;
  for (const auto& r : s.log.slam) {
    const double t = t_of(c, r.t_ns);
    reinit += r.state == SlamState::kReinit;
    if (t >= s.t_lost_s && t < s.t_reinit_s) lost_after_freeze += r.state == SlamState::kLost;
    if (t >= s.t_lost_s && t < s.t_reinit_s) CHECK(r.state == SlamState::kLost);
    if (t >= s.t_freeze_s && t < s.t_lost_s) {
      CHECK(r.state == SlamState::kTracking);
      if (frozen++ == 0) {
        fx = r.position_m.x();
        fy = r.position_m.y();
      }
      CHECK(std::hypot(r.position_m.x() - fx, r.position_m.y() - fy) < 0.25);  // stuck, up to noise
    }
    if (t >= s.t_reinit_s) CHECK(r.state != SlamState::kLost);
  }
  CHECK(reinit == 1);
  CHECK(frozen > 30);
  CHECK(lost_after_freeze > 100);
  // The reinit pose is expressed in a new frame: far from the world pose.
  const auto it = std::find_if(s.log.slam.begin(), s.log.slam.end(),
                               [](const auto& r) { return r.state == SlamState::kReinit; });
  REQUIRE(it != s.log.slam.end());
  CHECK(it->orientation.norm() == Approx(1.0));
}

TEST_CASE("Corridor sim: an invalid config is rejected, naming the field", "[sim]") {
  struct Case {
    void (*set)(CorridorSimConfig&);
    const char* what;
  };
  const Case cases[] = {
      {[](CorridorSimConfig& c) { c.wheel_rate_hz = 0; }, "wheel_rate_hz must be positive"},
      {[](CorridorSimConfig& c) { c.imu_rate_hz = -100; }, "imu_rate_hz must be positive"},
      {[](CorridorSimConfig& c) { c.slam_rate_hz = std::nan(""); }, "slam_rate_hz must be positive"},
      {[](CorridorSimConfig& c) { c.jitter_s = 0.01; }, "jitter_s must be less than half the sample period of wheel_rate_hz"},
      {[](CorridorSimConfig& c) { c.jitter_s = 0.005; }, "jitter_s must be less than half the sample period of imu_rate_hz"},  // 100 Hz: dt/2 = 5 ms
      {[](CorridorSimConfig& c) { c.jitter_s = -0.001; }, "jitter_s must be >= 0"},
      {[](CorridorSimConfig& c) { c.leg_a_m = 0; }, "leg_a_m must be positive"},
      {[](CorridorSimConfig& c) { c.cruise_speed_mps = -0.4; }, "cruise_speed_mps must be positive"},
      {[](CorridorSimConfig& c) { c.wheel_radius_m = 0; }, "wheel_radius_m must be positive"},
      {[](CorridorSimConfig& c) { c.slip_sigma = -0.01; }, "slip_sigma must be >= 0"},
      {[](CorridorSimConfig& c) { c.pause_s = -1; }, "pause_s must be >= 0"},
      {[](CorridorSimConfig& c) { c.complementary_alpha = 1.0; }, "complementary_alpha must lie in (0, 1)"},
      {[](CorridorSimConfig& c) { c.track_error = -1.0; }, "track_error must be > -1"},
      {[](CorridorSimConfig& c) { c.disturbance_blobs = -1; }, "disturbance_blobs must be >= 0"},
      {[](CorridorSimConfig& c) { c.reinit_after_corner3_m = 20; }, "reinit_after_corner3_m must lie within leg 3"},
      {[](CorridorSimConfig& c) { c.freeze_before_corner3_m = 30; }, "freeze_before_corner3_m must be shorter"},
  };
  for (const auto& k : cases) {
    CorridorSimConfig c;
    k.set(c);
    INFO(k.what);
    CHECK_THROWS_AS(simulate_corridor(c, 1), posefuse::invalid_argument);
    CHECK_THROWS_WITH(simulate_corridor(c, 1), Catch::Contains(std::string("CorridorSimConfig: ") + k.what));
  }
  CHECK_NOTHROW(posefuse::sim::validate(CorridorSimConfig{}));
  CorridorSimConfig edge;
  edge.jitter_s = 0.0049;  // just under half of the IMU's 10 ms
  const auto s = simulate_corridor(edge, 1);
  for (std::size_t i = 1; i < s.log.imu.size(); ++i) REQUIRE(s.log.imu[i].t_ns > s.log.imu[i - 1].t_ns);
}

TEST_CASE("Corridor sim: a clock origin too close to the end of int64 is rejected", "[sim][overflow]") {
  CorridorSimConfig c;
  c.t0_ns = std::numeric_limits<std::int64_t>::max() - 1'000'000'000;  // 1 s before the end
  CHECK_THROWS_AS(simulate_corridor(c, 1), posefuse::invalid_argument);
  CHECK_THROWS_WITH(simulate_corridor(c, 1), Catch::Contains("does not fit in int64 nanoseconds"));
  c.t0_ns = std::numeric_limits<std::int64_t>::min();  // the start of the range is fine
  const auto s = simulate_corridor(c, 1);
  CHECK(s.log.wheels.front().t_ns >= c.t0_ns);
  CHECK(posefuse::seconds_between(s.log.wheels.back().t_ns, c.t0_ns) == Approx(s.duration_s).margin(0.05));
}

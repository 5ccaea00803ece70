// The estimator (vio/estimator.hpp) end to end on the synthetic flight with
// simulated tracks (sim/feature_tracks.hpp) and a simulated IMU (sim/imu.hpp).
#include <catch2/catch.hpp>

#include <cmath>

#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/vio/estimator.hpp>

using namespace posefuse;

namespace {

struct Run {
  double max_position_error_m = 0;
  double final_position_error_m = 0;
  double final_gyro_bias_error = 0;
  int tracking = 0, frames = 0;
  Eigen::Vector3d final_p;
};

Run run(double duration_s, const ImuNoise& imu_noise, const sim::TrackSimConfig& tc, bool static_start = false) {
  sim::ImuSimConfig flight = sim::synthetic_flight();
  flight.noise = imu_noise;
  flight.initial_bias = ImuBias{Eigen::Vector3d(0.05, -0.04, 0.03), Eigen::Vector3d(0.002, -0.003, 0.001)};
  const sim::ImuSequence seq = sim::simulate_imu(flight, duration_s + 0.1);
  const PinholeRadtan cam = sim::synthetic_camera();
  const sim::SimulatedTracks st = sim::simulate_feature_tracks(flight, duration_s, cam, tc);
  VioEstimatorOptions o;
  if (imu_noise.accel_noise_density > 0) o.noise = imu_noise;
  VioEstimator est(cam, o);
  const sim::ImuTruth& t0 = seq.truth[0];
  if (!static_start) est.set_initial_state(ImuState{t0.p_w, t0.R_w_b, t0.v_w, t0.bias});
  Run r;
  std::size_t k = 0;
  for (const TrackFrame& f : st.tracks) {
    while (k < seq.samples.size() && seq.samples[k].t_ns <= f.t_ns + 5'000'000) est.add_imu(seq.samples[k++]);
    const VioFrameResult res = est.add_frame(f);
    ++r.frames;
    if (res.status == VioStatus::kTracking) ++r.tracking;
    const std::size_t s = std::size_t((f.t_ns - flight.start_t_ns) / 5'000'000);
    REQUIRE(seq.truth[s].t_ns == f.t_ns);
    const double e = (res.state.p - seq.truth[s].p_w).norm();
    r.max_position_error_m = std::max(r.max_position_error_m, e);
    r.final_position_error_m = e;
    r.final_gyro_bias_error = (res.state.bias.gyro - seq.truth[s].bias.gyro).norm();
    r.final_p = res.state.p;
  }
  return r;
}

}  // namespace

TEST_CASE("VioEstimator: follows the synthetic flight with noisy tracks and IMU", "[vio][estimator]") {
  sim::TrackSimConfig tc;
  tc.pixel_noise_px = 0.5;
  tc.outlier_fraction = 0.0;
  const ImuNoise noise;  // EuRoC-like densities
  const Run r = run(4.0, noise, tc);
  INFO("frames " << r.frames << " tracking " << r.tracking << " max |dp| " << r.max_position_error_m
                 << " m, final " << r.final_position_error_m << " m, gyro bias error " << r.final_gyro_bias_error);
  CHECK(r.tracking >= r.frames - 5);
  CHECK(r.max_position_error_m < 0.05);
}

namespace {

// The synthetic flight (moving from its first sample) with 0.5 px tracks and
// EuRoC-like IMU noise, run through an estimator with no initial state;
// `blank` frames in [blank_from_s, blank_to_s) have their features removed.
struct MotionRun {
  std::vector<VioFrameResult> results;
  std::vector<sim::ImuTruth> truth;  // at each frame
};

MotionRun run_from_motion(double duration_s, VioInit init, double blank_from_s = -1, double blank_to_s = -1) {
  sim::ImuSimConfig flight = sim::synthetic_flight();
  flight.noise = ImuNoise{};
  flight.initial_bias = ImuBias{Eigen::Vector3d(0.05, -0.04, 0.03), Eigen::Vector3d(0.002, -0.003, 0.001)};
  const sim::ImuSequence seq = sim::simulate_imu(flight, duration_s + 0.1);
  const PinholeRadtan cam = sim::synthetic_camera();
  sim::TrackSimConfig tc;
  tc.pixel_noise_px = 0.5;
  tc.outlier_fraction = 0.0;
  const sim::SimulatedTracks st = sim::simulate_feature_tracks(flight, duration_s, cam, tc);
  VioEstimatorOptions o;
  o.noise = flight.noise;
  o.init = init;
  VioEstimator est(cam, o);
  MotionRun r;
  std::size_t k = 0;
  for (TrackFrame f : st.tracks) {
    const double t_s = double(f.t_ns - flight.start_t_ns) * 1e-9;
    if (t_s >= blank_from_s && t_s < blank_to_s) f.features.clear();
    while (k < seq.samples.size() && seq.samples[k].t_ns <= f.t_ns + 5'000'000) est.add_imu(seq.samples[k++]);
    r.results.push_back(est.add_frame(f));
    r.truth.push_back(seq.truth[std::size_t((f.t_ns - flight.start_t_ns) / 5'000'000)]);
  }
  return r;
}

// Angle (deg) between the estimated and the true gravity direction in the body.
double gravity_error_deg(const ImuState& x, const sim::ImuTruth& t) {
  const Eigen::Vector3d a = x.R.matrix().transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d b = t.R_w_b.matrix().transpose() * Eigen::Vector3d::UnitZ();
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / 3.14159265358979;
}

}  // namespace

TEST_CASE("VioEstimator: starts in motion (SfM + visual-inertial alignment) within 2 s", "[vio][estimator]") {
  for (const VioInit init : {VioInit::kAuto, VioInit::kDynamic}) {
    const MotionRun r = run_from_motion(5.0, init);
    std::size_t s = 0;
    while (s < r.results.size() && !r.results[s].started) ++s;
    REQUIRE(s < r.results.size());
    INFO(to_string(init) << ": started at frame " << s << ": " << r.results[s].message);
    CHECK(r.results[s].message.find("in motion") != std::string::npos);
    CHECK(double(r.results[s].t_ns - r.results[0].t_ns) * 1e-9 <= 2.0);
    for (std::size_t i = 0; i < s; ++i) {
      CHECK(r.results[i].status == VioStatus::kInitializing);
      CHECK_FALSE(r.results[i].message.empty());
    }
    // From the start on: no failure; gravity, speed and distances as the truth's
    // (the start's world frame differs from the simulation's by a yaw and a translation).
    double worst_gravity = 0, worst_speed = 0, worst_distance = 0;
    for (std::size_t i = s; i < r.results.size(); ++i) {
      const VioFrameResult& x = r.results[i];
      REQUIRE(x.status != VioStatus::kFailed);
      worst_gravity = std::max(worst_gravity, gravity_error_deg(x.state, r.truth[i]));
      worst_speed = std::max(worst_speed, std::abs(x.state.v.norm() - r.truth[i].v_w.norm()));
      const double d_est = (x.state.p - r.results[s].state.p).norm();
      const double d_true = (r.truth[i].p_w - r.truth[s].p_w).norm();
      worst_distance = std::max(worst_distance, std::abs(d_est - d_true));
    }
    INFO("worst gravity error " << worst_gravity << " deg, speed error " << worst_speed << " m/s, distance error "
                                << worst_distance << " m");
    CHECK(worst_gravity < 1.0);
    CHECK(worst_speed < 0.1);
    CHECK(worst_distance < 0.1);
  }
}

TEST_CASE("VioEstimator: a static start is refused on a moving flight; kStatic never starts", "[vio][estimator]") {
  const MotionRun r = run_from_motion(2.0, VioInit::kStatic);
  for (const VioFrameResult& x : r.results) CHECK(x.status == VioStatus::kInitializing);
  CHECK(r.results.back().message.find("static start") != std::string::npos);
}

TEST_CASE("VioEstimator: two seconds without features fail, and it starts again where it was", "[vio][estimator]") {
  const MotionRun r = run_from_motion(9.0, VioInit::kAuto, 4.0, 6.0);
  std::size_t failed = r.results.size(), restarted = r.results.size();
  int starts = 0;
  for (std::size_t i = 0; i < r.results.size(); ++i) {
    if (r.results[i].started) ++starts;
    if (r.results[i].status == VioStatus::kFailed && failed == r.results.size()) failed = i;
    if (r.results[i].started && failed < r.results.size() && restarted == r.results.size()) restarted = i;
  }
  REQUIRE(failed < r.results.size());
  INFO(r.results[failed].message);
  CHECK(r.results[failed].message.find("tracked features") != std::string::npos);
  const double failed_at = double(r.results[failed].t_ns - r.results[0].t_ns) * 1e-9;
  CHECK(failed_at > 4.9);   // lost for more than max_lost_s = 1 s ...
  CHECK(failed_at < 5.2);   // ... and not much later
  CHECK(starts == 2);
  REQUIRE(restarted < r.results.size());
  CHECK(double(r.results[restarted].t_ns - r.results[0].t_ns) * 1e-9 < 8.0);  // within 2 s of vision's return
  CHECK(r.results[restarted].anchored);  // within anchor_within_s of the last good frame
  // Anchored: after the restart the estimate stays in the first start's frame.
  // The first start's frame is the truth's moved by a yaw and a translation;
  // find them from the first start's frame and compare after the restart.
  std::size_t s = 0;
  while (!r.results[s].started) ++s;
  CHECK_FALSE(r.results[s].anchored);  // the first start has nothing to be anchored to
  const auto yaw = [](const SO3d& R) { return std::atan2(R.matrix()(1, 0), R.matrix()(0, 0)); };
  const SO3d dR = SO3d::exp(Eigen::Vector3d(0, 0, yaw(r.truth[s].R_w_b) - yaw(r.results[s].state.R)));
  const Eigen::Vector3d dt = r.truth[s].p_w - dR.act(r.results[s].state.p);
  double worst = 0;
  for (std::size_t i = restarted; i < r.results.size(); ++i)
    worst = std::max(worst, (dR.act(r.results[i].state.p) + dt - r.truth[i].p_w).norm());
  INFO("worst position error after the restart " << worst << " m");
  CHECK(worst < 0.5);
}

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

// The estimator (vio/estimator.hpp) with wrong associations in its tracks:
// 5 % of the observations replaced by another landmark's pixel
// (sim/feature_tracks.hpp) must not move the position error by more than a
// stated factor against the same tracks without them.
#include <catch2/catch.hpp>

#include <cmath>

#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/vio/estimator.hpp>

using namespace posefuse;

namespace {

struct Ape {
  double rmse_m = 0;
  int tracking = 0, frames = 0;
};

// Position RMSE against the truth over every frame (no alignment: the
// estimator starts from the true state, so the truth's frame is its frame).
Ape run(double duration_s, double outlier_fraction, std::uint64_t seed) {
  sim::ImuSimConfig flight = sim::synthetic_flight();
  flight.noise = ImuNoise{};
  flight.initial_bias = ImuBias{Eigen::Vector3d(0.05, -0.04, 0.03), Eigen::Vector3d(0.002, -0.003, 0.001)};
  const sim::ImuSequence seq = sim::simulate_imu(flight, duration_s + 0.1);
  const PinholeRadtan cam = sim::synthetic_camera();
  sim::TrackSimConfig tc;
  tc.pixel_noise_px = 1.0;
  tc.outlier_fraction = outlier_fraction;
  tc.seed = seed;
  const sim::SimulatedTracks st = sim::simulate_feature_tracks(flight, duration_s, cam, tc);
  VioEstimatorOptions o;
  o.noise = flight.noise;
  VioEstimator est(cam, o);
  const sim::ImuTruth& t0 = seq.truth[0];
  est.set_initial_state(ImuState{t0.p_w, t0.R_w_b, t0.v_w, t0.bias});
  Ape a;
  double se = 0;
  std::size_t k = 0;
  for (const TrackFrame& f : st.tracks) {
    while (k < seq.samples.size() && seq.samples[k].t_ns <= f.t_ns + 5'000'000) est.add_imu(seq.samples[k++]);
    const VioFrameResult res = est.add_frame(f);
    ++a.frames;
    if (res.status == VioStatus::kTracking) ++a.tracking;
    const std::size_t s = std::size_t((f.t_ns - flight.start_t_ns) / 5'000'000);
    REQUIRE(seq.truth[s].t_ns == f.t_ns);
    se += (res.state.p - seq.truth[s].p_w).squaredNorm();
  }
  a.rmse_m = std::sqrt(se / a.frames);
  return a;
}

}  // namespace

TEST_CASE("VioEstimator: 5 % wrong associations move the position RMSE by at most 1.5x",
          "[vio][estimator][outliers][slow]") {
  // Same IMU and simulator seed; the wrong associations also shift the
  // simulator's later draws, so the two track sets differ beyond them.
  const Ape clean = run(4.0, 0.0, 3);
  const Ape wrong = run(4.0, 0.05, 3);
  INFO("RMSE without wrong associations " << clean.rmse_m << " m (tracking " << clean.tracking << "/"
                                          << clean.frames << "), with 5 %: " << wrong.rmse_m << " m (tracking "
                                          << wrong.tracking << "/" << wrong.frames << ")");
  CHECK(wrong.tracking >= wrong.frames - 5);
  // Measured: 0.042 m without, 0.027 m with (the track sets differ, see above).
  CHECK(wrong.rmse_m <= 1.5 * clean.rmse_m);
}

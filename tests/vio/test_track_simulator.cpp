// The feature-track simulator (sim/feature_tracks.hpp): exact projections
// without noise, the pixel noise sigma and the wrong-association fraction
// recovered from the output, the track length limit, the detection mask,
// determinism for a seed, ground-truth interpolation and its gap check, and
// the real V1_01_easy motion when present.
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <string>

#include <posefuse/io/euroc.hpp>
#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/vio/camera.hpp>

#include "support/data_path.hpp"

namespace {

namespace sim = posefuse::sim;

sim::SimulatedTracks simulate(const sim::TrackSimConfig& c, double duration_s = 10.0) {
  return sim::simulate_feature_tracks(sim::synthetic_flight(), duration_s, sim::synthetic_camera(), c);
}

// Observations per id, checking on the way that an id's frames are consecutive.
std::map<std::uint64_t, int> track_lengths(const sim::SimulatedTracks& s, bool& contiguous) {
  std::map<std::uint64_t, int> length;
  std::map<std::uint64_t, std::size_t> last;
  contiguous = true;
  for (std::size_t k = 0; k < s.tracks.size(); ++k) {
    for (const posefuse::FeatureObservation& o : s.tracks[k].features) {
      if (last.count(o.id) && last[o.id] + 1 != k) contiguous = false;
      last[o.id] = k;
      ++length[o.id];
    }
  }
  return length;
}

}  // namespace

TEST_CASE("Track simulator: without noise the pixels are the exact projections", "[vio][sim]") {
  sim::TrackSimConfig c;
  c.pixel_noise_px = 0;
  c.outlier_fraction = 0;
  const sim::SimulatedTracks s = simulate(c, 3.0);
  const posefuse::PinholeRadtan cam = sim::synthetic_camera();
  REQUIRE(s.tracks.size() == 61);  // 3 s at 20 Hz, both ends included
  CHECK(s.tracks[1].t_ns - s.tracks[0].t_ns == 50'000'000);
  CHECK(s.wrong_associations == 0);
  double worst = 0;
  for (std::size_t k = 0; k < s.tracks.size(); ++k) {
    const Eigen::Isometry3d T_C_W = (s.T_W_B[k] * cam.T_BS).inverse();
    for (std::size_t i = 0; i < s.tracks[k].features.size(); ++i) {
      const posefuse::FeatureObservation& o = s.tracks[k].features[i];
      CHECK(s.truth[k][i].landmark == s.landmark_of_id[o.id]);
      const Eigen::Vector3d p_C = T_C_W * s.landmarks_w[s.landmark_of_id[o.id]];
      CHECK(p_C.z() >= c.min_depth_m);
      const std::optional<Eigen::Vector2d> uv = cam.project(p_C);
      REQUIRE(uv);
      worst = std::max(worst, (*uv - o.uv).norm());
    }
  }
  CHECK(worst < 1e-9);
}

TEST_CASE("Track simulator: noise sigma, wrong-association fraction, features per frame", "[vio][sim]") {
  sim::TrackSimConfig c;  // defaults: 1 px, 5 %, 150 features, 60 frames
  const sim::SimulatedTracks s = simulate(c);
  REQUIRE(s.observations > 25000);
  double sum = 0, sum2 = 0;
  std::size_t n = 0, wrong = 0;
  for (std::size_t k = 0; k < s.tracks.size(); ++k) {
    for (std::size_t i = 0; i < s.tracks[k].features.size(); ++i) {
      if (s.truth[k][i].wrong_association) {
        ++wrong;
        continue;
      }
      const Eigen::Vector2d e = s.tracks[k].features[i].uv - s.truth[k][i].uv_true;
      sum += e.x() + e.y();
      sum2 += e.squaredNorm();
      n += 2;
    }
  }
  CHECK(wrong == s.wrong_associations);
  const double mean = sum / double(n), sigma = std::sqrt(sum2 / double(n) - mean * mean);
  // Standard errors: sigma / sqrt(2 n) = 0.004 px for the mean and about
  // 0.003 px for sigma; the bounds are 5 standard errors.
  CHECK(std::abs(mean) < 0.02);
  CHECK(std::abs(sigma - 1.0) < 0.015);
  const double fraction = double(s.wrong_associations) / double(s.observations);
  CHECK(std::abs(fraction - 0.05) < 0.0065);  // binomial standard error 0.0013
  const double per_frame = double(s.observations) / double(s.tracks.size());
  CHECK(per_frame > 145);
  CHECK(per_frame <= 150);
  for (const posefuse::TrackFrame& f : s.tracks) CHECK(f.features.size() <= 150);
}

TEST_CASE("Track simulator: wrong associations are far from the truth, the others exact", "[vio][sim]") {
  sim::TrackSimConfig c;
  c.pixel_noise_px = 0;
  c.outlier_fraction = 0.2;
  const sim::SimulatedTracks s = simulate(c, 4.0);
  std::size_t wrong = 0;
  for (std::size_t k = 0; k < s.tracks.size(); ++k) {
    for (std::size_t i = 0; i < s.tracks[k].features.size(); ++i) {
      const double e = (s.tracks[k].features[i].uv - s.truth[k][i].uv_true).norm();
      if (s.truth[k][i].wrong_association) {
        ++wrong;
        CHECK(e >= c.outlier_min_error_px);
      } else {
        CHECK(e == 0.0);
      }
    }
  }
  CHECK(std::abs(double(wrong) / double(s.observations) - 0.2) < 0.02);
}

TEST_CASE("Track simulator: track length limit, contiguous tracks, detection mask", "[vio][sim]") {
  sim::TrackSimConfig c;
  c.max_track_length = 20;
  c.pixel_noise_px = 0;
  c.outlier_fraction = 0;
  const sim::SimulatedTracks s = simulate(c);
  bool contiguous = false;
  const std::map<std::uint64_t, int> len = track_lengths(s, contiguous);
  CHECK(contiguous);
  int longest = 0;
  for (const auto& [id, l] : len) longest = std::max(longest, l);
  CHECK(longest == 20);
  CHECK(len.size() == s.landmark_of_id.size());
  CHECK(len.rbegin()->first + 1 == len.size());  // ids 0, 1, 2, ... without holes
  // New tracks keep min_feature_distance_px from the tracks going on: in the
  // first frame, where all tracks are new, no two features are closer.
  const auto& f0 = s.tracks.front().features;
  double closest = 1e9;
  for (std::size_t i = 0; i < f0.size(); ++i)
    for (std::size_t j = i + 1; j < f0.size(); ++j) closest = std::min(closest, (f0[i].uv - f0[j].uv).norm());
  CHECK(closest >= c.min_feature_distance_px);
  // The limits are spread over [10, 20], so not every track ends on the same frame.
  int at_limit = 0;
  for (const auto& [id, l] : len) at_limit += l == 20 ? 1 : 0;
  CHECK(at_limit < int(len.size()) / 2);
}

TEST_CASE("Track simulator: a seed gives the same tracks bit for bit", "[vio][sim]") {
  sim::TrackSimConfig c;
  const sim::SimulatedTracks a = simulate(c, 3.0), b = simulate(c, 3.0);
  REQUIRE(a.tracks.size() == b.tracks.size());
  bool same = a.landmarks_w == b.landmarks_w;
  for (std::size_t k = 0; k < a.tracks.size(); ++k) {
    same = same && a.tracks[k].features.size() == b.tracks[k].features.size();
    for (std::size_t i = 0; same && i < a.tracks[k].features.size(); ++i)
      same = a.tracks[k].features[i].id == b.tracks[k].features[i].id &&
             a.tracks[k].features[i].uv == b.tracks[k].features[i].uv;
  }
  CHECK(same);
  c.seed = 2;
  const sim::SimulatedTracks d = simulate(c, 3.0);
  CHECK(d.tracks[0].features[0].uv != a.tracks[0].features[0].uv);
}

TEST_CASE("Track simulator: along a ground truth, interpolated, gaps refused", "[vio][sim]") {
  const posefuse::EurocGroundTruth gt = sim::synthetic_groundtruth(sim::synthetic_flight(), 2.0, 200.0);
  sim::TrackSimConfig c;
  c.pixel_noise_px = 0;
  c.outlier_fraction = 0;
  // Frames at 20 Hz fall on every 10th state: the same poses as the flight's.
  const sim::SimulatedTracks s = sim::simulate_feature_tracks(gt, sim::synthetic_camera(), c);
  REQUIRE(s.T_W_B.size() == 41);
  CHECK(s.T_W_B[7].isApprox(gt.trajectory.poses[70], 0.0));
  // At 30 Hz frames fall between states: interpolated.
  c.rate_hz = 30;
  const sim::SimulatedTracks s30 = sim::simulate_feature_tracks(gt, sim::synthetic_camera(), c);
  REQUIRE(s30.T_W_B.size() == 61);
  const Eigen::Isometry3d T_exact = sim::synthetic_groundtruth(sim::synthetic_flight(), 1.0, 30.0).trajectory.poses[1];
  CHECK((s30.T_W_B[1].translation() - T_exact.translation()).norm() < 1e-4);  // 5 ms interval, ~2.5 m/s
  // Remove 30 states (0.15 s): a frame inside is refused, naming the stamps.
  posefuse::EurocGroundTruth gap = gt;
  gap.t_ns.erase(gap.t_ns.begin() + 100, gap.t_ns.begin() + 130);
  gap.trajectory.poses.erase(gap.trajectory.poses.begin() + 100, gap.trajectory.poses.begin() + 130);
  gap.trajectory.t_s.erase(gap.trajectory.t_s.begin() + 100, gap.trajectory.t_s.begin() + 130);
  c.rate_hz = 20;
  CHECK_THROWS_WITH(sim::simulate_feature_tracks(gap, sim::synthetic_camera(), c),
                    Catch::Contains("the ground truth has a gap of 0.155") &&
                        Catch::Contains(std::to_string(gt.t_ns[99]) + " and " + std::to_string(gt.t_ns[130])));
  c.max_pose_gap_s = 0.2;
  CHECK_NOTHROW(sim::simulate_feature_tracks(gap, sim::synthetic_camera(), c));
}

TEST_CASE("Track simulator: bad parameters are refused", "[vio][sim]") {
  const auto refused = [](auto edit) {
    sim::TrackSimConfig c;
    edit(c);
    try {
      (void)simulate(c, 1.0);
    } catch (const posefuse::invalid_argument&) {
      return true;
    }
    return false;
  };
  CHECK(refused([](sim::TrackSimConfig& c) { c.outlier_fraction = 1.0; }));
  CHECK(refused([](sim::TrackSimConfig& c) { c.pixel_noise_px = std::nan(""); }));
  CHECK(refused([](sim::TrackSimConfig& c) { c.rate_hz = 0; }));
  CHECK(refused([](sim::TrackSimConfig& c) { c.max_track_length = 1; }));
  CHECK(refused([](sim::TrackSimConfig& c) { c.free_depth_min_m = 5; }));
  CHECK_FALSE(refused([](sim::TrackSimConfig&) {}));
}

TEST_CASE("Track simulator: the real V1_01_easy motion with the real cam0", "[vio][sim][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  posefuse::EurocGroundTruth gt = posefuse::read_euroc_groundtruth(d / "groundtruth_20hz.csv");
  REQUIRE(gt.size() == 2895);
  // The first 30 s keep the test fast.
  const std::size_t n = 601;
  gt.t_ns.resize(n);
  gt.trajectory.t_s.resize(n);
  gt.trajectory.poses.resize(n);
  gt.velocity.reset();
  gt.gyro_bias.reset();
  gt.accel_bias.reset();
  const sim::SimulatedTracks s =
      sim::simulate_feature_tracks(gt, posefuse::read_euroc_camera(d / "cam0_sensor.yaml"), sim::TrackSimConfig{});
  CHECK(s.tracks.size() == 601);  // 50 ms frames over the 30 s of 601 states
  const double per_frame = double(s.observations) / double(s.tracks.size());
  CHECK(per_frame > 145);
  CHECK(std::abs(double(s.wrong_associations) / double(s.observations) - 0.05) < 0.005);
}

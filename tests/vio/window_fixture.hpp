#pragma once
// A noise-free synthetic window for the estimator tests: the IMU simulator's
// flight (sim/imu.hpp), keyframes every `frame_step` samples whose states are
// chained by the IMU factors' predictions (so every IMU residual is exactly
// zero at the truth), and landmarks seen through a pinhole camera looking
// along the body x axis, projected exactly (normalised coordinates).
#include <cmath>
#include <random>

#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/vio/window_state.hpp>

namespace vio_test {

struct WindowFixture {
  posefuse::VioWindow truth;
  posefuse::sim::ImuSequence seq;
};

// Camera z along body x, camera x along -body y, camera y along -body z.
inline posefuse::RigidPose camera_extrinsic() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return posefuse::RigidPose{Eigen::Vector3d(0.05, -0.02, 0.01), posefuse::SO3d(R)};
}

inline WindowFixture make_window(std::uint64_t seed, int frames = 10, int landmarks = 150,
                                 int frame_step = 20, double noise_px = 0.0) {
  using namespace posefuse;
  WindowFixture fx;
  sim::ImuSimConfig c;
  c.initial_bias = ImuBias{Eigen::Vector3d(0.05, -0.03, 0.08), Eigen::Vector3d(0.002, -0.001, 0.003)};
  c.position_amplitude_m = Eigen::Vector3d(1.0, 0.8, 0.3);
  c.attitude_amplitude_rad = Eigen::Vector3d(0.2, 0.15, 0.6);
  fx.seq = sim::simulate_imu(c, double(frames * frame_step) / c.rate_hz + 0.05);
  VioWindow& w = fx.truth;
  w.T_bc = camera_extrinsic();
  w.gravity_w = Eigen::Vector3d(0, 0, -c.gravity_mps2);
  w.sqrt_info = Eigen::Vector2d(460.0, 455.0);
  ImuNoise noise;  // EuRoC-like densities for the factors' covariances
  for (int k = 0; k < frames; ++k) {
    VioFrame f;
    const std::size_t s = std::size_t(k * frame_step);
    f.t_ns = fx.seq.samples[s].t_ns;
    f.id = std::uint64_t(k + 1);
    if (k == 0) {
      const sim::ImuTruth& t = fx.seq.truth[0];
      f.x = ImuState{t.p_w, t.R_w_b, t.v_w, t.bias};
    } else {
      f.pre = Preintegration(noise, w.frames.back().x.bias);
      for (std::size_t i = s - std::size_t(frame_step); i <= s; ++i) (void)f.pre.add(fx.seq.samples[i]);
      f.imu.emplace(f.pre, w.gravity_w);
      f.x = f.imu->predict(w.frames.back().x);
    }
    w.frames.push_back(std::move(f));
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uint64_t id = 100;
  int made = 0;
  while (made < landmarks) {
    const int a = int(std::uniform_int_distribution<int>(0, frames - 2)(rng));
    const Eigen::Vector3d m(0.5 * u(rng), 0.4 * u(rng), 1.0);
    const double depth = 5.0 + 3.0 * u(rng);
    const VioFrame& fa = w.frames[std::size_t(a)];
    const Eigen::Vector3d P_w = VioFrame::pose(fa.x).act(w.T_bc.act(m * depth));
    VioLandmark l;
    for (int k = a; k < frames; ++k) {
      const VioFrame& f = w.frames[std::size_t(k)];
      const Eigen::Vector3d P_c = w.T_bc.R.inverse().act(f.x.R.inverse().act(P_w - f.x.p) - w.T_bc.p);
      if (!(P_c.z() > 0.5)) break;
      Eigen::Vector2d mk = P_c.head<2>() / P_c.z();
      if (std::abs(mk.x()) > 0.7 || std::abs(mk.y()) > 0.55) break;
      if (noise_px > 0 && k > a) mk += Eigen::Vector2d(u(rng), u(rng)) * (noise_px / 460.0);
      l.obs.push_back(VioObservation{f.id, mk});
    }
    if (l.obs.size() < 3) continue;
    l.inv_depth = 1.0 / depth;
    l.initialised = true;
    w.landmarks.emplace(id++, std::move(l));
    ++made;
  }
  return fx;
}

// Perturbs every keyframe by `dp_m` in a random direction and `dphi_rad` about
// a random axis (and the velocities by 0.05 m/s, the inverse depths by 5 %).
inline void perturb(posefuse::VioWindow& w, std::uint64_t seed, double dp_m, double dphi_rad) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto dir = [&] { return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized(); };
  for (posefuse::VioFrame& f : w.frames) {
    f.x.p += dp_m * dir();
    f.x.R = f.x.R.plus(dphi_rad * dir());
    f.x.v += 0.05 * dir();
  }
  for (auto& [id, l] : w.landmarks) l.inv_depth *= 1.0 + 0.05 * n(rng);
}

}  // namespace vio_test

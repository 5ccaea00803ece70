// An IMU synthesised from sampled poses (sim/imu_from_trajectory.hpp): it
// matches the analytic IMU of the motion the poses were sampled from, its
// pre-integration reproduces the poses' relative motion, its noise is seeded
// and portable, and bad poses are refused.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <posefuse/inertial/preintegrate.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/sim/imu_from_trajectory.hpp>

using posefuse::ImuNoise;
using posefuse::ImuSample;
using posefuse::SO3d;
using posefuse::sim::ImuFromTrajectoryConfig;
using posefuse::sim::ImuSequence;
using posefuse::sim::StampedPose;
using posefuse::sim::imu_from_trajectory;

namespace {

// Poses of sim/imu.hpp's analytic trajectory at `rate_hz` over `duration_s`.
std::vector<StampedPose> analytic_poses(const posefuse::sim::ImuSimConfig& c, double rate_hz, double duration_s) {
  const posefuse::sim::ImuTrajectory traj(c);
  const auto step_ns = std::int64_t(std::llround(1e9 / rate_hz));
  std::vector<StampedPose> poses;
  for (std::int64_t k = 0; double(k * step_ns) <= duration_s * 1e9 + 1; ++k) {
    const double t = double(k * step_ns) * 1e-9;
    poses.push_back({c.start_t_ns + k * step_ns, traj.position(t), traj.rotation(t).quaternion()});
  }
  return poses;
}

// Largest accelerometer and gyroscope errors against the analytic readings
// over samples at least `margin_s` from both ends.
void analytic_errors(const ImuSequence& seq, const posefuse::sim::ImuSimConfig& c, double duration_s,
                     double margin_s, double& accel, double& gyro) {
  const posefuse::sim::ImuTrajectory traj(c);
  accel = gyro = 0;
  for (const ImuSample& s : seq.samples) {
    const double t = double(s.t_ns - c.start_t_ns) * 1e-9;
    if (t < margin_s || t > duration_s - margin_s) continue;
    accel = std::max(accel, (s.accel_mps2 - traj.specific_force_body(t)).cwiseAbs().maxCoeff());
    gyro = std::max(gyro, (s.gyro_radps - traj.angular_velocity_body(t)).cwiseAbs().maxCoeff());
  }
}

}  // namespace

TEST_CASE("IMU from poses: matches the analytic IMU of the sampled motion away from the ends",
          "[sim][imu_from_trajectory]") {
  // sim/imu.hpp's trajectory (up to 2.5 m/s^2 and 0.6 rad/s) sampled at
  // 20 Hz for 6 s, a fit through the poses, 200 Hz readings. Measured (g++ 12
  // -O2): 1.1e-3 m/s^2 and 5.5e-6 rad/s beyond 0.5 s from the ends; within
  // them the free ends of the fit err by up to 1.5 m/s^2.
  posefuse::sim::ImuSimConfig c;
  const double duration = 6.0;
  const std::vector<StampedPose> poses = analytic_poses(c, 20.0, duration);
  REQUIRE(poses.size() == 121);
  const ImuSequence seq = imu_from_trajectory(poses);
  REQUIRE(seq.samples.size() == 1201);
  CHECK(seq.samples.front().t_ns == poses.front().t_ns);
  CHECK(seq.samples.back().t_ns == poses.back().t_ns);
  double accel = 0, gyro = 0;
  analytic_errors(seq, c, duration, 0.5, accel, gyro);
  INFO("20 Hz poses: accel error " << accel << " m/s^2, gyro error " << gyro << " rad/s");
  CHECK(accel < 3e-3);
  CHECK(gyro < 2e-5);
  // Poses twice as dense: the spline's acceleration error is O(h^2).
  double accel40 = 0, gyro40 = 0;
  analytic_errors(imu_from_trajectory(analytic_poses(c, 40.0, duration)), c, duration, 0.5, accel40, gyro40);
  INFO("40 Hz poses: accel error " << accel40 << " m/s^2, gyro error " << gyro40 << " rad/s");
  CHECK(accel / accel40 > 3.0);
  CHECK(gyro40 < gyro);
}

TEST_CASE("IMU from poses: pre-integration between pose stamps reproduces the poses' relative motion",
          "[sim][imu_from_trajectory]") {
  // Every 1 s window between 20 Hz pose stamps over 6 s, ends included:
  // R_j = R_i dR, p_j = p_i + v_i T + g T^2 / 2 + R_i dp from the input poses
  // and the spline's velocity. Measured (g++ 12 -O2): 7.9e-6 m and 7.2e-5 deg,
  // the mid-point rule's error at 200 Hz.
  posefuse::sim::ImuSimConfig c;
  const std::vector<StampedPose> poses = analytic_poses(c, 20.0, 6.0);
  ImuFromTrajectoryConfig cfg;
  cfg.gravity_mps2 = 9.81;
  const ImuSequence seq = imu_from_trajectory(poses, cfg);
  const Eigen::Vector3d g_w(0, 0, -cfg.gravity_mps2);
  double pos_err = 0, rot_err_deg = 0, fit_pos = 0, fit_rot = 0;
  for (std::size_t i = 0; i + 20 < poses.size(); i += 5) {
    const std::size_t j = i + 20;
    posefuse::Preintegration pre;
    REQUIRE(posefuse::preintegrate(seq.samples, poses[i].t_ns, poses[j].t_ns, pre) == posefuse::ImuStatus::kApplied);
    const posefuse::ImuDelta d = pre.delta();
    const SO3d Ri(poses[i].q_w_b), Rj(poses[j].q_w_b);
    const posefuse::sim::ImuTruth& ti = seq.truth[10 * i];
    REQUIRE(ti.t_ns == poses[i].t_ns);
    const double T = 1.0;
    const Eigen::Vector3d pj = poses[i].p_w + ti.v_w * T + 0.5 * g_w * T * T + Ri.act(d.p);
    pos_err = std::max(pos_err, (pj - poses[j].p_w).norm());
    rot_err_deg = std::max(rot_err_deg, (Ri * d.R).between(Rj).log().norm() * 180.0 / std::numbers::pi);
    // The fit goes through the poses.
    fit_pos = std::max(fit_pos, (ti.p_w - poses[i].p_w).norm());
    fit_rot = std::max(fit_rot, ti.R_w_b.between(Ri).log().norm());
  }
  INFO("position " << pos_err << " m, rotation " << rot_err_deg << " deg; fit " << fit_pos << " m, " << fit_rot
                   << " rad");
  CHECK(pos_err < 5e-5);
  CHECK(rot_err_deg < 3e-4);
  CHECK(fit_pos < 1e-6);
  CHECK(fit_rot < 1e-6);
}

TEST_CASE("IMU from poses: a body at rest reads gravity and no rotation", "[sim][imu_from_trajectory]") {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  std::vector<StampedPose> poses;
  for (std::int64_t k = 0; k < 10; ++k) poses.push_back({k * 50'000'000, Eigen::Vector3d(1, -2, 3), q});
  const ImuSequence seq = imu_from_trajectory(poses);
  REQUIRE(seq.samples.size() == 91);
  const Eigen::Vector3d f = q.inverse() * Eigen::Vector3d(0, 0, 9.81);
  for (const ImuSample& s : seq.samples) {
    CHECK((s.accel_mps2 - f).cwiseAbs().maxCoeff() < 1e-9);
    CHECK(s.gyro_radps.cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("IMU from poses: seeded noise, the same bits for a seed, pinned draws", "[sim][imu_from_trajectory]") {
  const std::vector<StampedPose> poses = analytic_poses({}, 20.0, 1.0);
  ImuFromTrajectoryConfig cfg;
  const ImuSequence clean = imu_from_trajectory(poses, cfg);
  cfg.noise = ImuNoise{};  // EuRoC's ADIS16448
  cfg.initial_bias.accel = Eigen::Vector3d(0.1, -0.2, 0.3);
  cfg.initial_bias.gyro = Eigen::Vector3d(0.01, 0.02, -0.03);
  cfg.seed = 7;
  const ImuSequence a = imu_from_trajectory(poses, cfg), b = imu_from_trajectory(poses, cfg);
  CHECK(a.samples == b.samples);
  cfg.seed = 8;
  const ImuSequence other = imu_from_trajectory(poses, cfg);
  CHECK_FALSE(a.samples == other.samples);
  // The draws of one SeededRng(7) in the documented order: accelerometer
  // x y z, gyroscope x y z, accelerometer bias x y z, gyroscope bias x y z.
  // The first three normals of SeededRng(7), pinned: another generator or
  // std::normal_distribution would change them.
  const double dt = 0.005, sa = 2.0e-3 / std::sqrt(dt), sg = 1.6968e-4 / std::sqrt(dt);
  const double sba = 3.0e-3 * std::sqrt(dt);
  const Eigen::Vector3d na = a.samples[0].accel_mps2 - clean.samples[0].accel_mps2 - Eigen::Vector3d(0.1, -0.2, 0.3);
  CHECK(na.x() / sa == Approx(1.5913998756469563).epsilon(1e-9));
  CHECK(na.y() / sa == Approx(-0.52481323512949596).epsilon(1e-9));
  CHECK(na.z() / sa == Approx(0.38890323470535709).epsilon(1e-9));
  posefuse::sim::detail::SeededRng rng(7);
  Eigen::Matrix<double, 12, 1> n;
  for (int i = 0; i < 12; ++i) n(i) = rng.normal();
  const Eigen::Vector3d ng = a.samples[0].gyro_radps - clean.samples[0].gyro_radps - Eigen::Vector3d(0.01, 0.02, -0.03);
  CHECK((na - sa * n.segment<3>(0)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((ng - sg * n.segment<3>(3)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(a.truth[0].bias.accel == Eigen::Vector3d(0.1, -0.2, 0.3));
  CHECK((a.truth[1].bias.accel - Eigen::Vector3d(0.1, -0.2, 0.3) - sba * n.segment<3>(6)).cwiseAbs().maxCoeff() <
        1e-15);
  // White noise at the datasheet density: sigma / sqrt(dt) per sample.
  double sum2 = 0;
  for (std::size_t k = 0; k < a.samples.size(); ++k)
    sum2 += (a.samples[k].gyro_radps - clean.samples[k].gyro_radps - a.truth[k].bias.gyro).squaredNorm();
  const double sd = std::sqrt(sum2 / double(3 * a.samples.size()));
  CHECK(sd == Approx(sg).epsilon(0.1));  // 603 draws: 2.9 % standard error of the estimate
}

TEST_CASE("IMU from poses: bad poses and settings are refused", "[sim][imu_from_trajectory]") {
  using Catch::Contains;
  const std::vector<StampedPose> good = analytic_poses({}, 20.0, 1.0);
  const auto refused = [](std::vector<StampedPose> p, const ImuFromTrajectoryConfig& c = {}) {
    return [p, c] { (void)imu_from_trajectory(p, c); };
  };
  CHECK_NOTHROW(refused(good)());
  CHECK_THROWS_WITH(refused({good.begin(), good.begin() + 3})(), Contains("at least 4 poses, got 3"));
  std::vector<StampedPose> p = good;
  p[5].t_ns = p[4].t_ns;
  CHECK_THROWS_WITH(refused(p)(), Contains("stamps must increase strictly (pose 5"));
  p = good;
  p[6].t_ns = p[4].t_ns - 1;
  CHECK_THROWS_WITH(refused(p)(), Contains("stamps must increase strictly (pose 6"));
  p = good;
  p[2].p_w.y() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(refused(p)(), Contains("non-finite position (pose 2"));
  p = good;
  p[3].q_w_b.x() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(refused(p)(), Contains("non-finite quaternion (pose 3"));
  p = good;
  p[7].q_w_b.coeffs() *= 1.001;
  CHECK_THROWS_WITH(refused(p)(), Contains("is not unit") && Contains("(pose 7"));
  p[7].q_w_b.coeffs() /= 1.001;
  CHECK_NOTHROW(refused(p)());
  for (const double rate : {0.0, -200.0, std::numeric_limits<double>::quiet_NaN()}) {
    ImuFromTrajectoryConfig c;
    c.rate_hz = rate;
    CHECK_THROWS_WITH(refused(good, c)(), Contains("rate must be in (0, 1e6] Hz"));
  }
  ImuFromTrajectoryConfig c;
  c.noise.accel_random_walk = -1;
  CHECK_THROWS_WITH(refused(good, c)(), Contains("accel_random_walk must be finite and >= 0"));
  c = {};
  c.knot_spacing_s = -0.1;
  CHECK_THROWS_WITH(refused(good, c)(), Contains("knot spacing must be finite and >= 0"));
  c = {};
  c.smoothing = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(refused(good, c)(), Contains("smoothing must be finite and >= 0"));
  c = {};
  c.gravity_mps2 = -9.81;
  CHECK_THROWS_WITH(refused(good, c)(), Contains("gravity must be finite and >= 0"));
}

TEST_CASE("IMU from poses: sparser knots and smoothing trade fidelity for less jitter", "[sim][imu_from_trajectory]") {
  // Millimetre jitter on 20 Hz positions: a fit through them reads it as
  // accelerations of about jitter / h^2; knots every 0.2 s with smoothing do
  // not, and still follow the motion.
  posefuse::sim::ImuSimConfig c;
  std::vector<StampedPose> poses = analytic_poses(c, 20.0, 6.0);
  posefuse::sim::detail::SeededRng rng(3);
  for (StampedPose& p : poses)
    for (int i = 0; i < 3; ++i) p.p_w(i) += rng.normal(1e-3);
  double through = 0, smooth = 0, gyro = 0;
  analytic_errors(imu_from_trajectory(poses), c, 6.0, 1.0, through, gyro);
  ImuFromTrajectoryConfig cfg;
  cfg.knot_spacing_s = 0.2;
  cfg.smoothing = 1.0;
  analytic_errors(imu_from_trajectory(poses, cfg), c, 6.0, 1.0, smooth, gyro);
  INFO("accel error: through the poses " << through << " m/s^2, smoothed " << smooth << " m/s^2");
  CHECK(through > 1.0);
  CHECK(smooth < 0.3 * through);
}

// The IMU factor (inertial/imu_factor.hpp): zero residual at its own
// prediction, small residual at the simulator's truth, conformance-checked
// Jacobians with respect to both states (a flipped block fails), whitening.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <posefuse/sim/imu.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/testing/conformance.hpp>

namespace {

using posefuse::ImuFactor;
using posefuse::ImuState;

struct Fixture {
  posefuse::sim::ImuSimConfig c;
  posefuse::sim::ImuSequence seq;
  posefuse::Preintegration pre;
  Fixture() {
    c.rate_hz = 200.0;
    seq = posefuse::sim::simulate_imu(c, 1.0);
    posefuse::ImuBias lin;
    lin.accel << 0.02, -0.01, 0.03;
    lin.gyro << 0.001, -0.002, 0.0015;
    pre = posefuse::Preintegration(posefuse::ImuNoise{}, lin);
    for (const posefuse::ImuSample& s : seq.samples) (void)pre.add(s);
  }
  [[nodiscard]] ImuState truth(std::size_t k) const {
    const posefuse::sim::ImuTruth& t = seq.truth[k];
    return ImuState{t.p_w, t.R_w_b, t.v_w, t.bias};
  }
  [[nodiscard]] Eigen::Vector3d gravity() const { return {0, 0, -c.gravity_mps2}; }
};

// A state near x, drawn one coordinate at a time (same draws under any compiler).
ImuState perturbed(const ImuState& x, double scale, std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, scale);
  ImuState::Tangent d;
  for (int i = 0; i < 15; ++i) d(i) = n(rng);
  return x.plus(d);
}

}  // namespace

TEST_CASE("ImuState and ImuDelta: plus and minus are consistent (manifold conformance)",
          "[inertial][conformance]") {
  const Fixture f;
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const ImuState x = perturbed(f.truth(std::size_t(trial) * 10), 0.5, rng);
    std::normal_distribution<double> n(0.0, 0.7);
    ImuState::Tangent d;
    for (int i = 0; i < 15; ++i) d(i) = n(rng);
    const auto r = posefuse::testing::check_manifold(x, d, 1e-9);
    INFO(r.message);
    CHECK(r);
    const posefuse::ImuDelta delta = f.pre.delta();
    const auto r2 = posefuse::testing::check_manifold(delta, posefuse::ImuDelta::Tangent(d.head<9>()), 1e-9);
    INFO(r2.message);
    CHECK(r2);
  }
}

TEST_CASE("ImuFactor: zero residual at its prediction, small at the truth", "[inertial][factor]") {
  const Fixture f;
  const ImuFactor factor(f.pre, f.gravity());
  std::mt19937_64 rng(7);
  const ImuState xi = perturbed(f.truth(0), 0.05, rng);
  const ImuState xj = factor.predict(xi);
  CHECK(factor.residual(xi, xj).cwiseAbs().maxCoeff() < 1e-12);
  // The truth, with the pre-integration linearised at another bias than the
  // (zero) true one: first-order correction plus the mid-point error.
  const ImuFactor::Residual r = factor.residual(f.truth(0), f.truth(f.seq.samples.size() - 1));
  INFO("residual at the truth " << r.transpose());
  CHECK(r.cwiseAbs().maxCoeff() < 1e-4);
}

TEST_CASE("ImuFactor: Jacobians pass the conformance check; a flipped block fails",
          "[inertial][factor][conformance]") {
  const Fixture f;
  const ImuFactor factor(f.pre, f.gravity());
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const ImuState xi = perturbed(f.truth(0), 0.1, rng);
    const ImuState xj = perturbed(f.truth(f.seq.samples.size() - 1), 0.1, rng);
    ImuFactor::Jacobian J_i, J_j;
    (void)factor.residual(xi, xj, &J_i, &J_j);
    const auto fi = [&](const ImuState& x) { return factor.residual(x, xj); };
    const auto fj = [&](const ImuState& x) { return factor.residual(xi, x); };
    const auto ri = posefuse::testing::check_jacobian("J_r_xi", fi, xi, J_i, 1e-6);
    const auto rj = posefuse::testing::check_jacobian("J_r_xj", fj, xj, J_j, 1e-6);
    INFO(ri.message << "\n" << rj.message);
    CHECK(ri);
    CHECK(rj);
    if (trial > 0) continue;
    // Every non-zero 3x3 block, flipped, fails.
    for (int bi = 0; bi < 5; ++bi) {
      for (int bj = 0; bj < 5; ++bj) {
        for (int which = 0; which < 2; ++which) {
          ImuFactor::Jacobian J = which == 0 ? J_i : J_j;
          if (J.block<3, 3>(3 * bi, 3 * bj).isZero()) continue;
          J.block<3, 3>(3 * bi, 3 * bj) *= -1.0;
          const auto r = which == 0 ? posefuse::testing::check_jacobian("flip", fi, xi, J, 1e-6)
                                    : posefuse::testing::check_jacobian("flip", fj, xj, J, 1e-6);
          INFO("block " << bi << "," << bj << " of J_r_x" << (which == 0 ? "i" : "j"));
          CHECK_FALSE(r);
        }
      }
    }
  }
  // Whitened: |L^-1 r|^2 = r^T P^-1 r, and the Jacobians scale alike.
  const ImuState xi = perturbed(f.truth(0), 0.01, rng);
  const ImuState xj = perturbed(f.truth(f.seq.samples.size() - 1), 0.01, rng);
  ImuFactor::Jacobian J_i, W_i;
  const ImuFactor::Residual r = factor.residual(xi, xj, &J_i);
  const ImuFactor::Residual w = factor.whitened_residual(xi, xj, &W_i);
  const double m = r.dot(factor.covariance().ldlt().solve(r));
  CHECK(w.squaredNorm() == Approx(m).epsilon(1e-9));
  CHECK((W_i - factor.whitening() * J_i).cwiseAbs().maxCoeff() < 1e-9 * W_i.cwiseAbs().maxCoeff());
  CHECK_THROWS_AS(ImuFactor(posefuse::Preintegration{}, f.gravity()), posefuse::invalid_argument);
}

// ---------------------------------------------------------------------------
// Visual-inertial alignment (inertial/alignment.hpp) on simulated sequences.

#include <array>
#include <numbers>

#include <posefuse/inertial/alignment.hpp>
// The trajectory alignment and metrics of eval/ in the same translation
// unit: a program that evaluates a visual-inertial run includes both, and
// neither may define a name the other does (see the last test case).
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>

namespace {

constexpr int kFrames = 10;

struct AlignmentCase {
  posefuse::sim::ImuSimConfig c;
  posefuse::sim::ImuSequence seq;
  posefuse::SE3d T_b_c;
  double sfm_scale = 0.37;  // SfM units per metre: metric scale s = 1 / 0.37
  std::array<std::size_t, kFrames> idx{};
  std::array<posefuse::SE3d, kFrames> T_c0_c;
  std::array<posefuse::Preintegration, kFrames - 1> pre;

  explicit AlignmentCase(const posefuse::sim::ImuSimConfig& config, std::size_t step = 60)
      : c(config) {
    seq = posefuse::sim::simulate_imu(c, double(step * (kFrames - 1)) / c.rate_hz + 0.01);
    T_b_c = posefuse::SE3d(Eigen::Vector3d(0.05, -0.02, 0.01),
                           posefuse::SO3d::exp(Eigen::Vector3d(-1.2, 0.1, -1.5)));
    for (int k = 0; k < kFrames; ++k) idx[std::size_t(k)] = std::size_t(k) * step;
    const auto T_w_c = [&](std::size_t i) {
      const posefuse::sim::ImuTruth& t = seq.truth[i];
      return posefuse::SE3d(t.p_w, t.R_w_b).compose(T_b_c);
    };
    const posefuse::SE3d T_c0_w = T_w_c(0).inverse();
    for (int k = 0; k < kFrames; ++k) {
      const posefuse::SE3d T = T_c0_w.compose(T_w_c(idx[std::size_t(k)]));
      T_c0_c[std::size_t(k)] = posefuse::SE3d(T.translation() * sfm_scale, T.so3());
    }
    for (int k = 0; k + 1 < kFrames; ++k) {
      posefuse::Preintegration& p = pre[std::size_t(k)];
      for (std::size_t i = idx[std::size_t(k)]; i <= idx[std::size_t(k) + 1]; ++i)
        (void)p.add(seq.samples[i]);
    }
  }
  // Truth in c0: R_c0_w = R_c0_b0 ... via the first camera.
  [[nodiscard]] posefuse::SO3d R_c0_w() const {
    return posefuse::SE3d(seq.truth[0].p_w, seq.truth[0].R_w_b).compose(T_b_c).so3().inverse();
  }
};

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

}  // namespace

TEST_CASE("Alignment: recovers gyro bias, scale, gravity and velocities on a simulated sequence",
          "[inertial][alignment]") {
  posefuse::sim::ImuSimConfig c;
  c.initial_bias.gyro << 0.012, -0.021, 0.008;
  c.initial_bias.accel.setZero();
  c.noise = posefuse::ImuNoise{};  // EuRoC-like noise and random walks
  c.seed = 3;
  AlignmentCase a(c);
  const auto r = posefuse::align_visual_inertial<kFrames>(a.T_c0_c, a.T_b_c, a.pre);
  INFO("status " << posefuse::to_string(r.status) << ", accel std " << r.accel_std);
  REQUIRE(r.status == posefuse::VisualInertialAlignmentStatus::kOk);
  const double s_true = 1.0 / a.sfm_scale;
  INFO("scale " << r.scale << " (true " << s_true << "), gyro bias " << r.gyro_bias.transpose());
  CHECK(std::abs(r.scale - s_true) / s_true < 0.01);
  CHECK((r.gyro_bias - c.initial_bias.gyro).norm() < 1e-3);
  const Eigen::Vector3d g_true = a.R_c0_w().act(Eigen::Vector3d(0, 0, -c.gravity_mps2));
  CHECK(angle_deg(r.gravity_c0, g_true) < 0.5);
  for (int k = 0; k < kFrames; ++k) {
    const Eigen::Vector3d v_true = a.R_c0_w().act(a.seq.truth[a.idx[std::size_t(k)]].v_w);
    CHECK((r.velocity_c0[std::size_t(k)] - v_true).norm() < 0.05);
  }
  // World frame: gravity along -z, first body yaw zero, first body at the origin.
  CHECK((r.R_w_c0.act(r.gravity_c0) - Eigen::Vector3d(0, 0, -9.81)).norm() < 1e-9);
  CHECK(r.T_w_b[0].translation().norm() < 1e-12);
  const Eigen::Matrix3d Rb0 = r.T_w_b[0].so3().matrix();
  CHECK(std::abs(std::atan2(Rb0(1, 0), Rb0(0, 0))) < 1e-9);
}

TEST_CASE("Alignment: reports insufficient excitation instead of a scale", "[inertial][alignment]") {
  posefuse::sim::ImuSimConfig c;
  c.position_amplitude_m.setZero();  // the body only rotates slowly in place
  c.attitude_amplitude_rad << 0.05, 0.05, 0.3;
  AlignmentCase a(c);
  const auto r = posefuse::align_visual_inertial<kFrames>(a.T_c0_c, a.T_b_c, a.pre);
  INFO("accel std " << r.accel_std);
  CHECK(r.status == posefuse::VisualInertialAlignmentStatus::kInsufficientExcitation);
  CHECK(r.accel_std < 0.25);
}

TEST_CASE("Alignment: reports a gravity norm far from the configured one and a negative scale",
          "[inertial][alignment]") {
  posefuse::sim::ImuSimConfig c;
  AlignmentCase a(c);
  posefuse::VisualInertialAlignmentOptions o;
  o.gravity_norm = 5.0;  // the data says 9.81
  auto pre = a.pre;
  const auto r = posefuse::align_visual_inertial<kFrames>(a.T_c0_c, a.T_b_c, pre, o);
  CHECK(r.status == posefuse::VisualInertialAlignmentStatus::kGravityNorm);
  CHECK(r.gravity_norm_unrefined == Approx(9.81).epsilon(0.01));
  // Mirrored SfM positions: the only fit has a negative scale.
  std::array<posefuse::SE3d, kFrames> mirrored = a.T_c0_c;
  for (posefuse::SE3d& T : mirrored) T = posefuse::SE3d(-T.translation(), T.so3());
  pre = a.pre;
  const auto r2 = posefuse::align_visual_inertial<kFrames>(mirrored, a.T_b_c, pre);
  INFO("scale " << r2.scale);
  CHECK(r2.status == posefuse::VisualInertialAlignmentStatus::kNonPositiveScale);
}

TEST_CASE("Alignment and evaluation in one program: the aligned keyframes against the truth",
          "[inertial][alignment][eval]") {
  // Both alignment headers are included above; each type is named in full.
  posefuse::sim::ImuSimConfig c;
  c.initial_bias.gyro << 0.012, -0.021, 0.008;
  c.initial_bias.accel.setZero();
  c.seed = 3;
  AlignmentCase a(c);
  const posefuse::VisualInertialAlignmentOptions vi_options;
  const posefuse::VisualInertialAlignment<kFrames> vi =
      posefuse::align_visual_inertial<kFrames>(a.T_c0_c, a.T_b_c, a.pre, vi_options);
  REQUIRE(vi.status == posefuse::VisualInertialAlignmentStatus::kOk);
  // The metric keyframe poses in the aligned world frame against the truth.
  posefuse::Trajectory est, ref;
  for (int k = 0; k < kFrames; ++k) {
    const std::size_t i = a.idx[std::size_t(k)];
    const double t_s = 1e-9 * double(a.seq.samples[i].t_ns);
    Eigen::Isometry3d P = Eigen::Isometry3d::Identity(), Q = Eigen::Isometry3d::Identity();
    P.linear() = vi.T_w_b[std::size_t(k)].so3().matrix();
    P.translation() = vi.T_w_b[std::size_t(k)].translation();
    Q.linear() = a.seq.truth[i].R_w_b.matrix();
    Q.translation() = a.seq.truth[i].p_w;
    est.push_back(t_s, P);
    ref.push_back(t_s, Q);
  }
  posefuse::AlignmentOptions eval_options;
  eval_options.alignment = posefuse::Alignment::kSim3;
  const posefuse::MetricResult ape =
      posefuse::ape(ref, est, posefuse::PoseRelation::kTranslation, eval_options);
  const posefuse::AlignmentResult& sim3 = ape.alignment;
  const posefuse::MetricResult ape_se3 =
      posefuse::ape(ref, est, posefuse::PoseRelation::kTranslation, posefuse::Alignment::kSE3);
  const posefuse::AlignmentResult& se3 = ape_se3.alignment;
  const double s_ratio = (1.0 / a.sfm_scale) / vi.scale;  // true scale / estimated scale
  INFO("Sim(3): APE rmse " << ape.stats.rmse << " m, scale " << sim3.scale << " (s_true / s "
                           << s_ratio << "); SE(3): APE rmse " << ape_se3.stats.rmse
                           << " m, rotation\n" << se3.rotation);
  // The similarity that maps the aligned keyframes onto the truth undoes
  // exactly the alignment's scale error (measured: to 7e-8, rmse 8e-8 m) ...
  CHECK(std::abs(sim3.scale - s_ratio) < 1e-6);
  CHECK(ape.stats.rmse < 1e-6);
  // ... and without scale the residual is that error times the distances
  // (measured 1.1e-5 m); the rotation is about z only, since both frames have
  // gravity along -z and differ by the unobservable yaw (measured 8e-7).
  CHECK(ape_se3.stats.rmse < 1e-4);
  CHECK(std::abs(se3.rotation(2, 2) - 1.0) < 1e-9);
  CHECK(se3.rotation.row(2).head<2>().cwiseAbs().maxCoeff() < 1e-5);
  CHECK(se3.rotation.col(2).head<2>().cwiseAbs().maxCoeff() < 1e-5);
}

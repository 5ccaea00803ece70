// Per-step cost of posefuse::Ekf against the textbook EKF step, workload by
// workload, all in this one binary.
//
//   cmake --preset release && cmake --build --preset release --target bench_filters
//   ./build-release/benchmarks/bench_filters --benchmark_repetitions=5 \
//       --benchmark_report_aggregates_only=true --benchmark_enable_random_interleaving=true
//
// Every workload BM_<Workload> has these implementations of one EKF step
// (predict + update) on the same inputs:
//   BM_<Workload>/posefuse      posefuse::Ekf with the default options
//                               (EkfOptions: Joseph form, NIS always, Jacobian
//                               recorded, gain memo on) and the library's
//                               models, one step(u, dt, z) call
//   BM_<Workload>/posefuse_lean the same with LeanEkfOptions (standard form,
//                               NIS only when gated, no Jacobian record; every
//                               stored covariance still PSD-checked)
//   BM_<Workload>/posefuse_separate  the default options, predict(u, dt) then
//                               update<0>(z) (two calls, two covariance checks)
//   BM_<Workload>/naive_fixed   the textbook step written directly with
//                               fixed-size Eigen: Pbar = F P F^T + Q,
//                               K = Pbar H^T (H Pbar H^T + R)^-1,
//                               x = xbar + K (z - h(xbar)), P = (I - K H) Pbar
//   BM_<Workload>/dynamic       the same textbook step with Eigen::MatrixXd
// and, where posefuse's steady-state gain memo can hit, a fourth row without it:
//   BM_<Workload>/posefuse_nomemo   BasicEkf with EkfOptions::kGainMemo = false
//   BM_Seed000Ekf_Step/posefuse_recompute   update_with() a sensor held outside the
//                               filter (never memoised), as README has quoted it
// Before timing, each benchmark runs every implementation of its workload for
// 256 frames from the same start and stops with an error (SkipWithError)
// unless all states agree to 1e-9 (relative); so a faster row cannot be
// computing something else.
//
// The generators of the inputs below are noinline: inlined into a step
// (through the function-local statics' first-use path) their random engines
// gave every step function a 5 KB stack frame, which stopped g++ from inlining
// the filter's own helpers into it.
//
// Workloads (1024 frames generated once, cycled; one frame per iteration):
//   Seed000Ekf            seed 000: x' = x + u, H = I (2-D), constant noise
//   Seed000Kitti          the same with process noise R * dt / 0.1 s, dt the real
//                         frame intervals of KITTI 06 (times.txt, see kitti_intervals())
//   ConstantVelocityEkf   4-D constant velocity, 2-D position fix, dt = 0.1 s
//   ConstantVelocityKitti the same at the KITTI 06 frame intervals
//   UnicyclePoseFix       3-D unicycle (exact arc, control noise), full pose fix
//                         with the heading residual wrapped
//   Pose15                15-state 3-D kinematics (position, roll-pitch-yaw,
//                         their rates, linear acceleration; world frame, angles
//                         unwrapped) with a 6-D pose measurement
//   CtrvEkf               5-state constant turn rate and velocity (models/ctrv.hpp),
//                         2-D position fix, dt = 0.1 s, a vehicle turning both ways
// Also, the RTS smoother over a recorded 1024-frame run (time per call; the
// counter `frame` is the time per frame):
//   BM_RtsSmooth_<Model>/posefuse     posefuse::rts_smooth
//   BM_RtsSmooth_<Model>/naive_fixed  the textbook backward pass in fixed-size
//                                     Eigen, C = P F^T Pbar^-1 with .inverse()
//   for Model = ConstantVelocity (4 states) and Ctrv (5 states); both agree to
//   1e-9 before timing.
// Also:
//   BM_PsdCheck/<n>            is_positive_semidefinite() alone on covariances
//                              those filters produce (n = 2, 4, 15)
//   BM_PsdCheck_Reference/<n>  the same on the completely pivoted LDLT alone
#include <Eigen/Dense>
#include <benchmark/benchmark.h>
#include <posefuse/core/angles.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/ctrv.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/unicycle.hpp>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "seed000_frames.hpp"

namespace {

constexpr std::size_t kFrames = 1024;
static_assert(kFrames == posefuse_bench::kSeed000Frames);
constexpr int kCheckFrames = 256;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// ---------------------------------------------------------------------------
// Inputs

/// Frame intervals of KITTI 06: $POSEFUSE_DATA_DIR/kitti/06/times.txt, else
/// the configured data folder's kitti/06/times.txt (POSEFUSE_DATA_DIR at build time).
/// When neither exists, a generated equivalent: 1100 intervals uniform in
/// [0.10324, 0.10466] s (the real file's range; its mean is 0.10390 s, its
/// standard deviation 0.15 ms). Cycled to kFrames.
struct Intervals {
  std::vector<double> dt;
  bool real = false;
};
const Intervals& kitti_intervals() {
  static const Intervals out = []() __attribute__((noinline)) {
    Intervals iv;
    std::vector<std::string> paths;
    if (const char* d = std::getenv("POSEFUSE_DATA_DIR")) paths.push_back(std::string(d) + "/kitti/06/times.txt");
#ifdef POSEFUSE_DEFAULT_DATA_DIR
    paths.emplace_back(std::string(POSEFUSE_DEFAULT_DATA_DIR) + "/kitti/06/times.txt");
#endif
    for (const std::string& p : paths) {
      std::ifstream in(p);
      std::vector<double> t;
      double v = 0;
      while (in >> v) t.push_back(v);
      if (t.size() > 2) {
        for (std::size_t i = 1; i < t.size(); ++i) iv.dt.push_back(t[i] - t[i - 1]);
        iv.real = true;
        break;
      }
    }
    if (!iv.real) {
      std::mt19937 rng(6);
      std::uniform_real_distribution<double> u(0.10324, 0.10466);
      for (int i = 0; i < 1100; ++i) iv.dt.push_back(u(rng));
    }
    std::vector<double> cycled;
    for (std::size_t k = 0; k < kFrames; ++k) cycled.push_back(iv.dt[k % iv.dt.size()]);
    iv.dt = cycled;
    return iv;
  }();
  return out;
}

using posefuse_bench::PlanarFrames;
const PlanarFrames& planar_frames() { return posefuse_bench::seed000_frames(); }

template <class A, class B>
double rel_error(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
}

// ---------------------------------------------------------------------------
// The harness: agreement check, then the timed loop.

/// Runs every implementation of workload W for kCheckFrames frames and
/// compares their states with W::Naive's. @return empty, or what disagreed
template <class W>
std::string disagreement() {
  typename W::Naive ref;
  typename W::Posefuse a;
  typename W::Dynamic b;
  typename W::PosefuseNoMemo c;
  typename W::PosefuseLean d;
  typename W::PosefuseSeparate e;
  for (int k = 0; k < kCheckFrames; ++k) {
    (void)ref.step(std::size_t(k));
    (void)a.step(std::size_t(k));
    (void)b.step(std::size_t(k));
    (void)c.step(std::size_t(k));
    (void)d.step(std::size_t(k));
    (void)e.step(std::size_t(k));
  }
  const VectorXd x = ref.state();
  if (!x.allFinite()) return "reference state not finite";
  if (!(W::difference(a.state(), x) <= 1e-9)) return "posefuse state differs from naive_fixed";
  if (!(W::difference(b.state(), x) <= 1e-9)) return "dynamic state differs from naive_fixed";
  if (!(W::difference(c.state(), x) <= 1e-9)) return "posefuse_nomemo state differs from naive_fixed";
  if (!(W::difference(d.state(), x) <= 1e-9)) return "posefuse_lean state differs from naive_fixed";
  if (!(W::difference(e.state(), x) <= 1e-9)) return "posefuse_separate state differs from naive_fixed";
  return {};
}

template <class W, class Impl>
void BM_Step(benchmark::State& st) {
  static const std::string why = disagreement<W>();
  if (!why.empty()) {
    st.SkipWithError(why.c_str());
    return;
  }
  Impl impl;
  std::size_t k = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(impl.step(k));
    k = (k + 1) & (kFrames - 1);
  }
  benchmark::DoNotOptimize(impl.state());
}

struct NoMemo : posefuse::EkfOptions {
  static constexpr bool kGainMemo = false;
};

/// Euclidean states: relative max difference.
struct Euclidean {
  static double difference(const VectorXd& a, const VectorXd& b) { return rel_error(a, b); }
};

// ---------------------------------------------------------------------------
// Seed 000 (constant noise) and seed 000 at KITTI intervals

/// Seed 000's motion with process noise scaled by the frame interval.
struct ScaledDisplacement {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  static constexpr bool kIdentityJacobian = true;
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;  // per 0.1 s
  State predict(const State& x, const Control& u, double) const { return x + u; }
  Eigen::Matrix2d jacobian(const State&, const Control&, double) const {
    return Eigen::Matrix2d::Identity();
  }
  Eigen::Matrix2d noise(const State&, const Control&, double dt) const { return R * (dt / 0.1); }
};

template <bool kKitti>
struct Seed000 : Euclidean {
  static double dt(std::size_t k) { return kKitti ? kitti_intervals().dt[k] : 1.0; }
  static double scale(std::size_t k) { return kKitti ? dt(k) / 0.1 : 1.0; }
  using Motion = std::conditional_t<kKitti, ScaledDisplacement, posefuse::PlanarDisplacement<double>>;
  static Motion motion() {
    if constexpr (kKitti) {
      return ScaledDisplacement{};
    } else {
      return posefuse::PlanarDisplacement<double>::from_sigmas(0.1, 0.1);
    }
  }
  template <class Options, bool kFused = true>
  struct Filter {
    posefuse::BasicEkf<Options, Motion, posefuse::PositionFix<2>> ekf{
        motion(), posefuse::PositionFix<2>::isotropic(0.5)};
    Filter() { ekf.reset(planar_frames().z[0], Eigen::Matrix2d::Identity()); }
    posefuse::FilterStatus step(std::size_t k) {
      const PlanarFrames& f = planar_frames();
      if constexpr (kFused) {
        return ekf.step(f.u[k], dt(k), f.z[k]).template update<0>().status;
      } else {
        (void)ekf.predict(f.u[k], dt(k));
        return ekf.template update<0>(f.z[k]).status;
      }
    }
    VectorXd state() const { return ekf.state(); }
  };
  using Posefuse = Filter<posefuse::EkfOptions>;
  using PosefuseLean = Filter<posefuse::LeanEkfOptions>;
  using PosefuseSeparate = Filter<posefuse::EkfOptions, false>;
  using PosefuseNoMemo = Filter<NoMemo>;
  struct Naive {
    Eigen::Vector2d mu = planar_frames().z[0];
    Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
    double step(std::size_t k) {
      const PlanarFrames& f = planar_frames();
      const Eigen::Matrix2d G = Eigen::Matrix2d::Identity();
      const Eigen::Matrix2d H = Eigen::Matrix2d::Identity();
      const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * (0.01 * scale(k));
      const Eigen::Matrix2d Q = Eigen::Matrix2d::Identity() * 0.25;
      const Eigen::Vector2d mubar = mu + f.u[k];
      const Eigen::Matrix2d Sbar = G * S * G.transpose() + R;
      const Eigen::Matrix2d K = Sbar * H.transpose() * (H * Sbar * H.transpose() + Q).inverse();
      mu = mubar + K * (f.z[k] - H * mubar);
      S = (Eigen::Matrix2d::Identity() - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
  struct Dynamic {
    VectorXd mu = planar_frames().z[0];
    MatrixXd S = MatrixXd::Identity(2, 2);
    double step(std::size_t k) {
      const PlanarFrames& f = planar_frames();
      const MatrixXd G = MatrixXd::Identity(2, 2);
      const MatrixXd H = MatrixXd::Identity(2, 2);
      const MatrixXd I = MatrixXd::Identity(2, 2);
      const MatrixXd R = MatrixXd::Identity(2, 2) * (0.01 * scale(k));
      const MatrixXd Q = MatrixXd::Identity(2, 2) * 0.25;
      const VectorXd u = f.u[k];
      const VectorXd z = f.z[k];
      const VectorXd mubar = mu + u;
      const MatrixXd Sbar = G * S * G.transpose() + R;
      const MatrixXd Sinn = H * Sbar * H.transpose() + Q;
      const MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
      mu = mubar + K * (z - H * mubar);
      S = (I - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
};

/// update_with() a sensor held outside the filter: the gain is recomputed
/// every step (README's posefuse_recompute row).
struct Seed000Recompute {
  posefuse::PositionFix<2> fix = posefuse::PositionFix<2>::isotropic(0.5);
  posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<2>> ekf{
      posefuse::PlanarDisplacement<double>::from_sigmas(0.1, 0.1), fix};
  Seed000Recompute() { ekf.reset(planar_frames().z[0], Eigen::Matrix2d::Identity()); }
  posefuse::FilterStatus step(std::size_t k) {
    const PlanarFrames& f = planar_frames();
    (void)ekf.predict(f.u[k], 1.0);
    return ekf.update_with(fix, f.z[k]).status;
  }
  VectorXd state() const { return ekf.state(); }
};

// ---------------------------------------------------------------------------
// Constant velocity (dt = 0.1 s, and KITTI intervals)

template <bool kKitti>
struct ConstantVelocity : Euclidean {
  static constexpr double kQ = 1.0, kSigma = 0.5;
  static double dt(std::size_t k) { return kKitti ? kitti_intervals().dt[k] : 0.1; }
  static Eigen::Vector4d x0() {
    Eigen::Vector4d x;
    x << planar_frames().z[0], 0, 0;
    return x;
  }
  static Eigen::Vector2d z(std::size_t k) { return planar_frames().z[k] * 0.1; }
  template <class Options, bool kFused = true>
  struct Filter {
    posefuse::BasicEkf<Options, posefuse::ConstantVelocity2<double>, posefuse::PositionFix<4>> ekf{
        posefuse::ConstantVelocity2<double>(kQ), posefuse::PositionFix<4>::isotropic(kSigma)};
    Filter() { ekf.reset(x0(), Eigen::Matrix4d::Identity()); }
    posefuse::FilterStatus step(std::size_t k) {
      if constexpr (kFused) {
        return ekf.step(posefuse::NoControl{}, dt(k), z(k)).template update<0>().status;
      } else {
        (void)ekf.predict(posefuse::NoControl{}, dt(k));
        return ekf.template update<0>(z(k)).status;
      }
    }
    VectorXd state() const { return ekf.state(); }
  };
  using Posefuse = Filter<posefuse::EkfOptions>;
  using PosefuseLean = Filter<posefuse::LeanEkfOptions>;
  using PosefuseSeparate = Filter<posefuse::EkfOptions, false>;
  using PosefuseNoMemo = Filter<NoMemo>;
  struct Naive {
    Eigen::Vector4d mu = x0();
    Eigen::Matrix4d S = Eigen::Matrix4d::Identity();
    double step(std::size_t k) {
      const double t = dt(k);
      Eigen::Matrix4d F = Eigen::Matrix4d::Identity();
      F(0, 2) = F(1, 3) = t;
      Eigen::Matrix4d Q = Eigen::Matrix4d::Zero();
      Q(0, 0) = Q(1, 1) = kQ * t * t * t / 3;
      Q(0, 2) = Q(2, 0) = Q(1, 3) = Q(3, 1) = kQ * t * t / 2;
      Q(2, 2) = Q(3, 3) = kQ * t;
      Eigen::Matrix<double, 2, 4> H = Eigen::Matrix<double, 2, 4>::Zero();
      H(0, 0) = H(1, 1) = 1;
      const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * (kSigma * kSigma);
      const Eigen::Vector4d mubar = F * mu;
      const Eigen::Matrix4d Sbar = F * S * F.transpose() + Q;
      const Eigen::Matrix<double, 4, 2> K =
          Sbar * H.transpose() * (H * Sbar * H.transpose() + R).inverse();
      mu = mubar + K * (z(k) - H * mubar);
      S = (Eigen::Matrix4d::Identity() - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
  struct Dynamic {
    VectorXd mu = x0();
    MatrixXd S = MatrixXd::Identity(4, 4);
    double step(std::size_t k) {
      const double t = dt(k);
      MatrixXd F = MatrixXd::Identity(4, 4);
      F(0, 2) = F(1, 3) = t;
      MatrixXd Q = MatrixXd::Zero(4, 4);
      Q(0, 0) = Q(1, 1) = kQ * t * t * t / 3;
      Q(0, 2) = Q(2, 0) = Q(1, 3) = Q(3, 1) = kQ * t * t / 2;
      Q(2, 2) = Q(3, 3) = kQ * t;
      MatrixXd H = MatrixXd::Zero(2, 4);
      H(0, 0) = H(1, 1) = 1;
      const MatrixXd R = MatrixXd::Identity(2, 2) * (kSigma * kSigma);
      const VectorXd zk = z(k);
      const VectorXd mubar = F * mu;
      const MatrixXd Sbar = F * S * F.transpose() + Q;
      const MatrixXd Sinn = H * Sbar * H.transpose() + R;
      const MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
      mu = mubar + K * (zk - H * mubar);
      S = (MatrixXd::Identity(4, 4) - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
};

// ---------------------------------------------------------------------------
// Unicycle + pose fix

struct UnicyclePoseFix {
  struct Inputs {
    std::vector<Eigen::Vector2d> u;
    std::vector<posefuse::PlanarPose<double>> z;
  };
  static const Inputs& inputs() {
    static const Inputs in = []() __attribute__((noinline)) {
      Inputs out;
      std::mt19937 rng(7);
      std::normal_distribution<double> n(0.0, 1.0);
      posefuse::PlanarPose<double> p{};
      for (std::size_t k = 0; k < kFrames; ++k) {
        const double v = 1.0 + 0.1 * n(rng);
        const double w = 0.3 * std::sin(double(k) / 50.0) + 0.05 * n(rng);
        out.u.emplace_back(v, w);
        p = posefuse::unicycle_step(p, v * 0.1, w * 0.1, posefuse::Integration::kExactArc);
        const double ex = 0.2 * n(rng);
        const double ey = 0.2 * n(rng);
        const double et = 0.05 * n(rng);
        out.z.push_back({p.x + ex, p.y + ey, posefuse::wrap_angle(p.theta + et)});
      }
      return out;
    }();
    return in;
  }
  static constexpr double kDt = 0.1;
  static Eigen::Matrix2d control_cov() { return Eigen::Vector2d(0.05 * 0.05, 0.02 * 0.02).asDiagonal(); }
  static Eigen::Matrix3d pose_cov() { return Eigen::Vector3d(0.04, 0.04, 0.0025).asDiagonal(); }
  static double difference(const VectorXd& a, const VectorXd& b) {
    VectorXd d = a - b;
    d(2) = posefuse::angle_diff(a(2), b(2));
    return d.cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
  }
  static posefuse::Unicycle<double> motion() {
    posefuse::Unicycle<double> m;
    m.method = posefuse::Integration::kExactArc;
    m.control_cov = control_cov();
    return m;
  }
  template <class Options, bool kFused = true>
  struct Filter {
    posefuse::BasicEkf<Options, posefuse::Unicycle<double>, posefuse::PlanarPoseFix<double>> ekf{
        motion(), posefuse::PlanarPoseFix<double>(pose_cov())};
    Filter() { ekf.reset(posefuse::PlanarPose<double>{}, Eigen::Matrix3d::Identity() * 0.1); }
    posefuse::FilterStatus step(std::size_t k) {
      if constexpr (kFused) {
        return ekf.step(inputs().u[k], kDt, inputs().z[k]).template update<0>().status;
      } else {
        (void)ekf.predict(inputs().u[k], kDt);
        return ekf.template update<0>(inputs().z[k]).status;
      }
    }
    VectorXd state() const { return ekf.state().vector(); }
  };
  using Posefuse = Filter<posefuse::EkfOptions>;
  using PosefuseLean = Filter<posefuse::LeanEkfOptions>;
  using PosefuseSeparate = Filter<posefuse::EkfOptions, false>;
  using PosefuseNoMemo = Filter<NoMemo>;
  struct Naive {
    Eigen::Vector3d mu = Eigen::Vector3d::Zero();
    Eigen::Matrix3d S = Eigen::Matrix3d::Identity() * 0.1;
    double step(std::size_t k) {
      const Eigen::Vector2d& u = inputs().u[k];
      Eigen::Matrix3d G;
      Eigen::Matrix<double, 3, 2> V;
      const posefuse::PlanarPose<double> pbar = posefuse::unicycle_step(
          posefuse::PlanarPose<double>{mu(0), mu(1), mu(2)}, u(0) * kDt, u(1) * kDt,
          posefuse::Integration::kExactArc, &G, &V);
      const Eigen::Vector3d mubar = pbar.vector();
      const Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
      const Eigen::Matrix3d Sbar = G * S * G.transpose() + (kDt * kDt) * (V * control_cov() * V.transpose());
      const Eigen::Matrix3d K = Sbar * H.transpose() * (H * Sbar * H.transpose() + pose_cov()).inverse();
      const posefuse::PlanarPose<double>& z = inputs().z[k];
      Eigen::Vector3d r = z.vector() - H * mubar;
      r(2) = posefuse::angle_diff(z.theta, mubar(2));
      mu = mubar + K * r;
      mu(2) = posefuse::wrap_angle(mu(2));
      S = (Eigen::Matrix3d::Identity() - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
  struct Dynamic {
    VectorXd mu = VectorXd::Zero(3);
    MatrixXd S = MatrixXd::Identity(3, 3) * 0.1;
    double step(std::size_t k) {
      const Eigen::Vector2d& u = inputs().u[k];
      Eigen::Matrix3d Gf;
      Eigen::Matrix<double, 3, 2> Vf;
      const posefuse::PlanarPose<double> pbar = posefuse::unicycle_step(
          posefuse::PlanarPose<double>{mu(0), mu(1), mu(2)}, u(0) * kDt, u(1) * kDt,
          posefuse::Integration::kExactArc, &Gf, &Vf);
      const MatrixXd G = Gf, V = Vf, M = control_cov() * (kDt * kDt), Q = pose_cov();
      const MatrixXd H = MatrixXd::Identity(3, 3);
      const VectorXd mubar = pbar.vector();
      const MatrixXd Sbar = G * S * G.transpose() + V * M * V.transpose();
      const MatrixXd Sinn = H * Sbar * H.transpose() + Q;
      const MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
      const posefuse::PlanarPose<double>& z = inputs().z[k];
      VectorXd r = z.vector() - H * mubar;
      r(2) = posefuse::angle_diff(z.theta, mubar(2));
      mu = mubar + K * r;
      mu(2) = posefuse::wrap_angle(mu(2));
      S = (MatrixXd::Identity(3, 3) - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
};

// ---------------------------------------------------------------------------
// 15-state 3-D kinematics with a 6-D pose measurement

/// x = [p (3), rpy (3), v (3), rpy rates (3), a (3)] in the world frame:
/// p' = p + v dt + a dt^2 / 2, rpy' = rpy + w dt, v' = v + a dt; white noise
/// q dt on every component. The angles are treated as a vector (unwrapped;
/// a benchmark of the linear algebra, not an attitude filter).
struct Kinematic15 {
  using State = Eigen::Matrix<double, 15, 1>;
  using Control = posefuse::NoControl;
  using Matrix = Eigen::Matrix<double, 15, 15>;
  static Matrix F_of(double dt) {
    Matrix F = Matrix::Identity();
    for (int i = 0; i < 3; ++i) {
      F(i, 6 + i) = dt;
      F(i, 12 + i) = 0.5 * dt * dt;
      F(3 + i, 9 + i) = dt;
      F(6 + i, 12 + i) = dt;
    }
    return F;
  }
  static Eigen::Matrix<double, 15, 1> q_diag() {
    Eigen::Matrix<double, 15, 1> q;
    q << 0.01, 0.01, 0.01, 0.001, 0.001, 0.001, 0.1, 0.1, 0.1, 0.01, 0.01, 0.01, 1.0, 1.0, 1.0;
    return q;
  }
  State predict(const State& x, const Control&, double dt) const {
    State y = x;
    y.segment<3>(0) += dt * x.segment<3>(6) + (0.5 * dt * dt) * x.segment<3>(12);
    y.segment<3>(3) += dt * x.segment<3>(9);
    y.segment<3>(6) += dt * x.segment<3>(12);
    return y;
  }
  Matrix jacobian(const State&, const Control&, double dt) const { return F_of(dt); }
  Matrix noise(const State&, const Control&, double dt) const {
    return Matrix(q_diag().asDiagonal()) * dt;
  }
  /// F P F^T by row, then column, operations (rows 0-8 read rows 6-14 of P
  /// before they change: position and angle rows first, velocity rows last).
  Matrix propagate(const Matrix& P, const State&, const Control&, double dt) const {
    const double h = 0.5 * dt * dt;
    Matrix B = P;
    B.middleRows<3>(0) += dt * P.middleRows<3>(6) + h * P.middleRows<3>(12);
    B.middleRows<3>(3) += dt * P.middleRows<3>(9);
    B.middleRows<3>(6) += dt * P.middleRows<3>(12);
    Matrix out = B;
    out.middleCols<3>(0) += dt * B.middleCols<3>(6) + h * B.middleCols<3>(12);
    out.middleCols<3>(3) += dt * B.middleCols<3>(9);
    out.middleCols<3>(6) += dt * B.middleCols<3>(12);
    return out;
  }
};
static_assert(posefuse::HasPropagate<Kinematic15>);

struct Pose15 : Euclidean {
  static constexpr double kDt = 0.1;
  using Z = Eigen::Matrix<double, 6, 1>;
  static const std::vector<Z>& measurements() {
    static const std::vector<Z> zs = []() __attribute__((noinline)) {
      std::vector<Z> out;
      std::mt19937 rng(8);
      std::normal_distribution<double> n(0.0, 1.0);
      for (std::size_t k = 0; k < kFrames; ++k) {
        const double t = double(k) * kDt;
        Z z;
        z << 2 * std::sin(0.1 * t), 3 * std::cos(0.07 * t), 0.1 * t, 0.1 * std::sin(0.2 * t),
            0.05 * std::cos(0.3 * t), 0.2 * t;
        for (int i = 0; i < 6; ++i) {
          const double e = n(rng);
          z(i) += (i < 3 ? 0.1 : 0.01) * e;
        }
        out.push_back(z);
      }
      return out;
    }();
    return zs;
  }
  static Eigen::Matrix<double, 6, 6> R() {
    Eigen::Matrix<double, 6, 1> r;
    r << 0.01, 0.01, 0.01, 0.0001, 0.0001, 0.0001;
    return r.asDiagonal();
  }
  static Eigen::Matrix<double, 15, 15> P0() { return Eigen::Matrix<double, 15, 15>::Identity(); }
  using Fix = posefuse::PositionFix<15, 6>;
  template <class Options, bool kFused = true>
  struct Filter {
    posefuse::BasicEkf<Options, Kinematic15, Fix> ekf{Kinematic15{}, Fix(R())};
    Filter() { ekf.reset(Kinematic15::State::Zero(), P0()); }
    posefuse::FilterStatus step(std::size_t k) {
      if constexpr (kFused) {
        return ekf.step(posefuse::NoControl{}, kDt, measurements()[k]).template update<0>().status;
      } else {
        (void)ekf.predict(posefuse::NoControl{}, kDt);
        return ekf.template update<0>(measurements()[k]).status;
      }
    }
    VectorXd state() const { return ekf.state(); }
  };
  using Posefuse = Filter<posefuse::EkfOptions>;
  using PosefuseLean = Filter<posefuse::LeanEkfOptions>;
  using PosefuseSeparate = Filter<posefuse::EkfOptions, false>;
  using PosefuseNoMemo = Filter<NoMemo>;
  struct Naive {
    using M15 = Eigen::Matrix<double, 15, 15>;
    Eigen::Matrix<double, 15, 1> mu = Eigen::Matrix<double, 15, 1>::Zero();
    M15 S = P0();
    double step(std::size_t k) {
      const M15 F = Kinematic15::F_of(kDt);
      const M15 Q = M15(Kinematic15::q_diag().asDiagonal()) * kDt;
      Eigen::Matrix<double, 6, 15> H = Eigen::Matrix<double, 6, 15>::Zero();
      H.leftCols<6>().setIdentity();
      const Eigen::Matrix<double, 15, 1> mubar = F * mu;
      const M15 Sbar = F * S * F.transpose() + Q;
      const Eigen::Matrix<double, 15, 6> K =
          Sbar * H.transpose() * (H * Sbar * H.transpose() + R()).inverse();
      mu = mubar + K * (measurements()[k] - H * mubar);
      S = (M15::Identity() - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
  struct Dynamic {
    VectorXd mu = VectorXd::Zero(15);
    MatrixXd S = P0();
    double step(std::size_t k) {
      const MatrixXd F = Kinematic15::F_of(kDt);
      const MatrixXd Q = MatrixXd(Kinematic15::q_diag().asDiagonal()) * kDt;
      MatrixXd H = MatrixXd::Zero(6, 15);
      H.leftCols(6).setIdentity();
      const VectorXd z = measurements()[k];
      const VectorXd mubar = F * mu;
      const MatrixXd Sbar = F * S * F.transpose() + Q;
      const MatrixXd Sinn = H * Sbar * H.transpose() + R();
      const MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
      mu = mubar + K * (z - H * mubar);
      S = (MatrixXd::Identity(15, 15) - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
};


// ---------------------------------------------------------------------------
// Constant turn rate and velocity + position fix

struct CtrvEkf {
  static constexpr double kDt = 0.1, kQa = 0.5, kQw = 0.05, kSigma = 0.5;
  using State = posefuse::CtrvState<double>;
  using Vec5 = Eigen::Matrix<double, 5, 1>;
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  static const std::vector<Eigen::Vector2d>& measurements() {
    static const std::vector<Eigen::Vector2d> zs = []() __attribute__((noinline)) {
      std::vector<Eigen::Vector2d> out;
      std::mt19937 rng(9);
      std::normal_distribution<double> n(0.0, 1.0);
      const posefuse::Ctrv<double> m(kQa, kQw);
      State x(0, 0, 0.3, 8.0, 0.0);
      for (std::size_t k = 0; k < kFrames; ++k) {
        // speed and yaw rate wander; the yaw rate crosses zero both ways
        x.values(3) = 8.0 + 2.0 * std::sin(double(k) / 90.0) + 0.05 * n(rng);
        x.values(4) = 0.4 * std::sin(double(k) / 40.0) + 0.01 * n(rng);
        x = m.predict(x, {}, kDt);
        const double ex = n(rng);
        const double ey = n(rng);
        out.push_back(x.position() + kSigma * Eigen::Vector2d(ex, ey));
      }
      return out;
    }();
    return zs;
  }
  static State x0() { return State(measurements()[0].x(), measurements()[0].y(), 0.3, 8.0, 0.0); }
  static Mat5 P0() { return Vec5(1.0, 1.0, 0.1, 1.0, 0.01).asDiagonal(); }
  static posefuse::Ctrv<double> motion() { return posefuse::Ctrv<double>(kQa, kQw); }
  static double difference(const VectorXd& a, const VectorXd& b) {
    VectorXd d = a - b;
    d(2) = posefuse::angle_diff(a(2), b(2));
    return d.cwiseAbs().maxCoeff() / (1.0 + b.cwiseAbs().maxCoeff());
  }
  template <class Options, bool kFused = true>
  struct Filter {
    posefuse::BasicEkf<Options, posefuse::Ctrv<double>, posefuse::CtrvPositionFix<double>> ekf{
        motion(), posefuse::CtrvPositionFix<double>::isotropic(kSigma)};
    Filter() { ekf.reset(x0(), P0()); }
    posefuse::FilterStatus step(std::size_t k) {
      if constexpr (kFused) {
        return ekf.step(posefuse::NoControl{}, kDt, measurements()[k]).template update<0>().status;
      } else {
        (void)ekf.predict(posefuse::NoControl{}, kDt);
        return ekf.template update<0>(measurements()[k]).status;
      }
    }
    VectorXd state() const { return ekf.state().vector(); }
  };
  using Posefuse = Filter<posefuse::EkfOptions>;
  using PosefuseLean = Filter<posefuse::LeanEkfOptions>;
  using PosefuseSeparate = Filter<posefuse::EkfOptions, false>;
  using PosefuseNoMemo = Filter<NoMemo>;
  /// The textbook step on the model's f, F and Q (heading wrapped after the update).
  struct Naive {
    Vec5 mu = x0().vector();
    Mat5 S = P0();
    double step(std::size_t k) {
      const posefuse::Ctrv<double> m = motion();
      const State x(mu);
      const Vec5 mubar = m.predict(x, {}, kDt).vector();
      const Mat5 G = m.jacobian(x, {}, kDt);
      Eigen::Matrix<double, 2, 5> H = Eigen::Matrix<double, 2, 5>::Zero();
      H(0, 0) = H(1, 1) = 1;
      const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * (kSigma * kSigma);
      const Mat5 Sbar = G * S * G.transpose() + m.noise(x, {}, kDt);
      const Eigen::Matrix<double, 5, 2> K = Sbar * H.transpose() * (H * Sbar * H.transpose() + R).inverse();
      mu = mubar + K * (measurements()[k] - H * mubar);
      mu(2) = posefuse::wrap_angle(mu(2));
      S = (Mat5::Identity() - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
  struct Dynamic {
    VectorXd mu = x0().vector();
    MatrixXd S = P0();
    double step(std::size_t k) {
      const posefuse::Ctrv<double> m = motion();
      const State x{Vec5(mu)};
      const VectorXd mubar = m.predict(x, {}, kDt).vector();
      const MatrixXd G = m.jacobian(x, {}, kDt);
      const MatrixXd Q = m.noise(x, {}, kDt);
      MatrixXd H = MatrixXd::Zero(2, 5);
      H(0, 0) = H(1, 1) = 1;
      const MatrixXd R = MatrixXd::Identity(2, 2) * (kSigma * kSigma);
      const VectorXd z = measurements()[k];
      const MatrixXd Sbar = G * S * G.transpose() + Q;
      const MatrixXd Sinn = H * Sbar * H.transpose() + R;
      const MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
      mu = mubar + K * (z - H * mubar);
      mu(2) = posefuse::wrap_angle(mu(2));
      S = (MatrixXd::Identity(5, 5) - K * H) * Sbar;
      return S(0, 0);
    }
    VectorXd state() const { return mu; }
  };
};

// ---------------------------------------------------------------------------
// RTS smoothing of a recorded run

/// A recorded forward run (kFrames steps) of workload W's posefuse filter.
template <class W, class S>
const std::vector<posefuse::SmootherStep<S>>& recorded_run() {
  static const std::vector<posefuse::SmootherStep<S>> run = []() __attribute__((noinline)) {
    std::vector<posefuse::SmootherStep<S>> out;
    typename W::Posefuse f;
    for (std::size_t k = 0; k < kFrames; ++k) {
      posefuse::SmootherStep<S> st;
      if (k > 0) (void)f.ekf.predict(posefuse::NoControl{}, W::dt_of(k));
      st.predicted_mean = f.ekf.state();
      st.predicted_cov = f.ekf.covariance();
      if (k > 0) st.F = f.ekf.last_jacobian();
      (void)f.ekf.template update<0>(W::z_of(k));
      st.filtered_mean = f.ekf.state();
      st.filtered_cov = f.ekf.covariance();
      out.push_back(st);
    }
    return out;
  }();
  return run;
}

struct RtsCv : ConstantVelocity<false> {
  using S = Eigen::Vector4d;
  static double dt_of(std::size_t k) { return dt(k); }
  static Eigen::Vector2d z_of(std::size_t k) { return z(k); }
  static VectorXd vec(const S& x) { return x; }
  static S add(const S& x, const VectorXd& d) { return x + d; }
  static VectorXd sub(const S& a, const S& b) { return a - b; }
};
struct RtsCtrv : CtrvEkf {
  using S = posefuse::CtrvState<double>;
  static double dt_of(std::size_t) { return kDt; }
  static Eigen::Vector2d z_of(std::size_t k) { return measurements()[k]; }
  static VectorXd vec(const S& x) { return x.vector(); }
  static S add(const S& x, const Vec5& d) { return x.plus(d); }
  static Vec5 sub(const S& a, const S& b) { return a.minus(b); }
};

/// The textbook backward pass, fixed-size Eigen, explicit inverse.
template <class W>
std::vector<Eigen::Matrix<double, posefuse::DimOf<typename W::S>, 1>> naive_rts(
    const std::vector<posefuse::SmootherStep<typename W::S>>& run) {
  using S = typename W::S;
  constexpr int N = posefuse::DimOf<S>;
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  std::vector<Vec> out(run.size());
  S xs = run.back().filtered_mean;
  Mat Ps = run.back().filtered_cov;
  out.back() = W::vec(xs);
  for (std::size_t k = run.size() - 1; k-- > 0;) {
    const Mat C = run[k].filtered_cov * run[k + 1].F.transpose() * run[k + 1].predicted_cov.inverse();
    xs = W::add(run[k].filtered_mean, Vec(C * Vec(W::sub(xs, run[k + 1].predicted_mean))));
    Ps = run[k].filtered_cov + C * (Ps - run[k + 1].predicted_cov) * C.transpose();
    out[k] = W::vec(xs);
  }
  return out;
}

template <class W>
std::string rts_disagreement() {
  const auto& run = recorded_run<W, typename W::S>();
  const auto a = posefuse::rts_smooth(run);
  const auto b = naive_rts<W>(run);
  for (std::size_t k = 0; k < run.size(); ++k)
    if (!(W::difference(W::vec(a[k].mean), b[k]) <= 1e-9)) return "rts_smooth differs from naive_fixed";
  return {};
}

template <class W, bool kPosefuse>
void BM_Rts(benchmark::State& st) {
  static const std::string why = rts_disagreement<W>();
  if (!why.empty()) {
    st.SkipWithError(why.c_str());
    return;
  }
  const auto& run = recorded_run<W, typename W::S>();
  for (auto _ : st) {
    if constexpr (kPosefuse) {
      benchmark::DoNotOptimize(posefuse::rts_smooth(run).front().mean);
    } else {
      benchmark::DoNotOptimize(naive_rts<W>(run).front());
    }
  }
  st.counters["frame"] = benchmark::Counter(double(run.size()), benchmark::Counter::kIsIterationInvariantRate |
                                                                    benchmark::Counter::kInvert);
}

// ---------------------------------------------------------------------------
// Registration

template <class W>
void register_workload(const std::string& name, bool nomemo_row) {
  benchmark::RegisterBenchmark((name + "/posefuse").c_str(), BM_Step<W, typename W::Posefuse>);
  benchmark::RegisterBenchmark((name + "/posefuse_lean").c_str(), BM_Step<W, typename W::PosefuseLean>);
  benchmark::RegisterBenchmark((name + "/posefuse_separate").c_str(),
                               BM_Step<W, typename W::PosefuseSeparate>);
  if (nomemo_row)
    benchmark::RegisterBenchmark((name + "/posefuse_nomemo").c_str(),
                                 BM_Step<W, typename W::PosefuseNoMemo>);
  benchmark::RegisterBenchmark((name + "/naive_fixed").c_str(), BM_Step<W, typename W::Naive>);
  benchmark::RegisterBenchmark((name + "/dynamic").c_str(), BM_Step<W, typename W::Dynamic>);
}

// Covariances as the filters above produce them (predicted and posterior,
// the first 128 steps, so they still change), cycled.
template <int N>
const std::vector<Eigen::Matrix<double, N, N>>& filter_covariances() {
  static const std::vector<Eigen::Matrix<double, N, N>> out = [] {
    std::vector<Eigen::Matrix<double, N, N>> v;
    const auto record = [&v](auto& f, auto&& predict, auto&& update) {
      for (std::size_t k = 0; k < 128; ++k) {
        predict(k);
        v.push_back(f.ekf.covariance());
        update(k);
        v.push_back(f.ekf.covariance());
      }
    };
    if constexpr (N == 2) {
      Seed000<false>::PosefuseNoMemo f;
      record(
          f, [&f](std::size_t k) { (void)f.ekf.predict(planar_frames().u[k], 1.0); },
          [&f](std::size_t k) { (void)f.ekf.template update<0>(planar_frames().z[k]); });
    } else if constexpr (N == 4) {
      ConstantVelocity<false>::PosefuseNoMemo f;
      record(
          f, [&f](std::size_t) { (void)f.ekf.predict(posefuse::NoControl{}, 0.1); },
          [&f](std::size_t k) { (void)f.ekf.template update<0>(ConstantVelocity<false>::z(k)); });
    } else {
      static_assert(N == 15);
      Pose15::PosefuseNoMemo f;
      record(
          f, [&f](std::size_t) { (void)f.ekf.predict(posefuse::NoControl{}, Pose15::kDt); },
          [&f](std::size_t k) { (void)f.ekf.template update<0>(Pose15::measurements()[k]); });
    }
    return v;
  }();
  return out;
}

template <int N>
void BM_PsdCheck(benchmark::State& state) {
  const auto& P = filter_covariances<N>();
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::is_positive_semidefinite(P[k]));
    k = (k + 1) & 255;
  }
}
template <int N>
void BM_PsdCheck_Reference(benchmark::State& state) {
  const auto& P = filter_covariances<N>();
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::detail::psd_reference(P[k], false));
    k = (k + 1) & 255;
  }
}

const bool registered = [] {
  register_workload<Seed000<false>>("BM_Seed000Ekf_Step", true);
  benchmark::RegisterBenchmark("BM_Seed000Ekf_Step/posefuse_recompute",
                               BM_Step<Seed000<false>, Seed000Recompute>);
  register_workload<Seed000<true>>("BM_Seed000Kitti_Step", false);
  register_workload<ConstantVelocity<false>>("BM_ConstantVelocityEkf_Step", true);
  register_workload<ConstantVelocity<true>>("BM_ConstantVelocityKitti_Step", false);
  register_workload<UnicyclePoseFix>("BM_UnicyclePoseFix_Step", false);
  register_workload<Pose15>("BM_Pose15_Step", true);
  register_workload<CtrvEkf>("BM_CtrvEkf_Step", false);
  benchmark::RegisterBenchmark("BM_RtsSmooth_ConstantVelocity/posefuse", BM_Rts<RtsCv, true>);
  benchmark::RegisterBenchmark("BM_RtsSmooth_ConstantVelocity/naive_fixed", BM_Rts<RtsCv, false>);
  benchmark::RegisterBenchmark("BM_RtsSmooth_Ctrv/posefuse", BM_Rts<RtsCtrv, true>);
  benchmark::RegisterBenchmark("BM_RtsSmooth_Ctrv/naive_fixed", BM_Rts<RtsCtrv, false>);
  benchmark::RegisterBenchmark("BM_PsdCheck/2", BM_PsdCheck<2>);
  benchmark::RegisterBenchmark("BM_PsdCheck/4", BM_PsdCheck<4>);
  benchmark::RegisterBenchmark("BM_PsdCheck/15", BM_PsdCheck<15>);
  benchmark::RegisterBenchmark("BM_PsdCheck_Reference/2", BM_PsdCheck_Reference<2>);
  benchmark::RegisterBenchmark("BM_PsdCheck_Reference/4", BM_PsdCheck_Reference<4>);
  benchmark::RegisterBenchmark("BM_PsdCheck_Reference/15", BM_PsdCheck_Reference<15>);
  return true;
}();

}  // namespace

// The window problem (vio/window_problem.hpp): cost and gradient assembly,
// convergence of the noise-free window, the four unobservable directions,
// the block-profile Cholesky of the reduced system against a dense LDLT, and
// the rotation-compensated keyframe parallax (vio/sliding_window.hpp).
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "vio/window_fixture.hpp"
#include <posefuse/vio/detail/block_profile_cholesky.hpp>
#include <posefuse/vio/sliding_window.hpp>
#include <posefuse/vio/window_problem.hpp>

using namespace posefuse;

namespace {

// A prior that holds frame slot 0 at `x0` with standard deviation 1e-3 in every direction.
VioPrior anchor_prior(const VioFrame& f) {
  VioPrior p;
  p.linear.J = 1e3 * Eigen::MatrixXd::Identity(15, 15);
  p.linear.r0 = Eigen::VectorXd::Zero(15);
  for (int i = 0; i < 15; ++i) p.linear.kept.push_back(i);
  VioPriorBlock b;
  b.frame_id = f.id;
  b.frame_ref = f.x;
  p.blocks.push_back(b);
  return p;
}

double max_position_error(const VioWindow& a, const VioWindow& b) {
  double e = 0;
  for (std::size_t k = 0; k < a.frames.size(); ++k) e = std::max(e, (a.frames[k].x.p - b.frames[k].x.p).norm());
  return e;
}
double max_rotation_error(const VioWindow& a, const VioWindow& b) {
  double e = 0;
  for (std::size_t k = 0; k < a.frames.size(); ++k) e = std::max(e, a.frames[k].x.R.minus(b.frames[k].x.R).norm());
  return e;
}

}  // namespace

TEST_CASE("WindowProblem: zero cost at the noise-free truth; the gradient is J^T r of the cost",
          "[vio][window]") {
  const auto fx = vio_test::make_window(3, 4, 25);
  WindowSolveOptions o;
  o.loss.kind = ReprojectionLoss::Kind::kNone;
  CHECK(WindowProblem::cost(fx.truth, o) < 1e-18);
  for (const bool ext : {false, true}) {
    VioWindow w = fx.truth;
    w.estimate_extrinsic = ext;
    vio_test::perturb(w, 5, 0.02, 0.01);
    w.prior = anchor_prior(fx.truth.frames[0]);
    w.prior->blocks[0].frame_ref = fx.truth.frames[0].x.plus(ImuState::Tangent::Constant(1e-3));
    w.T_bc = w.T_bc.plus(RigidPose::Tangent::Constant(2e-3));
    WindowProblem P;
    P.linearize(w, o);
    // F = |r|^2, so dF/dx = 2 b on the camera-side variables (at fixed inverse depths).
    const int D = w.dimension();
    Eigen::VectorXd g(D);
    const double h = 1e-6;
    for (int i = 0; i < D; ++i) {
      VioWindow wp = w, wm = w;
      Eigen::VectorXd d = Eigen::VectorXd::Zero(D);
      d(i) = h;
      for (std::size_t k = 0; k < w.frames.size(); ++k) {
        wp.frames[k].x = w.frames[k].x.plus(d.segment<15>(15 * int(k)));
        wm.frames[k].x = w.frames[k].x.plus(-d.segment<15>(15 * int(k)));
      }
      if (ext) {
        wp.T_bc = w.T_bc.plus(d.tail<6>());
        wm.T_bc = w.T_bc.plus(-d.tail<6>());
      }
      g(i) = (WindowProblem::cost(wp, o) - WindowProblem::cost(wm, o)) / (2 * h);
    }
    const Eigen::VectorXd b2 = 2.0 * P.gradient();
    INFO("extrinsic " << ext << ": max |2b - dF/dx| = " << (b2 - g).cwiseAbs().maxCoeff() << " of "
                      << g.cwiseAbs().maxCoeff());
    CHECK((b2 - g).cwiseAbs().maxCoeff() <= 1e-5 * (1.0 + g.cwiseAbs().maxCoeff()));
    // Flipping the sign of one keyframe's gradient block is detected by the same comparison.
    Eigen::VectorXd flipped = b2;
    flipped.segment<15>(15) *= -1.0;
    CHECK_FALSE((flipped - g).cwiseAbs().maxCoeff() <= 1e-5 * (1.0 + g.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("WindowProblem: the noise-free window converges from 0.1 m / 2 deg to the truth within 1e-6 m",
          "[vio][window]") {
  const auto fx = vio_test::make_window(1, 10, 150);
  for (const bool ext : {false, true}) {
    VioWindow w = fx.truth;
    w.estimate_extrinsic = ext;
    w.prior = anchor_prior(fx.truth.frames[0]);
    if (ext) {  // the extrinsic moved too: 1 cm and 0.5 deg
      w.T_bc.p += Eigen::Vector3d(0.01, 0, 0);
      w.T_bc.R = w.T_bc.R.plus(Eigen::Vector3d(0.0087, 0, 0));
    }
    vio_test::perturb(w, 2, 0.1, 2.0 * M_PI / 180.0);
    WindowSolveOptions o;
    o.max_iterations = 30;
    WindowProblem P;
    const WindowSolveSummary s = P.solve(w, o);
    INFO("extrinsic " << ext << ": iterations " << s.iterations << ", cost " << s.initial_cost << " -> "
                      << s.final_cost);
    CHECK(max_position_error(w, fx.truth) <= 1e-6);
    CHECK(max_rotation_error(w, fx.truth) <= 1e-6);
    if (ext) CHECK((w.T_bc.p - fx.truth.T_bc.p).norm() <= 1e-6);
    // Deterministic: the same solve again gives the same bits.
    VioWindow w2 = fx.truth;
    w2.estimate_extrinsic = ext;
    w2.prior = anchor_prior(fx.truth.frames[0]);
    if (ext) {
      w2.T_bc.p += Eigen::Vector3d(0.01, 0, 0);
      w2.T_bc.R = w2.T_bc.R.plus(Eigen::Vector3d(0.0087, 0, 0));
    }
    vio_test::perturb(w2, 2, 0.1, 2.0 * M_PI / 180.0);
    WindowProblem P2;
    (void)P2.solve(w2, o);
    CHECK(w2.frames.back().x.p == w.frames.back().x.p);
  }
}

TEST_CASE("WindowProblem: without a prior the reduced Hessian has exactly four near-zero eigenvalues "
          "(x, y, z, yaw)",
          "[vio][window][observability]") {
  const auto fx = vio_test::make_window(4, 10, 150);
  const VioWindow& w = fx.truth;
  WindowSolveOptions o;
  WindowProblem P;
  P.linearize(w, o);
  Eigen::MatrixXd Hs;
  Eigen::VectorXd bs;
  P.reduced(Hs, bs);
  // Eigenvalues of the Jacobi-scaled Hessian D^-1/2 H D^-1/2 (D its diagonal),
  // so that variables of different units (m, rad, m/s, biases) compare.
  const Eigen::VectorXd dinv = Hs.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd Hn = dinv.asDiagonal() * Hs * dinv.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hn, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd ev = es.eigenvalues();
  const double lmax = ev.maxCoeff();
  INFO("eigenvalues / max: " << ev(0) / lmax << " " << ev(1) / lmax << " " << ev(2) / lmax << " " << ev(3) / lmax
                             << " | " << ev(4) / lmax << " " << ev(5) / lmax);
  // Measured: the four are ~1e-16 of the largest, the fifth ~2e-9.
  CHECK(std::abs(ev(3)) <= 1e-13 * lmax);
  CHECK(ev(4) >= 1e-11 * lmax);
  // The four directions: global translation and a rotation about gravity
  // (δp = e_z x p, δφ = R^T e_z, δv = e_z x v for every keyframe).
  const int D = w.dimension();
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(D, 4);
  const Eigen::Vector3d ez = -w.gravity_w.normalized();
  for (std::size_t k = 0; k < w.frames.size(); ++k) {
    const int off = 15 * int(k);
    N.block<3, 3>(off, 0).setIdentity();
    N.block<3, 1>(off, 3) = ez.cross(w.frames[k].x.p);
    N.block<3, 1>(off + 3, 3) = w.frames[k].x.R.inverse().act(ez);
    N.block<3, 1>(off + 6, 3) = ez.cross(w.frames[k].x.v);
  }
  const Eigen::MatrixXd HN = Hs * N;
  const double hmax = Hs.cwiseAbs().maxCoeff();
  INFO("|H N| / (max|H| |N|) per direction: " << HN.colwise().norm() / hmax);
  for (int c = 0; c < 4; ++c) CHECK(HN.col(c).norm() <= 1e-12 * hmax * N.col(c).norm());
}

TEST_CASE("Block-profile Cholesky: equals the dense LDLT solve on random SPD block-banded systems and on a "
          "real window",
          "[vio][window][profile]") {
  using Chol = detail::BlockProfileCholesky<15>;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto rel_err = [](const Eigen::VectorXd& x, const Eigen::VectorXd& ref) {
    return (x - ref).norm() / ref.norm();
  };
  for (int trial = 0; trial < 12; ++trial) {
    const int nb = 3 + trial % 5 * 5;  // 3 .. 23 blocks
    const int t = trial % 2 == 0 ? 0 : 6;
    const int bw = 1 + trial % 3;      // block bandwidth, plus a dense corner like the prior's
    std::vector<int> first(static_cast<std::size_t>(nb));
    for (int i = 0; i < nb; ++i)
      first[std::size_t(i)] = i < 4 ? 0 : std::max(0, i - int(std::uniform_int_distribution<int>(0, bw)(rng)));
    const int D = 15 * nb + t;
    // A = L L^T with L on the profile (and the border), so A has that profile.
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(D, D);
    for (int i = 0; i < nb; ++i)
      for (int j = first[std::size_t(i)]; j <= i; ++j)
        for (int r = 0; r < 15; ++r)
          for (int c = 0; c < 15; ++c) L(15 * i + r, 15 * j + c) = n(rng);
    for (int r = 15 * nb; r < D; ++r)
      for (int c = 0; c <= r; ++c) L(r, c) = n(rng);
    L = L.triangularView<Eigen::Lower>();
    L.diagonal().array() = L.diagonal().array().abs() + 4.0;
    const Eigen::MatrixXd A = L * L.transpose();
    const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(D, [&] { return n(rng); });
    const Eigen::VectorXd ref = A.ldlt().solve(b);
    // The upper triangle and the blocks outside the profile hold garbage: never read.
    Eigen::MatrixXd F = Eigen::MatrixXd::Constant(D, D, 1e30);
    for (int i = 0; i < nb; ++i)
      for (int j = first[std::size_t(i)]; j <= i; ++j) F.block<15, 15>(15 * i, 15 * j) = A.block<15, 15>(15 * i, 15 * j);
    F.bottomRows(t) = A.bottomRows(t);
    F.triangularView<Eigen::StrictlyUpper>().setConstant(1e30);
    REQUIRE(Chol::factor(F, first, t));
    Eigen::VectorXd x = b;
    Chol::solve(F, first, t, x);
    INFO("blocks " << nb << ", border " << t << ": relative error " << rel_err(x, ref));
    CHECK(rel_err(x, ref) <= 1e-9);
    CHECK(Chol::relative_work(first, t) <= 1.0 + 1e-12);
  }
  SECTION("a solver that ignores the profile's couplings is caught") {
    std::vector<int> first{0, 0, 1};
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(45, 45) * 10.0;
    A.block<15, 15>(15, 0).setConstant(1.0);
    A.block<15, 15>(0, 15).setConstant(1.0);
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(45);
    const Eigen::VectorXd ref = A.ldlt().solve(b);
    Eigen::MatrixXd F = A;
    std::vector<int> diagonal_only{0, 1, 2};  // claims block row 1 starts at column 1
    REQUIRE(Chol::factor(F, diagonal_only, 0));
    Eigen::VectorXd x = b;
    Chol::solve(F, diagonal_only, 0, x);
    CHECK_FALSE(rel_err(x, ref) <= 1e-9);
  }
  SECTION("a real window: the reduced system's recorded profile holds every coupling") {
    const auto fx = vio_test::make_window(5, 12, 150, 10);
    for (const bool ext : {false, true}) {
      VioWindow w = fx.truth;
      w.estimate_extrinsic = ext;
      w.prior = anchor_prior(fx.truth.frames[0]);
      vio_test::perturb(w, 6, 0.05, 1.0 * M_PI / 180.0);
      WindowSolveOptions o;
      WindowProblem P;
      P.linearize(w, o);
      Eigen::MatrixXd Hs;
      Eigen::VectorXd bs;
      P.reduced(Hs, bs);
      const std::vector<int>& first = P.profile();
      const int nb = int(w.frames.size()), t = ext ? 6 : 0;
      for (int i = 0; i < nb; ++i)
        for (int j = 0; j < first[std::size_t(i)]; ++j) CHECK(Hs.block<15, 15>(15 * i, 15 * j).cwiseAbs().maxCoeff() == 0.0);
      const Eigen::VectorXd ref = Hs.ldlt().solve(-bs);
      Eigen::MatrixXd F = Hs;
      REQUIRE(Chol::factor(F, first, t));
      Eigen::VectorXd x = -bs;
      Chol::solve(F, first, t, x);
      INFO("extrinsic " << ext << ": relative error " << rel_err(x, ref));
      CHECK(rel_err(x, ref) <= 1e-9);
      // The damped step of solve_step (whichever factorisation it chose) equals the dense one too.
      Eigen::VectorXd dx;
      std::vector<double> dl;
      REQUIRE(P.solve_step(0.0, dx, dl));
      CHECK(rel_err(dx, ref) <= 1e-9);
    }
  }
}

namespace {

// Two frames 0.1 s apart related by a pure rotation of the camera (constant
// gyro rate, the camera at the body origin so that it does not move), 60
// points 3 to 8 m in front of the first camera, observed exactly in both.
VioWindow pure_rotation_window() {
  VioWindow w;
  w.T_bc = vio_test::camera_extrinsic();
  w.T_bc.p.setZero();
  ImuNoise noise;
  const Eigen::Vector3d omega(0.4, -0.6, 0.9);  // rad/s (body)
  VioFrame f0, f1;
  f0.id = 1;
  f0.t_ns = 0;
  f0.x.R = SO3d::exp(Eigen::Vector3d(0.1, 0.2, -0.3));
  f1.id = 2;
  f1.t_ns = 100'000'000;
  f1.pre = Preintegration(noise, ImuBias{});
  for (int k = 0; k <= 20; ++k) {
    ImuSample s;
    s.t_ns = std::int64_t(k) * 5'000'000;
    s.gyro_radps = omega;
    s.accel_mps2 = Eigen::Vector3d(0, 0, 9.81);
    (void)f1.pre.add(s);
  }
  f1.x.R = f0.x.R.compose(SO3d::exp(0.1 * omega));
  w.frames = {f0, f1};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::uint64_t id = 0; id < 60; ++id) {
    const Eigen::Vector3d m(0.3 * u(rng), 0.25 * u(rng), 1.0);
    const Eigen::Vector3d P_w = VioFrame::pose(f0.x).act(w.T_bc.act(m * (5.5 + 2.5 * u(rng))));
    VioLandmark l;
    for (const VioFrame& f : w.frames) {
      const Eigen::Vector3d P_c = w.T_bc.R.inverse().act(f.x.R.inverse().act(P_w - f.x.p) - w.T_bc.p);
      l.obs.push_back(VioObservation{f.id, P_c.head<2>() / P_c.z()});
    }
    w.landmarks.emplace(id, std::move(l));
  }
  return w;
}

}  // namespace

TEST_CASE("Keyframe test: the rotation-compensated parallax of a pure rotation is ~0, the raw one is large",
          "[vio][window][keyframe]") {
  const VioWindow w = pure_rotation_window();
  SlidingWindowOptions o;
  o.focal_px = 460.0;
  o.min_keyframe_interval_s = 0.0;  // the parallax test alone first (the frames are 0.1 s apart)
  const auto [comp, n_comp] = mean_parallax(w, 1, o.focal_px, true);
  const auto [raw, n_raw] = mean_parallax(w, 1, o.focal_px, false);
  const auto [flipped, n_flipped] = mean_parallax(w, 1, o.focal_px, true, true);
  INFO("parallax (px): compensated " << comp << ", raw " << raw << ", flipped compensation " << flipped);
  CHECK(n_comp == 60);
  CHECK(n_raw == 60);
  CHECK(comp < 0.01);
  CHECK(raw > 4.0 * o.min_parallax_px);
  CHECK(flipped > 4.0 * o.min_parallax_px);
  o.rotation_compensated_parallax = true;
  CHECK_FALSE(is_keyframe(w, 1, o));
  o.rotation_compensated_parallax = false;
  CHECK(is_keyframe(w, 1, o));
  // The minimum interval holds the parallax test back (0.1 s between the frames) ...
  o.min_keyframe_interval_s = 0.15;
  CHECK_FALSE(is_keyframe(w, 1, o));
  // ... but not the loss of tracking.
  o.min_tracked = 100;
  CHECK(is_keyframe(w, 1, o));
}

// Reprojection factor (vio/reprojection_factor.hpp) and robust losses
// (vio/robust_loss.hpp): Jacobians through the conformance harness, a flip
// test for every block, and the loss derivatives.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <posefuse/testing/conformance.hpp>
#include <posefuse/vio/reprojection_factor.hpp>
#include <posefuse/vio/robust_loss.hpp>

using posefuse::ReprojectionFactor;
using posefuse::RigidPose;
using posefuse::SO3d;

namespace {

struct Setup {
  RigidPose Ti, Tj, Tbc;
  double lambda = 0;
  ReprojectionFactor factor{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones()};
};

// A random but well-conditioned configuration: a point 2-6 m in front of
// camera i, camera j 0.3-0.6 m away looking at it; the observation in j is
// the projection perturbed by a few pixels (non-zero residual).
Setup make_setup(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto vec = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  Setup s;
  s.Ti = RigidPose{vec() * 3.0, SO3d::exp(vec() * 2.0)};
  s.Tbc = RigidPose{vec() * 0.1, SO3d::exp(vec() * 1.5)};
  s.Tj = RigidPose{s.Ti.p + vec() * 0.4, s.Ti.R.plus(vec() * 0.1)};
  const Eigen::Vector2d mi(0.3 * u(rng), 0.3 * u(rng));
  s.lambda = 1.0 / (4.0 + 2.0 * u(rng));
  const ReprojectionFactor probe(mi, Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones());
  const Eigen::Vector3d Pcj = probe.point_in_observer(s.Ti, s.Tj, s.Tbc, s.lambda);
  const Eigen::Vector2d mj = Pcj.head<2>() / Pcj.z() + Eigen::Vector2d(u(rng), u(rng)) * 0.01;
  s.factor = ReprojectionFactor(mi, mj, Eigen::Vector2d(460.0, 455.0));
  return s;
}

using J26 = ReprojectionFactor::PoseJacobian;

struct Jacobians {
  J26 Ji, Jj, Jbc;
  Eigen::Vector2d Jl;
};

// The four conformance checks of one configuration, for given Jacobians.
posefuse::testing::CheckResult check_all(const Setup& s, const Jacobians& J, double tol) {
  namespace pt = posefuse::testing;
  const auto& f = s.factor;
  std::vector<pt::CheckResult> r;
  r.push_back(pt::check_jacobian(
      "J_pose_i", [&](const RigidPose& x) { return f.residual(x, s.Tj, s.Tbc, s.lambda); }, s.Ti, J.Ji, tol));
  r.push_back(pt::check_jacobian(
      "J_pose_j", [&](const RigidPose& x) { return f.residual(s.Ti, x, s.Tbc, s.lambda); }, s.Tj, J.Jj, tol));
  r.push_back(pt::check_jacobian(
      "J_extrinsic", [&](const RigidPose& x) { return f.residual(s.Ti, s.Tj, x, s.lambda); }, s.Tbc, J.Jbc,
      tol));
  const Eigen::Matrix<double, 1, 1> l(s.lambda);
  r.push_back(pt::check_jacobian(
      "J_inverse_depth",
      [&](const Eigen::Matrix<double, 1, 1>& x) { return f.residual(s.Ti, s.Tj, s.Tbc, x(0)); }, l, J.Jl,
      tol));
  return pt::combine("reprojection factor", r);
}

Jacobians analytic(const Setup& s) {
  Jacobians J;
  (void)s.factor.residual(s.Ti, s.Tj, s.Tbc, s.lambda, &J.Ji, &J.Jj, &J.Jbc, &J.Jl);
  return J;
}

}  // namespace

TEST_CASE("ReprojectionFactor: zero residual at the projection, whitened by f/sigma", "[vio][factor]") {
  std::mt19937_64 rng(7);
  const Setup s = make_setup(rng);
  const Eigen::Vector3d Pcj = s.factor.point_in_observer(s.Ti, s.Tj, s.Tbc, s.lambda);
  REQUIRE(Pcj.z() > 0);
  const ReprojectionFactor exact(s.factor.anchor().head<2>(), Pcj.head<2>() / Pcj.z(), Eigen::Vector2d(2, 3));
  CHECK(exact.residual(s.Ti, s.Tj, s.Tbc, s.lambda).norm() < 1e-12);
  // Moving the observation by (dx, dy) on the normalised plane gives -(2 dx, 3 dy).
  const ReprojectionFactor moved(s.factor.anchor().head<2>(), Pcj.head<2>() / Pcj.z() + Eigen::Vector2d(1e-3, -2e-3),
                                 Eigen::Vector2d(2, 3));
  const Eigen::Vector2d r = moved.residual(s.Ti, s.Tj, s.Tbc, s.lambda);
  CHECK(r.x() == Approx(-2e-3).margin(1e-12));
  CHECK(r.y() == Approx(6e-3).margin(1e-12));
  // The same camera as anchor and observer (identity between them) sees the anchor ray.
  const ReprojectionFactor self(s.factor.anchor().head<2>(), s.factor.anchor().head<2>(), Eigen::Vector2d(1, 1));
  CHECK(self.residual(s.Ti, s.Ti, s.Tbc, s.lambda).norm() < 1e-12);
  CHECK_THROWS_AS(ReprojectionFactor(Eigen::Vector2d(NAN, 0), Eigen::Vector2d::Zero(), Eigen::Vector2d::Ones()),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(ReprojectionFactor(Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d(1, 0)),
                  posefuse::invalid_argument);
}

TEST_CASE("ReprojectionFactor: Jacobians pass the conformance check; a flipped sign fails", "[vio][factor]") {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Setup s = make_setup(rng);
    REQUIRE(s.factor.point_in_observer(s.Ti, s.Tj, s.Tbc, s.lambda).z() > 0.5);
    const Jacobians J = analytic(s);
    // Residuals are in units of sigma (entries up to ~1e3 per unit of state):
    // the tolerance is relative for such entries (|a - n| <= tol (1 + |n|)).
    const auto r = check_all(s, J, 1e-6);
    INFO(r.message);
    REQUIRE(r);
    if (trial < 3) {
      // Flip the sign of each 3-column block (and of the inverse-depth column) in turn.
      for (int which = 0; which < 7; ++which) {
        Jacobians F = J;
        J26* blocks[3] = {&F.Ji, &F.Jj, &F.Jbc};
        if (which < 6) {
          J26& B = *blocks[which / 2];
          B.middleCols<3>(3 * (which % 2)) *= -1.0;
          if (B.middleCols<3>(3 * (which % 2)).cwiseAbs().maxCoeff() < 1e-3) continue;  // nothing to flip
        } else {
          F.Jl *= -1.0;
        }
        const auto bad = check_all(s, F, 1e-6);
        INFO("flipped block " << which << ": " << bad.message);
        CHECK_FALSE(bad);
      }
    }
  }
}

TEST_CASE("ReprojectionLoss: rho' and rho'' match central differences of rho; Cauchy and Huber shapes",
          "[vio][loss]") {
  using L = posefuse::ReprojectionLoss;
  for (const L::Kind kind : {L::Kind::kNone, L::Kind::kHuber, L::Kind::kCauchy}) {
    const L loss{kind, 1.5};
    for (const double s : {0.01, 0.5, 1.0, 3.0, 25.0, 400.0}) {
      if (kind == L::Kind::kHuber && std::abs(s - 2.25) < 0.1) continue;  // the kink
      const double h = 1e-5 * (1.0 + s);
      const double d1 = (loss.rho(s + h) - loss.rho(s - h)) / (2 * h);
      const double d2 = (loss.d_rho(s + h) - loss.d_rho(s - h)) / (2 * h);
      INFO("kind " << int(kind) << " s " << s);
      CHECK(loss.d_rho(s) == Approx(d1).epsilon(1e-7));
      CHECK(loss.d2_rho(s) == Approx(d2).epsilon(1e-5).margin(1e-12));
      CHECK(loss.d2_rho(s) <= 0.0);
      CHECK(loss.scaling(s) == Approx(std::sqrt(loss.d_rho(s))));
    }
  }
  const L huber{L::Kind::kHuber, 2.0}, cauchy{L::Kind::kCauchy, 2.0};
  CHECK(huber.rho(3.0) == 3.0);                       // quadratic inside delta^2 = 4
  CHECK(huber.rho(100.0) == Approx(2 * 2 * 10 - 4));  // linear in |r| beyond
  CHECK(cauchy.rho(4.0) == Approx(4.0 * std::log(2.0)));
  // Redescending: the Cauchy influence s rho'(s) -> c^2 while Huber's keeps growing.
  CHECK(1e6 * cauchy.d_rho(1e6) < 4.0 + 1e-3);
  CHECK(1e6 * huber.d_rho(1e6) > 1e3);
}

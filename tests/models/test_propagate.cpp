// The closed-form covariance propagation of the motion models
// (ConstantVelocity2::propagate, Unicycle and Ctrv linearize().propagate)
// against F P F^T from the model's own jacobian(), on random symmetric
// positive definite P of many scales and conditionings: equal to 1e-12
// (relative to the largest entry), exactly symmetric where the model
// computes one triangle (Unicycle, Ctrv), and a flipped sign of any
// non-trivial Jacobian entry inside propagate fails the same comparison.
// Also the unicycle's closed-form process noise against J_u (dt^2 S) J_u^T
// with a correlated control covariance.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/ctrv.hpp>
#include <posefuse/models/unicycle.hpp>
#include <random>
#include <vector>
#include "support/random_matrices.hpp"

using posefuse::Ctrv;
using posefuse::CtrvState;
using posefuse::NoControl;

namespace {

constexpr double kRel = 1e-12;

/// A random symmetric positive definite matrix: a random rotation of a
/// diagonal with entries in [lo, 1] times scale (exactly symmetric).
template <int N>
Eigen::Matrix<double, N, N> random_spd(std::mt19937& rng, double lo, double scale) {
  std::uniform_real_distribution<double> u(std::log(lo), 0.0);
  const Eigen::Matrix<double, N, N> Q = posefuse::test::random_orthogonal<N>(rng);
  Eigen::Matrix<double, N, 1> d;
  for (int i = 0; i < N; ++i) d(i) = std::exp(u(rng)) * scale;
  const Eigen::Matrix<double, N, N> P = Q * d.asDiagonal() * Q.transpose();
  return 0.5 * (P + P.transpose());
}

/// |a - b|_max / |b|_max.
template <class A, class B>
double rel_error(const A& a, const B& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

/// F P F^T, the textbook product.
template <int N>
Eigen::Matrix<double, N, N> sandwich(const Eigen::Matrix<double, N, N>& F, const Eigen::Matrix<double, N, N>& P) {
  return F * P * F.transpose();
}

/// Random covariances: scales 1e-6 .. 1e4, condition numbers up to 1e8.
template <int N>
std::vector<Eigen::Matrix<double, N, N>> covariances(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Matrix<double, N, N>> out;
  for (const double scale : {1e-6, 1e-2, 1.0, 1e4})
    for (const double lo : {0.5, 1e-3, 1e-8})
      for (int k = 0; k < 4; ++k) out.push_back(random_spd<N>(rng, lo, scale));
  return out;
}

}  // namespace

TEST_CASE("ConstantVelocity2::propagate equals F P F^T; a flipped dt fails",
          "[models][cv][propagate]") {
  const posefuse::ConstantVelocity2<double> m(0.7);
  const Eigen::Vector4d x(1, -2, 0.3, 0.7);
  int checked = 0;
  for (const Eigen::Matrix4d& P : covariances<4>(11)) {
    for (const double dt : {0.0, 1e-3, 0.1, 0.37, 2.0, 30.0}) {
      const Eigen::Matrix4d F = m.jacobian(x, {}, dt);
      const Eigen::Matrix4d out = m.propagate(P, x, {}, dt);
      const Eigen::Matrix4d ref = sandwich<4>(F, P);
      INFO("dt = " << dt << ", error " << rel_error(out, ref));
      CHECK(rel_error(out, ref) <= kRel);
      if (dt > 0) {
        // propagate with the sign of F's dt entries flipped is caught.
        CHECK(rel_error(m.propagate(P, x, {}, -dt), ref) > kRel);
      }
      ++checked;
    }
  }
  CHECK(checked == 48 * 6);
}

TEST_CASE("Unicycle: linearize().propagate equals F P F^T for both integrations; a flipped "
          "Jacobian entry fails",
          "[models][unicycle][propagate]") {
  std::mt19937 rng(12);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> heading(-std::numbers::pi, std::numbers::pi);
  for (const auto method : {posefuse::Integration::kExactArc, posefuse::Integration::kEuler}) {
    posefuse::Unicycle<double> m;
    m.method = method;
    m.control_cov << 0.04, 0.003, 0.003, 0.01;
    int flips_detected = 0, flips = 0;
    for (const Eigen::Matrix3d& P : covariances<3>(13)) {
      const posefuse::PlanarPose<double> x{n01(rng), n01(rng), heading(rng)};
      for (const double w : {0.0, 1e-12, -0.3, 2.0}) {
        const Eigen::Vector2d u(1.0 + n01(rng), w);
        for (const double dt : {0.01, 0.1, 1.0}) {
          const auto lin = m.linearize(x, u, dt);
          const Eigen::Matrix3d F = m.jacobian(x, u, dt);
          CHECK((lin.jacobian.array() == F.array()).all());
          const Eigen::Matrix3d ref = sandwich<3>(F, P);
          const Eigen::Matrix3d out = lin.propagate(P);
          INFO("w = " << w << ", dt = " << dt << ", error " << rel_error(out, ref));
          CHECK(rel_error(out, ref) <= kRel);
          CHECK(out == out.transpose());
          // The two motion entries of F, each flipped inside propagate.
          for (const int i : {0, 1}) {
            if (F(i, 2) == 0) continue;
            auto bad = lin;
            bad.jacobian(i, 2) = -bad.jacobian(i, 2);
            ++flips;
            flips_detected += rel_error(bad.propagate(P), ref) > kRel ? 1 : 0;
          }
        }
      }
    }
    CHECK(flips > 0);
    CHECK(flips_detected == flips);
  }
}

TEST_CASE("Unicycle: the closed-form noise equals J_u (dt^2 S) J_u^T, S correlated",
          "[models][unicycle][propagate]") {
  std::mt19937 rng(14);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (const auto method : {posefuse::Integration::kExactArc, posefuse::Integration::kEuler}) {
    for (int k = 0; k < 200; ++k) {
      posefuse::Unicycle<double> m;
      m.method = method;
      m.control_cov = random_spd<2>(rng, 1e-3, std::exp(n01(rng)));
      const posefuse::PlanarPose<double> x{n01(rng), n01(rng), posefuse::wrap_angle(3.0 * n01(rng))};
      const Eigen::Vector2d u(n01(rng), n01(rng));
      const double dt = 0.01 + std::abs(n01(rng));
      Eigen::Matrix<double, 3, 2> Ju;
      (void)posefuse::unicycle_step(x, u(0) * dt, u(1) * dt, method, nullptr, &Ju);
      const Eigen::Matrix3d ref = (dt * dt) * (Ju * m.control_cov * Ju.transpose());
      const Eigen::Matrix3d Q = m.noise(x, u, dt);
      INFO("error " << rel_error(Q, ref));
      CHECK(rel_error(Q, ref) <= kRel);
      CHECK(Q == Q.transpose());
      CHECK((m.linearize(x, u, dt).noise.array() == Q.array()).all());
    }
  }
}

TEST_CASE("Ctrv: linearize().propagate equals F P F^T, yaw rate through 0; each flipped "
          "Jacobian entry fails",
          "[models][ctrv][propagate]") {
  const Ctrv<double> m(0.5, 0.1);
  const double sw = posefuse::detail::kSincSeriesLimit<double>;
  std::mt19937 rng(15);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> heading(-std::numbers::pi, std::numbers::pi);
  // (i, j) of the seven motion entries of F.
  const int entries[7][2] = {{0, 2}, {0, 3}, {0, 4}, {1, 2}, {1, 3}, {1, 4}, {2, 4}};
  int detected[7] = {0, 0, 0, 0, 0, 0, 0};
  int eligible[7] = {0, 0, 0, 0, 0, 0, 0};
  int cases = 0;
  for (const Eigen::Matrix<double, 5, 5>& P : covariances<5>(16)) {
    for (const double dt : {0.01, 0.1, 1.0}) {
      // Yaw rates through 0 (both signs, the series switch of the sinc on both sides).
      const double w0 = 2.0 * sw / dt;
      for (const double w : {-1.5, -w0 * (1 + 1e-6), -1e-12, 0.0, 1e-12, w0 * (1 - 1e-6), 0.3, 5.0}) {
        const CtrvState<double> x(n01(rng), n01(rng), heading(rng), 1.0 + std::abs(3.0 * n01(rng)), w);
        const auto lin = m.linearize(x, {}, dt);
        const Eigen::Matrix<double, 5, 5> F = m.jacobian(x, {}, dt);
        const Eigen::Matrix<double, 5, 5> ref = sandwich<5>(F, P);
        const Eigen::Matrix<double, 5, 5> out = lin.propagate(P);
        INFO("w = " << w << ", dt = " << dt << ", error " << rel_error(out, ref));
        CHECK(rel_error(out, ref) <= kRel);
        CHECK(out == out.transpose());
        for (int e = 0; e < 7; ++e) {
          auto bad = lin;
          double& f = bad.jacobian(entries[e][0], entries[e][1]);
          if (std::abs(f) < 1e-6) continue;  // a sign flip of ~0 changes nothing
          f = -f;
          ++eligible[e];
          detected[e] += rel_error(bad.propagate(P), ref) > kRel ? 1 : 0;
        }
        ++cases;
      }
    }
  }
  CHECK(cases == 48 * 3 * 8);
  // Every entry flipped is caught wherever it is not ~0.
  for (int e = 0; e < 7; ++e) {
    INFO("entry (" << entries[e][0] << ", " << entries[e][1] << "): " << detected[e] << " of "
                   << eligible[e]);
    CHECK(eligible[e] >= cases / 2);
    CHECK(detected[e] == eligible[e]);
  }
}

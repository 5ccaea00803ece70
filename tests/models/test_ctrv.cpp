// Constant turn rate and velocity (models/ctrv.hpp): the Jacobian through
// the conformance harness at many states, yaw rates exactly 0, 1e-12, on
// both sides of the sinc series switch, large and at large dt; a flipped
// Jacobian entry must fail the harness; the noise against a quadrature of
// its defining integral; straight-line and circle predictions against their
// closed forms; the position fix; an EKF and RTS run on a turning vehicle
// whose heading crosses +-pi.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/models/ctrv.hpp>
#include <posefuse/testing/conformance.hpp>
#include <random>
#include <vector>

using posefuse::Ctrv;
using posefuse::CtrvPositionFix;
using posefuse::CtrvState;
using posefuse::NoControl;
namespace pt = posefuse::testing;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTol = 1e-8;

/// Ctrv whose jacobian() entry (i, j) has its sign flipped (no linearize(),
/// so the harness compares the flipped matrix with central differences).
struct FlipCtrv {
  using State = CtrvState<double>;
  using Control = NoControl;
  Ctrv<double> m;
  int i, j;
  State predict(const State& x, const Control& u, double dt) const { return m.predict(x, u, dt); }
  Eigen::Matrix<double, 5, 5> jacobian(const State& x, const Control& u, double dt) const {
    Eigen::Matrix<double, 5, 5> J = m.jacobian(x, u, dt);
    J(i, j) = -J(i, j);
    return J;
  }
  Eigen::Matrix<double, 5, 5> noise(const State& x, const Control& u, double dt) const {
    return m.noise(x, u, dt);
  }
};

/// A measurement model whose Jacobian entry (i, j) has its sign flipped.
struct FlipFix {
  using State = CtrvState<double>;
  using Measurement = Eigen::Vector2d;
  CtrvPositionFix<double> h;
  int i, j;
  Measurement predict(const State& x) const { return h.predict(x); }
  Eigen::Matrix<double, 2, 5> jacobian(const State& x) const {
    Eigen::Matrix<double, 2, 5> J = h.jacobian(x);
    J(i, j) = -J(i, j);
    return J;
  }
  Eigen::Matrix2d noise() const { return h.noise(); }
};

struct Case {
  CtrvState<double> x;
  double dt;
};

/// The sinc series switch of detail::sinc_and_derivative, |w dt / 2| = kSincSeriesLimit.
double series_switch() { return posefuse::detail::kSincSeriesLimit<double>; }

std::vector<Case> cases() {
  std::vector<Case> out;
  std::mt19937 rng(231);
  std::normal_distribution<double> n(0.0, 5.0);
  std::uniform_real_distribution<double> a(-kPi, kPi);
  const double yaw_rates[] = {0.0, 1e-12, -1e-12, 1e-9, 0.3, -1.5, 5.0};
  for (const double dt : {0.01, 0.1, 1.0, 10.0}) {
    for (const double w : yaw_rates) {
      out.push_back({CtrvState<double>(n(rng), n(rng), a(rng), 0.5 * n(rng), w), dt});
    }
    // Just below and just above the series switch.
    const double w0 = 2.0 * series_switch() / dt;
    out.push_back({CtrvState<double>(1, 2, 0.7, 3.0, w0 * (1 - 1e-6)), dt});
    out.push_back({CtrvState<double>(1, 2, 0.7, 3.0, -w0 * (1 + 1e-6)), dt});
  }
  // Headings next to +-pi (the prediction wraps), standing still, reversing.
  out.push_back({CtrvState<double>(1, 2, kPi - 1e-3, 2.0, 0.4), 0.2});
  out.push_back({CtrvState<double>(-1, 0, -kPi + 1e-3, 2.0, -0.4), 0.2});
  out.push_back({CtrvState<double>(0, 0, 1.0, 0.0, 0.0), 0.5});
  out.push_back({CtrvState<double>(3, -4, -2.0, -1.5, 0.2), 0.5});
  return out;
}

/// The CTRV arc written the textbook way (division by w; w != 0 only).
Eigen::Vector2d textbook_position(const CtrvState<double>& x, double dt) {
  const double w = x.yaw_rate(), v = x.speed(), th = x.heading();
  return {x.x() + v / w * (std::sin(th + w * dt) - std::sin(th)),
          x.y() + v / w * (std::cos(th) - std::cos(th + w * dt))};
}

}  // namespace

TEST_CASE("Ctrv: Jacobian and noise pass the conformance harness, yaw rate 0 and 1e-12 included",
          "[models][ctrv][conformance]") {
  const Ctrv<double> m(0.5, 0.1);
  const auto cs = cases();
  for (std::size_t k = 0; k < cs.size(); ++k) {
    const auto r = pt::check_motion_model(m, cs[k].x, NoControl{}, cs[k].dt, kTol);
    INFO("case " << k << ": w = " << cs[k].x.yaw_rate() << ", dt = " << cs[k].dt << ": " << r.message);
    CHECK(r);
    // The Jacobian of the one-call form equals jacobian() bit for bit.
    CHECK((m.linearize(cs[k].x, {}, cs[k].dt).jacobian.array() ==
           m.jacobian(cs[k].x, {}, cs[k].dt).array())
              .all());
  }
}

TEST_CASE("Ctrv: flipping the sign of any non-zero Jacobian entry fails the harness",
          "[models][ctrv][conformance]") {
  const Ctrv<double> m(0.5, 0.1);
  const auto cs = cases();
  int flipped = 0;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      bool nonzero = false, detected = false;
      const FlipCtrv bad{m, i, j};
      for (const Case& c : cs) {
        nonzero = nonzero || m.jacobian(c.x, {}, c.dt)(i, j) != 0;
        detected = detected || !pt::check_motion_model(bad, c.x, NoControl{}, c.dt, kTol);
      }
      INFO("flipped entry (" << i << ", " << j << ")");
      CHECK(detected == nonzero);
      flipped += nonzero ? 1 : 0;
    }
  }
  CHECK(flipped == 5 + 7);  // the diagonal and the seven motion entries

  // At yaw rate exactly 0 alone: the yaw-rate column (series branch) is checked too.
  const CtrvState<double> x0(1, 2, 0.7, 3.0, 0.0);
  for (const int i : {0, 1}) {
    const FlipCtrv bad{m, i, 4};
    CHECK(m.jacobian(x0, {}, 0.5)(i, 4) != 0);
    CHECK_FALSE(pt::check_motion_model(bad, x0, NoControl{}, 0.5, kTol));
  }
}

TEST_CASE("Ctrv: the yaw-rate -> 0 limit is smooth: 0, 1e-12 and the series switch agree",
          "[models][ctrv]") {
  const Ctrv<double> m(0.5, 0.1);
  const double dt = 0.7;
  const CtrvState<double> x0(1, -2, 2.5, 4.0, 0.0);
  CtrvState<double> x12 = x0;
  x12.values(4) = 1e-12;
  const auto J0 = m.jacobian(x0, {}, dt);
  const auto J12 = m.jacobian(x12, {}, dt);
  CHECK(J0.allFinite());
  CHECK((J12 - J0).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(m.predict(x12, {}, dt).minus(m.predict(x0, {}, dt)).cwiseAbs().maxCoeff() < 1e-11);
  CHECK((m.noise(x12, {}, dt) - m.noise(x0, {}, dt)).cwiseAbs().maxCoeff() < 1e-12);
  // On both sides of the switch the two branches meet to round-off.
  const double w0 = 2.0 * series_switch() / dt;
  CtrvState<double> lo = x0, hi = x0;
  lo.values(4) = w0 * (1 - 1e-9);
  hi.values(4) = w0 * (1 + 1e-9);
  CHECK((m.jacobian(lo, {}, dt) - m.jacobian(hi, {}, dt)).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(m.predict(lo, {}, dt).minus(m.predict(hi, {}, dt)).cwiseAbs().maxCoeff() < 1e-9);
  // Just above the switch the chord form equals the textbook v / w form.
  CHECK((m.predict(hi, {}, dt).position() - textbook_position(hi, dt)).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("Ctrv: straight line at yaw rate 0 and a circle, against their closed forms",
          "[models][ctrv]") {
  const Ctrv<double> m(0.5, 0.1);
  SECTION("straight line: p + v t (cos th, sin th), heading and speed unchanged") {
    const double th = -2.3, v = 7.5;
    CtrvState<double> x(10, -3, th, v, 0.0);
    for (int k = 0; k < 50; ++k) x = m.predict(x, {}, 0.1);
    const double t = 5.0;
    CHECK(x.x() == Approx(10 + v * t * std::cos(th)).margin(1e-12));
    CHECK(x.y() == Approx(-3 + v * t * std::sin(th)).margin(1e-12));
    CHECK(x.heading() == th);
    CHECK(x.speed() == v);
    CHECK(x.yaw_rate() == 0.0);
  }
  SECTION("circle of radius v / w about p0 + r (-sin th0, cos th0)") {
    const double v = 3.0, w = 0.4, r = v / w, th0 = 2.9;
    const Eigen::Vector2d p0(1.0, 2.0);
    const Eigen::Vector2d centre = p0 + r * Eigen::Vector2d(-std::sin(th0), std::cos(th0));
    const CtrvState<double> start(p0.x(), p0.y(), th0, v, w);
    for (const double t : {0.05, 1.0, 2.5, 7.0, 2 * kPi / w}) {
      const Eigen::Vector2d expect =
          centre + r * Eigen::Vector2d(std::sin(th0 + w * t), -std::cos(th0 + w * t));
      // One step of length t, and 200 steps of t / 200 (CTRV composes exactly).
      const CtrvState<double> one = m.predict(start, {}, t);
      CtrvState<double> many = start;
      for (int k = 0; k < 200; ++k) many = m.predict(many, {}, t / 200);
      INFO("t = " << t);
      CHECK((one.position() - expect).cwiseAbs().maxCoeff() < 1e-12 * (1 + r));
      CHECK((many.position() - expect).cwiseAbs().maxCoeff() < 1e-11 * (1 + r));
      CHECK(std::abs(posefuse::angle_diff(one.heading(), th0 + w * t)) < 1e-13);
      CHECK(std::abs(posefuse::angle_diff(many.heading(), th0 + w * t)) < 1e-12);
      CHECK(one.heading() >= -kPi);
      CHECK(one.heading() < kPi);
      CHECK((one.position() - textbook_position(start, t)).cwiseAbs().maxCoeff() < 1e-12 * (1 + r));
    }
  }
}

TEST_CASE("Ctrv: the noise equals a quadrature of its defining integral", "[models][ctrv]") {
  const double qa = 0.7, qw = 0.2;
  const Ctrv<double> m(qa, qw);
  for (const Case& c : {Case{CtrvState<double>(0, 0, 0.4, 5.0, 0.3), 0.1},
                        Case{CtrvState<double>(3, 1, -2.8, -2.0, -1.1), 1.5},
                        Case{CtrvState<double>(0, 0, 1.0, 12.0, 0.0), 4.0}}) {
    const double dt = c.dt, v = c.x.speed();
    const double mid = c.x.heading() + c.x.yaw_rate() * dt / 2;
    const Eigen::Vector2d e(std::cos(mid), std::sin(mid)), nn(-std::sin(mid), std::cos(mid));
    // Simpson's rule (exact for these polynomials of degree <= 4 per piece
    // up to round-off; 2000 intervals).
    Eigen::Matrix<double, 5, 5> Q = Eigen::Matrix<double, 5, 5>::Zero();
    const int n = 2000;
    for (int i = 0; i <= n; ++i) {
      const double tau = dt * i / n;
      const double wgt = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
      Eigen::Matrix<double, 5, 1> ga, gw;
      ga << tau * e, 0, 1, 0;
      gw << v * tau * tau / 2 * nn, tau, 0, 1;
      Q += wgt * (qa * ga * ga.transpose() + qw * gw * gw.transpose());
    }
    Q *= dt / (3.0 * n);
    const auto Qm = m.noise(c.x, {}, dt);
    INFO("dt = " << dt);
    CHECK((Qm - Q).cwiseAbs().maxCoeff() < 1e-9 * (1 + Q.cwiseAbs().maxCoeff()));
    CHECK(Qm == Qm.transpose());
  }
  CHECK(m.noise(CtrvState<double>(1, 2, 3, 4, 5), {}, 0.0).isZero(0.0));
  // Standing still, heading 0: the (x, v) block is the constant-velocity model's.
  const posefuse::ConstantVelocity2<double> cv(qa);
  const auto Qcv = cv.noise(Eigen::Vector4d::Zero(), {}, 0.3);
  const auto Qc = m.noise(CtrvState<double>(0, 0, 0, 0, 0), {}, 0.3);
  CHECK(Qc(0, 0) == Approx(Qcv(0, 0)).epsilon(1e-14));
  CHECK(Qc(0, 3) == Approx(Qcv(0, 2)).epsilon(1e-14));
  CHECK(Qc(3, 3) == Approx(Qcv(2, 2)).epsilon(1e-14));
}

TEST_CASE("Ctrv: construction, the state's wrapping and the position fix", "[models][ctrv]") {
  CHECK_THROWS_AS(Ctrv<double>(0.0, 1.0), posefuse::invalid_argument);
  CHECK_THROWS_AS(Ctrv<double>(1.0, -1.0), posefuse::invalid_argument);
  CHECK_THROWS_AS(Ctrv<double>(std::nan(""), 1.0), posefuse::invalid_argument);
  CHECK_THROWS_AS(Ctrv<double>(1.0, std::numeric_limits<double>::infinity()), posefuse::invalid_argument);
  CHECK_THROWS_AS(CtrvPositionFix<double>(Eigen::Matrix2d::Zero()), posefuse::invalid_argument);

  const CtrvState<double> a(0, 0, 3.0 * kPi / 2, 1, 0);  // wrapped to -pi / 2
  CHECK(a.heading() == Approx(-kPi / 2));
  const CtrvState<double> b(0, 0, kPi - 0.01, 0, 0), c(0, 0, -kPi + 0.01, 0, 0);
  CHECK(c.minus(b)(2) == Approx(0.02));
  CHECK(b.plus(Eigen::Matrix<double, 5, 1>(0, 0, 0.02, 0, 0)).heading() == Approx(-kPi + 0.01));
  CHECK(pt::check_manifold(b, Eigen::Matrix<double, 5, 1>(0.1, -0.2, 0.3, 0.4, -0.5), 1e-14));

  const auto fix = CtrvPositionFix<double>::isotropic(0.3);
  std::vector<CtrvState<double>> xs{a, b, c, CtrvState<double>(4, -5, 1, 2, 3)};
  for (const auto& x : xs) {
    INFO(pt::check_measurement_model(fix, x, kTol).message);
    CHECK(pt::check_measurement_model(fix, x, kTol));
  }
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 5; ++j) {
      const FlipFix bad{fix, i, j};
      const bool nonzero = fix.jacobian(a)(i, j) != 0;
      CHECK(!pt::check_measurement_model(bad, xs.back(), kTol) == nonzero);
    }
  }
}

TEST_CASE("Ctrv: EKF and RTS on a vehicle circling through heading +-pi", "[models][ctrv][filters]") {
  const double v = 5.0, w = 0.25, dt = 0.1, sigma = 0.5;
  const Ctrv<double> model(0.05, 0.001);
  posefuse::Ekf<Ctrv<double>, CtrvPositionFix<double>> ekf(model, CtrvPositionFix<double>::isotropic(sigma));
  std::mt19937 rng(23);
  std::normal_distribution<double> n(0.0, sigma);
  CtrvState<double> truth(0, 0, 0, v, w);
  Eigen::Matrix<double, 5, 1> p0(4, 4, 1, 25, 1);
  ekf.reset(CtrvState<double>(0, 0, 0, 0, 0), Eigen::Matrix<double, 5, 5>(p0.asDiagonal()));
  std::vector<posefuse::SmootherStep<CtrvState<double>>> steps;
  std::vector<CtrvState<double>> truths;
  const auto record_prediction = [&steps](const auto& f, const Eigen::Matrix<double, 5, 5>& F) {
    posefuse::SmootherStep<CtrvState<double>> s;
    s.predicted_mean = f.state();
    s.predicted_cov = f.covariance();
    s.F = F;
    steps.push_back(s);
  };
  record_prediction(ekf, Eigen::Matrix<double, 5, 5>::Identity());
  int crossings = 0;
  for (int k = 0; k < 800; ++k) {  // 20 s per turn: four turns
    if (k > 0) {
      const double before = truth.heading();
      truth = model.predict(truth, {}, dt);
      crossings += std::abs(truth.heading() - before) > kPi ? 1 : 0;
      REQUIRE(ekf.predict(NoControl{}, dt) == posefuse::FilterStatus::kApplied);
      record_prediction(ekf, ekf.last_jacobian());
    }
    const Eigen::Vector2d z = truth.position() + Eigen::Vector2d(n(rng), n(rng));
    REQUIRE(ekf.update<0>(z).status == posefuse::FilterStatus::kApplied);
    steps.back().filtered_mean = ekf.state();
    steps.back().filtered_cov = ekf.covariance();
    truths.push_back(truth);
  }
  CHECK(crossings >= 3);
  CHECK(ekf.state().yaw_rate() == Approx(w).margin(0.01));
  CHECK(ekf.state().speed() == Approx(v).margin(0.1));
  const auto smoothed = posefuse::rts_smooth(steps);
  double filt = 0, smooth = 0, head = 0;
  for (std::size_t k = 200; k < truths.size(); ++k) {  // after convergence
    filt += (steps[k].filtered_mean.position() - truths[k].position()).squaredNorm();
    smooth += (smoothed[k].mean.position() - truths[k].position()).squaredNorm();
    head = std::max(head, std::abs(smoothed[k].mean.minus(truths[k])(2)));
  }
  CHECK(smooth < 0.8 * filt);  // the smoother uses the future too
  CHECK(std::sqrt(smooth / 600) < 0.5 * sigma);
  CHECK(head < 0.05);  // no 2 pi jumps through the wrap
}

TEST_CASE("Ctrv<float>: the harness at float tolerance, yaw rate 0 and 1e-12 included",
          "[models][ctrv][conformance]") {
  const Ctrv<float> m(0.5f, 0.1f);
  const auto fix = CtrvPositionFix<float>::isotropic(0.3f);
  for (const float dt : {0.1f, 1.0f}) {
    for (const float w : {0.0f, 1e-12f, 0.3f, -1.5f}) {
      const CtrvState<float> x(1.5f, -2.0f, 2.9f, 4.0f, w);
      const auto r = pt::check_motion_model(m, x, NoControl{}, dt, 3e-3);
      INFO("w = " << w << ", dt = " << dt << ": " << r.message);
      CHECK(r);
      CHECK(pt::check_measurement_model(fix, x, 3e-3));
    }
  }
}

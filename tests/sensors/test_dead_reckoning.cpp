// Tests for models/unicycle.hpp and sensors/dead_reckoning.hpp (seed 001 eq 10).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/sensors/dead_reckoning.hpp>

using posefuse::Integration;
using posefuse::PlanarPose;

TEMPLATE_TEST_CASE("Unicycle: one step, Euler (eq 10) and exact arc, hand-worked",
                   "[sensors][dead_reckoning]", float, double) {
  using T = TestType;
  // From the origin, ds = 1 m, dtheta = 0.5 rad.
  // Euler (eq 10): x = 0 + 1 cos 0 = 1, y = 0 + 1 sin 0 = 0, theta = 0.5.
  PlanarPose<T> e = posefuse::unicycle_step(PlanarPose<T>{}, T(1), T(0.5), Integration::kEuler);
  CHECK(e.x == Approx(1.0));
  CHECK(e.y == Approx(0.0));
  CHECK(e.theta == Approx(0.5));
  // Arc of radius ds / dtheta = 2 m: x = 2 sin 0.5 = 0.958851, y = 2 (1 - cos 0.5) = 0.244835.
  PlanarPose<T> a = posefuse::unicycle_step(PlanarPose<T>{}, T(1), T(0.5), Integration::kExactArc);
  CHECK(a.x == Approx(0.958851077208406).epsilon(1e-6));
  CHECK(a.y == Approx(0.24483487621925448).epsilon(1e-6));
  CHECK(a.theta == Approx(0.5));
  // Straight line: both agree; heading 3 rad + 0.5 wraps to 3.5 - 2 pi.
  a = posefuse::unicycle_step(PlanarPose<T>{T(1), T(2), T(3)}, T(2), T(0.5), Integration::kEuler);
  CHECK(a.x == Approx(1 + 2 * std::cos(3.0)).epsilon(1e-6));
  CHECK(a.theta == Approx(3.5 - 2 * std::numbers::pi).epsilon(1e-6));
}

TEST_CASE("Unicycle: exact arc lands on the closed-form circle, Euler drifts off it",
          "[sensors][dead_reckoning]") {
  // v = 1 m/s, w = 0.5 rad/s, dt = 0.1 s, 1000 steps (100 s, ~8 turns): the circle of radius 2 m
  // about (0, 2): x(t) = 2 sin(w t), y(t) = 2 (1 - cos(w t)).
  const double v = 1.0, w = 0.5, dt = 0.1;
  PlanarPose<double> arc, eul;
  double worst_arc = 0.0, worst_eul = 0.0;
  for (int k = 1; k <= 1000; ++k) {
    arc = posefuse::unicycle_step(arc, v * dt, w * dt, Integration::kExactArc);
    eul = posefuse::unicycle_step(eul, v * dt, w * dt, Integration::kEuler);
    const double t = k * dt;
    const double cx = 2 * std::sin(w * t), cy = 2 * (1 - std::cos(w * t));
    worst_arc = std::max(worst_arc, std::hypot(arc.x - cx, arc.y - cy));
    worst_eul = std::max(worst_eul, std::hypot(eul.x - cx, eul.y - cy));
  }
  CHECK(worst_arc < 1e-11);
  // Each Euler step is the exact chord rotated by -w dt / 2 and lengthened by 1 / sinc(w dt / 2),
  // so Euler runs on a circle whose centre is turned by 0.025 rad about the start: up to
  // 0.025 * 4 m = 0.1 m off the true circle.
  CHECK(worst_eul > 0.09);
  CHECK(worst_eul < 0.11);
  CHECK(posefuse::angle_diff(eul.theta, arc.theta) == Approx(0).margin(1e-9));
}

TEMPLATE_TEST_CASE("Unicycle: analytic Jacobians match central differences",
                   "[sensors][dead_reckoning]", float, double) {
  using T = TestType;
  const T eps = std::is_same_v<T, float> ? T(1e-2) : T(1e-6);
  const T tol = std::is_same_v<T, float> ? T(2e-3) : T(1e-8);
  const T thetas[] = {T(0), T(0.7), T(-2.9)};
  const T dss[] = {T(0), T(0.3), T(-1.2)};
  const T dths[] = {T(0), T(1e-7), T(0.005), T(0.4), T(-1.5)};
  for (const Integration method : {Integration::kEuler, Integration::kExactArc}) {
    for (const T th : thetas) {
      for (const T ds : dss) {
        for (const T dth : dths) {
          const PlanarPose<T> x{T(0.5), T(-1), th};
          Eigen::Matrix<T, 3, 3> Jx, Jxn;
          Eigen::Matrix<T, 3, 2> Ju, Jun;
          const PlanarPose<T> y = posefuse::unicycle_step(x, ds, dth, method, &Jx, &Ju);
          (void)y;
          for (int k = 0; k < 3; ++k) {
            Eigen::Matrix<T, 3, 1> d = Eigen::Matrix<T, 3, 1>::Zero();
            d(k) = eps;
            Jxn.col(k) = posefuse::unicycle_step(x.plus(d), ds, dth, method)
                             .minus(posefuse::unicycle_step(x.plus(-d), ds, dth, method)) /
                         (2 * eps);
          }
          for (int k = 0; k < 2; ++k) {
            const T a = k == 0 ? eps : T(0), b = k == 1 ? eps : T(0);
            Jun.col(k) = posefuse::unicycle_step(x, ds + a, dth + b, method)
                             .minus(posefuse::unicycle_step(x, ds - a, dth - b, method)) /
                         (2 * eps);
          }
          INFO("method " << int(method) << " theta " << th << " ds " << ds << " dtheta " << dth);
          REQUIRE((Jx - Jxn).norm() < tol);
          REQUIRE((Ju - Jun).norm() < tol);
        }
      }
    }
  }
}

TEST_CASE("Unicycle: satisfies the MotionModel concept and predicts like unicycle_step",
          "[sensors][dead_reckoning]") {
  static_assert(posefuse::MotionModel<posefuse::Unicycle<double>>);
  posefuse::Unicycle<double> m;
  m.control_cov = Eigen::Vector2d(0.01, 0.001).asDiagonal();
  const PlanarPose<double> x{1, 2, 0.3};
  const Eigen::Vector2d u(1.0, 0.5);
  const PlanarPose<double> y = m.predict(x, u, 0.1);
  const PlanarPose<double> z = posefuse::unicycle_step(x, 0.1, 0.05, Integration::kExactArc);
  CHECK(y.minus(z).norm() == 0.0);
  CHECK(posefuse::is_positive_semidefinite(m.noise(x, u, 0.1)));
  CHECK(m.jacobian(x, u, 0.1)(0, 2) != 0.0);
}

TEST_CASE("DeadReckoning: covariance stays symmetric PSD and grows as predicted",
          "[sensors][dead_reckoning]") {
  // Straight along x (theta = 0) with Sigma_u = diag(s2, q2) every step. Linear propagation gives
  //  var(theta)_n = n q2, var(x)_n = n s2, and with y_n = ds sum_j e_j (n - j + 1/2) (exact arc:
  //  J_x(1,2) = ds, J_u(1,1) = ds/2): var(y)_n = ds^2 q2 sum_{k=0}^{n-1} (k + 1/2)^2.
  const double ds = 0.05, s2 = 1e-6, q2 = 1e-5;
  const int n = 200;
  posefuse::DeadReckoning dr(Integration::kExactArc);
  posefuse::BodyMotion m;
  m.ds_m = ds;
  m.cov = Eigen::Vector2d(s2, q2).asDiagonal();
  double prev_trace = 0.0, sum = 0.0;
  for (int k = 0; k < n; ++k) {
    m.t_ns = 100'000'000 * std::int64_t(k + 1);
    const posefuse::PlanarPoseEstimate p = dr(m);
    REQUIRE(p.status == posefuse::SampleStatus::kOk);
    REQUIRE(p.t_ns == m.t_ns);
    REQUIRE(posefuse::is_positive_semidefinite(p.pose.cov));
    REQUIRE(p.pose.cov == p.pose.cov.transpose());
    REQUIRE(p.pose.cov.trace() > prev_trace);
    REQUIRE(p.pose.mean.x == dr.pose().x);
    prev_trace = p.pose.cov.trace();
    sum += (k + 0.5) * (k + 0.5);
  }
  const Eigen::Matrix3d& P = dr.covariance();
  CHECK(P(2, 2) == Approx(n * q2).epsilon(1e-12));
  CHECK(P(0, 0) == Approx(n * s2).epsilon(1e-12));
  CHECK(P(1, 1) == Approx(ds * ds * q2 * sum).epsilon(1e-12));
  CHECK(dr.pose().x == Approx(n * ds).epsilon(1e-12));

  // On a curve (Euler too) it stays symmetric PSD.
  posefuse::DeadReckoning de(Integration::kEuler);
  m.dtheta_rad = 0.03;
  m.cov << 1e-6, 2e-7, 2e-7, 1e-5;
  for (int k = 0; k < 1000; ++k) {
    const posefuse::PlanarPoseEstimate p = de(m);
    REQUIRE(posefuse::is_positive_semidefinite(p.pose.cov));
  }
}

TEST_CASE("DeadReckoning: reset re-anchors, bad inputs are reported", "[sensors][dead_reckoning]") {
  posefuse::DeadReckoning dr;
  CHECK(dr.method() == Integration::kExactArc);
  const Eigen::Matrix3d P0 = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  dr.reset(PlanarPose<double>{3, 4, 7.0}, P0);
  CHECK(dr.pose().x == 3);
  CHECK(dr.pose().theta == Approx(7.0 - 2 * std::numbers::pi));  // wrapped
  CHECK(dr.covariance() == P0);
  Eigen::Matrix3d bad = P0;
  bad(0, 1) = 1.0;  // not symmetric
  CHECK_THROWS_AS(dr.reset(PlanarPose<double>{}, bad), posefuse::invalid_argument);
  CHECK_THROWS_AS(dr.reset(PlanarPose<double>{}, -P0), posefuse::invalid_argument);
  CHECK_THROWS_AS(dr.reset(PlanarPose<double>{std::nan(""), 0, 0}, P0), posefuse::invalid_argument);
  CHECK(dr.pose().x == 3);  // untouched by the failed resets

  posefuse::BodyMotion m;
  m.ds_m = std::nan("");
  const posefuse::PlanarPoseEstimate p = dr(m);
  CHECK(p.status == posefuse::SampleStatus::kNonFinite);
  CHECK(p.pose.mean.x == 3);
  CHECK(p.pose.cov == P0);
  const posefuse::Gaussian<PlanarPose<double>> b = dr.belief();
  CHECK(b.mean.x == 3);
  CHECK(b.cov == P0);
}

// The planar models the gated fuser is built from: Se2Odometry (motion),
// PlanarPoseFix and HeadingFix (measurements), checked with the library's
// conformance harness at many states, headings near ±π included.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include <posefuse/lie/se2.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/testing/conformance.hpp>

using namespace posefuse;

namespace {

template <class T>
std::vector<PlanarPose<T>> test_states() {
  constexpr T pi = std::numbers::pi_v<T>;
  const T near = T(8) * std::numeric_limits<T>::epsilon();  // a few ulps inside ±π
  return {
      {T(0), T(0), T(0)},          {T(1.5), T(-2), T(0.7)},   {T(-3), T(4), T(-2.2)},
      {T(2), T(1), pi - near},     {T(2), T(1), -pi + near},  {T(-1), T(-1), -pi},
      {T(0.3), T(5), T(3.0)},      {T(10), T(-10), T(-3.1)},  {T(0), T(2), pi / T(2)},
  };
}

template <class T>
std::vector<SE2<T>> test_increments() {
  return {
      SE2<T>(T(0), T(0), T(0)),       // standing still
      SE2<T>(T(0.05), T(0), T(0)),    // straight ahead
      SE2<T>(T(0.3), T(-0.1), T(0.2)),
      SE2<T>(T(-0.2), T(0.4), T(-1.0)),
      SE2<T>(T(1.0), T(0.5), T(0.3)),  // carries a heading near π across it
  };
}

template <class T>
double tolerance() {
  return std::is_same_v<T, float> ? 1e-2 : 1e-7;
}

}  // namespace

TEMPLATE_TEST_CASE("Se2Odometry: passes check_motion_model at many states and increments",
                   "[models][se2_odometry][conformance]", float, double) {
  using T = TestType;
  const Se2Odometry<T> m;
  int checked = 0;
  for (const auto& x : test_states<T>()) {
    for (const auto& d : test_increments<T>()) {
      const auto r = testing::check_motion_model(m, x, d, T(0.1), tolerance<T>());
      INFO("x = (" << x.x << ", " << x.y << ", " << x.theta << "), delta = (" << d.x() << ", "
                   << d.y() << ", " << d.angle() << ")");
      INFO(r.message);
      CHECK(r);
      ++checked;
    }
  }
  CHECK(checked == 45);
}

TEST_CASE("Se2Odometry: the heading terms of F are what a turn of the state does",
          "[models][se2_odometry]") {
  // Heading theta = 0, increment 1 m straight ahead: turning the state by
  // +epsilon moves the end point to +y (F(1, 2) = +1), not to -y. A sign flip
  // of F's heading column fails here and in check_motion_model above.
  const Se2Odometry<double> m;
  const Eigen::Matrix3d F = m.jacobian({0, 0, 0}, SE2<double>(1, 0, 0), 0);
  CHECK(F(0, 2) == Approx(0).margin(1e-15));
  CHECK(F(1, 2) == Approx(1.0));
  const Eigen::Matrix3d G = m.jacobian({0, 0, std::numbers::pi / 2}, SE2<double>(1, 0, 0), 0);
  CHECK(G(0, 2) == Approx(-1.0));  // heading +y: a left turn of the state moves it to -x
  CHECK(G(1, 2) == Approx(0).margin(1e-15));
}

TEST_CASE("Se2Odometry: F is SE(2)'s right Jacobian in the R2 x S1 parametrisation",
          "[models][se2_odometry]") {
  // The file comment's relation: F = M(theta') J_c_a M(theta)^T with
  // J_c_a = Ad(delta^-1) from SE2::compose and M(theta) = diag(R(theta), 1).
  const Se2Odometry<double> m;
  const auto M = [](double th) {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    R.topLeftCorner<2, 2>() = SO2<double>(th).matrix();
    return R;
  };
  for (const auto& x : test_states<double>()) {
    for (const auto& d : test_increments<double>()) {
      SE2<double>::Jacobian J_c_a;
      const SE2<double> c = as_se2(x).compose(d, &J_c_a);
      const Eigen::Matrix3d F_lie = M(c.angle()) * J_c_a * M(x.theta).transpose();
      const Eigen::Matrix3d F = m.jacobian(x, d, 0);
      CHECK((F - F_lie).cwiseAbs().maxCoeff() < 1e-12);
    }
  }
}

TEMPLATE_TEST_CASE("Se2Odometry: increment Jacobian and noise", "[models][se2_odometry]", float,
                   double) {
  using T = TestType;
  const Se2Odometry<T> m(Se2OdometryNoise<T>{T(0.1), T(0.02), T(0.05)});
  for (const auto& x : test_states<T>()) {
    for (const auto& d : test_increments<T>()) {
      // J_delta against central differences in the increment's components.
      const auto f = [&](const Eigen::Matrix<T, 3, 1>& e) {
        return m.predict(x, SE2<T>(d.x() + e(0), d.y() + e(1), d.angle() + e(2)), T(0));
      };
      const auto r = testing::check_jacobian("J_x'_delta", f, Eigen::Matrix<T, 3, 1>::Zero().eval(),
                                             m.jacobian_increment(x, d), tolerance<T>());
      INFO(r.message);
      CHECK(r);
      const auto q = testing::check_covariance("Q", m.noise(x, d, T(0)), tolerance<T>());
      INFO(q.message);
      CHECK(q);
    }
  }
  // 0.3 m straight at heading 0: Q = diag(0.01 * 0.3, 0.01 * 0.3, 0.0004 * 0.3).
  const Eigen::Matrix<T, 3, 3> Q = m.noise({T(0), T(0), T(0)}, SE2<T>(T(0.3), T(0), T(0)), T(0));
  CHECK(Q(0, 0) == Approx(0.003).epsilon(1e-5));
  CHECK(Q(1, 1) == Approx(0.003).epsilon(1e-5));
  CHECK(Q(2, 2) == Approx(0.00012).epsilon(1e-5));
  CHECK(Q(0, 1) == Approx(0).margin(1e-9));
  // A pure turn of 0.5 rad adds heading variance 0.05^2 * 0.5 only.
  const Eigen::Matrix<T, 3, 3> Qt = m.noise({T(1), T(2), T(3)}, SE2<T>(T(0), T(0), T(0.5)), T(0));
  CHECK(Qt(2, 2) == Approx(0.00125).epsilon(1e-5));
  CHECK(Qt(0, 0) == T(0));
  CHECK_THROWS_AS(Se2Odometry<T>(Se2OdometryNoise<T>{T(-0.1), T(0), T(0)}), invalid_argument);
  CHECK_THROWS_AS(Se2Odometry<T>(Se2OdometryNoise<T>{T(0), std::numeric_limits<T>::quiet_NaN(), T(0)}),
                  invalid_argument);
}

TEST_CASE("Se2Odometry: predict is SE(2) composition, headings wrap", "[models][se2_odometry]") {
  const Se2Odometry<double> m;
  const PlanarPose<double> x{1, 2, 3.0};
  const SE2<double> d(0.5, 0.1, 0.3);  // 3.0 + 0.3 crosses +π
  const PlanarPose<double> y = m.predict(x, d, 0.1);
  const SE2<double> c = as_se2(x) * d;
  CHECK(y.x == Approx(c.x()));
  CHECK(y.y == Approx(c.y()));
  CHECK(y.theta == Approx(3.3 - 2 * std::numbers::pi));
  CHECK(y.x == Approx(1 + std::cos(3.0) * 0.5 - std::sin(3.0) * 0.1));
  // Round trip through the conversions.
  const PlanarPose<double> back = as_planar_pose(as_se2(x));
  CHECK(back.x == x.x);
  CHECK(back.y == x.y);
  CHECK(back.theta == Approx(x.theta).epsilon(1e-15));
}

TEMPLATE_TEST_CASE("PlanarPoseFix: passes check_measurement_model; residual wraps",
                   "[models][planar_pose_fix][conformance]", float, double) {
  using T = TestType;
  const auto h = PlanarPoseFix<T>::from_sigmas(T(0.05), T(0.02));
  for (const auto& x : test_states<T>()) {
    const auto r = testing::check_measurement_model(h, x, tolerance<T>());
    INFO("theta = " << x.theta << ": " << r.message);
    CHECK(r);
  }
  CHECK(h.noise()(0, 0) == Approx(0.0025));
  CHECK(h.noise()(2, 2) == Approx(0.0004));
  // 179° measured, -179° predicted: the residual is -2°, not 358°.
  const T d = std::numbers::pi_v<T> / T(180);
  const PlanarPose<T> z{T(0), T(0), T(179) * d};
  const auto res = minus(z, h.predict({T(0), T(0), T(-179) * d}));
  CHECK(res(2) == Approx(-2 * d).epsilon(1e-4));
  Eigen::Matrix<T, 3, 3> bad = Eigen::Matrix<T, 3, 3>::Identity();
  bad(2, 2) = T(-1);
  CHECK_THROWS_AS(PlanarPoseFix<T>(bad), invalid_argument);
  CHECK_THROWS_AS(PlanarPoseFix<T>::from_sigmas(T(-1), T(0.1)), invalid_argument);
}

TEMPLATE_TEST_CASE("HeadingFix: passes check_measurement_model; residual wraps",
                   "[models][heading_fix][conformance]", float, double) {
  using T = TestType;
  const HeadingFix<T> h(T(0.1));
  for (const auto& x : test_states<T>()) {
    const auto r = testing::check_measurement_model(h, x, tolerance<T>());
    INFO("theta = " << x.theta << ": " << r.message);
    CHECK(r);
  }
  CHECK(h.noise()(0, 0) == Approx(0.01));
  const T d = std::numbers::pi_v<T> / T(180);
  const auto res = minus(SO2<T>(T(-179) * d), h.predict({T(0), T(0), T(179) * d}));
  CHECK(res(0) == Approx(2 * d).epsilon(1e-4));
  CHECK_THROWS_AS(HeadingFix<T>(T(0)), invalid_argument);
  CHECK_THROWS_AS(HeadingFix<T>(std::numeric_limits<T>::infinity()), invalid_argument);
}

TEST_CASE("PlanarPose: plus and minus are consistent across ±π", "[models][planar_pose]") {
  for (const auto& x : test_states<double>()) {
    const auto r = testing::check_manifold(x, Eigen::Vector3d(0.3, -0.2, 0.5), 1e-12);
    INFO(r.message);
    CHECK(r);
  }
}

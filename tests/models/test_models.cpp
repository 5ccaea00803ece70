#include <catch2/catch.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>

using namespace posefuse;

TEST_CASE("ConstantVelocity2: Jacobian matches central differences", "[models][cv]") {
  const ConstantVelocity2<double> m(0.5);
  const Eigen::Vector4d x(1, -2, 0.3, 0.7);
  const double dt = 0.37;
  const Eigen::Matrix4d J = m.jacobian(x, NoControl{}, dt);
  Eigen::Matrix4d num;
  const double h = 1e-6;
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector4d d = Eigen::Vector4d::Zero();
    d(i) = h;
    num.col(i) = (m.predict(x + d, {}, dt) - m.predict(x - d, {}, dt)) / (2 * h);
  }
  CHECK((J - num).cwiseAbs().maxCoeff() < 1e-8);
}

TEST_CASE("ConstantVelocity2: process noise is the integrated white acceleration",
          "[models][cv]") {
  // Q(dt1 + dt2) for a still state equals F(dt2) Q(dt1) F(dt2)^T + Q(dt2).
  const ConstantVelocity2<double> m(2.0);
  const Eigen::Vector4d x = Eigen::Vector4d::Zero();
  const Eigen::Matrix4d F2 = m.jacobian(x, {}, 0.3);
  const Eigen::Matrix4d lhs = m.noise(x, {}, 0.5);
  const Eigen::Matrix4d rhs = F2 * m.noise(x, {}, 0.2) * F2.transpose() + m.noise(x, {}, 0.3);
  CHECK((lhs - rhs).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("PositionFix: Jacobian selects the position", "[models][position]") {
  const PositionFix<4> h = PositionFix<4>::isotropic(0.5);
  const Eigen::Vector4d x(1, 2, 3, 4);
  CHECK(h.predict(x) == Eigen::Vector2d(1, 2));
  CHECK(h.jacobian(x) * x == h.predict(x));
  CHECK(h.noise()(0, 0) == Approx(0.25));
  static_assert(PositionFix<2>::kIdentityJacobian);
  static_assert(!PositionFix<4>::kIdentityJacobian);
}

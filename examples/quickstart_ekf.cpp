// quickstart_ekf: track a target on the plane from noisy position fixes
// with a constant-velocity EKF, gating outliers by their NIS.
#include <posefuse/core/chi_square.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/position.hpp>
#include <cmath>
#include <cstdio>
#include <random>

int main() {
  using Motion = posefuse::ConstantVelocity2<double>;  // x = [px, py, vx, vy] (m, m/s)
  using Fix = posefuse::PositionFix<4, 2>;              // z = [px, py] (m)
  posefuse::Ekf<Motion, Fix> ekf(Motion(0.05), Fix::isotropic(0.3));
  ekf.reset(Eigen::Vector4d::Zero(), Eigen::Vector4d(1, 1, 4, 4).asDiagonal());
  const double gate = posefuse::chi_square_quantile(0.999, 2);  // NIS gate, 2 dof

  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  const double dt = 0.1;
  double sq_fix = 0, sq_ekf = 0;
  int gated = 0;
  for (int k = 1; k <= 300; ++k) {
    const double t = k * dt;
    const Eigen::Vector2d truth(2.0 * t, 3.0 * std::sin(0.2 * t));
    Eigen::Vector2d z = truth;
    z.x() += noise(rng);  // one draw a statement: the order of arguments is unspecified
    z.y() += noise(rng);
    sq_fix += (z - truth).squaredNorm();
    if (k % 50 == 0) z.x() += 5.0;  // an outlier now and then
    if (ekf.predict({}, dt) != posefuse::FilterStatus::kApplied) return 1;
    const auto r = ekf.update<0>(z, gate);  // anything but kApplied leaves the filter as it was
    if (r.status == posefuse::FilterStatus::kGated) ++gated;
    sq_ekf += (ekf.state().head<2>() - truth).squaredNorm();
  }
  std::printf("position RMSE: fixes %.3f m, EKF %.3f m; %d fixes gated\n", std::sqrt(sq_fix / 300),
              std::sqrt(sq_ekf / 300), gated);
  std::printf("velocity at t = 30 s: (%.2f, %.2f) m/s, true (2.00, %.2f)\n", ekf.state()(2), ekf.state()(3),
              0.6 * std::cos(6.0));
}

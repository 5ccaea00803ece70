// Runs seed 000's filter (x_t = x_{t-1} + u_t, z_t = x_t) on three road-plane
// positions through the installed headers; exits 0 when it returns its input.
#include <algorithm>
#include <cstdio>
#include <posefuse/posefuse.hpp>

int main() {
  using Motion = posefuse::PlanarDisplacement<double>;
  using Fix = posefuse::PositionFix<2>;
  posefuse::Ekf<Motion, Fix> ekf(Motion(Eigen::Matrix2d::Identity() * 0.01),
                                 Fix(Eigen::Matrix2d::Identity() * 0.25));
  ekf.reset(Eigen::Vector2d::Zero(), Eigen::Matrix2d::Identity());
  double worst = 0;
  Eigen::Vector2d previous = Eigen::Vector2d::Zero();
  for (int k = 1; k < 4; ++k) {
    const Eigen::Vector2d z(0.5 * k, 2.0 * k);
    if (ekf.predict(z - previous, 0.1) != posefuse::FilterStatus::kApplied) return 1;
    if (!ekf.update<0>(z)) return 1;
    worst = std::max(worst, (ekf.state() - z).norm());
    previous = z;
  }
  std::printf("consumer: largest deviation %g m\n", worst);
  return worst < 1e-12 ? 0 : 1;
}

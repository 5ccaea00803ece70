// expect: the sensor's State must be the filter's State type
// A 4-D position fix given to update_with() of a filter on a 2-D state.
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>

int main() {
  posefuse::Ekf<posefuse::PlanarDisplacement<double>> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(1, 1));
  ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity());
  const auto r = ekf.update_with(posefuse::PositionFix<4>::isotropic(1), {1.0, 2.0});
  (void)r;
}

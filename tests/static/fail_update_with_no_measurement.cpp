// expect: a measurement model must name its measurement type
// A sensor type without `using Measurement = ...;` given to update_with().
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>

struct NoMeasurementType {
  using State = Eigen::Vector2d;
};

int main() {
  posefuse::Ekf<posefuse::PlanarDisplacement<double>> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(1, 1));
  ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity());
  const auto r = ekf.update_with(NoMeasurementType{}, Eigen::Vector2d(1, 2));
  (void)r;
}

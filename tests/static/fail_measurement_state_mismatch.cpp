// expect: every measurement model must have the motion model's State type
// A 4-D position fix on a 2-D state does not fit the filter.
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>

int main() {
  posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<4>> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(1, 1), posefuse::PositionFix<4>::isotropic(1));
  (void)ekf;
}

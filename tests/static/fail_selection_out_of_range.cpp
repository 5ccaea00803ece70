// expect: kSelection must list Measurement::Dim distinct state indices
// A measurement model that declares a selection Jacobian naming a state
// component the state does not have (index 2 of a 2-D state).
#include <array>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>

struct BadSelection {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Matrix<double, 1, 1>;
  static constexpr std::array<int, 1> kSelection = {2};
  Measurement predict(const State& x) const { return Measurement(x(1)); }
  Eigen::Matrix<double, 1, 2> jacobian(const State&) const { return {0.0, 1.0}; }
  Eigen::Matrix<double, 1, 1> noise() const { return Eigen::Matrix<double, 1, 1>(1.0); }
};

int main() {
  posefuse::Ekf<posefuse::PlanarDisplacement<double>, BadSelection> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(1, 1), BadSelection{});
  (void)ekf;
}

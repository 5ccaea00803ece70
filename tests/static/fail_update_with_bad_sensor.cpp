// expect: a measurement model needs .Matrix<Scalar, Measurement::Dim, State::Dim> jacobian
// A sensor built per measurement and passed to Ekf::update_with() that has no
// jacobian(): the compiler must say so in posefuse's words, not "no matching
// function for call to update_with".
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/planar_displacement.hpp>

struct RangeWithoutJacobian {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Matrix<double, 1, 1>;
  Measurement predict(const State& x) const { return Measurement(x.norm()); }
  Eigen::Matrix<double, 1, 1> noise() const { return Eigen::Matrix<double, 1, 1>(0.01); }
};

int main() {
  posefuse::Ekf<posefuse::PlanarDisplacement<double>> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(1, 1));
  ekf.reset(Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity());
  const auto r = ekf.update_with(RangeWithoutJacobian{}, Eigen::Matrix<double, 1, 1>(1.0));
  (void)r;
}

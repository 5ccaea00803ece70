// expect: posefuse: a motion model needs `Matrix<Scalar, Dim, Dim> noise
// An EKF over a motion model that forgets its process noise: the compiler
// must say which requirement is missing, in one sentence.
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/position.hpp>

struct NoNoise {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  State predict(const State& x, const Control& u, double) const { return x + u; }
  Eigen::Matrix2d jacobian(const State&, const Control&, double) const {
    return Eigen::Matrix2d::Identity();
  }
};

int main() {
  posefuse::Ekf<NoNoise, posefuse::PositionFix<2>> ekf(NoNoise{}, posefuse::PositionFix<2>::isotropic(1));
  (void)ekf;
}

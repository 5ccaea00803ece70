// Runs seed 000's corrector on three poses; exits 0 when it returns its input.
#include <cstdio>
#include <posefuse/posefuse.hpp>

int main() {
  auto corrector = posefuse::make_seed000_corrector(
      posefuse::Plane::kXZ, Eigen::Matrix2d::Identity() * 0.01, Eigen::Matrix2d::Identity() * 0.25,
      Eigen::Matrix2d::Identity());
  double worst = 0;
  for (int k = 0; k < 3; ++k) {
    posefuse::StampedPose in;
    in.t = 0.1 * k;
    in.T_world_body.translation() << 0.5 * k, 0.0, 2.0 * k;
    const auto out = corrector(in);
    worst = std::max(worst, (out.p - Eigen::Vector2d(0.5 * k, 2.0 * k)).norm());
  }
  std::printf("consumer: largest deviation %g m\n", worst);
  return worst < 1e-12 ? 0 : 1;
}

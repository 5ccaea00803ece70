// expect: align_visual_inertial needs at least 4 keyframes
// Three keyframes give the visual-inertial alignment 12 equations for 13
// unknowns; the template refuses them at compile time.
#include <array>
#include <posefuse/inertial/alignment.hpp>

int main() {
  std::array<posefuse::SE3d, 3> poses{};
  std::array<posefuse::Preintegration, 2> pre{};
  const auto r = posefuse::align_visual_inertial<3>(poses, posefuse::SE3d{}, std::span<posefuse::Preintegration, 2>(pre));
  (void)r;
}

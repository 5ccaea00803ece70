// expect: StageMismatch<posefuse::DisplacementControl, posefuse::ProjectToPlane
// Seed 000's stages in the wrong order: DisplacementControl produces a
// CorrectorStep, ProjectToPlane wants a StampedPose. The message names both.
#include <apps/trajectory_correction.hpp>

int main() {
  auto p = posefuse::make_pipeline(posefuse::DisplacementControl{}, posefuse::ProjectToPlane{});
  (void)p;
}

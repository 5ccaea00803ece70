// expect: StageMismatch<posefuse::FourWheelAverage, posefuse::DeadReckoning
//
// Must FAIL to compile: the four-wheel averaging stage (eq 8) produces
// StampedSideTicks, but dead reckoning (eq 10) consumes BodyMotion; the
// diff-drive stage (eq 9) that turns one into the other is missing. The
// compiler names both stages through posefuse::detail::StageMismatch.
#include <posefuse/sensors/pipelines.hpp>

int main() {
  auto broken = posefuse::make_pipeline(posefuse::FourWheelAverage{}, posefuse::DeadReckoning{});
  (void)broken;
  return 0;
}

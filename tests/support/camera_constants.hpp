#pragma once
// The pinhole focal length and the degree that the two-view and SfM tests
// share (one definition, so that their files can be compiled together).
#include <numbers>

namespace posefuse_test {
inline constexpr double kFocal = 460.0;                     // px
inline constexpr double kDeg = std::numbers::pi / 180.0;    // rad
}  // namespace posefuse_test

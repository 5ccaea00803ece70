// Every io/ header in one translation unit: their detail helpers must not
// collide (each header also compiles on its own; see the other test files).
#include <catch2/catch.hpp>

#include <posefuse/io/association.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/kitti.hpp>
#include <posefuse/core/plane.hpp>
#include <posefuse/io/read_options.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/tum.hpp>

TEST_CASE("Io headers: all io headers compile together", "[io]") {
  CHECK(posefuse::to_string(posefuse::Format::kKitti) == "kitti");
  CHECK(posefuse::to_string(posefuse::Plane::kXZ) == "xz");
}

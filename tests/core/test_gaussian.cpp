#include <catch2/catch.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/models/planar_pose.hpp>

using namespace posefuse;

TEST_CASE("Gaussian: covariance checks", "[core][gaussian]") {
  Eigen::Matrix2d spd;
  spd << 2, 1, 1, 2;
  Eigen::Matrix2d indefinite;
  indefinite << 1, 2, 2, 1;
  Eigen::Matrix2d asym;
  asym << 1, 0.5, 0, 1;
  CHECK(is_positive_definite(spd));
  CHECK(is_positive_semidefinite(Eigen::Matrix2d::Zero()));
  CHECK_FALSE(is_positive_definite(Eigen::Matrix2d::Zero()));
  CHECK_FALSE(is_positive_semidefinite(indefinite));
  CHECK_FALSE(is_symmetric(asym));
  CHECK_NOTHROW(Gaussian<Eigen::Vector2d>(Eigen::Vector2d::Zero(), spd));
  CHECK_THROWS_AS(Gaussian<Eigen::Vector2d>(Eigen::Vector2d::Zero(), indefinite),
                  posefuse::invalid_argument);
  CHECK_THROWS_AS(Gaussian<Eigen::Vector2d>(Eigen::Vector2d::Zero(), asym),
                  posefuse::invalid_argument);
  Eigen::Matrix2d with_nan = spd;
  with_nan(0, 0) = std::nan("");
  CHECK_THROWS_WITH(Gaussian<Eigen::Vector2d>(Eigen::Vector2d::Zero(), with_nan),
                    Catch::Contains("NaN"));
}

TEMPLATE_TEST_CASE("State conformance: PlanarPose plus/minus round trip and wrap", "[core][state]",
                   float, double) {
  using T = TestType;
  using P = PlanarPose<T>;
  const P a{T(1), T(2), T(3.1)};
  const P b{T(-1), T(0.5), T(-3.1)};
  const P c = a.plus(b.minus(a));
  CHECK(c.x == Approx(b.x));
  CHECK(c.y == Approx(b.y));
  CHECK(c.theta == Approx(b.theta));
  // 3.1 -> -3.1 is a short step across pi, not a long way round.
  CHECK(std::abs(b.minus(a)(2)) < T(0.1));
}

#include <catch2/catch.hpp>
#include <Eigen/QR>
#include <cmath>
#include <random>
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

TEST_CASE("Gaussian: indefinite and singular matrices are refused whatever their scale",
          "[core][gaussian]") {
  // Eigenvalues +-1e20: a tolerance relative to max|m_ij| used to accept it.
  Eigen::Matrix2d huge_indefinite;
  huge_indefinite << -1, 1e20, 1e20, 0;
  CHECK_FALSE(is_positive_semidefinite(huge_indefinite));
  CHECK_THROWS_AS(Gaussian<Eigen::Vector2d>(Eigen::Vector2d::Zero(), huge_indefinite),
                  posefuse::invalid_argument);
  // A negative variance next to a huge one.
  Eigen::Matrix2d negative_next_to_huge;
  negative_next_to_huge << -679.7, 0, 0, 7e156;
  CHECK_FALSE(is_positive_semidefinite(negative_next_to_huge));
  // Singular [[a, a], [a, a]] is PSD but not PD, even where Cholesky's
  // round-off would succeed.
  const double a = 42.47;
  Eigen::Matrix2d singular;
  singular << a, a, a, a;
  CHECK(is_positive_semidefinite(singular));
  CHECK_FALSE(is_positive_definite(singular));
  // A zero variance with a non-zero covariance cannot be PSD.
  Eigen::Matrix2d zero_var;
  zero_var << 0, 1e-3, 1e-3, 1;
  CHECK_FALSE(is_positive_semidefinite(zero_var));
  // Very different but valid scales stay accepted.
  Eigen::Matrix3d scaled = Eigen::Vector3d(1e-12, 1.0, 1e12).asDiagonal();
  scaled(0, 1) = scaled(1, 0) = 0.5e-6;  // correlation 0.5
  CHECK(is_positive_definite(scaled));
  // Correlation just above 1 is indefinite; just below is fine.
  Eigen::Matrix2d rho;
  rho << 4, 2 * 3 * (1 + 1e-9), 2 * 3 * (1 + 1e-9), 9;
  CHECK_FALSE(is_positive_semidefinite(rho));
  rho(0, 1) = rho(1, 0) = 2 * 3 * (1 - 1e-9);
  CHECK(is_positive_definite(rho));
}

TEST_CASE("Gaussian: PSD check against the smallest eigenvalue on random matrices",
          "[core][gaussian]") {
  // Random symmetric 4x4 matrices with a prescribed smallest eigenvalue:
  // clearly negative ones are refused, non-negative ones accepted.
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int k = 0; k < 300; ++k) {
    Eigen::Matrix4d A;
    for (int i = 0; i < 16; ++i) A(i / 4, i % 4) = n01(rng);
    const Eigen::HouseholderQR<Eigen::Matrix4d> qr(A);
    const Eigen::Matrix4d Q = qr.householderQ();
    Eigen::Vector4d lambda(std::exp(3 * n01(rng)), std::exp(3 * n01(rng)), std::exp(3 * n01(rng)), 0);
    const bool negative = k % 2 == 0;
    lambda(3) = negative ? -1e-6 * lambda.head<3>().maxCoeff() : 1e-3 * lambda.head<3>().minCoeff();
    Eigen::Matrix4d M = Q * lambda.asDiagonal() * Q.transpose();
    M = 0.5 * (M + M.transpose()).eval();
    INFO("draw " << k << ", lambda_min " << lambda(3));
    CHECK(is_positive_semidefinite(M) == !negative);
  }
}

// NEES against chi-square bounds: a consistent synthetic estimator (errors
// drawn from the covariance it reports) averages near its dimension and
// within the bounds; an overconfident one does not; an alignment moves the
// covariance with the estimate. Also the covariance-carrying TUM reader.
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include <posefuse/eval/consistency.hpp>
#include <posefuse/io/tum.hpp>
#include <posefuse/lie/so3.hpp>

#include "support/synthetic_trajectory.hpp"
#include "support/temp_dir.hpp"

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

Mat6 random_covariance(std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Mat6 A;
  for (int i = 0; i < 36; ++i) A(i / 6, i % 6) = n01(rng);
  Mat6 C = A * A.transpose() / 6.0 + 0.2 * Mat6::Identity();
  C.topLeftCorner<3, 3>() *= 0.04;     // position: about 0.2 m
  C.topRightCorner<3, 3>() *= 0.002;   // weakly correlated
  C.bottomLeftCorner<3, 3>() *= 0.002;
  C.bottomRightCorner<3, 3>() *= 1e-4; // rotation: about 0.01 rad
  return C;
}

// An estimate whose errors are drawn from the covariances it reports:
// p_ref = p + dp, R_ref = R Exp(dtheta) (see TumWithCovariance).
struct Noisy {
  posefuse::Trajectory est;
  std::vector<Mat6> covariance;
};

Noisy draw(const posefuse::Trajectory& ref, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Noisy out;
  out.est = ref;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Mat6 C = random_covariance(rng);
    Eigen::Matrix<double, 6, 1> z;
    for (int i = 0; i < 6; ++i) z(i) = n01(rng);
    const Eigen::Matrix<double, 6, 1> e = Eigen::LLT<Mat6>(C).matrixL() * z;
    out.est.poses[k].translation() = ref.poses[k].translation() - e.head<3>();
    const Eigen::Matrix3d dR = posefuse::SO3<double>::exp(e.tail<3>()).matrix();
    out.est.poses[k].linear() = ref.poses[k].linear() * dR.transpose();
    out.covariance.push_back(C);
  }
  return out;
}

}  // namespace

TEST_CASE("Consistency: a consistent estimator's NEES averages its dimension", "[eval][nees]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(2000, 61, 0.0);
  const Noisy noisy = draw(ref, 62);
  for (const int dim : {3, 6}) {
    const posefuse::NeesResult r = posefuse::nees(ref, noisy.est, noisy.covariance, dim);
    INFO("dim " << dim << " mean " << r.mean << " bounds " << r.lower << " " << r.upper);
    CHECK(r.mean == Approx(dim).epsilon(0.05));
    CHECK(r.consistent());
    CHECK(r.lower < dim);
    CHECK(r.upper > dim);
    // Reported covariances four times too small: NEES about four times too large.
    std::vector<Mat6> small = noisy.covariance;
    for (Mat6& C : small) C /= 4.0;
    const posefuse::NeesResult over = posefuse::nees(ref, noisy.est, small, dim);
    CHECK(over.mean == Approx(4.0 * r.mean).epsilon(1e-9));
    CHECK_FALSE(over.consistent());
    CHECK(over.mean > over.upper);
  }
}

TEST_CASE("Consistency: an alignment moves the covariance with the estimate", "[eval][nees]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(300, 63, 0.0);
  const Noisy noisy = draw(ref, 64);
  const posefuse::NeesResult direct = posefuse::nees(ref, noisy.est, noisy.covariance, 6);
  // Express the estimate in another world frame: x' = (R^T (x - t)) / c,
  // so that the similarity (c, R, t) maps it back exactly.
  posefuse::AlignmentResult a;
  a.rotation = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  a.translation = Eigen::Vector3d(4, -5, 6);
  a.scale = 2.0;
  posefuse::Trajectory moved = noisy.est;
  std::vector<Mat6> moved_cov = noisy.covariance;
  for (std::size_t k = 0; k < moved.size(); ++k) {
    moved.poses[k].translation() = a.rotation.transpose() * (noisy.est.poses[k].translation() - a.translation) / a.scale;
    moved.poses[k].linear() = a.rotation.transpose() * noisy.est.poses[k].linear();
    Mat6& C = moved_cov[k];
    C.topLeftCorner<3, 3>() = a.rotation.transpose() * C.topLeftCorner<3, 3>() * a.rotation / (a.scale * a.scale);
    C.topRightCorner<3, 3>() = a.rotation.transpose() * C.topRightCorner<3, 3>() / a.scale;
    C.bottomLeftCorner<3, 3>() = C.topRightCorner<3, 3>().transpose();
  }
  const posefuse::NeesResult aligned = posefuse::nees(ref, moved, moved_cov, 6, a);
  for (std::size_t k = 0; k < ref.size(); ++k) CHECK(aligned.nees[k] == Approx(direct.nees[k]).epsilon(1e-8));
  // Without the alignment the same numbers are far off.
  CHECK(posefuse::nees(ref, moved, moved_cov, 6).mean > 100.0 * direct.mean);
}

TEST_CASE("Consistency: chi-square bounds beyond 1000 degrees of freedom", "[eval][nees]") {
  // Wilson-Hilferty takes over above 1000 dof: continuous there and close to
  // the exact quantile at 1000.
  for (const double p : {0.025, 0.5, 0.975}) {
    const double exact = posefuse::chi_square_quantile(p, 1000);
    const double wh = posefuse::chi_square_quantile_any(p, 1001) * 1000.0 / 1001.0;
    CHECK(wh == Approx(exact).epsilon(2e-4));
  }
  CHECK(posefuse::chi_square_quantile_any(0.5, 6000000) == Approx(6000000 - 2.0 / 3.0).epsilon(1e-9));
  CHECK_THROWS_AS(posefuse::chi_square_quantile_any(1.0, 10), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::nees({}, {}, {}, 3), posefuse::invalid_argument);
}

TEST_CASE("Consistency: TUM files with covariance columns", "[eval][nees][io]") {
  posefuse::test::TempDir dir("tum-cov");
  const auto three = dir.write("p.tum",
                               "# t x y z qx qy qz qw xx xy xz yy yz zz\n"
                               "1 0 0 0 0 0 0 1 4 1 0 9 0 16\n"
                               "2 1 0 0 0 0 0 1 1 0 0 1 0 1\n");
  const posefuse::TumWithCovariance t3 = posefuse::read_tum_with_covariance(three);
  REQUIRE(t3.covariance_dim == 3);
  REQUIRE(t3.covariance.size() == 2);
  CHECK(t3.covariance[0](0, 0) == 4.0);
  CHECK(t3.covariance[0](1, 0) == 1.0);
  CHECK(t3.covariance[0](0, 1) == 1.0);
  CHECK(t3.covariance[0](2, 2) == 16.0);
  CHECK(t3.covariance[0](3, 3) == 0.0);
  std::string row = "1 0 0 0 0 0 0 1";
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) row += i == j ? " 2" : " 0.5";
  const auto six = dir.write("q.tum", row + "\n");
  const posefuse::TumWithCovariance t6 = posefuse::read_tum_with_covariance(six);
  REQUIRE(t6.covariance_dim == 6);
  CHECK(t6.covariance[0](5, 4) == 0.5);
  CHECK(t6.covariance[0](5, 5) == 2.0);
  // Plain TUM files read with no covariance; read_tum refuses the extra columns.
  CHECK(posefuse::read_tum_with_covariance(dir.write("r.tum", "1 0 0 0 0 0 0 1\n")).covariance_dim == 0);
  CHECK_THROWS_WITH(posefuse::read_tum(three), Catch::Contains("p.tum:2: expected 8"));
  // Not positive definite, or a line of another width: file:line.
  CHECK_THROWS_WITH(posefuse::read_tum_with_covariance(dir.write("s.tum", "1 0 0 0 0 0 0 1 1 2 0 1 0 1\n")),
                    Catch::Contains("s.tum:1: covariance is not positive definite"));
  CHECK_THROWS_WITH(posefuse::read_tum_with_covariance(dir.write("m.tum", "1 0 0 0 0 0 0 1 1 0 0 1 0 1\n2 0 0 0 0 0 0 1\n")),
                    Catch::Contains("m.tum:2: expected 14"));
}

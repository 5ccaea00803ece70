// Schur-complement marginalisation: the dense Gaussian marginal, PSD on
// near-singular inputs, residual form, and refused inputs.

#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <posefuse/graph/marginalization.hpp>

using namespace posefuse;

namespace {

Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::MatrixXd A(rows, cols);
  for (Eigen::Index c = 0; c < cols; ++c)
    for (Eigen::Index r = 0; r < rows; ++r) A(r, c) = n01(rng);
  return A;
}

}  // namespace

TEST_CASE("marginalize: equals the dense marginal of a Gaussian", "[graph][marginalization]") {
  std::mt19937 rng(5);
  const Eigen::MatrixXd A = random_matrix(40, 12, rng);
  const Eigen::MatrixXd H = A.transpose() * A;  // information, SPD
  const Eigen::VectorXd b = random_matrix(12, 1, rng);
  const std::vector<int> remove = {0, 3, 4, 11};
  const MarginalizationPrior p = marginalize(H, b, remove);
  REQUIRE(p.kept == std::vector<int>({1, 2, 5, 6, 7, 8, 9, 10}));
  CHECK(p.clamped == 0);
  // Marginal covariance: (H^-1) restricted to the kept variables.
  const Eigen::MatrixXd P = H.inverse();
  Eigen::MatrixXd Pr(8, 8);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) Pr(r, c) = P(p.kept[std::size_t(r)], p.kept[std::size_t(c)]);
  const Eigen::MatrixXd Hp = p.information();
  CHECK((Hp.inverse() - Pr).cwiseAbs().maxCoeff() < 1e-9 * Pr.cwiseAbs().maxCoeff());
  // The minimiser of the prior is the full minimiser's kept part: delta = -H^-1 b.
  const Eigen::VectorXd full = -H.ldlt().solve(b);
  const Eigen::VectorXd kept = -Hp.ldlt().solve(p.gradient());
  for (int r = 0; r < 8; ++r) CHECK(kept(r) == Approx(full(p.kept[std::size_t(r)])).margin(1e-9));
  // Residual form: |r0 + J d|^2 - |r0|^2 = 2 b*^T d + d^T H* d.
  const Eigen::VectorXd d = random_matrix(8, 1, rng);
  const double lhs = p.residual(d).squaredNorm() - p.r0.squaredNorm();
  const double rhs = 2.0 * p.gradient().dot(d) + d.dot(Hp * d);
  CHECK(lhs == Approx(rhs).epsilon(1e-9));
}

TEST_CASE("marginalize: the prior stays PSD on near-singular inputs", "[graph][marginalization]") {
  std::mt19937 rng(8);
  for (int trial = 0; trial < 20; ++trial) {
    // Rank-deficient information (a gauge freedom), scaled over many orders,
    // plus round-off-sized indefinite noise, which can make a plain Schur
    // complement indefinite.
    const Eigen::MatrixXd A = random_matrix(6, 14, rng);
    Eigen::VectorXd s(14);
    for (int k = 0; k < 14; ++k) s(k) = std::pow(10.0, (k % 7) - 2);
    Eigen::MatrixXd H = s.asDiagonal() * (A.transpose() * A) * s.asDiagonal();
    const Eigen::MatrixXd N = random_matrix(14, 14, rng);
    H += 1e-9 * (N + N.transpose());
    const Eigen::VectorXd b = random_matrix(14, 1, rng);
    const MarginalizationPrior p = marginalize(H, b, {0, 1, 2, 3, 4});
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(p.information());
    INFO("trial " << trial << " min eigenvalue " << es.eigenvalues().minCoeff() << " clamped " << p.clamped);
    CHECK(es.eigenvalues().minCoeff() >= -1e-9 * es.eigenvalues().maxCoeff());
    CHECK(p.clamped > 0);  // rank 6 < 9 kept variables
    CHECK(p.J.rows() + p.clamped == 9);
    CHECK(p.J.allFinite());
    CHECK(p.r0.allFinite());
  }
}

TEST_CASE("marginalize: bad inputs are refused", "[graph][marginalization]") {
  const Eigen::MatrixXd H = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd b = Eigen::VectorXd::Zero(3);
  CHECK_THROWS_WITH(marginalize(H, Eigen::VectorXd::Zero(2), {0}), Catch::Contains("same size"));
  CHECK_THROWS_WITH(marginalize(H, b, {3}), Catch::Contains("out of range"));
  CHECK_THROWS_WITH(marginalize(H, b, {1, 1}), Catch::Contains("repeated"));
  CHECK_THROWS_WITH(marginalize(H, b, {0, 1, 2}), Catch::Contains("no variable"));
  Eigen::MatrixXd asym = H;
  asym(0, 1) = 0.5;
  CHECK_THROWS_WITH(marginalize(asym, b, {0}), Catch::Contains("not symmetric"));
  Eigen::MatrixXd nan = H;
  nan(2, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(marginalize(nan, b, {0}), Catch::Contains("not finite"));
}

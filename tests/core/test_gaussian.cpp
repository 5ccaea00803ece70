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

namespace {
// Random symmetric N x N matrix Q diag(lambda) Q^T, then scaled by a random
// diagonal (so variances differ by many orders of magnitude), symmetrised.
template <class T, int N, class Rng>
Eigen::Matrix<T, N, N> random_with_spectrum(Rng& rng, const Eigen::Matrix<double, N, 1>& lambda,
                                            double log10_scale_spread) {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u(-log10_scale_spread, log10_scale_spread);
  Eigen::Matrix<double, N, N> A;
  for (int i = 0; i < N * N; ++i) A(i / N, i % N) = n01(rng);
  const Eigen::HouseholderQR<Eigen::Matrix<double, N, N>> qr(A);
  const Eigen::Matrix<double, N, N> Q = qr.householderQ();
  Eigen::Matrix<double, N, 1> s;
  for (int i = 0; i < N; ++i) s(i) = std::pow(10.0, u(rng));
  Eigen::Matrix<double, N, N> M = s.asDiagonal() * Q * lambda.asDiagonal() * Q.transpose() *
                                  s.asDiagonal();
  const Eigen::Matrix<T, N, N> Mt = M.template cast<T>();
  return T(0.5) * (Mt + Mt.transpose());
}

struct FastPathCounts {
  int fast = 0, total = 0, pd_reference = 0;
};

// The fast path may only accept what the reference accepts as positive
// definite; the public functions must equal the reference on every input.
template <class T, int N>
void check_fast_path_agrees(const Eigen::Matrix<T, N, N>& M, FastPathCounts& c) {
  const bool fast = detail::psd_fast_accepts(M);
  const bool ref_psd = detail::psd_reference(M, false);
  const bool ref_pd = detail::psd_reference(M, true);
  INFO("N = " << N << "\n" << M);
  if (fast) CHECK(ref_pd);
  CHECK(is_positive_semidefinite(M) == ref_psd);
  CHECK(is_positive_definite(M) == ref_pd);
  c.fast += fast;
  c.pd_reference += ref_pd;
  ++c.total;
}

template <class T, int N>
FastPathCounts fast_path_property(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  std::uniform_int_distribution<int> kind(0, 5);
  const double eps = double(std::numeric_limits<T>::epsilon());
  FastPathCounts c;
  for (int draw = 0; draw < 400; ++draw) {
    Eigen::Matrix<double, N, 1> lambda;
    for (int i = 0; i < N; ++i) lambda(i) = std::exp(2 * n01(rng));
    const double top = lambda.maxCoeff();
    switch (kind(rng)) {
      case 0: break;                                            // PSD, well conditioned
      case 1: lambda(0) = -top * std::exp(2 * n01(rng)); break;  // clearly indefinite
      case 2: lambda(0) = -top * eps * std::exp(3 * n01(rng)); break;  // barely indefinite
      case 3: lambda(0) = top * eps * std::exp(3 * n01(rng)); break;   // barely definite
      case 4: lambda(0) = 0; break;                                   // singular
      case 5: lambda(0) = top * std::pow(10.0, -12 * std::abs(n01(rng))); break;  // ill-conditioned
    }
    const double spread = draw % 3 == 0 ? 0.0 : draw % 3 == 1 ? 3.0 : 30.0;
    check_fast_path_agrees<T, N>(random_with_spectrum<T, N>(rng, lambda, spread), c);
  }
  // Structured cases: [[a, a], [a, a]]-like blocks, a zero row, a negative
  // variance, huge and tiny scales, a non-finite entry, an asymmetric ulp.
  Eigen::Matrix<T, N, N> M = Eigen::Matrix<T, N, N>::Constant(T(42.47));
  check_fast_path_agrees<T, N>(M, c);
  M = Eigen::Matrix<T, N, N>::Identity();
  M(0, 0) = T(0);
  check_fast_path_agrees<T, N>(M, c);
  M(0, 0) = T(-1e-30);
  check_fast_path_agrees<T, N>(M, c);
  for (T scale : {T(1e-30), T(1e30), std::numeric_limits<T>::min(), std::numeric_limits<T>::max()}) {
    M = Eigen::Matrix<T, N, N>::Identity() * scale;
    check_fast_path_agrees<T, N>(M, c);
    if constexpr (N > 1) {
      M(1, 0) = M(0, 1) = scale;  // singular
      check_fast_path_agrees<T, N>(M, c);
      M(1, 0) = M(0, 1) = scale * T(1.5);  // indefinite
      check_fast_path_agrees<T, N>(M, c);
    }
  }
  M = Eigen::Matrix<T, N, N>::Identity();
  M(N - 1, 0) = M(0, N - 1) = std::numeric_limits<T>::infinity();
  check_fast_path_agrees<T, N>(M, c);
  M(N - 1, 0) = M(0, N - 1) = std::numeric_limits<T>::quiet_NaN();
  check_fast_path_agrees<T, N>(M, c);
  if constexpr (N > 1) {
    M = Eigen::Matrix<T, N, N>::Identity();
    M(1, 0) = T(0.5);
    M(0, 1) = std::nextafter(T(0.5), T(1));
    check_fast_path_agrees<T, N>(M, c);
  }
  return c;
}

template <class T>
void fast_path_all_sizes() {
  const FastPathCounts c[] = {fast_path_property<T, 1>(11), fast_path_property<T, 2>(12),
                              fast_path_property<T, 3>(13), fast_path_property<T, 4>(14),
                              fast_path_property<T, 5>(15), fast_path_property<T, 6>(16)};
  for (int n = 1; n <= 6; ++n) {
    INFO("size " << n << ": fast path took " << c[n - 1].fast << " of " << c[n - 1].pd_reference
                 << " positive definite matrices (" << c[n - 1].total << " in all)");
    CHECK(c[n - 1].fast <= c[n - 1].pd_reference);
    // The fast path must actually take the common, well-conditioned case
    // (except float at sizes where its margin exceeds 1).
    if (detail::psd_fast_min_pivot<T>(n) < T(1e-2)) CHECK(c[n - 1].fast > c[n - 1].pd_reference / 4);
  }
}
}  // namespace

TEST_CASE("Gaussian: the PSD fast path never accepts what the reference refuses",
          "[core][gaussian]") {
  fast_path_all_sizes<double>();
  fast_path_all_sizes<float>();
}

TEST_CASE("Gaussian: the fast path takes the covariances an Ekf produces", "[core][gaussian]") {
  Eigen::Matrix3d P;
  P << 0.04, 0.01, 0.002, 0.01, 0.02, -0.001, 0.002, -0.001, 0.001;
  CHECK(detail::psd_fast_accepts(P));
  CHECK(detail::psd_fast_accepts(Eigen::Matrix2d::Identity()));
  CHECK(detail::psd_fast_accepts(Eigen::Matrix4d::Identity()));
  // Singular and indefinite matrices are left to the reference.
  Eigen::Matrix2d singular;
  singular << 42.47, 42.47, 42.47, 42.47;
  CHECK_FALSE(detail::psd_fast_accepts(singular));
  Eigen::Matrix2d indefinite;
  indefinite << 1, 2, 2, 1;
  CHECK_FALSE(detail::psd_fast_accepts(indefinite));
  CHECK_FALSE(detail::psd_fast_accepts(Eigen::MatrixXd(Eigen::MatrixXd::Identity(3, 3))));
}

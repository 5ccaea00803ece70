// rts_smooth (filters/rts_smoother.hpp) on linear-Gaussian models against
// the closed-form posterior computed independently: the whole trajectory
// x_0..x_{N-1} as one Gaussian in information form,
//   Lambda = blkdiag(P0^-1, 0, ...) + sum_k A_k^T Q_k^-1 A_k + sum_k H^T R^-1 H
//   eta    = P0^-1 m0 + sum_k A_k^T Q_k^-1 b_k + sum_k H^T R^-1 z_k
// (A_k selects x_{k+1} - F_k x_k, b_k the control's contribution), assembled
// densely and solved with Eigen's LLT. Its mean is the batch least-squares
// answer and its covariance's diagonal blocks are the marginals; the RTS
// smoother must reproduce both to 1e-9, at every step.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>
#include <limits>
#include <random>
#include <vector>

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// One linear-Gaussian problem: x_{k+1} = F_k x_k + B u_k + w, z_k = H x_k + v.
template <int N, int M>
struct Problem {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  Vec m0;
  Mat P0;
  std::vector<Mat> F, Q;      // F[k], Q[k]: the transition into step k (k >= 1)
  std::vector<Vec> b;         // b[k] = B u_k, the control's contribution into step k
  Eigen::Matrix<double, M, N> H;
  Eigen::Matrix<double, M, M> R;
  std::vector<Eigen::Matrix<double, M, 1>> z;
};

/// The closed-form posterior of all states: means and marginal covariances.
template <int N, int M>
void information_form(const Problem<N, M>& p, std::vector<VectorXd>& mean, std::vector<MatrixXd>& cov) {
  const int K = int(p.z.size());
  MatrixXd L = MatrixXd::Zero(N * K, N * K);
  VectorXd eta = VectorXd::Zero(N * K);
  const MatrixXd P0i = p.P0.inverse();
  L.block(0, 0, N, N) += P0i;
  eta.segment(0, N) += P0i * p.m0;
  const MatrixXd Ri = p.R.inverse();
  for (int k = 0; k < K; ++k) {
    L.block(N * k, N * k, N, N) += p.H.transpose() * Ri * p.H;
    eta.segment(N * k, N) += p.H.transpose() * Ri * p.z[std::size_t(k)];
  }
  for (int k = 1; k < K; ++k) {
    // residual x_k - F x_{k-1} - b_k: A = [-F, I] on (x_{k-1}, x_k)
    MatrixXd A = MatrixXd::Zero(N, 2 * N);
    A.leftCols(N) = -p.F[std::size_t(k)];
    A.rightCols(N).setIdentity();
    const MatrixXd Qi = p.Q[std::size_t(k)].inverse();
    L.block(N * (k - 1), N * (k - 1), 2 * N, 2 * N) += A.transpose() * Qi * A;
    eta.segment(N * (k - 1), 2 * N) += A.transpose() * Qi * p.b[std::size_t(k)];
  }
  const Eigen::LLT<MatrixXd> llt(L);
  REQUIRE(llt.info() == Eigen::Success);
  const VectorXd x = llt.solve(eta);
  const MatrixXd S = llt.solve(MatrixXd::Identity(N * K, N * K));
  mean.clear();
  cov.clear();
  for (int k = 0; k < K; ++k) {
    mean.push_back(x.segment(N * k, N));
    cov.push_back(S.block(N * k, N * k, N, N));
  }
}

/// Runs the EKF (exact for these linear models) and rts_smooth, and
/// compares every smoothed mean and covariance with the closed form.
template <class Filter, class Control, int N, int M>
void compare(Filter& ekf, const Problem<N, M>& p, const std::vector<Control>& u,
             const std::vector<double>& dt) {
  using S = Eigen::Matrix<double, N, 1>;
  std::vector<posefuse::SmootherStep<S>> steps;
  ekf.reset(p.m0, p.P0);
  for (std::size_t k = 0; k < p.z.size(); ++k) {
    posefuse::SmootherStep<S> s;
    if (k > 0) REQUIRE(ekf.predict(u[k], dt[k]) == posefuse::FilterStatus::kApplied);
    s.predicted_mean = ekf.state();
    s.predicted_cov = ekf.covariance();
    if (k > 0) s.F = ekf.last_jacobian();
    REQUIRE(ekf.template update<0>(p.z[k]).status == posefuse::FilterStatus::kApplied);
    s.filtered_mean = ekf.state();
    s.filtered_cov = ekf.covariance();
    steps.push_back(s);
  }
  const auto smoothed = posefuse::rts_smooth(steps);
  std::vector<VectorXd> mean;
  std::vector<MatrixXd> cov;
  information_form(p, mean, cov);
  REQUIRE(smoothed.size() == mean.size());
  double worst_mean = 0, worst_cov = 0;
  for (std::size_t k = 0; k < mean.size(); ++k) {
    worst_mean = std::max(worst_mean, (VectorXd(smoothed[k].mean) - mean[k]).cwiseAbs().maxCoeff() /
                                          (1 + mean[k].cwiseAbs().maxCoeff()));
    worst_cov = std::max(worst_cov, (MatrixXd(smoothed[k].cov) - cov[k]).cwiseAbs().maxCoeff() /
                                        (1 + cov[k].cwiseAbs().maxCoeff()));
  }
  INFO("largest relative difference: mean " << worst_mean << ", covariance " << worst_cov);
  CHECK(worst_mean <= 1e-9);
  CHECK(worst_cov <= 1e-9);
  // The last smoothed belief is the last filtered one, and the first
  // smoothed belief is not the filtered one (the future moved it).
  CHECK((VectorXd(smoothed.back().mean) - VectorXd(steps.back().filtered_mean)).norm() == 0.0);
  CHECK((VectorXd(smoothed.front().mean) - VectorXd(steps.front().filtered_mean)).norm() > 1e-3);
}

}  // namespace

TEST_CASE("rts_smooth: constant velocity with varying dt equals the information-form posterior",
          "[filters][rts][closed_form]") {
  constexpr int K = 60;
  const double q = 0.8, sigma = 0.4;
  const posefuse::ConstantVelocity2<double> cv(q);
  const auto fix = posefuse::PositionFix<4>::isotropic(sigma);
  Problem<4, 2> p;
  p.m0 << 0.5, -1.0, 1.0, 0.2;
  p.P0 = Eigen::Vector4d(4.0, 4.0, 1.0, 1.0).asDiagonal();
  p.H = fix.jacobian(Eigen::Vector4d::Zero());
  p.R = fix.noise();
  std::mt19937 rng(2323);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> udt(0.05, 0.4);
  std::vector<double> dt(K, 0.0);
  std::vector<posefuse::NoControl> u(K);
  Eigen::Vector4d truth = p.m0;
  for (int k = 0; k < K; ++k) {
    if (k > 0) {
      dt[std::size_t(k)] = udt(rng);
      truth = cv.predict(truth, {}, dt[std::size_t(k)]);
      truth(2) += 0.3 * n(rng);
      truth(3) += 0.3 * n(rng);
    }
    p.F.push_back(cv.jacobian(truth, {}, dt[std::size_t(k)]));
    p.Q.push_back(cv.noise(truth, {}, dt[std::size_t(k)]));
    p.b.push_back(Eigen::Vector4d::Zero());
    p.z.push_back(truth.head<2>() + sigma * Eigen::Vector2d(n(rng), n(rng)));
  }
  posefuse::Ekf<posefuse::ConstantVelocity2<double>, posefuse::PositionFix<4>> ekf(cv, fix);
  compare(ekf, p, u, dt);
}

TEST_CASE("rts_smooth: seed 000's x' = x + u, z = x equals the information-form posterior",
          "[filters][rts][closed_form]") {
  constexpr int K = 80;
  Eigen::Matrix2d Rproc, Rmeas;
  Rproc << 0.02, 0.005, 0.005, 0.01;
  Rmeas << 0.25, -0.05, -0.05, 0.16;
  const posefuse::PlanarDisplacement<double> motion(Rproc);
  const posefuse::PositionFix<2> fix(Rmeas);
  Problem<2, 2> p;
  p.m0 << 1.0, 2.0;
  p.P0 = Eigen::Matrix2d::Identity();
  p.H = Eigen::Matrix2d::Identity();
  p.R = Rmeas;
  std::mt19937 rng(2324);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector2d> u(K, Eigen::Vector2d::Zero());
  std::vector<double> dt(K, 1.0);
  Eigen::Vector2d truth = p.m0;
  for (int k = 0; k < K; ++k) {
    if (k > 0) {
      u[std::size_t(k)] = Eigen::Vector2d(1.0 + 0.2 * n(rng), 0.3 * n(rng));
      truth += u[std::size_t(k)] + Eigen::Vector2d(0.1 * n(rng), 0.1 * n(rng));
    }
    p.F.push_back(Eigen::Matrix2d::Identity());
    p.Q.push_back(Rproc);
    p.b.push_back(u[std::size_t(k)]);
    p.z.push_back(truth + Eigen::Vector2d(0.5 * n(rng), 0.4 * n(rng)));
  }
  posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<2>> ekf(motion, fix);
  compare(ekf, p, u, dt);
}

namespace {

/// A recorded run of K steps on N states with random positive definite
/// covariances and random transitions (the predictions consistent with the
/// filtered beliefs: Pbar = F P F^T + Q).
template <int N>
std::vector<posefuse::SmootherStep<Eigen::Matrix<double, N, 1>>> random_run(int K, unsigned seed) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto mat = [&] {
    Mat M;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) M(i, j) = n(rng);
    return M;
  };
  const auto vec = [&] {
    Vec v;
    for (int i = 0; i < N; ++i) v(i) = n(rng);
    return v;
  };
  const auto spd = [&](double floor) {
    const Mat M = mat();
    const Mat P = M * M.transpose() + floor * Mat::Identity();
    return Mat(0.5 * (P + P.transpose()));  // exactly symmetric
  };
  std::vector<posefuse::SmootherStep<Vec>> run(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) {
    auto& s = run[std::size_t(k)];
    if (k > 0) {
      const auto& prev = run[std::size_t(k - 1)];
      s.F = Mat::Identity() + 0.3 * mat();
      s.predicted_mean = s.F * prev.filtered_mean;
      s.predicted_cov = s.F * prev.filtered_cov * s.F.transpose() + spd(0.05);
    } else {
      s.predicted_mean = vec();
      s.predicted_cov = spd(0.5);
    }
    s.filtered_mean = s.predicted_mean + 0.1 * vec();
    s.filtered_cov = spd(0.2);
  }
  return run;
}

/// The textbook backward pass with a dynamic-size Cholesky solve.
template <int N>
std::vector<VectorXd> reference_rts(const std::vector<posefuse::SmootherStep<Eigen::Matrix<double, N, 1>>>& run,
                                    std::vector<MatrixXd>& cov) {
  std::vector<VectorXd> mean(run.size());
  cov.assign(run.size(), MatrixXd());
  VectorXd xs = run.back().filtered_mean;
  MatrixXd Ps = run.back().filtered_cov;
  mean.back() = xs;
  cov.back() = Ps;
  for (std::size_t k = run.size() - 1; k-- > 0;) {
    const MatrixXd Pbar = run[k + 1].predicted_cov;
    const MatrixXd C = Pbar.llt().solve(MatrixXd(run[k + 1].F * run[k].filtered_cov)).transpose();
    xs = run[k].filtered_mean + C * (xs - run[k + 1].predicted_mean);
    Ps = run[k].filtered_cov + C * (Ps - Pbar) * C.transpose();
    mean[k] = xs;
    cov[k] = Ps;
  }
  return mean;
}

template <int N>
void check_against_reference_and_refusals() {
  INFO(N << " states");
  using Mat = Eigen::Matrix<double, N, N>;
  auto run = random_run<N>(6, 4000u + unsigned(N));
  const auto s = posefuse::rts_smooth(run);
  std::vector<MatrixXd> cov;
  const std::vector<VectorXd> mean = reference_rts<N>(run, cov);
  for (std::size_t k = 0; k < run.size(); ++k) {
    CHECK((VectorXd(s[k].mean) - mean[k]).cwiseAbs().maxCoeff() <= 1e-12 * (1 + mean[k].cwiseAbs().maxCoeff()));
    CHECK((MatrixXd(s[k].cov) - cov[k]).cwiseAbs().maxCoeff() <= 1e-12 * (1 + cov[k].cwiseAbs().maxCoeff()));
    CHECK(s[k].cov == s[k].cov.transpose());  // exactly symmetric
  }
  // A predicted covariance that is indefinite, singular, zero or not finite
  // is refused, naming its step.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  Mat indefinite = Mat::Identity();
  indefinite(N - 1, N - 1) = -1e-3;
  const Eigen::Matrix<double, N, 1> v = Eigen::Matrix<double, N, 1>::LinSpaced(1.0, 2.0);
  Mat rank_one = v * v.transpose();  // singular for N >= 2
  if (N == 1) rank_one.setZero();
  Mat with_nan = run[2].predicted_cov, with_inf = run[2].predicted_cov;
  with_nan(N - 1, 0) = nan;
  with_inf(N - 1, N - 1) = inf;
  for (const Mat& bad : {indefinite, rank_one, Mat(Mat::Zero()), with_nan, with_inf}) {
    auto broken = run;
    broken[2].predicted_cov = bad;
    CHECK_THROWS_WITH(posefuse::rts_smooth(broken),
                      "rts_smooth: predicted covariance 2 is not positive definite");
  }
}

}  // namespace

TEST_CASE("rts_smooth: 1 to 5 states equal a textbook Cholesky pass; a predicted covariance that is not "
          "positive definite or not finite is refused naming its step",
          "[filters][rts]") {
  check_against_reference_and_refusals<1>();
  check_against_reference_and_refusals<2>();
  check_against_reference_and_refusals<3>();
  check_against_reference_and_refusals<4>();
  check_against_reference_and_refusals<5>();  // beyond the closed-form blocks: Cholesky
}

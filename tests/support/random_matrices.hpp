#pragma once
// Random matrices for the filter and model tests: a random orthogonal N x N
// matrix, from which the tests build covariances of chosen spectra
// (Q diag(lambda) Q^T). Deterministic for a given std::mt19937 state.
#include <Eigen/Core>
#include <random>

namespace posefuse::test {

/// A random orthogonal N x N matrix: Gram-Schmidt on the columns of a matrix
/// of standard normal entries (drawn row by row).
template <int N>
Eigen::Matrix<double, N, N> random_orthogonal(std::mt19937& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, N, N> A;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) A(i, j) = n01(rng);
  Eigen::Matrix<double, N, N> Q;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> v = A.col(j);
    for (int k = 0; k < j; ++k) v -= Q.col(k).dot(v) * Q.col(k);
    Q.col(j) = v.normalized();
  }
  return Q;
}

}  // namespace posefuse::test

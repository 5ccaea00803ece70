#pragma once
/// @file
/// A Gaussian belief on a manifold: a mean and a covariance on its tangent space.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <algorithm>
#include <limits>
#include <string>

namespace posefuse {

/// True when every entry of a matrix is finite.
template <class Derived>
[[nodiscard]] bool all_finite(const Eigen::MatrixBase<Derived>& m) {
  return m.allFinite();
}

/// True when a square matrix is symmetric to a relative tolerance.
template <class Derived>
[[nodiscard]] bool is_symmetric(
    const Eigen::MatrixBase<Derived>& m,
    typename Derived::Scalar rel_tol = typename Derived::Scalar(1e4) *
                                       std::numeric_limits<typename Derived::Scalar>::epsilon()) {
  using T = typename Derived::Scalar;
  const T scale = std::max(T(1), m.cwiseAbs().maxCoeff());
  return ((m - m.transpose()).cwiseAbs().maxCoeff()) <= rel_tol * scale;
}

/// True when a symmetric matrix is positive semi-definite (LDLT with
/// non-negative pivots, to a small tolerance).
template <class Derived>
[[nodiscard]] bool is_positive_semidefinite(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  using M = Eigen::Matrix<T, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  if (!m.allFinite() || !is_symmetric(m)) return false;
  const Eigen::LDLT<M> ldlt{M(m)};
  if (ldlt.info() != Eigen::Success) return false;
  const T tol = T(-64) * std::numeric_limits<T>::epsilon() *
                std::max(T(1), m.cwiseAbs().maxCoeff());
  return (ldlt.vectorD().array() >= tol).all();
}

/// True when a symmetric matrix is positive definite (Cholesky succeeds).
template <class Derived>
[[nodiscard]] bool is_positive_definite(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  using M = Eigen::Matrix<T, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  if (!m.allFinite() || !is_symmetric(m)) return false;
  const Eigen::LLT<M> llt{M(m)};
  return llt.info() == Eigen::Success;
}

/// Throws posefuse::invalid_argument unless `m` is a finite, symmetric,
/// positive semi-definite covariance. `what` names it in the message.
template <class Derived>
void require_covariance(const Eigen::MatrixBase<Derived>& m, const char* what) {
  if (!m.allFinite()) throw invalid_argument(std::string(what) + ": covariance has NaN or Inf");
  if (!is_symmetric(m)) throw invalid_argument(std::string(what) + ": covariance is not symmetric");
  if (!is_positive_semidefinite(m))
    throw invalid_argument(std::string(what) + ": covariance is not positive semi-definite");
}

/// A Gaussian \f$ N(\mu, \Sigma) \f$ on the state type S; \f$ \Sigma \f$ lives on
/// the tangent space at \f$ \mu \f$.
template <State S>
struct Gaussian {
  using StateType = S;
  using Scalar = ScalarOf<S>;
  static constexpr int Dim = DimOf<S>;
  using Covariance = CovarianceOf<S>;

  S mean{};
  Covariance cov = Covariance::Identity();

  Gaussian() = default;
  /// @throws posefuse::invalid_argument if `cov` is not a finite, symmetric
  ///         PSD matrix
  Gaussian(const S& m, const Covariance& c) : mean(m), cov(c) {
    require_covariance(cov, "Gaussian");
  }
};

}  // namespace posefuse

#pragma once
/// @file
/// A Gaussian belief on a manifold: a mean and a covariance on its tangent space.

#include <Eigen/Core>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <algorithm>
#include <cmath>
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

namespace detail {
/// The scale-free form of a symmetric matrix with a non-negative diagonal:
/// \f$ C = D^{-1/2} M D^{-1/2} \f$, \f$ D = \mathrm{diag}(M) \f$ (a
/// correlation matrix when M is a covariance). A zero diagonal entry keeps
/// scale 1, so its row stays as it is and must be zero for M to be PSD.
/// @return false when a diagonal entry is negative
template <class M>
[[nodiscard]] bool correlation_form(const M& m, M& c) {
  using T = typename M::Scalar;
  constexpr int N = M::RowsAtCompileTime;
  Eigen::Matrix<T, N, 1> inv_scale;
  for (int i = 0; i < N; ++i) {
    if (!(m(i, i) >= T(0))) return false;  // negative (or NaN) variance
    inv_scale(i) = m(i, i) > T(0) ? T(1) / std::sqrt(m(i, i)) : T(1);
  }
  c = inv_scale.asDiagonal() * m * inv_scale.asDiagonal();
  return true;
}

/// Round-off allowance on the pivots of the scale-free form (whose
/// diagonal is 1): 16 n eps. A matrix indefinite by less than this, relative
/// to its own variances, is numerically PSD.
template <class T>
[[nodiscard]] constexpr T definiteness_tolerance(int n) noexcept {
  return T(16) * T(n) * std::numeric_limits<T>::epsilon();
}
}  // namespace detail

namespace detail {
/// Smallest pivot of a symmetric LDLT factorisation that picks, at every
/// step, the largest remaining diagonal entry of the *current* Schur
/// complement (complete symmetric pivoting). Once every remaining diagonal
/// entry is at most `tol`, the remaining block must be zero to within `tol`
/// for the matrix to be PSD; the function then returns the smallest of
/// those entries, or -inf when an off-diagonal entry there exceeds `tol`
/// (such a block is indefinite). Unlike Eigen's LDLT, which fixes the pivot
/// order from the original diagonal and reports a zero pivot followed by a
/// non-zero one as a failure, this accepts every PSD matrix, singular ones
/// included.
template <class M>
[[nodiscard]] typename M::Scalar smallest_pivot(M c, typename M::Scalar tol) {
  using T = typename M::Scalar;
  const int n = int(c.rows());
  T smallest = std::numeric_limits<T>::infinity();
  for (int k = 0; k < n; ++k) {
    int j = k;
    for (int i = k + 1; i < n; ++i)
      if (c(i, i) > c(j, j)) j = i;
    if (j != k) {
      c.row(k).swap(c.row(j));
      c.col(k).swap(c.col(j));
    }
    const T d = c(k, k);
    if (!(d > tol)) {  // the rest is numerically zero, or the matrix is indefinite
      for (int r = k; r < n; ++r) {
        smallest = std::min(smallest, c(r, r));
        for (int q = r + 1; q < n; ++q)
          if (!(std::abs(c(r, q)) <= tol)) return -std::numeric_limits<T>::infinity();
      }
      return smallest;
    }
    smallest = std::min(smallest, d);
    for (int r = k + 1; r < n; ++r)
      for (int q = k + 1; q < n; ++q) c(r, q) -= c(r, k) * c(k, q) / d;
  }
  return smallest;
}
}  // namespace detail

/// True when a symmetric matrix is positive semi-definite.
///
/// **The criterion, used everywhere in posefuse** (covariance validation,
/// Gaussian, Ekf::reset, model noise, and the Ekf's own results): every
/// diagonal entry is >= 0, and the completely pivoted LDLT of the scale-free
/// form \f$ C = D^{-1/2} M D^{-1/2} \f$ (\f$ D = \mathrm{diag}(M) \f$) has
/// no pivot below \f$ -16\,n\,\epsilon \f$ (detail::smallest_pivot). By
/// Sylvester's law of inertia an indefinite M has a negative pivot; scaling
/// each row and column by its own variance makes the tolerance relative to
/// that variance, so a huge variance elsewhere cannot hide a negative one
/// (unlike a tolerance relative to max|m_ij|).
template <class Derived>
[[nodiscard]] bool is_positive_semidefinite(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  using M = Eigen::Matrix<T, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  if (!m.allFinite() || !is_symmetric(m)) return false;
  M c;
  if (!detail::correlation_form(M(m), c)) return false;
  const T tol = detail::definiteness_tolerance<T>(int(c.rows()));
  return detail::smallest_pivot(c, tol) >= -tol;
}

/// True when a symmetric matrix is positive definite: every diagonal entry
/// is > 0 and every pivot of the scale-free form (see
/// is_positive_semidefinite) exceeds \f$ 16\,n\,\epsilon \f$, so a singular
/// matrix such as [[a, a], [a, a]] is refused even when round-off would let a
/// Cholesky factorisation succeed.
template <class Derived>
[[nodiscard]] bool is_positive_definite(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  using M = Eigen::Matrix<T, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  if (!m.allFinite() || !is_symmetric(m)) return false;
  if (!(m.diagonal().array() > T(0)).all()) return false;
  M c;
  if (!detail::correlation_form(M(m), c)) return false;
  const T tol = detail::definiteness_tolerance<T>(int(c.rows()));
  return detail::smallest_pivot(c, tol) > tol;
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

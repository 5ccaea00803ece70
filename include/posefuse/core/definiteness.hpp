#pragma once
/// @file
/// Deciding whether a symmetric matrix is positive semi-definite (or
/// definite), the criterion every covariance in posefuse is held to:
/// is_positive_semidefinite() and is_positive_definite(), with is_symmetric()
/// and all_finite().
///
/// The decision is the reference test, detail::psd_reference (the completely
/// pivoted LDLT of the scale-free form, see is_positive_semidefinite), tried
/// after a cheaper sufficient condition, detail::psd_fast_accepts, that can
/// only answer "certainly accepted" or "undecided". Each fast path carries
/// the argument for why it never accepts what the reference refuses.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

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

/// Bound on \f$ \|L^{-1}\|_F^2 \f$ for an n x n unit lower-triangular L
/// whose entries are at most `l` in magnitude: \f$ |(L^{-1})_{ij}| \le
/// l (1 + l)^{i-j-1} \f$, so \f$ n + \sum_{m=1}^{n-1} (n - m)\,
/// (l (1 + l)^{m-1})^2 \f$.
template <class T>
[[nodiscard]] constexpr T unit_lower_inverse_bound(int n, T l) noexcept {
  T sum = T(n), b = l;
  for (int m = 1; m < n; ++m) {
    sum += T(n - m) * b * b;
    b *= T(1) + l;
  }
  return sum;
}

/// Largest size the fast path of is_positive_semidefinite handles.
inline constexpr int kPsdFastMaxSize = 6;
/// Largest multiplier of the scale-free factor the fast path accepts.
inline constexpr int kPsdFastMaxMultiplier = 2;

/// Smallest scale-free pivot the fast path accepts, for size n:
/// \f$ \beta_n = 16\,K_n\,n(n+1)\,\epsilon \f$ with \f$ K_n \f$ =
/// unit_lower_inverse_bound(n, 2) (double: 1.3e-13 at n = 2, 5.0e-9 at
/// n = 6; float: 1.1e-3 at n = 3, 0.21 at n = 5; at n = 6 it exceeds 1, so
/// float 6x6 always takes the reference path).
template <class T>
[[nodiscard]] constexpr T psd_fast_min_pivot(int n) noexcept {
  return T(16) * unit_lower_inverse_bound<T>(n, T(kPsdFastMaxMultiplier)) * T(n) * T(n + 1) *
         std::numeric_limits<T>::epsilon();
}

/// The diagonal shift of psd_shifted_ldlt_accepts for size n, relative to
/// each variance: \f$ \delta_n = 2\,(2 n(n+1) + 19 n + 3)\,\epsilon \f$
/// (double: 3.4e-13 at n = 15; float: 1.8e-4 at n = 15).
template <class T>
[[nodiscard]] constexpr T psd_shift(int n) noexcept {
  return T(2) * (T(2) * T(n) * T(n + 1) + T(19) * T(n) + T(3)) * std::numeric_limits<T>::epsilon();
}

/// The fast path of is_positive_semidefinite for fixed sizes above
/// kPsdFastMaxSize: a sufficient condition for the reference (true only when
/// psd_reference is certain to accept `m`, as definite); false means
/// "undecided". After the checks of psd_fast_accepts (exact symmetry,
/// variances in range), an unpivoted LDLT of the *shifted* matrix
/// \f$ M - \delta_n D \f$ (\f$ D = \mathrm{diag}(M) \f$, psd_shift) must
/// complete with positive pivots (Rump's verification of positive
/// definiteness by a floating-point Cholesky of a shifted matrix: Rump,
/// BIT 46 (2006) 433-452).
///
/// Why: the computed factors satisfy \f$ \hat L \hat D \hat L^\top = M - \delta_n
/// D + \eta + \Delta M \f$ with \f$ |\Delta M| \le \gamma_{n+1} |\hat L|
/// |\hat D| |\hat L^\top| \f$ (Higham, *Accuracy and Stability*, Thm 10.3
/// and its LDLT form) and \f$ |\eta_{ii}| \le 2.1\,\epsilon\, m_{ii} \f$
/// (rounding of the shifted diagonal). With positive pivots, Cauchy-Schwarz
/// bounds \f$ (|\hat L||\hat D||\hat L^\top|)_{ij} \f$ by
/// \f$ \sqrt{m_{ii} m_{jj}} (1 + 3\epsilon) / (1 - \gamma_{n+1}) \f$, so in
/// the scale-free form C, \f$ C - \delta_n I + E \succeq 0 \f$ with
/// \f$ \|E\|_2 \lesssim (n(n+1) + 2.1)\epsilon \f$, i.e. \f$ \lambda_{\min}(C)
/// \gtrsim \delta_n - (n(n+1) + 2.1)\epsilon \f$. The reference's completely
/// pivoted LDLT is exact for a matrix within \f$ (n(n+1) + 3n)\epsilon \f$
/// of C (see psd_fast_accepts), so its pivots exceed \f$ \delta_n - (2n(n+1)
/// + 3n + 2.1)\epsilon > 16 n \epsilon \f$, the tolerance, with a factor 2 to
/// spare in \f$ \delta_n \f$: the reference accepts, as definite. The range of
/// the variances keeps every rounding error relative (underflow in a product
/// is far below \f$ \epsilon \sqrt{m_{ii} m_{jj}} \f$); an overflow, NaN or
/// Inf makes a later pivot NaN or \f$ -\infty \f$, which fails.
/// tests/filters/test_ekf_fast_paths.cpp checks the agreement with the
/// reference on random PSD, indefinite and near-singular matrices.
template <class Derived>
[[nodiscard]] bool psd_shifted_ldlt_accepts(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  constexpr int N = Derived::RowsAtCompileTime;
  constexpr T delta = psd_shift<T>(N);
  if constexpr (!(delta < T(0.5))) {
    return false;
  } else {
    const T min_diag = std::sqrt(std::numeric_limits<T>::min()) / std::numeric_limits<T>::epsilon();
    const T max_diag = std::sqrt(std::numeric_limits<T>::max()) * std::numeric_limits<T>::epsilon();
    T s[N][N];  // lower triangle of the Schur complements of the shifted matrix
    for (int i = 0; i < N; ++i) {
      const T d = m(i, i);
      if (!(d >= min_diag && d <= max_diag)) return false;
      s[i][i] = d - delta * d;
      for (int j = 0; j < i; ++j) {
        if (!(m(i, j) == m(j, i))) return false;
        s[i][j] = m(i, j);
      }
    }
    for (int k = 0; k < N; ++k) {
      const T d = s[k][k];
      if (!(d > T(0))) return false;
      const T inv = T(1) / d;
      T c[N];  // column k, contiguous so that the row updates vectorise
      for (int j = k + 1; j < N; ++j) c[j] = s[j][k];
      for (int i = k + 1; i < N; ++i) {
        const T l = c[i] * inv;
        for (int j = k + 1; j <= i; ++j) s[i][j] -= l * c[j];
      }
    }
    return true;
  }
}

/// Division-free first try of the fast path for sizes 3, 4 and 5: Sylvester's
/// criterion with margins. True only when the reference (psd_reference) is
/// certain to accept `m` as definite; false means "undecided".
///
/// Checks: `m` exactly symmetric, every variance in \f$ [2^{-e}, 2^{e}] \f$
/// (e = (max_exponent - 24) / 2n: double 125 at n = 4, 100 at n = 5; float
/// 13 at n = 4, 10 at n = 5),
/// \f$ m_{ij}^2 \le m_{ii} m_{jj} \f$, then the leading principal minors
/// \f$ D_k \f$ (cofactor / Laplace expansion) against \f$ \theta_k \prod_{i<k}
/// m_{ii} \f$ with \f$ \theta_k = 12 k\,k!\,\epsilon \f$ for k < n and
/// \f$ \theta_n = 12 n\,n!\,\epsilon + 3\delta_n \f$ (\f$ \delta_n \f$ = psd_shift).
///
/// Why: each expansion sums the k! Leibniz products, each after at most 3k
/// roundings (k - 1 multiplications and the additions of nested 2x2 and
/// 3x3 minors: at most 10 for k = 4 and, with the ten-term sum of D_5
/// added as a tree, 12 for k = 5), so \f$ |\hat D_k - D_k| \le \gamma_{3k}\,\mathrm{per}|M_k| \le
/// \gamma_{3k}\,k! \prod m_{ii} (1 + k\epsilon) \f$ (the permanent bounded by
/// the entry check). Hence every exact leading minor is positive (Sylvester:
/// M, and its scale-free form C, are positive definite) and
/// \f$ \det C = D_n / \prod m_{ii} \ge 3\delta_n \f$ (to first order). The
/// other n - 1 eigenvalues of C have a product at most
/// \f$ (\mathrm{tr}\,C / (n-1))^{n-1} = (n/(n-1))^{n-1} < e \f$, so
/// \f$ \lambda_{\min}(C) > \delta_n \f$, which (see psd_shifted_ldlt_accepts)
/// makes the reference accept. The variance range keeps every product
/// normal or its underflow far below the margins; NaN fails a comparison.
template <class Derived>
[[nodiscard]] bool psd_minors_accept(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  constexpr int N = Derived::RowsAtCompileTime;
  static_assert(N >= 3 && N <= 5);
  constexpr T eps = std::numeric_limits<T>::epsilon();
  constexpr T theta3 = T(12 * 3 * 6) * eps + (N == 3 ? T(3) * psd_shift<T>(3) : T(0));
  constexpr T theta4 = T(12 * 4 * 24) * eps + (N == 4 ? T(3) * psd_shift<T>(4) : T(0));
  constexpr T theta5 = T(12 * 5 * 120) * eps + T(3) * psd_shift<T>(5);
  constexpr T theta2 = T(12 * 2 * 2) * eps;
  if constexpr (!(theta3 < T(0.5) && theta4 < T(0.5) && theta5 < T(0.5))) {
    return false;
  } else {
    // 2^-e and 2^e with e = (max_exponent - 24) / (2N): every product of
    // up to N entries (and the thresholds) stays a normal number (double:
    // 2^-125 .. 2^125 at N = 4; float: 2^-13 .. 2^13).
    constexpr int e = (std::numeric_limits<T>::max_exponent - 24) / (2 * N);
    constexpr T hi = [] {
      T v = T(1);
      for (int i = 0; i < e; ++i) v *= T(2);
      return v;
    }();
    constexpr T lo = T(1) / hi;
    T a[N][N];
    for (int i = 0; i < N; ++i) {
      a[i][i] = m(i, i);
      if (!(a[i][i] >= lo && a[i][i] <= hi)) return false;
    }
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < i; ++j) {
        const T v = m(i, j);
        if (!(v == m(j, i) && v * v <= a[i][i] * a[j][j])) return false;
        a[i][j] = a[j][i] = v;
      }
    const T p2 = a[0][0] * a[1][1];
    const T d2 = p2 - a[0][1] * a[0][1];
    if (!(d2 >= theta2 * p2)) return false;
    // 2x2 minors of rows 0, 1 (columns c0 < c1).
    const T m01 = d2;
    const T m02 = a[0][0] * a[1][2] - a[0][2] * a[1][0];
    const T m12 = a[0][1] * a[1][2] - a[0][2] * a[1][1];
    const T d3 = a[2][0] * m12 - a[2][1] * m02 + a[2][2] * m01;
    const T p3 = p2 * a[2][2];
    if constexpr (N == 3) {
      return d3 >= theta3 * p3;
    } else {
      if (!(d3 >= T(12 * 3 * 6) * eps * p3)) return false;
      const T m03 = a[0][0] * a[1][3] - a[0][3] * a[1][0];
      const T m13 = a[0][1] * a[1][3] - a[0][3] * a[1][1];
      const T m23 = a[0][2] * a[1][3] - a[0][3] * a[1][2];
      // Complementary 2x2 minors of rows 2, 3.
      const T n23 = a[2][2] * a[3][3] - a[2][3] * a[3][2];
      const T n13 = a[2][1] * a[3][3] - a[2][3] * a[3][1];
      const T n12 = a[2][1] * a[3][2] - a[2][2] * a[3][1];
      const T n03 = a[2][0] * a[3][3] - a[2][3] * a[3][0];
      const T n02 = a[2][0] * a[3][2] - a[2][2] * a[3][0];
      const T n01 = a[2][0] * a[3][1] - a[2][1] * a[3][0];
      const T d4 = m01 * n23 - m02 * n13 + m03 * n12 + m12 * n03 - m13 * n02 + m23 * n01;
      const T p4 = p3 * a[3][3];
      if constexpr (N == 4) {
        return d4 >= theta4 * p4;
      } else {
        if (!(d4 >= theta4 * p4)) return false;
        // D_5 by Laplace along rows 0, 1: the 2x2 minors m_ab of rows 0, 1
        // times the complementary 3x3 minors t_cde of rows 2, 3, 4 (each
        // along row 2, with the 2x2 minors q_ab of rows 3, 4).
        const T m04 = a[0][0] * a[1][4] - a[0][4] * a[1][0];
        const T m14 = a[0][1] * a[1][4] - a[0][4] * a[1][1];
        const T m24 = a[0][2] * a[1][4] - a[0][4] * a[1][2];
        const T m34 = a[0][3] * a[1][4] - a[0][4] * a[1][3];
        T q[5][5];
        for (int i = 0; i < 5; ++i)
          for (int j = i + 1; j < 5; ++j) q[i][j] = a[3][i] * a[4][j] - a[3][j] * a[4][i];
        const auto t = [&a, &q](int i, int j, int k) {  // rows 2, 3, 4; columns i < j < k
          return a[2][i] * q[j][k] - a[2][j] * q[i][k] + a[2][k] * q[i][j];
        };
        // The sign of m_ab t_cde is that of the permutation (a b c d e).
        const T d5 = ((m01 * t(2, 3, 4) - m02 * t(1, 3, 4)) + (m03 * t(1, 2, 4) - m04 * t(1, 2, 3))) +
                     ((m12 * t(0, 3, 4) - m13 * t(0, 2, 4)) + (m14 * t(0, 2, 3) + m23 * t(0, 1, 4))) +
                     (m34 * t(0, 1, 2) - m24 * t(0, 1, 3));
        return d5 >= theta5 * (p4 * a[4][4]);
      }
    }
  }
}

/// A sufficient condition for the criterion of is_positive_definite (and so
/// of is_positive_semidefinite), cheaper than the reference: true only when
/// the reference test (psd_reference) is certain to accept `m` as positive
/// definite; false means "undecided", never "indefinite".
///
/// Sizes above 6 take psd_shifted_ldlt_accepts; sizes 3 to 5 first try
/// psd_minors_accept (no division). For fixed sizes 1..6: `m` exactly symmetric, every diagonal entry in
/// [sqrt(min) / eps, sqrt(max) * eps] (no overflow or underflow below), then
/// an LDLT of `m` in its given order, without pivoting, square roots or any
/// division but one per pivot, in which every pivot of the scale-free form,
/// \f$ d_k / m_{kk} \f$, is at least \f$ \beta_n \f$
/// (psd_fast_min_pivot) and every multiplier of the scale-free factor,
/// \f$ l_{ik} \sqrt{m_{kk} / m_{ii}} \f$, is at most 2 in magnitude.
/// (Every entry of `m` enters a pivot or a multiplier, so a NaN or Inf
/// fails one of these comparisons.)
///
/// Why that implies the reference accepts (C the scale-free form): with
/// positive computed pivots, \f$ \hat L \hat D \hat L^\top = C + E \f$
/// with \f$ \|E\|_2 \lesssim n \gamma_{n+1} \approx n(n+1)\epsilon \f$
/// (Higham, *Accuracy and Stability*, Thm 10.3 and its proof: \f$ |\hat
/// L||\hat D||\hat L^\top| \f$ has diagonal \f$ \approx 1 \f$); and
/// \f$ \lambda_{\min}(C + E) \ge \min_k \hat d_k / \|\hat L^{-1}\|_2^2
/// \ge \beta_n / K_n = 16 n(n+1)\epsilon \f$. So \f$ \lambda_{\min}(C)
/// \gtrsim 15 n(n+1)\epsilon \f$; the reference's completely pivoted LDLT
/// is then (by the same backward-error argument, and Demmel's condition
/// for Cholesky to complete) exact for a matrix within \f$ \approx
/// (n(n+1) + 3n)\epsilon \f$ of C, whose pivots are all at least its
/// smallest eigenvalue \f$ \gtrsim (14 n(n+1) - 3n)\epsilon > 16 n
/// \epsilon \f$, the tolerance: the reference accepts, as definite. tests/core/test_gaussian.cpp checks the agreement on
/// random PSD, indefinite and near-singular matrices of sizes 1..6.
template <class Derived>
[[nodiscard]] bool psd_fast_accepts(const Eigen::MatrixBase<Derived>& m) {
  using T = typename Derived::Scalar;
  constexpr int N = Derived::RowsAtCompileTime;
  if constexpr (N == Eigen::Dynamic || N != Derived::ColsAtCompileTime || N < 1 ||
                !std::is_floating_point_v<T>) {
    return false;
  } else if constexpr (N > kPsdFastMaxSize) {
    return psd_shifted_ldlt_accepts(m);
  } else {
    constexpr T beta = psd_fast_min_pivot<T>(N);
    if constexpr (!(beta < T(1))) {
      return false;
    } else {
      const T min_diag = std::sqrt(std::numeric_limits<T>::min()) / std::numeric_limits<T>::epsilon();
      const T max_diag = std::sqrt(std::numeric_limits<T>::max()) * std::numeric_limits<T>::epsilon();
      if constexpr (N == 1) {
        return m(0, 0) >= min_diag && m(0, 0) <= max_diag;
      } else if constexpr (N == 2) {
        // The loop below in closed form, without a division: the scale-free
        // pivot 1 - rho^2 >= beta, i.e. m10^2 <= (1 - beta) m00 m11 (which
        // also bounds the multiplier |rho| by 1). A NaN or Inf fails.
        if (!(m(0, 0) >= min_diag && m(0, 0) <= max_diag && m(1, 1) >= min_diag &&
              m(1, 1) <= max_diag && m(1, 0) == m(0, 1)))
          return false;
        return m(1, 0) * m(1, 0) <= (T(1) - beta) * (m(0, 0) * m(1, 1));
      }
      if constexpr (N >= 3 && N <= 5) {
        if (psd_minors_accept(m)) return true;  // else the LDLT below decides
      }
      constexpr T l2 = T(kPsdFastMaxMultiplier) * T(kPsdFastMaxMultiplier);
      T diag[N];
      T s[N][N];  // lower triangle of the Schur complements
      for (int i = 0; i < N; ++i) {
        diag[i] = m(i, i);
        if (!(diag[i] >= min_diag && diag[i] <= max_diag)) return false;
        s[i][i] = diag[i];
        for (int j = 0; j < i; ++j) {
          if (!(m(i, j) == m(j, i))) return false;
          s[i][j] = m(i, j);
        }
      }
      for (int k = 0; k < N; ++k) {
        const T d = s[k][k];
        if (!(d >= beta * diag[k])) return false;
        const T inv = T(1) / d;
        T l[N];
        for (int i = k + 1; i < N; ++i) {
          l[i] = s[i][k] * inv;
          if (!(l[i] * l[i] * diag[k] <= l2 * diag[i])) return false;
        }
        for (int i = k + 1; i < N; ++i)
          for (int j = k + 1; j <= i; ++j) s[i][j] -= l[i] * s[j][k];
      }
      return true;
    }
  }
}

/// The reference test behind is_positive_semidefinite (definite = false) and
/// is_positive_definite (definite = true): finiteness, symmetry, the
/// diagonal, then the completely pivoted LDLT of the scale-free form.
template <class Derived>
[[nodiscard]] bool psd_reference(const Eigen::MatrixBase<Derived>& m, bool definite) {
  using T = typename Derived::Scalar;
  using M = Eigen::Matrix<T, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  if (!m.allFinite() || !is_symmetric(m)) return false;
  if (definite && !(m.diagonal().array() > T(0)).all()) return false;
  M c;
  if (!correlation_form(M(m), c)) return false;
  const T tol = definiteness_tolerance<T>(int(c.rows()));
  const T p = smallest_pivot(c, tol);
  return definite ? p > tol : p >= -tol;
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
  return detail::psd_fast_accepts(m) || detail::psd_reference(m, false);
}

/// True when a symmetric matrix is positive definite: every diagonal entry
/// is > 0 and every pivot of the scale-free form (see
/// is_positive_semidefinite) exceeds \f$ 16\,n\,\epsilon \f$, so a singular
/// matrix such as [[a, a], [a, a]] is refused even when round-off would let a
/// Cholesky factorisation succeed.
template <class Derived>
[[nodiscard]] bool is_positive_definite(const Eigen::MatrixBase<Derived>& m) {
  return detail::psd_fast_accepts(m) || detail::psd_reference(m, true);
}

}  // namespace posefuse

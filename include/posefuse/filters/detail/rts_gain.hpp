#pragma once
/// @file
/// The gain of one RTS backward step, \f$ C = A\,\bar P^{-1} \f$ with
/// \f$ A = P F^\top \f$, for a small state (not API; filters/rts_smoother.hpp).
///
/// For N <= 4 states \f$ \bar P \f$ is factorised in blocks of n1 = ceil(N/2)
/// and n2 = N - n1 rows, \f$ \bar P = L\,\mathrm{diag}(\bar P_{11}, S)\,L^\top \f$
/// with \f$ L = [I, 0; W^\top, I] \f$, \f$ W = \bar P_{11}^{-1}\bar P_{12} \f$ and
/// the Schur complement \f$ S = \bar P_{22} - \bar P_{21} W \f$ (1x1 and 2x2
/// blocks inverted in closed form), and
/// \f$ C = [Z_1 - Z_2 W^\top,\; Z_2] \f$ with \f$ Z_1 = A_1 \bar P_{11}^{-1} \f$,
/// \f$ Z_2 = (A_2 - A_1 W) S^{-1} \f$: no inverse of \f$ \bar P \f$ is formed,
/// and no loop runs. \f$ \bar P \f$ counts as positive definite when every
/// pivot of its \f$ L D L^\top \f$ factorisation is above round-off,
/// \f$ d_j > N \epsilon \bar P_{jj} \f$, the criterion of core/spd_solver.hpp
/// (NaN and infinite entries fail it). Only the lower triangle of
/// \f$ \bar P \f$ is read.

#include <Eigen/Core>
#include <limits>

namespace posefuse::detail {

/// The inverse of the symmetric n x n block B (n = 1 or 2, lower triangle
/// read) when its pivots pass \f$ d_j > \mathrm{tol}\cdot r_j \f$ (r: the
/// reference diagonal, the original \f$ \bar P_{jj} \f$).
/// @return false otherwise (the output is then unspecified)
template <int n, class T>
[[nodiscard, gnu::always_inline]] inline bool small_spd_inverse(const Eigen::Matrix<T, n, n>& B,
                                                               const Eigen::Matrix<T, n, 1>& ref, T tol,
                                                               Eigen::Matrix<T, n, n>& inv) {
  static_assert(n == 1 || n == 2);
  constexpr T kMax = std::numeric_limits<T>::max();
  if constexpr (n == 1) {
    const T d = B(0, 0);
    if (!(d > tol * ref(0) && d > T(0) && d <= kMax)) return false;
    inv(0, 0) = T(1) / d;
  } else {
    const T a = B(0, 0), b = B(1, 0), c = B(1, 1);
    const T det = a * c - b * b;  // pivots a and det / a
    if (!(a > tol * ref(0) && a > T(0) && a <= kMax && det > tol * ref(1) * a && det <= kMax)) return false;
    const T r = T(1) / det;
    inv(0, 0) = c * r;
    inv(1, 1) = a * r;
    inv(0, 1) = inv(1, 0) = -b * r;
  }
  return true;
}

/// \f$ C = A\,\bar P^{-1} \f$ for N <= 4 (see the file comment).
/// @return false, C unspecified, unless \f$ \bar P \f$ is positive definite
template <class T, int N>
[[nodiscard]] inline bool rts_gain_small(const Eigen::Matrix<T, N, N>& A, const Eigen::Matrix<T, N, N>& Pbar,
                                         Eigen::Matrix<T, N, N>& C) {
  static_assert(N >= 1 && N <= 4);
  constexpr int n1 = (N + 1) / 2;
  constexpr int n2 = N - n1;
  const T tol = T(N) * std::numeric_limits<T>::epsilon();
  const Eigen::Matrix<T, N, 1> diag = Pbar.diagonal();
  Eigen::Matrix<T, n1, n1> inv1;
  if (!small_spd_inverse<n1>(Eigen::Matrix<T, n1, n1>(Pbar.template topLeftCorner<n1, n1>()),
                             Eigen::Matrix<T, n1, 1>(diag.template head<n1>()), tol, inv1))
    return false;
  if constexpr (n2 == 0) {
    C = A * inv1;
    return true;
  } else {
    const Eigen::Matrix<T, n2, n1> P21 = Pbar.template bottomLeftCorner<n2, n1>();
    const Eigen::Matrix<T, n1, n2> W = inv1 * P21.transpose();
    const Eigen::Matrix<T, n2, n2> S = Pbar.template bottomRightCorner<n2, n2>() - P21 * W;  // lower used
    Eigen::Matrix<T, n2, n2> inv2;
    if (!small_spd_inverse<n2>(S, Eigen::Matrix<T, n2, 1>(diag.template tail<n2>()), tol, inv2)) return false;
    const Eigen::Matrix<T, N, n1> A1 = A.template leftCols<n1>();
    const Eigen::Matrix<T, N, n2> Z2 = (A.template rightCols<n2>() - A1 * W) * inv2;
    C.template leftCols<n1>() = A1 * inv1 - Z2 * W.transpose();
    C.template rightCols<n2>() = Z2;
    return true;
  }
}

}  // namespace posefuse::detail

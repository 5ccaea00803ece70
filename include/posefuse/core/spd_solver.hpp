#pragma once
/// @file
/// detail::SpdSolver: the positive-definiteness test of a small symmetric
/// matrix S of fixed size and the solves with it, for the innovation
/// covariance of a Kalman update (filters/ekf.hpp).
///
/// For sizes 1, 2 and 3, S is tested by Sylvester's criterion and inverted
/// in closed form (its adjugate over its determinant: a few dozen flops, no
/// loop). Larger ones are factorised, \f$ S = L D L^\top \f$ (L unit lower
/// triangular, no square roots), and the solves use L; no inverse is formed.
/// Either way S counts as positive definite only when every pivot is above
/// round-off: \f$ L_{ii}^2 > n\,\epsilon\,S_{ii} \f$ (2x2:
/// \f$ \det S > 2 \epsilon S_{00} S_{11} \f$; 3x3 the same pivots written
/// with the leading minors, \f$ d_1 = D_2 / S_{00} \f$ and \f$ d_2 = D_3 /
/// D_2 \f$: \f$ D_2 > 3\epsilon S_{00} S_{11} \f$ and \f$ D_3 > 3\epsilon
/// S_{22} D_2 \f$), which is invariant to the units of each component, so an
/// indefinite or (numerically) singular S is refused instead of producing a
/// huge gain. Only the lower triangle of S is read.

#include <Eigen/Core>
#include <limits>
#include <type_traits>

namespace posefuse::detail {

/// The positive-definiteness test and the solves with a symmetric N x N
/// matrix S (see the file comment). Sizes 1 and 2 keep S⁻¹, size 3 adj(S),
/// and all three \f$ 1 / \det S \f$ in closed form; larger sizes
/// keep the factors of S = L D Lᵀ and never form S⁻¹.
template <class Mat, int N = Mat::RowsAtCompileTime>
class SpdSolver {
  using T = typename Mat::Scalar;
  using Vec = Eigen::Matrix<T, N, 1>;

 public:
  /// Factorises S. @return false (solver unusable) unless S is positive definite
  [[nodiscard, gnu::always_inline]] bool compute(const Mat& S) {
    if constexpr (N == 1) {
      if (!(S(0, 0) > T(0))) return false;
      recip_ = T(1) / S(0, 0);
      inv_(0, 0) = recip_;
      return true;
    } else if constexpr (N == 2) {
      const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
      if (!(S(0, 0) > T(0) && det > T(2) * std::numeric_limits<T>::epsilon() * S(0, 0) * S(1, 1)))
        return false;
      const T r = T(1) / det;
      recip_ = r;
      inv_(0, 0) = S(1, 1) * r;
      inv_(1, 1) = S(0, 0) * r;
      inv_(0, 1) = -S(0, 1) * r;
      inv_(1, 0) = -S(1, 0) * r;
      return true;
    } else if constexpr (N == 3) {
      // The lower triangle a b c / d e / f; adj(S) by cofactors, D3 along
      // the first column. The two tests are the LDLT pivot tests d_1 > 3 eps
      // S_11 and d_2 > 3 eps S_22 times the (positive) earlier minors.
      const T a = S(0, 0), b = S(1, 0), c = S(2, 0), d = S(1, 1), e = S(2, 1), f = S(2, 2);
      const T A00 = d * f - e * e, A10 = c * e - b * f, A20 = b * e - c * d;
      const T D2 = a * d - b * b;
      const T D3 = a * A00 + (b * A10 + c * A20);
      const T tol = T(3) * std::numeric_limits<T>::epsilon();
      if (!(a > T(0) && D2 > tol * (a * d) && D3 > tol * (f * D2))) return false;
      adj_(0, 0) = A00;
      adj_(1, 0) = adj_(0, 1) = A10;
      adj_(2, 0) = adj_(0, 2) = A20;
      adj_(1, 1) = a * f - c * c;
      adj_(2, 1) = adj_(1, 2) = b * c - a * e;
      adj_(2, 2) = D2;
      const T r = T(1) / D3;
      recip_ = r;
      return true;
    } else {
      // S = L D L^T (L unit lower triangular), column by column, from the
      // lower triangle of S; no square roots, 1 / d_j kept so that the
      // solves below multiply. d_j is the squared Cholesky pivot L_jj^2.
      const T tol = T(N) * std::numeric_limits<T>::epsilon();
      for (int j = 0; j < N; ++j) {
        T d = S(j, j);
        for (int k = 0; k < j; ++k) d -= L_(j, k) * LD_(j, k);
        // The pivot criterion of the file comment (NaN fails).
        if (!(d > tol * S(j, j))) return false;
        inv_diag_(j) = T(1) / d;
        for (int i = j + 1; i < N; ++i) {
          T v = S(i, j);
          for (int k = 0; k < j; ++k) v -= L_(i, k) * LD_(j, k);
          LD_(i, j) = v;  // L_ij d_j
          L_(i, j) = v * inv_diag_(j);
        }
      }
      return true;
    }
  }
  /// Sizes 1 to 3: \f$ 1 / \det S \f$ (S⁻¹ = adj(S) / det S), after a
  /// successful compute(). A caller that forms products with adj(S) itself
  /// scales them by this once.
  [[nodiscard, gnu::always_inline]] T recip_det() const noexcept
    requires(N <= 3)
  {
    return recip_;
  }
  /// Size 3: adj(S) (symmetric), after a successful compute().
  [[nodiscard, gnu::always_inline]] const Mat& adjugate() const noexcept
    requires(N == 3)
  {
    return adj_;
  }
  /// \f$ r^\top S^{-1} r \f$ (3x3: \f$ r^\top \mathrm{adj}(S)\, r / \det S \f$);
  /// beyond 3x3 \f$ \sum_j y_j^2 / d_j,\; y = L^{-1} r \f$.
  [[nodiscard, gnu::always_inline]] T nis(const Vec& r) const {
    if constexpr (N == 1) {
      return r(0) * (inv_(0, 0) * r(0));
    } else if constexpr (N == 2) {
      return r(0) * (inv_(0, 0) * r(0) + inv_(0, 1) * r(1)) +
             r(1) * (inv_(1, 0) * r(0) + inv_(1, 1) * r(1));
    } else if constexpr (N == 3) {
      const T q = r(0) * (adj_(0, 0) * r(0) + T(2) * (adj_(1, 0) * r(1) + adj_(2, 0) * r(2))) +
                  (r(1) * (adj_(1, 1) * r(1) + T(2) * adj_(2, 1) * r(2)) + r(2) * (adj_(2, 2) * r(2)));
      return q * recip_;
    } else {
      Vec y;
      T sum = T(0);
      for (int j = 0; j < N; ++j) {
        T v = r(j);
        for (int k = 0; k < j; ++k) v -= L_(j, k) * y(k);
        y(j) = v;
        sum += v * v * inv_diag_(j);
      }
      return sum;
    }
  }
  /// \f$ A S^{-1} \f$ for an M x N matrix A (beyond 3x3: rows solved with L,
  /// then with Lᵀ).
  template <int M>
  [[nodiscard, gnu::always_inline]] Eigen::Matrix<T, M, N> right_solve(
      const Eigen::Matrix<T, M, N>& A) const {
    if constexpr (N <= 2) {
      return A * inv_;
    } else if constexpr (N == 3) {
      return (A * adj_) * recip_;
    } else {
      // X S = A  <=>  (X L D) L^T = A: Y L^T = A forward, Y D^-1, then
      // X L = Y D^-1 backward (L unit lower triangular).
      Eigen::Matrix<T, M, N> X;
      for (int j = 0; j < N; ++j) {
        Eigen::Matrix<T, M, 1> v = A.col(j);
        for (int k = 0; k < j; ++k) v -= L_(j, k) * X.col(k);
        X.col(j) = v;
      }
      for (int j = N - 1; j >= 0; --j) {
        Eigen::Matrix<T, M, 1> v = X.col(j) * inv_diag_(j);
        for (int k = j + 1; k < N; ++k) v -= L_(k, j) * X.col(k);
        X.col(j) = v;
      }
      return X;
    }
  }

 private:
  static constexpr bool kClosedForm = N <= 3;
  struct Empty {};
  // Members of the other size class are Empty and take no space.
  using Inverse = std::conditional_t<(N <= 2), Mat, Empty>;
  using Factor = std::conditional_t<kClosedForm, Empty, Mat>;
  using InvDiag = std::conditional_t<kClosedForm, Empty, Vec>;
  using Adjugate = std::conditional_t<N == 3, Mat, Empty>;
  template <class Member>
  static Member zero() {
    if constexpr (std::is_same_v<Member, Empty>) {
      return Empty{};
    } else if constexpr (std::is_arithmetic_v<Member>) {
      return Member(0);
    } else {
      return Member::Zero();
    }
  }
  [[no_unique_address]] Inverse inv_ = zero<Inverse>();     // S^-1 (sizes 1 and 2)
  [[no_unique_address]] Adjugate adj_ = zero<Adjugate>();   // adj(S) (size 3)
  T recip_ = T(0);  // 1 / det S (sizes 1 to 3)
  [[no_unique_address]] Factor L_ = zero<Factor>();         // unit lower triangular L
  [[no_unique_address]] Factor LD_ = zero<Factor>();        // L_ij d_j (i > j)
  [[no_unique_address]] InvDiag inv_diag_ = zero<InvDiag>();  // 1 / d_j
};

}  // namespace posefuse::detail

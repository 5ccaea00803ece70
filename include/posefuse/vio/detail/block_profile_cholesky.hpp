#pragma once
/// @file
/// Cholesky factorisation \f$ A = L L^\top \f$ of a symmetric positive
/// definite matrix made of `nb` square blocks of a fixed size B followed by
/// an optional dense border of `t` rows (t <= 6), when the blocks have a
/// *profile* (variable band): block row i has no non-zero block left of
/// block column `first[i]` (first[i] <= i). The factor keeps that profile
/// (no fill outside it), so the cost is about
/// \f$ \sum_i (i - first_i + 1)^2 B^3 \f$ instead of \f$ (nb\,B)^3 / 3 \f$:
/// for a block-tridiagonal system, linear in nb. The border (the
/// camera-IMU extrinsic of the window, coupled to every keyframe) is
/// factored densely after the blocks.
///
/// Works in place on the lower triangle of a column-major dense matrix
/// (only the blocks inside the profile and the border rows are read or
/// written; the strict upper triangle is never touched), with B x B
/// fixed-size products. No allocation once the matrix is sized.
/// Used by vio/window_problem.hpp for the reduced system of the window
/// (B = 15, one block per keyframe).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <vector>

namespace posefuse::detail {

/// See the file comment. B: the block size.
template <int B>
class BlockProfileCholesky {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  using BlockVec = Eigen::Matrix<double, B, 1>;
  static constexpr int kMaxBorder = 6;  ///< largest border
  using Border = Eigen::Matrix<double, Eigen::Dynamic, B, 0, kMaxBorder, B>;

  /// Factors `A` in place (its lower triangle becomes L).
  /// @param A     (nb B + t) square, column-major; lower triangle inside the profile read
  /// @param first first non-zero block column of each block row (size nb)
  /// @param t     border rows (0..6)
  /// @return false when A is not (numerically) positive definite
  static bool factor(Eigen::MatrixXd& A, const std::vector<int>& first, int t) {
    const int nb = int(first.size());
    for (int i = 0; i < nb; ++i) {
      const int fi = first[std::size_t(i)];
      for (int j = fi; j < i; ++j) {
        Block S = A.template block<B, B>(B * i, B * j);
        for (int k = std::max(fi, first[std::size_t(j)]); k < j; ++k)
          S.noalias() -= A.template block<B, B>(B * i, B * k) * A.template block<B, B>(B * j, B * k).transpose();
        // L_ij = S L_jj^{-T}
        A.template block<B, B>(B * j, B * j).template triangularView<Eigen::Lower>().transpose().template solveInPlace<Eigen::OnTheRight>(S);
        A.template block<B, B>(B * i, B * j) = S;
      }
      Block D = A.template block<B, B>(B * i, B * i);
      for (int k = fi; k < i; ++k)
        D.noalias() -= A.template block<B, B>(B * i, B * k) * A.template block<B, B>(B * i, B * k).transpose();
      Eigen::LLT<Block> llt(D);
      if (llt.info() != Eigen::Success) return false;
      A.template block<B, B>(B * i, B * i) = llt.matrixL();
    }
    if (t == 0) return true;
    const int r0 = B * nb;
    for (int j = 0; j < nb; ++j) {
      Border S = A.block(r0, B * j, t, B);
      for (int k = first[std::size_t(j)]; k < j; ++k)
        S.noalias() -= A.block(r0, B * k, t, B) * A.template block<B, B>(B * j, B * k).transpose();
      A.template block<B, B>(B * j, B * j).template triangularView<Eigen::Lower>().transpose().template solveInPlace<Eigen::OnTheRight>(S);
      A.block(r0, B * j, t, B) = S;
    }
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxBorder, kMaxBorder> D = A.block(r0, r0, t, t);
    D.noalias() -= A.block(r0, 0, t, r0) * A.block(r0, 0, t, r0).transpose();
    Eigen::LLT<decltype(D)> llt(D);
    if (llt.info() != Eigen::Success) return false;
    A.block(r0, r0, t, t) = llt.matrixL();
    return true;
  }

  /// Solves \f$ L L^\top x = b \f$ in place with the factor of factor().
  static void solve(const Eigen::MatrixXd& L, const std::vector<int>& first, int t, Eigen::VectorXd& x) {
    const int nb = int(first.size());
    const int r0 = B * nb;
    // Forward: L y = b.
    for (int i = 0; i < nb; ++i) {
      BlockVec s = x.template segment<B>(B * i);
      for (int k = first[std::size_t(i)]; k < i; ++k)
        s.noalias() -= L.template block<B, B>(B * i, B * k) * x.template segment<B>(B * k);
      L.template block<B, B>(B * i, B * i).template triangularView<Eigen::Lower>().solveInPlace(s);
      x.template segment<B>(B * i) = s;
    }
    if (t > 0) {
      x.segment(r0, t).noalias() -= L.block(r0, 0, t, r0) * x.head(r0);
      L.block(r0, r0, t, t).template triangularView<Eigen::Lower>().solveInPlace(x.segment(r0, t));
      // Backward, border first: L_EE^T x_E = y_E.
      L.block(r0, r0, t, t).template triangularView<Eigen::Lower>().transpose().solveInPlace(x.segment(r0, t));
      x.head(r0).noalias() -= L.block(r0, 0, t, r0).transpose() * x.segment(r0, t);
    }
    // Backward: L^T x = y, column-oriented (block column i of L^T is block row i of L).
    for (int i = nb - 1; i >= 0; --i) {
      BlockVec s = x.template segment<B>(B * i);
      L.template block<B, B>(B * i, B * i).template triangularView<Eigen::Lower>().transpose().solveInPlace(s);
      x.template segment<B>(B * i) = s;
      for (int k = first[std::size_t(i)]; k < i; ++k)
        x.template segment<B>(B * k).noalias() -= L.template block<B, B>(B * i, B * k).transpose() * s;
    }
  }

  /// Floating-point work of factor() relative to a dense Cholesky of the
  /// same matrix, \f$ n^3/3 \f$ (exactly 1 for a full profile, less for a
  /// narrower one); used to fall back to a dense solver.
  [[nodiscard]] static double relative_work(const std::vector<int>& first, int t) {
    const double nb = double(first.size()), b = B, tb = t;
    double blocks = 0.0, border = 0.0;
    for (std::size_t i = 0; i < first.size(); ++i) {
      const double w = double(int(i) - first[i] + 1);  // blocks in row i, diagonal included
      blocks += w * w - w + 1.0 / 3.0;
      border += 2.0 * w - 1.0;
    }
    const double n = nb * b + tb;
    const double work = b * b * b * blocks + tb * b * b * border + tb * tb * nb * b + tb * tb * tb / 3.0;
    return n > 0 ? work / (n * n * n / 3.0) : 1.0;
  }
};

}  // namespace posefuse::detail

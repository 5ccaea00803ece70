#pragma once
/// @file
/// A symmetric block-sparse normal-equation system \f$ H \Delta = -b \f$ with
/// fixed B x B blocks, stored as the upper triangle of a column-major
/// Eigen::SparseMatrix whose pattern is built once (not API). The block
/// ordering is chosen once by approximate minimum degree on the *block*
/// graph (one node per B x B block, B times smaller than AMD on the scalar
/// matrix) and baked into the variable numbering, so the factorisation runs
/// with Eigen's NaturalOrdering and never copies or permutes the matrix.

#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace posefuse::detail {

/// Fill-reducing numbering of n blocks linked by `pairs` (block indices,
/// -1 for a fixed end): position[i] = the block's column in the system.
template <class Lazy = void>
[[nodiscard]] std::vector<int> block_amd_order(int n, const std::vector<std::pair<int, int>>& pairs) {
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(2 * pairs.size() + std::size_t(n));
  for (int i = 0; i < n; ++i) trip.emplace_back(i, i, 1.0);
  for (const auto& e : pairs) {
    if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
    trip.emplace_back(e.first, e.second, 1.0);
    trip.emplace_back(e.second, e.first, 1.0);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> Pinv;
  Eigen::AMDOrdering<int> amd;
  amd(A, Pinv);
  // Eigen's solvers factor P A P^T with P = Pinv^{-1}: old index i goes to P(i).
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> P = Pinv.inverse();
  std::vector<int> position(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) position[std::size_t(i)] = P.indices()(i);
  return position;
}

/// The system of n blocks of size B over edges linking two blocks (or one
/// block and a fixed, eliminated one: index -1).
template <int B>
class BlockSystem {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;

  /// Builds the pattern. `pairs[k]` are the (already ordered) block columns
  /// of edge k's two ends, -1 for a fixed end.
  void build(int n, const std::vector<std::pair<int, int>>& pairs) {
    n_ = n;
    std::vector<std::vector<int>> rows(static_cast<std::size_t>(n));  // row blocks of each block column
    for (const auto& e : pairs) {
      if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
      const int lo = std::min(e.first, e.second), hi = std::max(e.first, e.second);
      rows[std::size_t(hi)].push_back(lo);
    }
    std::vector<int> outer(std::size_t(n) * B + 1, 0);
    diag_m_.assign(std::size_t(n), 0);
    for (int c = 0; c < n; ++c) {
      std::vector<int>& r = rows[std::size_t(c)];
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
      diag_m_[std::size_t(c)] = static_cast<int>(r.size());
    }
    for (int c = 0; c < n; ++c)
      for (int s = 0; s < B; ++s)
        outer[std::size_t(c * B + s + 1)] = outer[std::size_t(c * B + s)] + B * diag_m_[std::size_t(c)] + s + 1;
    const int nnz = outer.back();
    H.resize(n * B, n * B);
    H.resizeNonZeros(nnz);
    std::copy(outer.begin(), outer.end(), H.outerIndexPtr());
    int* inner = H.innerIndexPtr();
    for (int c = 0; c < n; ++c) {
      const std::vector<int>& r = rows[std::size_t(c)];
      for (int s = 0; s < B; ++s) {
        int k = outer[std::size_t(c * B + s)];
        for (const int rb : r)
          for (int a = 0; a < B; ++a) inner[k++] = rb * B + a;
        for (int a = 0; a <= s; ++a) inner[k++] = c * B + a;
      }
    }
    off_m_.assign(pairs.size(), -1);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto& e = pairs[k];
      if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
      const int lo = std::min(e.first, e.second), hi = std::max(e.first, e.second);
      const std::vector<int>& r = rows[std::size_t(hi)];
      off_m_[k] = static_cast<int>(std::lower_bound(r.begin(), r.end(), lo) - r.begin());
    }
    pairs_ = pairs;
    b.resize(n * B);
  }

  /// Zeroes H's values and b.
  void set_zero() {
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
    b.setZero();
  }

  /// Adds \f$ H_{ii}, H_{ij} (= J_i^\top W J_j), H_{jj}, b_i, b_j \f$ of edge k.
  void add(std::size_t k, const Block& Hii, const Block& Hij, const Block& Hjj, const Vec& bi,
           const Vec& bj) {
    const int i = pairs_[k].first, j = pairs_[k].second;
    if (i >= 0) add_diag(i, Hii, bi);
    if (j >= 0) add_diag(j, Hjj, bj);
    if (i < 0 || j < 0) return;
    if (i == j) {  // a self-loop: both ends on one block
      const Block S = Hij + Hij.transpose();
      add_diag(i, S, Vec::Zero());
      return;
    }
    double* v = H.valuePtr();
    const int* outer = H.outerIndexPtr();
    const int m = off_m_[k];
    if (i < j) {  // block (i, j) lives in column j
      for (int c = 0; c < B; ++c) {
        double* col = v + outer[j * B + c] + B * m;
        for (int a = 0; a < B; ++a) col[a] += Hij(a, c);
      }
    } else {  // block (j, i) = Hij^T lives in column i
      for (int c = 0; c < B; ++c) {
        double* col = v + outer[i * B + c] + B * m;
        for (int a = 0; a < B; ++a) col[a] += Hij(c, a);
      }
    }
  }

  /// The diagonal of H (for Levenberg–Marquardt scaling).
  [[nodiscard]] Eigen::VectorXd diagonal() const {
    Eigen::VectorXd d(n_ * B);
    const int* outer = H.outerIndexPtr();
    for (int c = 0; c < n_ * B; ++c) d(c) = H.valuePtr()[outer[c + 1] - 1];
    return d;
  }
  /// Adds `delta` to H's diagonal.
  void add_to_diagonal(const Eigen::VectorXd& delta) {
    const int* outer = H.outerIndexPtr();
    for (int c = 0; c < n_ * B; ++c) H.valuePtr()[outer[c + 1] - 1] += delta(c);
  }
  /// \f$ x^\top H x \f$ from the upper triangle.
  [[nodiscard]] double quadratic_form(const Eigen::VectorXd& x) const {
    const Eigen::VectorXd Hx = H.template selfadjointView<Eigen::Upper>() * x;
    return x.dot(Hx);
  }

  Eigen::SparseMatrix<double> H;  ///< upper triangle, column-major
  Eigen::VectorXd b;              ///< gradient \f$ \sum J^\top W e \f$

 private:
  void add_diag(int i, const Block& Hii, const Vec& bi) {
    double* v = H.valuePtr();
    const int* outer = H.outerIndexPtr();
    const int m = diag_m_[std::size_t(i)];
    for (int c = 0; c < B; ++c) {
      double* col = v + outer[i * B + c] + B * m;
      for (int a = 0; a <= c; ++a) col[a] += Hii(a, c);
    }
    b.template segment<B>(i * B) += bi;
  }

  int n_ = 0;
  std::vector<int> diag_m_;  ///< number of off-diagonal row blocks per block column
  std::vector<int> off_m_;   ///< per edge: index of its off-diagonal block in its column
  std::vector<std::pair<int, int>> pairs_;
};

/// The sparse Cholesky used on BlockSystem: LDLᵀ on the upper triangle,
/// natural ordering (the numbering already is fill-reducing).
using BlockCholesky =
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::NaturalOrdering<int>>;

}  // namespace posefuse::detail

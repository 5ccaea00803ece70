#pragma once
/// @file
/// A symmetric block-sparse normal-equation system \f$ H \Delta = -b \f$ with
/// fixed B x B blocks and its sparse Cholesky factorisation (not API).
///
/// The block ordering is chosen once by approximate minimum degree on the
/// *block* graph (one node per B x B block: B times fewer nodes than AMD on
/// the scalar matrix) and baked into the variable numbering. H is stored as
/// block columns (the strictly upper blocks of each column, then its
/// diagonal block), filled in place each iteration on a pattern built once.
///
/// BlockCholesky is the up-looking sparse Cholesky of Davis, "Direct Methods
/// for Sparse Linear Systems", SIAM 2006, Ch. 4 (elimination tree, row
/// patterns by `ereach`), run on B x B blocks: every scalar operation of the
/// textbook algorithm becomes a fixed-size B x B product, triangular solve
/// or Cholesky, so the index work is B² times smaller than a scalar
/// simplicial factorisation and the arithmetic is vectorised.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/OrderingMethods>
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
    std::vector<std::vector<int>> rows(static_cast<std::size_t>(n));
    for (const auto& e : pairs) {
      if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
      rows[std::size_t(std::max(e.first, e.second))].push_back(std::min(e.first, e.second));
    }
    colptr.assign(std::size_t(n) + 1, 0);
    rowidx.clear();
    for (int c = 0; c < n; ++c) {
      std::vector<int>& r = rows[std::size_t(c)];
      std::sort(r.begin(), r.end());
      r.erase(std::unique(r.begin(), r.end()), r.end());
      rowidx.insert(rowidx.end(), r.begin(), r.end());
      colptr[std::size_t(c) + 1] = static_cast<int>(rowidx.size());
    }
    off.assign(rowidx.size(), Block::Zero());
    diag.assign(std::size_t(n), Block::Zero());
    slot_.assign(pairs.size(), -1);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto& e = pairs[k];
      if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
      const int lo = std::min(e.first, e.second), hi = std::max(e.first, e.second);
      const auto first = rowidx.begin() + colptr[std::size_t(hi)];
      const auto last = rowidx.begin() + colptr[std::size_t(hi) + 1];
      slot_[k] = static_cast<int>(std::lower_bound(first, last, lo) - rowidx.begin());
    }
    pairs_ = pairs;
    b.resize(n * B);
  }

  /// Number of block columns.
  [[nodiscard]] int size() const noexcept { return n_; }

  /// Zeroes H and b.
  void set_zero() {
    for (Block& m : off) m.setZero();
    for (Block& m : diag) m.setZero();
    b.setZero();
  }

  /// Adds \f$ H_{ii}, H_{ij} (= J_i^\top W J_j), H_{jj}, b_i, b_j \f$ of edge k.
  void add(std::size_t k, const Block& Hii, const Block& Hij, const Block& Hjj, const Vec& bi,
           const Vec& bj) {
    const int i = pairs_[k].first, j = pairs_[k].second;
    if (i >= 0) {
      diag[std::size_t(i)] += Hii;
      b.template segment<B>(i * B) += bi;
    }
    if (j >= 0) {
      diag[std::size_t(j)] += Hjj;
      b.template segment<B>(j * B) += bj;
    }
    if (i < 0 || j < 0 || i == j) return;
    if (i < j) off[std::size_t(slot_[k])] += Hij;  // block (i, j), column j
    else off[std::size_t(slot_[k])] += Hij.transpose();  // block (j, i) = Hij^T, column i
  }

  /// The diagonal of H (for Levenberg–Marquardt scaling).
  [[nodiscard]] Eigen::VectorXd diagonal() const {
    Eigen::VectorXd d(n_ * B);
    for (int c = 0; c < n_; ++c) d.template segment<B>(c * B) = diag[std::size_t(c)].diagonal();
    return d;
  }
  /// Adds `delta` to H's diagonal.
  void add_to_diagonal(const Eigen::VectorXd& delta) {
    for (int c = 0; c < n_; ++c) diag[std::size_t(c)].diagonal() += delta.template segment<B>(c * B);
  }
  /// \f$ x^\top H x \f$.
  [[nodiscard]] double quadratic_form(const Eigen::VectorXd& x) const {
    double q = 0.0;
    for (int c = 0; c < n_; ++c) {
      const Vec xc = x.template segment<B>(c * B);
      q += xc.dot(diag[std::size_t(c)] * xc);
      for (int p = colptr[std::size_t(c)]; p < colptr[std::size_t(c) + 1]; ++p)
        q += 2.0 * x.template segment<B>(rowidx[std::size_t(p)] * B).dot(off[std::size_t(p)] * xc);
    }
    return q;
  }

  std::vector<int> colptr;  ///< block column c's strictly upper blocks are [colptr[c], colptr[c+1])
  std::vector<int> rowidx;  ///< their row blocks, increasing
  std::vector<Block> off;   ///< their values
  std::vector<Block> diag;  ///< diagonal blocks (full, symmetric)
  Eigen::VectorXd b;        ///< gradient \f$ \sum J^\top W e \f$

 private:
  int n_ = 0;
  std::vector<int> slot_;  ///< per edge: index of its off-diagonal block
  std::vector<std::pair<int, int>> pairs_;
};

/// Up-looking block sparse Cholesky \f$ H = L L^\top \f$ (see the file comment).
template <int B>
class BlockCholesky {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;

  /// Symbolic analysis: elimination tree and the pattern of L (Davis Alg. 4.1, 4.2).
  void analyze(const BlockSystem<B>& sys) {
    n_ = sys.size();
    const std::size_t n = std::size_t(n_);
    parent_.assign(n, -1);
    std::vector<int> ancestor(n, -1);
    for (int k = 0; k < n_; ++k) {
      for (int p = sys.colptr[std::size_t(k)]; p < sys.colptr[std::size_t(k) + 1]; ++p) {
        int i = sys.rowidx[std::size_t(p)];
        while (i != -1 && i < k) {
          const int next = ancestor[std::size_t(i)];
          ancestor[std::size_t(i)] = k;
          if (next == -1) parent_[std::size_t(i)] = k;
          i = next;
        }
      }
    }
    // Column counts of L (strictly lower) from every row pattern.
    std::vector<int> count(n, 0);
    stack_.assign(n, 0);
    mark_.assign(n, -1);
    for (int k = 0; k < n_; ++k) {
      const int top = ereach(sys, k);
      for (int t = top; t < n_; ++t) ++count[std::size_t(stack_[std::size_t(t)])];
    }
    Lp_.assign(n + 1, 0);
    for (std::size_t c = 0; c < n; ++c) Lp_[c + 1] = Lp_[c] + count[c];
    Li_.assign(std::size_t(Lp_[n]), 0);
    Lx_.assign(std::size_t(Lp_[n]), Block::Zero());
    Ldinv_.assign(n, Block::Zero());
    x_.assign(n, Block::Zero());
  }

  /// Numeric factorisation of H (same pattern as analyzed).
  /// @return false when H is not (numerically) positive definite
  [[nodiscard]] bool factorize(const BlockSystem<B>& sys) {
    std::vector<int> next(Lp_.begin(), Lp_.end() - 1);  // next free slot of each column
    for (int k = 0; k < n_; ++k) {
      const int top = ereach(sys, k);
      for (int p = sys.colptr[std::size_t(k)]; p < sys.colptr[std::size_t(k) + 1]; ++p)
        x_[std::size_t(sys.rowidx[std::size_t(p)])] = sys.off[std::size_t(p)];
      Block d = sys.diag[std::size_t(k)];
      for (int t = top; t < n_; ++t) {
        const int i = stack_[std::size_t(t)];
        // y = L_ii^{-1} x_i; L(k, i) = y^T.
        const Block y = Ldinv_[std::size_t(i)] * x_[std::size_t(i)];
        x_[std::size_t(i)].setZero();
        for (int p = Lp_[std::size_t(i)]; p < next[std::size_t(i)]; ++p)
          x_[std::size_t(Li_[std::size_t(p)])].noalias() -= Lx_[std::size_t(p)] * y;
        d.noalias() -= y.transpose() * y;
        const int p = next[std::size_t(i)]++;
        Li_[std::size_t(p)] = k;
        Lx_[std::size_t(p)] = y.transpose();
      }
      const Eigen::LLT<Block> llt(d);
      if (llt.info() != Eigen::Success) return false;
      const Block L = llt.matrixL();
      Ldinv_[std::size_t(k)] = L.template triangularView<Eigen::Lower>().solve(Block::Identity());
      if (!Ldinv_[std::size_t(k)].allFinite()) return false;
    }
    return true;
  }

  /// \f$ H^{-1} r \f$ from the factor: \f$ L y = r \f$, then \f$ L^\top x = y \f$.
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::VectorXd& r) const {
    Eigen::VectorXd y = r;
    for (int j = 0; j < n_; ++j) {
      const Vec yj = Ldinv_[std::size_t(j)] * y.template segment<B>(j * B);
      y.template segment<B>(j * B) = yj;
      for (int p = Lp_[std::size_t(j)]; p < Lp_[std::size_t(j) + 1]; ++p)
        y.template segment<B>(Li_[std::size_t(p)] * B).noalias() -= Lx_[std::size_t(p)] * yj;
    }
    for (int j = n_ - 1; j >= 0; --j) {
      Vec yj = y.template segment<B>(j * B);
      for (int p = Lp_[std::size_t(j)]; p < Lp_[std::size_t(j) + 1]; ++p)
        yj.noalias() -= Lx_[std::size_t(p)].transpose() * y.template segment<B>(Li_[std::size_t(p)] * B);
      y.template segment<B>(j * B).noalias() = Ldinv_[std::size_t(j)].transpose() * yj;
    }
    return y;
  }

  /// Number of strictly lower blocks of L.
  [[nodiscard]] std::size_t factor_blocks() const noexcept { return Li_.size(); }

 private:
  /// Pattern of row k of L in topological order: stack_[top .. n) (Davis Alg. 4.2).
  int ereach(const BlockSystem<B>& sys, int k) {
    int top = n_;
    mark_[std::size_t(k)] = k;
    for (int p = sys.colptr[std::size_t(k)]; p < sys.colptr[std::size_t(k) + 1]; ++p) {
      int i = sys.rowidx[std::size_t(p)];
      int len = 0;
      // Walk up the tree to a marked node, then push the path (reversed) on the stack.
      path_.clear();
      for (; i != -1 && mark_[std::size_t(i)] != k; i = parent_[std::size_t(i)]) {
        path_.push_back(i);
        mark_[std::size_t(i)] = k;
        ++len;
      }
      while (len > 0) stack_[std::size_t(--top)] = path_[std::size_t(--len)];
    }
    return top;
  }

  int n_ = 0;
  std::vector<int> parent_;  ///< elimination tree
  std::vector<int> Lp_, Li_;  ///< L's strictly lower blocks, column by column
  std::vector<Block> Lx_;
  std::vector<Block> Ldinv_;  ///< inverses of the diagonal blocks' lower Cholesky factors
  std::vector<Block> x_;   ///< work: the column being eliminated
  std::vector<int> stack_, mark_, path_;
};

}  // namespace posefuse::detail

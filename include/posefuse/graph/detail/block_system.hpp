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
/// patterns by `ereach`, found once by the symbolic analysis and kept for
/// every numeric factorisation), run on B x B blocks: every scalar operation of the
/// textbook algorithm becomes a fixed-size B x B product, triangular solve
/// or Cholesky, so the index work is B² times smaller than a scalar
/// simplicial factorisation and the arithmetic is vectorised.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace posefuse::detail {

/// Fill-reducing numbering of n blocks linked by `pairs` (block indices,
/// -1 for a fixed end): position[i] = the block's column in the system.
template <class Lazy = void>
[[nodiscard]] std::vector<int> block_amd_order(int n, const std::vector<std::pair<int, int>>& pairs) {
  // The block graph's full symmetric pattern with its diagonal, sorted by
  // row within each column, built directly (counting sort); parallel edges
  // are merged.
  std::vector<int> count(std::size_t(n) + 1, 0);
  for (const auto& e : pairs) {
    if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
    ++count[std::size_t(e.first) + 1];
    ++count[std::size_t(e.second) + 1];
  }
  for (int i = 0; i < n; ++i) count[std::size_t(i) + 1] += count[std::size_t(i)] + 1;  // + the diagonal
  std::vector<int> rows(static_cast<std::size_t>(count[std::size_t(n)]));
  std::vector<int> fill(count.begin(), count.end() - 1);
  for (int i = 0; i < n; ++i) rows[std::size_t(fill[std::size_t(i)]++)] = i;
  for (const auto& e : pairs) {
    if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
    rows[std::size_t(fill[std::size_t(e.first)]++)] = e.second;
    rows[std::size_t(fill[std::size_t(e.second)]++)] = e.first;
  }
  std::vector<int> nnz_per_col(std::size_t(n), 0);
  std::size_t total = 0;
  for (int c = 0; c < n; ++c) {
    const auto first = rows.begin() + count[std::size_t(c)], end = rows.begin() + count[std::size_t(c) + 1];
    std::sort(first, end);
    nnz_per_col[std::size_t(c)] = int(std::unique(first, end) - first);
    total += std::size_t(nnz_per_col[std::size_t(c)]);
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.resizeNonZeros(Eigen::Index(total));
  int q = 0;
  for (int c = 0; c < n; ++c) {
    A.outerIndexPtr()[c] = q;
    for (int t = 0; t < nnz_per_col[std::size_t(c)]; ++t) {
      A.innerIndexPtr()[q] = rows[std::size_t(count[std::size_t(c)] + t)];
      A.valuePtr()[q++] = 1.0;
    }
  }
  A.outerIndexPtr()[n] = q;
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> Pinv;
  Eigen::AMDOrdering<int>()(A, Pinv);  // A is symmetric: its A + A^T has the same pattern
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
    // Two-pass CSR (counting sort by column, then by row within a column):
    // no per-column vectors, and the arrays keep their capacity when the
    // system is rebuilt, so a reused system allocates nothing.
    n_ = n;
    const std::size_t m = pairs.size();
    colptr.assign(std::size_t(n) + 1, 0);
    for (const auto& e : pairs)
      if (e.first >= 0 && e.second >= 0 && e.first != e.second) ++colptr[std::size_t(std::max(e.first, e.second)) + 1];
    for (int c = 0; c < n; ++c) colptr[std::size_t(c) + 1] += colptr[std::size_t(c)];
    // Entries (row, edge) sorted by column, then by row through a second
    // counting pass over the rows.
    work_.assign(std::size_t(n) + 1, 0);
    for (const auto& e : pairs)
      if (e.first >= 0 && e.second >= 0 && e.first != e.second) ++work_[std::size_t(std::min(e.first, e.second)) + 1];
    for (int r = 0; r < n; ++r) work_[std::size_t(r) + 1] += work_[std::size_t(r)];
    by_row_.resize(std::size_t(colptr[std::size_t(n)]));
    for (std::size_t k = 0; k < m; ++k) {
      const auto& e = pairs[k];
      if (e.first < 0 || e.second < 0 || e.first == e.second) continue;
      by_row_[std::size_t(work_[std::size_t(std::min(e.first, e.second))]++)] = int(k);
    }
    // Visiting edges in increasing row order and dropping each into its
    // column keeps every column's rows sorted.
    next_.assign(colptr.begin(), colptr.end() - 1);
    rowidx.resize(by_row_.size());
    slot_.assign(m, -1);
    for (const int k : by_row_) {
      const auto& e = pairs[std::size_t(k)];
      const int lo = std::min(e.first, e.second), hi = std::max(e.first, e.second);
      const int q = next_[std::size_t(hi)];
      if (q > colptr[std::size_t(hi)] && rowidx[std::size_t(q) - 1] == lo) {
        slot_[std::size_t(k)] = q - 1;  // a parallel edge: same block
        continue;
      }
      rowidx[std::size_t(q)] = lo;
      slot_[std::size_t(k)] = q;
      ++next_[std::size_t(hi)];
    }
    // Compact the columns (parallel edges left gaps).
    int w = 0;
    remap_.resize(rowidx.size());
    for (int c = 0; c < n; ++c) {
      const int begin = colptr[std::size_t(c)], end = next_[std::size_t(c)];
      colptr[std::size_t(c)] = w;
      for (int q = begin; q < end; ++q) {
        remap_[std::size_t(q)] = w;
        rowidx[std::size_t(w++)] = rowidx[std::size_t(q)];
      }
    }
    colptr[std::size_t(n)] = w;
    rowidx.resize(std::size_t(w));
    for (int& q : slot_)
      if (q >= 0) q = remap_[std::size_t(q)];
    off.resize(rowidx.size());
    diag.resize(std::size_t(n));
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
  /// H as a dense symmetric matrix (small systems: tests, covariances).
  [[nodiscard]] Eigen::MatrixXd dense() const {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n_ * B, n_ * B);
    for (int c = 0; c < n_; ++c) {
      H.template block<B, B>(c * B, c * B) = diag[std::size_t(c)];
      for (int p = colptr[std::size_t(c)]; p < colptr[std::size_t(c) + 1]; ++p) {
        const int r = rowidx[std::size_t(p)];
        H.template block<B, B>(r * B, c * B) = off[std::size_t(p)];
        H.template block<B, B>(c * B, r * B) = off[std::size_t(p)].transpose();
      }
    }
    return H;
  }
  /// Bytes of heap storage held (capacity, including build() scratch).
  [[nodiscard]] std::size_t capacity_bytes() const noexcept {
    const std::size_t ints = colptr.capacity() + rowidx.capacity() + slot_.capacity() + work_.capacity() +
                             by_row_.capacity() + next_.capacity() + remap_.capacity();
    return sizeof(int) * ints + sizeof(Block) * (off.capacity() + diag.capacity()) +
           sizeof(double) * std::size_t(b.size()) + sizeof(std::pair<int, int>) * pairs_.capacity();
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
  std::vector<int> work_, by_row_, next_, remap_;  ///< build() scratch
};

/// Up-looking block sparse Cholesky \f$ H = L L^\top \f$ (see the file comment).
template <int B>
class BlockCholesky {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  using Vec = Eigen::Matrix<double, B, 1>;

  /// Symbolic analysis: elimination tree, the pattern of L and its row
  /// patterns (Davis Alg. 4.1, 4.2).
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
    // Every row pattern of L (topological order), kept for factorize(), and
    // the column counts of L (strictly lower).
    Lp_.assign(n + 1, 0);
    Rp_.assign(n + 1, 0);
    Ri_.clear();
    stack_.resize(n);
    mark_.assign(n, -1);
    for (int k = 0; k < n_; ++k) {
      const int top = ereach(sys, k);
      for (int t = top; t < n_; ++t) {
        const int i = stack_[std::size_t(t)];
        Ri_.push_back(i);
        ++Lp_[std::size_t(i) + 1];
      }
      Rp_[std::size_t(k) + 1] = int(Ri_.size());
    }
    for (std::size_t c = 0; c < n; ++c) Lp_[c + 1] += Lp_[c];
    // Row k's entries are appended to their columns in increasing k, so
    // every column's rows are sorted.
    next_.resize(n);
    std::copy(Lp_.begin(), Lp_.end() - 1, next_.begin());
    Li_.resize(std::size_t(Lp_[n]));
    for (int k = 0; k < n_; ++k)
      for (int t = Rp_[std::size_t(k)]; t < Rp_[std::size_t(k) + 1]; ++t)
        Li_[std::size_t(next_[std::size_t(Ri_[std::size_t(t)])]++)] = k;
    // L's blocks are written by factorize() before they are read; only the
    // accumulator x_ must start at zero (factorize() leaves it zero).
    Lx_.resize(std::size_t(Lp_[n]));
    Ldinv_.resize(n);
    x_.assign(n, Block::Zero());
  }

  /// Numeric factorisation of H (same pattern as analyzed).
  /// @return false when H is not (numerically) positive definite
  [[nodiscard]] bool factorize(const BlockSystem<B>& sys) {
    std::vector<int>& next = next_;  // next free slot of each column
    std::copy(Lp_.begin(), Lp_.end() - 1, next.begin());
    for (int k = 0; k < n_; ++k) {
      for (int p = sys.colptr[std::size_t(k)]; p < sys.colptr[std::size_t(k) + 1]; ++p)
        x_[std::size_t(sys.rowidx[std::size_t(p)])] = sys.off[std::size_t(p)];
      Block d = sys.diag[std::size_t(k)];
      for (int t = Rp_[std::size_t(k)]; t < Rp_[std::size_t(k) + 1]; ++t) {
        const int i = Ri_[std::size_t(t)];
        // y = L_ii^{-1} x_i; L(k, i) = y^T.
        const Block y = Ldinv_[std::size_t(i)] * x_[std::size_t(i)];
        x_[std::size_t(i)].setZero();
        for (int p = Lp_[std::size_t(i)]; p < next[std::size_t(i)]; ++p)
          x_[std::size_t(Li_[std::size_t(p)])].noalias() -= Lx_[std::size_t(p)] * y;
        d.noalias() -= y.transpose() * y;
        Lx_[std::size_t(next[std::size_t(i)]++)] = y.transpose();  // Li_ holds k there
      }
      if (!lower_cholesky_inverse(d, Ldinv_[std::size_t(k)])) {
        for (Block& m : x_) m.setZero();  // leave the accumulator clean for the next call
        return false;
      }
    }
    return true;
  }

  /// \f$ L^{-1} \f$ of the lower Cholesky factor L of a symmetric B x B block
  /// (the lower triangle of `d` is read), by the textbook column Cholesky
  /// and forward substitution on the identity, fixed-size and unrolled.
  /// @return false when a pivot is not positive and finite
  [[nodiscard]] static bool lower_cholesky_inverse(const Block& d, Block& Linv) {
    Block L = Block::Zero();
    for (int j = 0; j < B; ++j) {
      double s = d(j, j);
      for (int p = 0; p < j; ++p) s -= L(j, p) * L(j, p);
      if (!(s > 0.0) || !std::isfinite(s)) return false;
      const double ljj = std::sqrt(s);
      L(j, j) = ljj;
      const double inv = 1.0 / ljj;
      for (int i = j + 1; i < B; ++i) {
        double t = d(i, j);
        for (int p = 0; p < j; ++p) t -= L(i, p) * L(j, p);
        L(i, j) = t * inv;
      }
    }
    Linv.setZero();
    for (int c = 0; c < B; ++c) {
      Linv(c, c) = 1.0 / L(c, c);
      for (int i = c + 1; i < B; ++i) {
        double t = 0.0;
        for (int p = c; p < i; ++p) t -= L(i, p) * Linv(p, c);
        Linv(i, c) = t / L(i, i);
      }
    }
    return Linv.allFinite();
  }

  /// \f$ H^{-1} r \f$ from the factor: \f$ L y = r \f$, then \f$ L^\top x = y \f$.
  [[nodiscard]] Eigen::VectorXd solve(const Eigen::VectorXd& r) const {
    Eigen::VectorXd y = r;
    solve_in_place(y);
    return y;
  }

  /// solve() overwriting its argument.
  void solve_in_place(Eigen::VectorXd& y) const {
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
  }

  /// Bytes of heap storage held (capacity, the factor and its work arrays).
  [[nodiscard]] std::size_t capacity_bytes() const noexcept {
    const std::size_t ints = parent_.capacity() + Lp_.capacity() + Li_.capacity() + Rp_.capacity() +
                             Ri_.capacity() + stack_.capacity() + mark_.capacity() + path_.capacity() +
                             next_.capacity();
    return sizeof(int) * ints + sizeof(Block) * (Lx_.capacity() + Ldinv_.capacity() + x_.capacity());
  }

 private:
  /// Pattern of row k of L in topological order: stack_[top .. n) (Davis Alg. 4.2).
  /// Run once per row by analyze(), which keeps the patterns for factorize().
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
  std::vector<int> Rp_, Ri_;  ///< L's rows: row k's columns, in the order factorize() eliminates them
  std::vector<Block> Lx_;
  std::vector<Block> Ldinv_;  ///< inverses of the diagonal blocks' lower Cholesky factors
  std::vector<Block> x_;   ///< work: the column being eliminated
  std::vector<int> stack_, mark_, path_, next_;
};

}  // namespace posefuse::detail

#pragma once
/// @file
/// Schur-complement marginalisation for sliding-window estimators, kept
/// positive semi-definite, returned in square-root (residual / Jacobian)
/// form.
///
/// A window's cost linearised at \f$ x_0 \f$ is
/// \f$ F(x_0 \oplus \delta) \approx \mathrm{const} + 2 b^\top \delta + \delta^\top H \delta \f$
/// with \f$ H = \sum J^\top \Omega J \f$, \f$ b = \sum J^\top \Omega e \f$. Splitting
/// \f$ \delta = [\delta_m; \delta_r] \f$ into the variables to remove (m) and to
/// keep (r) and minimising over \f$ \delta_m \f$ leaves the prior
/// \f[ H^* = H_{rr} - H_{rm} H_{mm}^{+} H_{mr}, \qquad b^* = b_r - H_{rm} H_{mm}^{+} b_m \f]
/// (the Schur complement; VINS-Mono, Qin et al., T-RO 2018, Sec. VI-D;
/// Sibley et al. 2010 for the sliding-window filter). \f$ H_{mm}^{+} \f$ is
/// the eigenvalue-thresholded pseudo-inverse. Round-off makes \f$ H^* \f$
/// slightly indefinite on near-singular inputs (VINS-Mono issue #432), so
/// \f$ H^* = V \Lambda V^\top \f$ is decomposed and eigenvalues below
/// \f$ \epsilon \lambda_{\max} \f$ are set to 0; the prior is then the
/// residual
/// \f[ r(\delta_r) = r_0 + J \delta_r, \qquad J = \Lambda_+^{1/2} V_+^\top, \quad
///     r_0 = \Lambda_+^{-1/2} V_+^\top b^*, \f]
/// so that \f$ J^\top J = V_+ \Lambda_+ V_+^\top \f$ is PSD by construction
/// and \f$ J^\top r_0 \f$ is \f$ b^* \f$ projected on its range.
///
/// **Re-linearisation (first-estimate Jacobians).** J and r₀ are fixed at
/// the linearisation point \f$ x_{r,0} \f$ of the kept variables; a solver
/// evaluates the prior at a later estimate \f$ x_r \f$ as
/// \f$ r_0 + J\,(x_r \ominus x_{r,0}) \f$ and must keep linearising the
/// variables involved in the prior at \f$ x_{r,0} \f$ (first-estimate
/// Jacobians; Huang, Mourikis, Roumeliotis 2009), or the prior adds
/// spurious information along unobservable directions.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// A marginalisation prior in residual form \f$ r_0 + J\,\delta_r \f$ (see the file comment).
struct MarginalizationPrior {
  std::vector<int> kept;  ///< indices of the kept variables in the original system, in order
  Eigen::MatrixXd J;      ///< \f$ \Lambda_+^{1/2} V_+^\top \f$ (rank x kept)
  Eigen::VectorXd r0;     ///< \f$ \Lambda_+^{-1/2} V_+^\top b^* \f$ (rank)
  int clamped = 0;        ///< eigenvalues of \f$ H^* \f$ set to 0 (numerically zero or negative)

  /// The prior's residual at \f$ \delta_r = x_r \ominus x_{r,0} \f$.
  [[nodiscard]] Eigen::VectorXd residual(const Eigen::VectorXd& delta_r) const { return r0 + J * delta_r; }
  /// Its information \f$ J^\top J \f$ (PSD).
  [[nodiscard]] Eigen::MatrixXd information() const { return J.transpose() * J; }
  /// Its gradient term \f$ J^\top r_0 \f$.
  [[nodiscard]] Eigen::VectorXd gradient() const { return J.transpose() * r0; }
};

/// Marginalises the variables `remove` out of the linearised system (H, b).
/// @param[in] H symmetric PSD information of the window (n x n)
/// @param[in] b gradient term (n)
/// @param[in] remove indices to marginalise (distinct, in [0, n))
/// @param[in] eps relative eigenvalue threshold for \f$ H_{mm}^{+} \f$ and the PSD clamp
/// @return the prior on the other variables (in increasing index order)
/// @throws posefuse::invalid_argument for mismatched sizes, non-finite or
///         non-symmetric H, bad indices, or nothing left to keep
template <class Lazy = void>
[[nodiscard]] MarginalizationPrior marginalize(const Eigen::MatrixXd& H, const Eigen::VectorXd& b,
                                               const std::vector<int>& remove, double eps = 1e-10) {
  const Eigen::Index n = H.rows();
  if (H.cols() != n || b.size() != n)
    throw invalid_argument("marginalize: H must be square and b of the same size");
  if (!H.allFinite() || !b.allFinite()) throw invalid_argument("marginalize: H or b is not finite");
  const double scale = std::max(1.0, H.cwiseAbs().maxCoeff());
  if (!((H - H.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale))
    throw invalid_argument("marginalize: H is not symmetric");
  std::vector<char> is_removed(static_cast<std::size_t>(n), 0);
  for (const int i : remove) {
    if (i < 0 || i >= n) throw invalid_argument("marginalize: index " + std::to_string(i) + " is out of range");
    if (is_removed[std::size_t(i)]) throw invalid_argument("marginalize: index " + std::to_string(i) + " is repeated");
    is_removed[std::size_t(i)] = 1;
  }
  MarginalizationPrior prior;
  std::vector<int> m;
  for (int i = 0; i < n; ++i) (is_removed[std::size_t(i)] ? m : prior.kept).push_back(i);
  if (prior.kept.empty()) throw invalid_argument("marginalize: no variable is left to keep");
  const Eigen::Index nm = static_cast<Eigen::Index>(m.size());
  const Eigen::Index nr = static_cast<Eigen::Index>(prior.kept.size());
  const auto pick = [&H](const std::vector<int>& rows, const std::vector<int>& cols) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t r = 0; r < rows.size(); ++r)
      for (std::size_t c = 0; c < cols.size(); ++c) out(Eigen::Index(r), Eigen::Index(c)) = H(rows[r], cols[c]);
    return out;
  };
  const Eigen::MatrixXd Hrr = pick(prior.kept, prior.kept);
  Eigen::VectorXd br(nr);
  for (Eigen::Index k = 0; k < nr; ++k) br(k) = b(prior.kept[std::size_t(k)]);
  Eigen::MatrixXd Hs = Hrr;
  Eigen::VectorXd bs = br;
  if (nm > 0) {
    const Eigen::MatrixXd Hmm = pick(m, m);
    const Eigen::MatrixXd Hrm = pick(prior.kept, m);
    Eigen::VectorXd bm(nm);
    for (Eigen::Index k = 0; k < nm; ++k) bm(k) = b(m[std::size_t(k)]);
    // Pseudo-inverse of H_mm by eigenvalues (symmetrised first).
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Hmm + Hmm.transpose()));
    const double lmax = std::max(es.eigenvalues().cwiseAbs().maxCoeff(), 0.0);
    Eigen::VectorXd inv(nm);
    for (Eigen::Index k = 0; k < nm; ++k) {
      const double l = es.eigenvalues()(k);
      inv(k) = l > eps * lmax && l > 0 ? 1.0 / l : 0.0;
    }
    const Eigen::MatrixXd HrmV = Hrm * es.eigenvectors();
    Hs.noalias() -= HrmV * inv.asDiagonal() * HrmV.transpose();
    bs.noalias() -= HrmV * (inv.asDiagonal() * (es.eigenvectors().transpose() * bm));
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Hs + Hs.transpose()));
  const double lmax = std::max(es.eigenvalues().maxCoeff(), 0.0);
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < nr; ++k) {
    if (es.eigenvalues()(k) > eps * lmax && es.eigenvalues()(k) > 0) keep.push_back(k);
    else ++prior.clamped;
  }
  prior.J.resize(static_cast<Eigen::Index>(keep.size()), nr);
  prior.r0.resize(static_cast<Eigen::Index>(keep.size()));
  for (std::size_t q = 0; q < keep.size(); ++q) {
    const double l = es.eigenvalues()(keep[q]);
    const Eigen::VectorXd v = es.eigenvectors().col(keep[q]);
    prior.J.row(Eigen::Index(q)) = std::sqrt(l) * v.transpose();
    prior.r0(Eigen::Index(q)) = v.dot(bs) / std::sqrt(l);
  }
  return prior;
}

}  // namespace posefuse

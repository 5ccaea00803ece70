#pragma once
/// @file
/// Camera pose from 3-D points and their normalised image coordinates
/// (perspective-n-point) with RANSAC, then Gauss–Newton refinement on SE(3).
///
/// **Conventions.** `points_w[i]` is a point in some frame w (m or any common
/// unit), `normalised[i]` its observation (x/z, y/z) in the camera. The
/// result is `T_w_c`, the camera pose in w: \f$ p_w = T_{wc}\,p_c \f$. The
/// residual of a correspondence is \f$ r = \pi(T_{wc}^{-1} p_w) - m \f$ with
/// \f$ \pi(p) = (x/z, y/z) \f$, in normalised units (multiply by the focal
/// length for pixels); a point at depth \f$ z \le \f$ 1e-6 in the camera is
/// never an inlier.
///
/// **Hypotheses.** Each RANSAC trial solves the direct linear transform (DLT,
/// Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §7.1) for the
/// 3×4 matrix \f$ P = [R \mid t] \f$ from 6 correspondences, with the 3-D
/// points centred and scaled to unit mean distance first (H&Z §4.4.4):
/// \f$ m \times P\,[p;1] = 0 \f$ gives two rows per point, the null vector of
/// the 12×12 system A (eigenvector of the smallest eigenvalue of
/// \f$ A^\top A \f$) is P up to scale, and the closest rotation to its left
/// block (SVD, scale = mean singular value, sign from det > 0) gives R and t.
/// DLT is chosen because it is short, has no branch on the point
/// configuration and is exact on noise-free data; it needs non-coplanar
/// points (a planar sample is singular and the trial is skipped). When a
/// `guess` is given it is scored as the first hypothesis, so a good guess
/// survives even when the samples are unlucky. The trial count adapts to the
/// inlier ratio w: it stops after \f$ \log(1-\mathrm{confidence}) /
/// \log(1-w^6) \f$ trials, never after more than `max_iterations`. Sampling
/// uses std::mt19937_64 seeded with `seed` (same input, same answer).
///
/// **Refinement.** The best hypothesis is refined on its inliers by
/// Levenberg–Marquardt steps \f$ T_{wc} \leftarrow T_{wc}\,\mathrm{Exp}(\delta) \f$
/// (right perturbation, lie/se3.hpp) with the analytic Jacobian of
/// reprojection_residual — each new best hypothesis at once (local
/// optimisation), and the final one in rounds of refine and re-classify until
/// the inlier set settles.
///
/// **Statuses** (`reason` holds a sentence whenever status != kOk):
/// kTooFewPoints (fewer than max(6, min_inliers) correspondences),
/// kDegenerate (no trial gave a pose with 6 points in front of the camera —
/// e.g. coplanar or collinear points), kTooFewInliers (best pose explains
/// fewer than min_inliers correspondences). On failure T_w_c is the best
/// pose found (or identity) and must not be used.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse {

/// Outcome of solve_pnp_ransac.
enum class PnpStatus { kOk, kTooFewPoints, kDegenerate, kTooFewInliers };

/// The enumerator's name without the k ("Ok", "TooFewPoints", ...).
[[nodiscard]] constexpr const char* to_string(PnpStatus s) noexcept {
  switch (s) {
    case PnpStatus::kOk: return "Ok";
    case PnpStatus::kTooFewPoints: return "TooFewPoints";
    case PnpStatus::kDegenerate: return "Degenerate";
    case PnpStatus::kTooFewInliers: return "TooFewInliers";
  }
  return "?";
}

/// Settings of solve_pnp_ransac.
struct PnpOptions {
  double inlier_threshold = 2.0 / 460.0;  ///< residual norm in normalised coordinates (~2 px), > 0
  int max_iterations = 200;               ///< RANSAC trials at most (adaptive stop at `confidence`), ≥ 1
  double confidence = 0.999;              ///< in (0, 1)
  int min_inliers = 15;                   ///< fewer inliers is kTooFewInliers, ≥ 6
  std::uint64_t seed = 1;                 ///< RANSAC sampling seed (deterministic)
  int refine_iterations = 10;             ///< Levenberg–Marquardt steps per refinement, ≥ 0
};

/// Result of solve_pnp_ransac.
struct PnpResult {
  PnpStatus status = PnpStatus::kTooFewPoints;  ///< see the file comment
  SE3d T_w_c;                                   ///< camera pose in the points' frame (p_w = T_w_c p_c)
  std::vector<char> inlier;                     ///< one per correspondence (1 = inlier)
  int inliers = 0;                              ///< number of inliers
  double rms_residual = 0;                      ///< RMS residual norm over the inliers, normalised units
  std::string reason;                           ///< a sentence whenever status != kOk
};

/// Reprojection residual \f$ r = \pi(T_{wc}^{-1} p_w) - m \f$ (normalised units)
/// and its Jacobians: with \f$ q = T_{wc}^{-1} p_w \f$ and the right perturbation
/// \f$ T_{wc}\,\mathrm{Exp}(\tau) \f$, \f$ \partial q / \partial\tau = [-I,\; [q]_\times] \f$
/// and \f$ \partial q / \partial p_w = R_{wc}^\top \f$, each times
/// \f$ \partial\pi/\partial q = [1/z, 0, -x/z^2;\; 0, 1/z, -y/z^2] \f$.
/// @param[in] T_w_c the camera pose, p_w = T_w_c p_c
/// @param[in] p_w the point in the world
/// @param[in] m its normalised observation
/// @param[out] J_pose if not null, \f$ \partial r / \partial\tau \f$ (2x6)
/// @param[out] J_point if not null, \f$ \partial r / \partial p_w \f$ (2x3)
/// Not validated (hot path); the caller keeps q in front of the camera.
/// @param[out] depth if not null, z of q
inline Eigen::Vector2d reprojection_residual(const SE3d& T_w_c, const Eigen::Vector3d& p_w,
                                             const Eigen::Vector2d& m,
                                             Eigen::Matrix<double, 2, 6>* J_pose = nullptr,
                                             Eigen::Matrix<double, 2, 3>* J_point = nullptr,
                                             double* depth = nullptr) noexcept {
  const Eigen::Matrix3d Rt = T_w_c.so3().matrix().transpose();
  const Eigen::Vector3d q = Rt * (p_w - T_w_c.translation());
  const double iz = 1.0 / q.z();
  if (depth) *depth = q.z();
  if (J_pose || J_point) {
    Eigen::Matrix<double, 2, 3> Jpi;
    Jpi << iz, 0.0, -q.x() * iz * iz, 0.0, iz, -q.y() * iz * iz;
    if (J_pose) {
      J_pose->leftCols<3>() = -Jpi;
      J_pose->rightCols<3>() = Jpi * SO3d::hat(q);
    }
    if (J_point) *J_point = Jpi * Rt;
  }
  return Eigen::Vector2d(q.x() * iz, q.y() * iz) - m;
}

namespace detail {

inline constexpr double kPnpMinDepth = 1e-6;

// T_w_c from the 6-point DLT on sample `idx`; nullopt when singular.
inline std::optional<SE3d> pnp_dlt(std::span<const Eigen::Vector3d> P, std::span<const Eigen::Vector2d> m,
                                   const std::array<int, 6>& idx) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int i : idx) c += P[i];
  c /= 6.0;
  double d = 0;
  for (int i : idx) d += (P[i] - c).norm();
  d /= 6.0;
  if (!(d > 0)) return std::nullopt;
  Eigen::Matrix<double, 12, 12> A;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d X = (P[idx[k]] - c) / d;
    const Eigen::Vector4d Xh(X.x(), X.y(), X.z(), 1.0);
    const double u = m[idx[k]].x(), v = m[idx[k]].y();
    // rows of [m]_x P X = 0: (P2 X) u - P0 X = 0 and (P2 X) v - P1 X = 0
    A.row(2 * k) << -Xh.transpose(), Eigen::RowVector4d::Zero(), u * Xh.transpose();
    A.row(2 * k + 1) << Eigen::RowVector4d::Zero(), -Xh.transpose(), v * Xh.transpose();
  }
  // Null vector from the eigenvectors of AᵀA (several times faster than a
  // 12x12 SVD; the squared conditioning costs accuracy only in the
  // hypothesis, which the refinement polishes).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> es(A.transpose() * A);
  const auto& ev = es.eigenvalues();  // ascending
  if (!(ev(1) > 1e-12 * ev(11))) return std::nullopt;  // null space of dimension > 1
  const Eigen::Matrix<double, 12, 1> p = es.eigenvectors().col(0);
  Eigen::Matrix<double, 3, 4> Pm;
  Pm << p.segment<4>(0).transpose(), p.segment<4>(4).transpose(), p.segment<4>(8).transpose();
  Eigen::Matrix3d M = Pm.leftCols<3>() / d;      // undo the point scaling
  Eigen::Vector3d t = Pm.col(3) - M * c;         // and the centring
  if (M.determinant() < 0) {
    M = -M;
    t = -t;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> s3(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double scale = s3.singularValues().mean();
  if (!(scale > 0) || !(s3.singularValues()(2) > 1e-9 * s3.singularValues()(0))) return std::nullopt;
  const Eigen::Matrix3d R = s3.matrixU() * s3.matrixV().transpose();
  const SE3d T_c_w(t / scale, SO3d(R, 1e-6));
  if (!T_c_w.translation().allFinite()) return std::nullopt;
  return T_c_w.inverse();
}

// Inlier mask of a pose; returns the count and the MSAC-style score
// (sum of min(r², thr²)) through `score`.
inline int pnp_classify(const SE3d& T_w_c, std::span<const Eigen::Vector3d> P, std::span<const Eigen::Vector2d> m,
                        double thr, std::vector<char>& mask, double& score) {
  int n = 0;
  score = 0;
  mask.assign(P.size(), 0);
  for (std::size_t i = 0; i < P.size(); ++i) {
    double z = 0;
    const Eigen::Vector2d r = reprojection_residual(T_w_c, P[i], m[i], nullptr, nullptr, &z);
    const double r2 = r.squaredNorm();
    if (z > kPnpMinDepth && r2 <= thr * thr) {
      mask[i] = 1;
      ++n;
      score += r2;
    } else {
      score += thr * thr;
    }
  }
  return n;
}

// Levenberg–Marquardt on the masked correspondences; returns the refined pose.
inline SE3d pnp_refine(SE3d T, std::span<const Eigen::Vector3d> P, std::span<const Eigen::Vector2d> m,
                       const std::vector<char>& mask, int iterations) {
  const auto cost = [&](const SE3d& X) {
    double c = 0;
    for (std::size_t i = 0; i < P.size(); ++i)
      if (mask[i]) c += reprojection_residual(X, P[i], m[i]).squaredNorm();
    return c;
  };
  double c0 = cost(T);
  double lambda = 1e-6;
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (!mask[i]) continue;
      Eigen::Matrix<double, 2, 6> J;
      const Eigen::Vector2d r = reprojection_residual(T, P[i], m[i], &J);
      H.noalias() += J.transpose() * J;
      g.noalias() += J.transpose() * r;
    }
    if (g.cwiseAbs().maxCoeff() < 1e-15) break;
    bool accepted = false;
    for (int k = 0; k < 8 && !accepted; ++k) {
      Eigen::Matrix<double, 6, 6> A = H;
      A.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
      const Eigen::Matrix<double, 6, 1> dx = A.ldlt().solve(-g);
      if (!dx.allFinite()) break;
      const SE3d Tn = T.plus(dx);
      const double c1 = cost(Tn);
      if (c1 <= c0) {
        accepted = true;
        T = Tn;
        lambda = std::max(lambda * 0.1, 1e-12);
        const bool converged = c0 - c1 <= 1e-14 * c0 || dx.norm() < 1e-13;
        c0 = c1;
        if (converged) return T;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) break;
  }
  return T;
}

}  // namespace detail

/// Camera pose from 3-D–2-D correspondences with RANSAC (see the file comment).
/// @param[in] points_w points in frame w
/// @param[in] normalised their observations (x/z, y/z), same count
/// @param[in] o settings
/// @param[in] guess optional T_w_c, scored as the first hypothesis
/// @throws posefuse::invalid_argument on mismatched lengths, non-finite input or
///         settings outside their ranges
[[nodiscard]] inline PnpResult solve_pnp_ransac(std::span<const Eigen::Vector3d> points_w,
                                                std::span<const Eigen::Vector2d> normalised,
                                                const PnpOptions& o = {},
                                                const std::optional<SE3d>& guess = std::nullopt) {
  if (points_w.size() != normalised.size())
    throw invalid_argument("solve_pnp_ransac: " + std::to_string(points_w.size()) + " points but " +
                           std::to_string(normalised.size()) + " observations");
  for (std::size_t i = 0; i < points_w.size(); ++i)
    if (!points_w[i].allFinite() || !normalised[i].allFinite())
      throw invalid_argument("solve_pnp_ransac: correspondence " + std::to_string(i) + " is not finite");
  if (!(o.inlier_threshold > 0) || o.max_iterations < 1 || !(o.confidence > 0 && o.confidence < 1) ||
      o.min_inliers < 6 || o.refine_iterations < 0)
    throw invalid_argument(
        "solve_pnp_ransac: options out of range (threshold > 0, max_iterations >= 1, confidence in (0, 1), "
        "min_inliers >= 6, refine_iterations >= 0)");
  if (guess && !(guess->translation().allFinite() && guess->so3().matrix().allFinite()))
    throw invalid_argument("solve_pnp_ransac: the guess is not finite");

  PnpResult res;
  const int n = int(points_w.size());
  res.inlier.assign(points_w.size(), 0);
  const int needed = std::max(6, o.min_inliers);
  if (n < needed) {
    res.status = PnpStatus::kTooFewPoints;
    res.reason = "PnP: " + std::to_string(n) + " correspondences, at least " + std::to_string(needed) + " needed.";
    return res;
  }

  std::optional<SE3d> best;
  std::vector<char> mask, best_mask;
  int best_n = -1;
  double best_score = std::numeric_limits<double>::infinity();
  // Scores a hypothesis; a new best is refined on its inliers at once and
  // kept when that scores better still (local optimisation, Chum et al.,
  // "Locally optimized RANSAC", DAGM 2003), which lifts the inlier count that
  // drives the adaptive stop from that of a 6-point fit to that of a fit on all.
  const auto consider = [&](const SE3d& T) {
    double score = 0;
    const int k = detail::pnp_classify(T, points_w, normalised, o.inlier_threshold, mask, score);
    if (k < 6 || !(score < best_score)) return;
    best_score = score;
    best_n = k;
    best = T;
    best_mask = mask;
    const SE3d Tr = detail::pnp_refine(T, points_w, normalised, best_mask, o.refine_iterations);
    const int kr = detail::pnp_classify(Tr, points_w, normalised, o.inlier_threshold, mask, score);
    if (kr >= 6 && score < best_score) {
      best_score = score;
      best_n = kr;
      best = Tr;
      best_mask = mask;
    }
  };
  if (guess) consider(*guess);

  std::mt19937_64 rng(o.seed);
  const double log_fail = std::log(1.0 - o.confidence);
  long trials_needed = o.max_iterations;
  for (long trial = 0; trial < std::min<long>(o.max_iterations, trials_needed); ++trial) {
    std::array<int, 6> idx{};
    for (int k = 0; k < 6; ++k) {
      bool fresh = false;
      while (!fresh) {
        idx[k] = int(rng() % std::uint64_t(n));
        fresh = std::find(idx.begin(), idx.begin() + k, idx[k]) == idx.begin() + k;
      }
    }
    const std::optional<SE3d> T = detail::pnp_dlt(points_w, normalised, idx);
    if (!T) continue;
    consider(*T);
    if (best_n > 0) {
      const double w = double(best_n) / n;
      const double denom = std::log(1.0 - std::pow(w, 6.0));
      if (denom < 0) trials_needed = std::max<long>(1, long(std::ceil(log_fail / denom)));
    }
  }
  if (!best) {
    res.status = PnpStatus::kDegenerate;
    res.reason = "PnP: no hypothesis put 6 correspondences within the threshold in front of the camera "
                 "(points coplanar or collinear, or too many wrong correspondences).";
    return res;
  }

  // Refine and re-classify until the inlier set settles (at most 5 rounds);
  // a round that scores worse is not taken.
  SE3d T = *best;
  mask = best_mask;
  int k = best_n;
  for (int round = 0; round < 5; ++round) {
    const SE3d Tr = detail::pnp_refine(T, points_w, normalised, mask, o.refine_iterations);
    std::vector<char> mr;
    double score = 0;
    const int kr = detail::pnp_classify(Tr, points_w, normalised, o.inlier_threshold, mr, score);
    if (kr < 6 || score > best_score) break;
    best_score = score;
    T = Tr;
    k = kr;
    const bool settled = mr == mask;
    mask = std::move(mr);
    if (settled) break;
  }
  res.T_w_c = T;
  res.inlier = mask;
  res.inliers = k;
  double ss = 0;
  for (int i = 0; i < n; ++i)
    if (mask[i]) ss += reprojection_residual(T, points_w[i], normalised[i]).squaredNorm();
  res.rms_residual = k > 0 ? std::sqrt(ss / k) : 0.0;
  if (k < o.min_inliers) {
    res.status = PnpStatus::kTooFewInliers;
    res.reason = "PnP: best pose explains " + std::to_string(k) + " of " + std::to_string(n) +
                 " correspondences, at least " + std::to_string(o.min_inliers) + " needed.";
    return res;
  }
  res.status = PnpStatus::kOk;
  return res;
}

}  // namespace posefuse

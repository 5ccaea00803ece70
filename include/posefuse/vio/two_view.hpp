#pragma once
/// @file
/// Relative pose of two calibrated views from normalised correspondences:
/// the essential matrix by the eight-point algorithm inside RANSAC, its
/// decomposition, and the choice among the four candidates by cheirality.
///
/// **Conventions.** `m1[i]` and `m2[i]` are normalised coordinates (x/z, y/z)
/// of one point in cameras 1 and 2. The result is \f$ T_{12} \f$, camera 2 in
/// camera 1 (\f$ p_1 = R\,p_2 + t \f$), with \f$ |t| = 1 \f$ (two views fix
/// the translation only up to scale). With \f$ x = (m, 1) \f$ the epipolar
/// constraint is \f$ x_1^\top E\,x_2 = 0 \f$, \f$ E = [t]_\times R \f$.
///
/// **Method.** Eight-point algorithm with Hartley's normalisation (Hartley &
/// Zisserman, *Multiple View Geometry*, 2nd ed., §11.2, Alg. 11.1): each image's
/// points are centred and scaled to mean distance √2, the null vector of the
/// stacked \f$ x_1 \otimes x_2 \f$ rows (SVD) gives E, and its singular values
/// are replaced by (1, 1, 0) (§9.6.1). The eight-point solver is chosen over
/// the five-point one because it is linear, short and exact on noise-free
/// data, and because VINS-Mono's initialisation (Qin et al., T-RO 2018) uses
/// the same; RANSAC supplies the robustness. A pair is an inlier when its
/// Sampson distance \f$ |x_1^\top E x_2| / \sqrt{(Ex_2)_1^2 + (Ex_2)_2^2 +
/// (E^\top x_1)_1^2 + (E^\top x_1)_2^2} \f$ (H&Z eq. 11.9, normalised units)
/// is within `inlier_threshold`. A new best hypothesis is re-estimated from
/// all its inliers at once (local optimisation), the final one until its
/// inlier set settles. The trial count adapts as in vio/pnp.hpp (sample
/// size 8, std::mt19937_64 seeded with `seed`). E's SVD
/// \f$ U\,\mathrm{diag}(1,1,0)\,V^\top \f$ gives \f$ R \in \{U W V^\top, U W^\top V^\top\} \f$,
/// \f$ t = \pm u_3 \f$ (H&Z result 9.19); the candidate that puts most inliers
/// at positive depth in both cameras wins. It is then refined by
/// Levenberg–Marquardt on the Sampson residuals of the inliers (rotation
/// \f$ R\,\mathrm{Exp}(\phi) \f$, unit translation moved in its tangent
/// plane; analytic Jacobian in sampson_residual), which removes most of the
/// eight-point algorithm's algebraic bias under noise.
///
/// **Degeneracy.** With no translation every \f$ [a]_\times R \f$ fits the
/// data, so E's direction is arbitrary: the rotation stays right but t is
/// noise. The rotation-compensated parallax — the angle between the ray of
/// \f$ m_1 \f$ and the rotated ray \f$ R\,(m_2, 1) \f$ — tells the two apart: its
/// median over the inliers (the smaller of the two rotation candidates'; the
/// wrong one is turned by π) must reach `min_parallax_rad`, else the status
/// is kTooLittleParallax. Then at least max(min_inliers, `min_front_fraction` of
/// the inliers) must triangulate in front of both cameras, else kDegenerate.
/// Points on one plane are degenerate for the eight-point algorithm (H&Z
/// §11.9) and end in kDegenerate or a low inlier count.
///
/// **Statuses** (`reason` holds a sentence whenever status != kOk):
/// kTooFewPoints (fewer than max(8, min_inliers) pairs), kDegenerate,
/// kTooFewInliers, kTooLittleParallax. On failure T_1_2 must not be used.

#include <Eigen/Core>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse {

/// Outcome of solve_two_view.
enum class TwoViewStatus { kOk, kTooFewPoints, kDegenerate, kTooFewInliers, kTooLittleParallax };

/// The enumerator's name without the k.
[[nodiscard]] constexpr const char* to_string(TwoViewStatus s) noexcept {
  switch (s) {
    case TwoViewStatus::kOk: return "Ok";
    case TwoViewStatus::kTooFewPoints: return "TooFewPoints";
    case TwoViewStatus::kDegenerate: return "Degenerate";
    case TwoViewStatus::kTooFewInliers: return "TooFewInliers";
    case TwoViewStatus::kTooLittleParallax: return "TooLittleParallax";
  }
  return "?";
}

/// Settings of solve_two_view.
struct TwoViewOptions {
  double inlier_threshold = 2.0 / 460.0;  ///< Sampson distance, normalised units (~2 px at 460 px), > 0
  int max_iterations = 200;               ///< RANSAC trials at most, ≥ 1
  double confidence = 0.999;              ///< adaptive stop, in (0, 1)
  int min_inliers = 15;                   ///< ≥ 8
  double min_parallax_rad = 3.0 / 460.0;  ///< median rotation-compensated parallax (~3 px), ≥ 0
  double min_front_fraction = 0.5;        ///< of the inliers, in front of both cameras, in [0, 1]
  std::uint64_t seed = 1;                 ///< RANSAC sampling seed (deterministic)
  int refine_iterations = 10;             ///< Levenberg–Marquardt steps of the Sampson refinement, ≥ 0
};

/// Result of solve_two_view.
struct TwoViewResult {
  TwoViewStatus status = TwoViewStatus::kTooFewPoints;  ///< see the file comment
  SE3d T_1_2;                  ///< camera 2 in camera 1, |t| = 1 (valid when kOk)
  std::vector<char> inlier;    ///< one per pair: epipolar inlier in front of both cameras
  int inliers = 0;             ///< number of set entries of `inlier`
  double median_parallax_rad = 0;  ///< median rotation-compensated parallax of the epipolar inliers
  std::string reason;          ///< a sentence whenever status != kOk
};

namespace detail {

// Similarity taking the points to centroid 0, mean distance sqrt(2).
inline Eigen::Matrix3d hartley_normalisation(std::span<const Eigen::Vector2d> m, std::span<const int> idx) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int i : idx) c += m[i];
  c /= double(idx.size());
  double d = 0;
  for (int i : idx) d += (m[i] - c).norm();
  d /= double(idx.size());
  const double s = d > 0 ? std::sqrt(2.0) / d : 1.0;
  Eigen::Matrix3d T;
  T << s, 0, -s * c.x(), 0, s, -s * c.y(), 0, 0, 1;
  return T;
}

// Essential matrix (singular values 1, 1, 0) from the pairs idx; nullopt when
// it is not finite.
inline std::optional<Eigen::Matrix3d> eight_point(std::span<const Eigen::Vector2d> m1,
                                                  std::span<const Eigen::Vector2d> m2, std::span<const int> idx) {
  const Eigen::Matrix3d T1 = hartley_normalisation(m1, idx), T2 = hartley_normalisation(m2, idx);
  Eigen::Matrix<double, Eigen::Dynamic, 9> A(std::max<Eigen::Index>(9, Eigen::Index(idx.size())), 9);
  A.setZero();
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const Eigen::Vector3d a = T1 * m1[idx[k]].homogeneous(), b = T2 * m2[idx[k]].homogeneous();
    for (int r = 0; r < 3; ++r) A.block<1, 3>(Eigen::Index(k), 3 * r) = a(r) * b.transpose();
  }
  // No rank test: without translation the null space is {[a]_x R}, three
  // dimensions of valid essential matrices with the right R (see the file
  // comment); the parallax test tells that case apart.
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 9>> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> e = svd.matrixV().col(8);
  Eigen::Matrix3d En;
  En << e(0), e(1), e(2), e(3), e(4), e(5), e(6), e(7), e(8);
  const Eigen::Matrix3d E = T1.transpose() * En * T2;
  const Eigen::JacobiSVD<Eigen::Matrix3d> s3(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d Ee = s3.matrixU() * Eigen::Vector3d(1, 1, 0).asDiagonal() * s3.matrixV().transpose();
  if (!Ee.allFinite()) return std::nullopt;
  return Ee;
}

inline double sampson_distance(const Eigen::Matrix3d& E, const Eigen::Vector2d& m1, const Eigen::Vector2d& m2) {
  const Eigen::Vector3d x1 = m1.homogeneous(), x2 = m2.homogeneous();
  const Eigen::Vector3d l1 = E * x2, l2 = E.transpose() * x1;
  const double den = l1.head<2>().squaredNorm() + l2.head<2>().squaredNorm();
  return den > 0 ? std::abs(x1.dot(l1)) / std::sqrt(den) : std::numeric_limits<double>::infinity();
}

// Depths (λ1, λ2) with λ1 x1 = R λ2 x2 + t, least squares.
inline Eigen::Vector2d two_view_depths(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector2d& m1,
                                       const Eigen::Vector2d& m2) {
  Eigen::Matrix<double, 3, 2> A;
  A.col(0) = m1.homogeneous();
  A.col(1) = -R * m2.homogeneous();
  const Eigen::Matrix2d AtA = A.transpose() * A;
  const double det = AtA.determinant();
  if (!(std::abs(det) > 1e-14 * AtA.squaredNorm())) return Eigen::Vector2d(-1, -1);  // parallel rays
  return AtA.inverse() * (A.transpose() * t);
}

// Unit vectors b1, b2 completing t (unit) to an orthonormal basis.
inline Eigen::Matrix<double, 3, 2> sphere_basis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d a = std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = t.cross(a).normalized();
  B.col(1) = t.cross(B.col(0));
  return B;
}

}  // namespace detail

/// Signed Sampson residual \f$ r = x_1^\top E x_2 / \sqrt{d} \f$,
/// \f$ E = [t]_\times R \f$, \f$ d = (Ex_2)_1^2 + (Ex_2)_2^2 + (E^\top x_1)_1^2 +
/// (E^\top x_1)_2^2 \f$ (normalised units), and its Jacobian with respect to
/// \f$ [\phi, \delta] \f$ of the update \f$ R\,\mathrm{Exp}(\phi) \f$,
/// \f$ (t + B\delta)/|t + B\delta| \f$ at 0, B the columns of `basis` (unit
/// t; \f$ \partial E/\partial\phi_k = [t]_\times R [e_k]_\times \f$,
/// \f$ \partial E/\partial\delta_j = [b_j]_\times R \f$). Not validated.
inline double sampson_residual(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector2d& m1,
                               const Eigen::Vector2d& m2, const Eigen::Matrix<double, 3, 2>& basis,
                               Eigen::Matrix<double, 1, 5>* J = nullptr) noexcept {
  const Eigen::Matrix3d E = SO3d::hat(t) * R;
  const Eigen::Vector3d x1 = m1.homogeneous(), x2 = m2.homogeneous();
  const Eigen::Vector3d l1 = E * x2, l2 = E.transpose() * x1;
  const double e = x1.dot(l1);
  const double den = l1.head<2>().squaredNorm() + l2.head<2>().squaredNorm();
  const double is = 1.0 / std::sqrt(den);
  if (J) {
    for (int k = 0; k < 5; ++k) {
      const Eigen::Matrix3d dE = k < 3 ? Eigen::Matrix3d(E * SO3d::hat(Eigen::Vector3d::Unit(k)))
                                       : Eigen::Matrix3d(SO3d::hat(basis.col(k - 3)) * R);
      const Eigen::Vector3d d1 = dE * x2, d2 = dE.transpose() * x1;
      const double de = x1.dot(d1);
      const double dden = 2.0 * (l1.head<2>().dot(d1.head<2>()) + l2.head<2>().dot(d2.head<2>()));
      (*J)(k) = de * is - 0.5 * e * is * is * is * dden;
    }
  }
  return e * is;
}

namespace detail {

// Levenberg–Marquardt on the Sampson residuals of the pairs idx.
inline void refine_two_view(Eigen::Matrix3d& R, Eigen::Vector3d& t, std::span<const Eigen::Vector2d> m1,
                            std::span<const Eigen::Vector2d> m2, std::span<const int> idx, int iterations) {
  const auto cost = [&](const Eigen::Matrix3d& Rx, const Eigen::Vector3d& tx) {
    const Eigen::Matrix<double, 3, 2> B = sphere_basis(tx);
    double c = 0;
    for (int i : idx) c += std::pow(sampson_residual(Rx, tx, m1[i], m2[i], B), 2);
    return c;
  };
  double c0 = cost(R, t);
  double lambda = 1e-4;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::Matrix<double, 3, 2> B = sphere_basis(t);
    Eigen::Matrix<double, 5, 5> H = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> g = Eigen::Matrix<double, 5, 1>::Zero();
    for (int i : idx) {
      Eigen::Matrix<double, 1, 5> J;
      const double r = sampson_residual(R, t, m1[i], m2[i], B, &J);
      H.noalias() += J.transpose() * J;
      g.noalias() += J.transpose() * r;
    }
    bool accepted = false;
    for (int k = 0; k < 8 && !accepted; ++k) {
      Eigen::Matrix<double, 5, 5> A = H;
      A.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
      const Eigen::Matrix<double, 5, 1> dx = A.ldlt().solve(-g);
      if (!dx.allFinite()) return;
      const Eigen::Matrix3d Rn = R * SO3d::exp(dx.head<3>()).matrix();
      const Eigen::Vector3d tn = (t + B * dx.tail<2>()).normalized();
      const double c1 = cost(Rn, tn);
      if (c1 <= c0) {
        accepted = true;
        const bool converged = c0 - c1 <= 1e-14 * c0 || dx.norm() < 1e-13;
        R = Rn;
        t = tn;
        c0 = c1;
        lambda = std::max(lambda * 0.1, 1e-12);
        if (converged) return;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) return;
  }
}

}  // namespace detail

/// Relative pose of two views (see the file comment).
/// @param[in] o RANSAC and refinement settings
/// @param[in] m1 normalised coordinates in camera 1
/// @param[in] m2 the same points' normalised coordinates in camera 2, same count
/// @throws posefuse::invalid_argument on mismatched lengths, non-finite input or
///         settings outside their ranges
[[nodiscard]] inline TwoViewResult solve_two_view(std::span<const Eigen::Vector2d> m1,
                                                  std::span<const Eigen::Vector2d> m2, const TwoViewOptions& o = {}) {
  if (m1.size() != m2.size())
    throw invalid_argument("solve_two_view: " + std::to_string(m1.size()) + " points in view 1 but " +
                           std::to_string(m2.size()) + " in view 2");
  for (std::size_t i = 0; i < m1.size(); ++i)
    if (!m1[i].allFinite() || !m2[i].allFinite())
      throw invalid_argument("solve_two_view: pair " + std::to_string(i) + " is not finite");
  if (!(o.inlier_threshold > 0) || o.max_iterations < 1 || !(o.confidence > 0 && o.confidence < 1) ||
      o.min_inliers < 8 || o.refine_iterations < 0 || !(o.min_parallax_rad >= 0) || !(o.min_front_fraction >= 0 && o.min_front_fraction <= 1))
    throw invalid_argument(
        "solve_two_view: options out of range (threshold > 0, max_iterations >= 1, confidence in (0, 1), "
        "min_inliers >= 8, min_parallax_rad >= 0, min_front_fraction in [0, 1])");

  TwoViewResult res;
  const int n = int(m1.size());
  res.inlier.assign(m1.size(), 0);
  const int needed = std::max(8, o.min_inliers);
  if (n < needed) {
    res.status = TwoViewStatus::kTooFewPoints;
    res.reason = "Two views: " + std::to_string(n) + " correspondences, at least " + std::to_string(needed) +
                 " needed.";
    return res;
  }

  std::optional<Eigen::Matrix3d> best;
  std::vector<int> best_idx, idx_buf;
  double best_score = std::numeric_limits<double>::infinity();
  const double thr2 = o.inlier_threshold * o.inlier_threshold;
  // MSAC score and inlier list of a hypothesis.
  const auto classify = [&](const Eigen::Matrix3d& E, std::vector<int>& in) {
    in.clear();
    double score = 0;
    for (int i = 0; i < n; ++i) {
      const double d = detail::sampson_distance(E, m1[i], m2[i]);
      if (d * d <= thr2) {
        in.push_back(i);
        score += d * d;
      } else {
        score += thr2;
      }
    }
    return score;
  };
  const auto consider = [&](const Eigen::Matrix3d& E) {
    const double score = classify(E, idx_buf);
    if (int(idx_buf.size()) < 8 || !(score < best_score)) return;
    best = E;
    best_score = score;
    best_idx = idx_buf;
    // local optimisation: re-estimate from all inliers
    if (const auto Er = detail::eight_point(m1, m2, best_idx)) {
      const double sr = classify(*Er, idx_buf);
      if (int(idx_buf.size()) >= 8 && sr < best_score) {
        best = *Er;
        best_score = sr;
        best_idx = idx_buf;
      }
    }
  };

  std::mt19937_64 rng(o.seed);
  const double log_fail = std::log(1.0 - o.confidence);
  long trials_needed = o.max_iterations;
  for (long trial = 0; trial < std::min<long>(o.max_iterations, trials_needed); ++trial) {
    std::array<int, 8> idx{};
    for (int k = 0; k < 8; ++k) {
      bool fresh = false;
      while (!fresh) {
        idx[k] = int(rng() % std::uint64_t(n));
        fresh = std::find(idx.begin(), idx.begin() + k, idx[k]) == idx.begin() + k;
      }
    }
    if (const auto E = detail::eight_point(m1, m2, idx)) consider(*E);
    if (!best_idx.empty()) {
      const double denom = std::log(1.0 - std::pow(double(best_idx.size()) / n, 8.0));
      if (denom < 0) trials_needed = std::max<long>(1, long(std::ceil(log_fail / denom)));
    }
  }
  if (!best) {
    res.status = TwoViewStatus::kDegenerate;
    res.reason = "Two views: no eight-point sample gave an essential matrix (degenerate configuration).";
    return res;
  }
  for (int round = 0; round < 5; ++round) {  // re-estimate until the inlier set settles
    const auto Er = detail::eight_point(m1, m2, best_idx);
    if (!Er) break;
    std::vector<int> in;
    const double sr = classify(*Er, in);
    if (int(in.size()) < 8 || sr > best_score) break;
    best = *Er;
    best_score = sr;
    const bool settled = in == best_idx;
    best_idx = std::move(in);
    if (settled) break;
  }
  const int n_epi = int(best_idx.size());
  if (n_epi < o.min_inliers) {
    res.status = TwoViewStatus::kTooFewInliers;
    res.reason = "Two views: the best essential matrix explains " + std::to_string(n_epi) + " of " +
                 std::to_string(n) + " correspondences, at least " + std::to_string(o.min_inliers) + " needed.";
    return res;
  }

  // The four candidates (H&Z result 9.19); most inliers in front of both wins.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(*best, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
  if (U.determinant() < 0) U = -U;
  if (V.determinant() < 0) V = -V;
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  const std::array<Eigen::Matrix3d, 2> Rs = {U * W * V.transpose(), U * W.transpose() * V.transpose()};
  int best_front = -1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  std::vector<char> front_best;
  for (const Eigen::Matrix3d& Rc : Rs) {
    for (double sign : {1.0, -1.0}) {
      const Eigen::Vector3d tc = sign * U.col(2);
      std::vector<char> front(m1.size(), 0);
      int k = 0;
      for (int i : best_idx) {
        const Eigen::Vector2d l = detail::two_view_depths(Rc, tc, m1[i], m2[i]);
        if (l(0) > 0 && l(1) > 0) {
          front[i] = 1;
          ++k;
        }
      }
      if (k > best_front) {
        best_front = k;
        R = Rc;
        t = tc;
        front_best = std::move(front);
      }
    }
  }
  // Median rotation-compensated parallax under either rotation candidate; the
  // smaller one is that of the right rotation (the other is turned by π).
  res.median_parallax_rad = std::numeric_limits<double>::infinity();
  for (const Eigen::Matrix3d& Rc : Rs) {
    std::vector<double> parallax;
    parallax.reserve(best_idx.size());
    for (int i : best_idx) {
      const Eigen::Vector3d a = m1[i].homogeneous(), b = Rc * m2[i].homogeneous();
      parallax.push_back(std::atan2(a.cross(b).norm(), a.dot(b)));
    }
    std::nth_element(parallax.begin(), parallax.begin() + long(parallax.size() / 2), parallax.end());
    res.median_parallax_rad = std::min(res.median_parallax_rad, parallax[parallax.size() / 2]);
  }
  // Sampson refinement of the chosen candidate on the epipolar inliers, then
  // the inliers and their cheirality again under the refined pose.
  t.normalize();
  detail::refine_two_view(R, t, m1, m2, best_idx, o.refine_iterations);
  {
    const Eigen::Matrix<double, 3, 2> B = detail::sphere_basis(t);
    std::vector<int> in;
    for (int i = 0; i < n; ++i)
      if (std::abs(sampson_residual(R, t, m1[i], m2[i], B)) <= o.inlier_threshold) in.push_back(i);
    if (int(in.size()) >= 8) {
      if (in != best_idx) detail::refine_two_view(R, t, m1, m2, in, o.refine_iterations);
      best_idx = std::move(in);
    }
  }
  front_best.assign(m1.size(), 0);
  best_front = 0;
  for (int i : best_idx) {
    const Eigen::Vector2d l = detail::two_view_depths(R, t, m1[i], m2[i]);
    if (l(0) > 0 && l(1) > 0) {
      front_best[i] = 1;
      ++best_front;
    }
  }
  res.T_1_2 = SE3d(t, SO3d(R, 1e-6));
  res.inlier = front_best;
  res.inliers = best_front;
  if (res.median_parallax_rad < o.min_parallax_rad) {
    res.status = TwoViewStatus::kTooLittleParallax;
    res.reason = "Two views: median rotation-compensated parallax " +
                 std::to_string(res.median_parallax_rad * 180.0 / std::numbers::pi) + " deg is below " +
                 std::to_string(o.min_parallax_rad * 180.0 / std::numbers::pi) + " deg (too little translation).";
    return res;
  }
  const int front_needed = std::max(o.min_inliers, int(std::ceil(o.min_front_fraction * n_epi)));
  if (best_front < front_needed) {
    res.status = TwoViewStatus::kDegenerate;
    res.reason = "Two views: only " + std::to_string(best_front) + " of " + std::to_string(n_epi) +
                 " epipolar inliers lie in front of both cameras, at least " + std::to_string(front_needed) +
                 " needed.";
    return res;
  }
  res.status = TwoViewStatus::kOk;
  return res;
}

}  // namespace posefuse

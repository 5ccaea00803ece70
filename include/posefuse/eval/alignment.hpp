#pragma once
/// @file
/// Umeyama SE(3) / Sim(3) alignment of an estimated trajectory to a
/// reference, as evo's `geometry.umeyama_alignment` and
/// `trajectory.align_trajectory` (`evo_ape ... -a` / `-as`).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// Which alignment to apply before computing a metric.
enum class Alignment {
  kNone,  ///< compare as is
  kSE3,   ///< rotation + translation (evo `--align`)
  kSim3,  ///< rotation + translation + scale (evo `--align --correct_scale`), for monocular SLAM
  kScale,  ///< scale only: positions multiplied by Umeyama's scale (evo `--correct_scale` alone)
  /// position and yaw about the world z axis (4-DoF, for visual-inertial
  /// estimates whose roll and pitch are observable; evo has no such mode)
  kPosYaw,
};

/// Parses "none", "se3", "sim3", "scale" or "posyaw".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] Alignment parse_alignment(std::string_view name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSE3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "scale") return Alignment::kScale;
  if (name == "posyaw") return Alignment::kPosYaw;
  throw invalid_argument("unknown alignment '" + std::string(name) +
                         "' (expected none, se3, sim3, scale or posyaw)");
}

/// The name `parse_alignment` accepts for `alignment`.
[[nodiscard]] constexpr std::string_view to_string(Alignment alignment) noexcept {
  switch (alignment) {
    case Alignment::kNone: return "none";
    case Alignment::kSE3: return "se3";
    case Alignment::kSim3: return "sim3";
    case Alignment::kScale: return "scale";
    case Alignment::kPosYaw: return "posyaw";
  }
  return "?";
}

/// A similarity \f$ y = c R x + t \f$ mapping estimate positions onto the
/// reference (identity for `Alignment::kNone`).
struct AlignmentResult {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  ///< \f$ R \f$ (est world → ref world)
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   ///< \f$ t \f$ (m, reference frame)
  double scale = 1.0;                                      ///< \f$ c \f$ (1 unless Sim(3))

  /// Maps a point: \f$ c R x + t \f$.
  template <class Lazy = void>  // compiled only where called (compile cost, core/lazy.hpp)
  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& x) const {
    const detail::dependent_t<Eigen::Matrix3d, Lazy>& R = rotation;
    return scale * (R * x) + translation;
  }
};

/// Least-squares similarity between two registered point sets (Umeyama,
/// IEEE PAMI 13(4), 1991), as evo's `umeyama_alignment(x, y, with_scale)`:
/// means (eq. 34-35), \f$ \sigma_x^2 = \frac1n \sum \lVert x_i - \mu_x \rVert^2 \f$
/// (eq. 36), \f$ \Sigma_{xy} = \frac1n \sum (y_i - \mu_y)(x_i - \mu_x)^\top
/// = U D V^\top \f$ (eq. 38), \f$ S = \mathrm{diag}(1, 1, -1) \f$ when
/// \f$ \det U \det V < 0 \f$ (eq. 43), \f$ R = U S V^\top \f$ (eq. 40),
/// \f$ c = \mathrm{tr}(D S) / \sigma_x^2 \f$ (eq. 42) and
/// \f$ t = \mu_y - c R \mu_x \f$ (eq. 41).
/// @param[in] x source points (estimate), at least 3
/// @param[in] y target points (reference), same count, `y[i]` registered to `x[i]`
/// @param[in] with_scale estimate \f$ c \f$ (Sim(3)); otherwise \f$ c = 1 \f$ (SE(3))
/// @return \f$ (R, t, c) \f$ minimising \f$ \sum \lVert y_i - (c R x_i + t) \rVert^2 \f$
/// @throws posefuse::invalid_argument for different counts, fewer than 3
///         points, non-finite points, or a covariance of rank < 2 (evo's
///         "Degenerate covariance rank": e.g. all points identical or collinear)
// A template (with nothing to deduce) so that the 3x3 SVD is instantiated
// only in translation units that call it: a plain inline function would be
// compiled by every file that includes this header (compile cost, README).
template <class Lazy = void>
[[nodiscard]] AlignmentResult umeyama_alignment(std::span<const Eigen::Vector3d> x,
                                                std::span<const Eigen::Vector3d> y,
                                                bool with_scale) {
  if (x.size() != y.size()) {
    throw invalid_argument("umeyama_alignment: " + std::to_string(x.size()) + " source but " +
                           std::to_string(y.size()) + " target points");
  }
  if (x.size() < 3) {
    throw invalid_argument("umeyama_alignment: needs at least 3 point pairs, got " +
                           std::to_string(x.size()));
  }
  // Dependent spellings: the SVD and the expressions compile only where
  // this is called (core/lazy.hpp).
  using Vec3 = detail::dependent_t<Eigen::Vector3d, Lazy>;
  using Mat3 = detail::dependent_t<Eigen::Matrix3d, Lazy>;
  const double n = static_cast<double>(x.size());
  Vec3 mean_x = Vec3::Zero();
  Vec3 mean_y = Vec3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3& xi = x[i];
    const Vec3& yi = y[i];
    if (!xi.allFinite() || !yi.allFinite()) {
      throw invalid_argument("umeyama_alignment: point pair " + std::to_string(i) +
                             " is not finite");
    }
    mean_x += xi;
    mean_y += yi;
  }
  mean_x /= n;
  mean_y /= n;
  double sigma_x = 0.0;
  Mat3 cov = Mat3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3& xi = x[i];
    const Vec3& yi = y[i];
    const Vec3 dx = xi - mean_x;
    sigma_x += dx.squaredNorm();
    cov += (yi - mean_y) * dx.transpose();
  }
  sigma_x /= n;
  cov /= n;

  const Eigen::JacobiSVD<Mat3> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 d = svd.singularValues();
  int rank = 0;
  for (int i = 0; i < 3; ++i) rank += d(i) > std::numeric_limits<double>::epsilon() ? 1 : 0;
  if (rank < 2) {
    throw invalid_argument("umeyama_alignment: degenerate covariance rank " + std::to_string(rank) +
                           " (points identical or collinear), alignment is not possible");
  }
  Mat3 S = Mat3::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;

  AlignmentResult r;
  const Mat3 R = svd.matrixU() * S * svd.matrixV().transpose();
  r.rotation = R;
  r.scale = with_scale ? (d.asDiagonal() * S).trace() / sigma_x : 1.0;
  r.translation = mean_y - r.scale * (R * mean_x);
  return r;
}

/// Applies a similarity to a trajectory the way evo does: first scale the
/// positions \f$ p_k \leftarrow c\,p_k \f$ (rotations untouched), then
/// left-multiply every pose by the SE(3) \f$ [R \mid t] \f$:
/// \f$ T_k \leftarrow [R \mid t]\,T_k \f$. The result is again SE(3).
/// @param[in] traj the trajectory to move
/// @param[in] a the similarity
/// @return the moved trajectory (stamps unchanged)
template <class Lazy = void>
[[nodiscard]] Trajectory apply_alignment(const Trajectory& traj, const AlignmentResult& a) {
  Eigen::Isometry3d T_align = Eigen::Isometry3d::Identity();
  T_align.linear() = a.rotation;
  T_align.translation() = a.translation;
  Trajectory out = traj;
  for (Eigen::Isometry3d& T : out.poses) {
    T.translation() *= a.scale;
    T = T_align * T;
  }
  return out;
}

/// An aligned trajectory with the similarity that produced it.
struct AlignedTrajectory {
  Trajectory trajectory;      ///< the estimate moved onto the reference
  AlignmentResult transform;  ///< \f$ (R, t, c) \f$ used
};

/// Least-squares 4-DoF alignment: position and yaw only (rotation about the
/// world z axis), for visual-inertial estimates whose roll and pitch are
/// observable from gravity (VINS-Mono, Qin et al. 2018; evo has no such mode).
/// Minimises \f$ \sum \lVert y_i - (R_z(\psi) x_i + t) \rVert^2 \f$: with the
/// centred points \f$ a_i = x_i - \mu_x \f$, \f$ b_i = y_i - \mu_y \f$,
/// \f$ \psi = \mathrm{atan2}\big(\sum (a_{i,x} b_{i,y} - a_{i,y} b_{i,x}),
/// \sum (a_{i,x} b_{i,x} + a_{i,y} b_{i,y})\big) \f$ and \f$ t = \mu_y - R_z(\psi)\mu_x \f$
/// (the planar case of Umeyama 1991 / Horn 1987).
/// @param[in] x source points (estimate), at least 2
/// @param[in] y target points (reference), same count, `y[i]` registered to `x[i]`
/// @return \f$ (R_z(\psi), t, 1) \f$
/// @throws posefuse::invalid_argument for different counts, fewer than 2
///         points, non-finite points, or no horizontal spread (the yaw is undefined)
template <class Lazy = void>
[[nodiscard]] AlignmentResult posyaw_alignment(std::span<const Eigen::Vector3d> x,
                                               std::span<const Eigen::Vector3d> y) {
  if (x.size() != y.size())
    throw invalid_argument("posyaw_alignment: " + std::to_string(x.size()) + " source but " +
                           std::to_string(y.size()) + " target points");
  if (x.size() < 2) throw invalid_argument("posyaw_alignment: needs at least 2 points");
  Eigen::Vector3d mx = Eigen::Vector3d::Zero(), my = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!x[i].allFinite() || !y[i].allFinite())
      throw invalid_argument("posyaw_alignment: point " + std::to_string(i) + " is not finite");
    mx += x[i];
    my += y[i];
  }
  mx /= double(x.size());
  my /= double(y.size());
  double C = 0.0, S = 0.0, norms = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Eigen::Vector2d a = (x[i] - mx).head<2>(), b = (y[i] - my).head<2>();
    C += a.dot(b);
    S += a.x() * b.y() - a.y() * b.x();
    norms += a.norm() * b.norm();
  }
  if (!(std::hypot(C, S) > 1e-12 * norms) || norms == 0.0)
    throw invalid_argument("posyaw_alignment: the points have no horizontal spread; the yaw is undefined");
  const double psi = std::atan2(S, C);
  AlignmentResult r;
  const double c = std::cos(psi), s = std::sin(psi);
  r.rotation << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;  // R_z(ψ)
  r.translation = my - r.rotation * mx;
  return r;
}

/// Aligns `est` to `ref` by position and yaw (posyaw_alignment on all their
/// already associated positions), then moves every pose by it.
/// @throws posefuse::invalid_argument for different sizes or the cases of posyaw_alignment
template <class Lazy = void>
[[nodiscard]] AlignedTrajectory align_posyaw(const Trajectory& est, const Trajectory& ref) {
  if (est.size() != ref.size())
    throw invalid_argument("align_posyaw: estimate has " + std::to_string(est.size()) +
                           " poses but reference has " + std::to_string(ref.size()) +
                           " (call associate() first)");
  const std::vector<Eigen::Vector3d> x = est.positions();
  const std::vector<Eigen::Vector3d> y = ref.positions();
  const AlignmentResult a = posyaw_alignment(x, y);
  return {apply_alignment(est, a), a};
}

/// Aligns `est` to `ref` over their (already associated) positions, as
/// evo's `align_trajectory(est, ref, correct_scale, correct_only_scale, n)`.
/// @param[in] est estimate, pose k registered to `ref` pose k
/// @param[in] ref reference
/// @param[in] alignment kNone (returns `est` and the identity), kSE3, kSim3,
///            kScale (Umeyama's Sim(3) scale applied to the positions
///            alone, rotation and translation left as they are) or kPosYaw
///            (position and yaw, `posyaw_alignment`)
/// @param[in] n_to_align use only the first `n_to_align` pose pairs to
///            compute the alignment (evo `--n_to_align`); 0 means all
/// @return the aligned estimate (every pose moved) and the similarity
/// @throws posefuse::invalid_argument for different sizes, `n_to_align`
///         larger than the poses, or the degenerate cases of `umeyama_alignment`
template <class Lazy = void>
[[nodiscard]] AlignedTrajectory align_trajectory(const Trajectory& est,
                                                 const Trajectory& ref,
                                                 Alignment alignment,
                                                 std::size_t n_to_align = 0) {
  if (est.size() != ref.size()) {
    throw invalid_argument("align_trajectory: estimate has " + std::to_string(est.size()) +
                           " poses but reference has " + std::to_string(ref.size()) +
                           " (call associate() first)");
  }
  if (n_to_align > est.size()) {
    throw invalid_argument("align_trajectory: " + std::to_string(n_to_align) +
                           " poses to align requested but only " + std::to_string(est.size()) +
                           " are associated");
  }
  if (alignment == Alignment::kNone) return {est, AlignmentResult{}};
  std::vector<Eigen::Vector3d> x = est.positions();
  std::vector<Eigen::Vector3d> y = ref.positions();
  if (n_to_align > 0) {
    x.resize(n_to_align);
    y.resize(n_to_align);
  }
  if (alignment == Alignment::kPosYaw) {
    const AlignmentResult a = posyaw_alignment(x, y);
    return {apply_alignment(est, a), a};
  }
  AlignmentResult a = umeyama_alignment(x, y, alignment != Alignment::kSE3);
  if (alignment == Alignment::kScale) {
    a.rotation = Eigen::Matrix3d::Identity();
    a.translation = Eigen::Vector3d::Zero();
  }
  return {apply_alignment(est, a), a};
}

}  // namespace posefuse

#pragma once
/// @file
/// Linear triangulation of one point from two or more posed views, with
/// cheirality and parallax checks.
///
/// **Method.** The direct linear transform (Hartley & Zisserman, *Multiple
/// View Geometry*, 2nd ed., §12.2): with \f$ P_k = [R_k \mid t_k] \f$ the
/// world-to-camera map of view k (\f$ T_{wc,k}^{-1} \f$) and its normalised
/// observation \f$ m_k = (u, v) \f$, each view contributes the rows
/// \f$ u P_k^{(3)} - P_k^{(1)} \f$ and \f$ v P_k^{(3)} - P_k^{(2)} \f$; the right
/// singular vector of the smallest singular value is the homogeneous point.
/// Exact on noise-free data; with noise it minimises an algebraic error (good
/// enough as the start of a bundle adjustment).
///
/// **Checks** (TriangulationStatus): kTooFewViews (fewer than 2), kDegenerate
/// (the homogeneous point is at infinity or the system has no unique null
/// vector, e.g. all views at one centre looking along one ray),
/// kBehindCamera (depth \f$ \le \f$ min_depth in some view — points behind
/// a camera are never returned as valid), kTooLittleParallax (the largest
/// angle between two viewing rays is below min_parallax_rad, so the depth is
/// ill-determined). Normalised coordinates are (x/z, y/z) in each camera.

#include <Eigen/Core>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse {

/// Outcome of triangulate_point.
enum class TriangulationStatus { kOk, kTooFewViews, kDegenerate, kBehindCamera, kTooLittleParallax };

/// The enumerator's name without the k.
[[nodiscard]] constexpr const char* to_string(TriangulationStatus s) noexcept {
  switch (s) {
    case TriangulationStatus::kOk: return "Ok";
    case TriangulationStatus::kTooFewViews: return "TooFewViews";
    case TriangulationStatus::kDegenerate: return "Degenerate";
    case TriangulationStatus::kBehindCamera: return "BehindCamera";
    case TriangulationStatus::kTooLittleParallax: return "TooLittleParallax";
  }
  return "?";
}

/// Settings of triangulate_point.
struct TriangulationOptions {
  double min_depth = 1e-6;         ///< a depth at or below this in any view is kBehindCamera
  double min_parallax_rad = 0.0;   ///< largest ray angle below this is kTooLittleParallax
};

/// A triangulated point.
struct Triangulation {
  TriangulationStatus status = TriangulationStatus::kTooFewViews;  ///< see the file comment
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();  ///< the point in the poses' frame (valid when kOk)
  double parallax_rad = 0;  ///< largest angle between two viewing rays
  double min_depth = 0;     ///< smallest depth over the views
};

/// Angle between the viewing rays of m_a in camera a and m_b in camera b
/// (both rotated into w): the parallax they give a point.
[[nodiscard]] inline double ray_angle(const SE3d& T_w_a, const Eigen::Vector2d& m_a, const SE3d& T_w_b,
                                      const Eigen::Vector2d& m_b) noexcept {
  const Eigen::Vector3d a = T_w_a.so3().act(Eigen::Vector3d(m_a.x(), m_a.y(), 1.0));
  const Eigen::Vector3d b = T_w_b.so3().act(Eigen::Vector3d(m_b.x(), m_b.y(), 1.0));
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Triangulates one point from its normalised observations in posed views
/// (see the file comment).
/// @param[in] o depth and parallax limits
/// @param[in] T_w_c camera poses, p_w = T_w_c p_c
/// @param[in] m the point's normalised observation in each view, same count
/// @throws posefuse::invalid_argument on mismatched lengths or non-finite observations
[[nodiscard]] inline Triangulation triangulate_point(std::span<const SE3d> T_w_c, std::span<const Eigen::Vector2d> m,
                                                     const TriangulationOptions& o = {}) {
  if (T_w_c.size() != m.size())
    throw invalid_argument("triangulate_point: " + std::to_string(T_w_c.size()) + " poses but " +
                           std::to_string(m.size()) + " observations");
  for (const Eigen::Vector2d& x : m)
    if (!x.allFinite()) throw invalid_argument("triangulate_point: an observation is not finite");
  Triangulation out;
  const std::size_t n = m.size();
  if (n < 2) return out;
  Eigen::Matrix<double, Eigen::Dynamic, 4> A(2 * n, 4);
  for (std::size_t k = 0; k < n; ++k) {
    const SE3d T_c_w = T_w_c[k].inverse();
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = T_c_w.so3().matrix();
    P.col(3) = T_c_w.translation();
    A.row(Eigen::Index(2 * k)) = m[k].x() * P.row(2) - P.row(0);
    A.row(Eigen::Index(2 * k + 1)) = m[k].y() * P.row(2) - P.row(1);
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 4>> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d s = svd.singularValues();
  const Eigen::Vector4d X = svd.matrixV().col(3);
  if (!(s(2) > 1e-12 * s(0)) || !(std::abs(X(3)) > 1e-12 * X.head<3>().norm())) {
    out.status = TriangulationStatus::kDegenerate;
    return out;
  }
  out.p_w = X.head<3>() / X(3);
  out.min_depth = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k)
    out.min_depth = std::min(out.min_depth, T_w_c[k].inverse().act(out.p_w).z());
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      out.parallax_rad = std::max(out.parallax_rad, ray_angle(T_w_c[a], m[a], T_w_c[b], m[b]));
  if (!out.p_w.allFinite()) {
    out.status = TriangulationStatus::kDegenerate;
  } else if (!(out.min_depth > o.min_depth)) {
    out.status = TriangulationStatus::kBehindCamera;
  } else if (out.parallax_rad < o.min_parallax_rad) {
    out.status = TriangulationStatus::kTooLittleParallax;
  } else {
    out.status = TriangulationStatus::kOk;
  }
  return out;
}

/// Two-view shortcut of triangulate_point.
[[nodiscard]] inline Triangulation triangulate_point(const SE3d& T_w_a, const Eigen::Vector2d& m_a, const SE3d& T_w_b,
                                                     const Eigen::Vector2d& m_b, const TriangulationOptions& o = {}) {
  const SE3d T[2] = {T_w_a, T_w_b};
  const Eigen::Vector2d M[2] = {m_a, m_b};
  return triangulate_point(std::span<const SE3d>(T, 2), std::span<const Eigen::Vector2d>(M, 2), o);
}

}  // namespace posefuse

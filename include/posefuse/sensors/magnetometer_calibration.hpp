#pragma once
/// @file
/// Hard- and soft-iron magnetometer calibration by a least-squares ellipsoid
/// fit (seed 001 §2: "Hard Iron, Soft Iron ... must be calibrated"; the
/// authors used the sensor's built-in calibration).
///
/// Model: a raw reading is \f$ m = D\,b + h \f$ for the true field b, a
/// soft-iron matrix D and a hard-iron offset h. Over all orientations the raw
/// readings lie on the ellipsoid \f$ (m - h)^\top Q (m - h) = 1 \f$; the
/// calibration is \f$ \hat b = S (m - h) \f$ with the symmetric
/// \f$ S = k\,Q^{1/2} \f$, which equals \f$ D^{-1} \f$ when D is symmetric and
/// k is the true field magnitude (a rotation part of D is unobservable).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <posefuse/core/error.hpp>
#include <span>
#include <string>

namespace posefuse {

/// Hard- and soft-iron correction of a magnetometer, \f$ \hat b = S (m - h) \f$.
struct MagnetometerCalibration {
  Eigen::Vector3d hard_iron = Eigen::Vector3d::Zero();      ///< offset h, µT (sensor frame)
  Eigen::Matrix3d soft_iron = Eigen::Matrix3d::Identity();  ///< symmetric S, dimensionless

  /// The calibrated field \f$ S (m - h) \f$.
  /// @param[in] m raw reading, µT (sensor frame)
  /// @return calibrated reading, µT (sensor frame)
  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& m) const {
    return soft_iron * (m - hard_iron);
  }
};

/// Fits a general ellipsoid to raw magnetometer readings taken over many
/// orientations and returns the calibration that maps it onto a sphere.
///
/// Solves the algebraic least-squares problem
/// \f$ \min_\beta \sum_i (v_i^\top \beta - 1)^2 \f$ with
/// \f$ v = (x^2, y^2, z^2, 2xy, 2xz, 2yz, 2x, 2y, 2z) \f$ on centred and
/// scaled samples (for conditioning), i.e. the quadric
/// \f$ m^\top A m + 2 u^\top m = 1 \f$; then \f$ h = -A^{-1} u \f$ and
/// \f$ Q = A / (1 + h^\top A h) \f$. Fixed-size 9x9 normal equations; no
/// allocation.
/// @param[in] samples raw readings, µT (at least 9, spread over orientations)
/// @param[in] field_norm_uT magnitude the calibrated readings should have
///            (e.g. the local field strength); 0 keeps the geometric mean
///            radius of the fitted ellipsoid
/// @return hard-iron offset and symmetric positive-definite soft-iron matrix
/// @throws posefuse::invalid_argument with fewer than 9 samples, non-finite
///         samples, a negative field_norm_uT, samples that do not span an
///         ellipsoid (e.g. all in one plane), or a fit that is not an ellipsoid
[[nodiscard]] inline MagnetometerCalibration fit_ellipsoid(std::span<const Eigen::Vector3d> samples,
                                                           double field_norm_uT = 0.0) {
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  using Mat9 = Eigen::Matrix<double, 9, 9>;
  if (samples.size() < 9)
    throw invalid_argument("posefuse: fit_ellipsoid needs at least 9 samples, got " +
                           std::to_string(samples.size()));
  if (!(std::isfinite(field_norm_uT) && field_norm_uT >= 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid field_norm_uT must be finite and >= 0");
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& m : samples) {
    if (!m.allFinite()) throw invalid_argument("posefuse: fit_ellipsoid got a non-finite sample");
    c += m;
  }
  c /= double(samples.size());
  double s2 = 0.0;
  for (const auto& m : samples) s2 += (m - c).squaredNorm();
  const double s = std::sqrt(s2 / double(samples.size()));
  if (!(s > 0.0)) throw invalid_argument("posefuse: fit_ellipsoid samples are all equal");

  Mat9 N = Mat9::Zero();
  Vec9 rhs = Vec9::Zero();
  for (const auto& m : samples) {
    const Eigen::Vector3d p = (m - c) / s;
    Vec9 v;
    v << p.x() * p.x(), p.y() * p.y(), p.z() * p.z(), 2 * p.x() * p.y(), 2 * p.x() * p.z(),
        2 * p.y() * p.z(), 2 * p.x(), 2 * p.y(), 2 * p.z();
    N.selfadjointView<Eigen::Lower>().rankUpdate(v);
    rhs += v;
  }
  N.triangularView<Eigen::StrictlyUpper>() = N.transpose();
  const Eigen::SelfAdjointEigenSolver<Mat9> es(N);
  const double lmax = es.eigenvalues().maxCoeff();
  if (es.info() != Eigen::Success || !(es.eigenvalues().minCoeff() > 1e-10 * lmax))
    throw invalid_argument(
        "posefuse: fit_ellipsoid samples do not determine an ellipsoid (too few orientations, "
        "e.g. all in one plane)");
  const Vec9 beta = es.eigenvectors() *
                    (es.eigenvalues().cwiseInverse().asDiagonal() *
                     (es.eigenvectors().transpose() * rhs));
  Eigen::Matrix3d A;
  A << beta(0), beta(3), beta(4), beta(3), beta(1), beta(5), beta(4), beta(5), beta(2);
  const Eigen::Vector3d u(beta(6), beta(7), beta(8));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ea(A);
  if (!(ea.eigenvalues().minCoeff() > 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid: the fitted quadric is not an ellipsoid");
  const Eigen::Vector3d h = -(ea.eigenvectors() * (ea.eigenvalues().cwiseInverse().asDiagonal() *
                                                   (ea.eigenvectors().transpose() * u)));
  const double g = 1.0 + h.dot(A * h);
  if (!(g > 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid: the fitted quadric is not an ellipsoid");
  // Back to raw units: Q_raw = A / (g s^2); S = k Q_raw^{1/2}.
  const Eigen::Vector3d q = ea.eigenvalues() / (g * s * s);
  const double k = field_norm_uT > 0.0 ? field_norm_uT : std::cbrt(1.0 / std::sqrt(q.prod()));
  MagnetometerCalibration cal;
  cal.hard_iron = c + s * h;
  cal.soft_iron = k * ea.eigenvectors() * q.cwiseSqrt().asDiagonal() * ea.eigenvectors().transpose();
  return cal;
}

}  // namespace posefuse

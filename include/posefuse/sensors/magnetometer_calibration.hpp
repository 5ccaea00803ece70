#pragma once
/// @file
/// Hard- and soft-iron magnetometer calibration by a least-squares ellipsoid
/// fit (seed 001 §2: "Hard Iron, Soft Iron ... must be calibrated"; the
/// authors used the sensor's built-in calibration), and its horizontal
/// counterpart for ground robots, which turn about z only.
///
/// Model: a raw reading is \f$ m = D\,b + h \f$ for the true field b, a
/// soft-iron matrix D and a hard-iron offset h. Over all orientations the raw
/// readings lie on the ellipsoid \f$ (m - h)^\top Q (m - h) = 1 \f$; the
/// calibration is \f$ \hat b = S (m - h) \f$ with the symmetric
/// \f$ S = k\,Q^{1/2} \f$, which equals \f$ D^{-1} \f$ when D is symmetric and
/// k is the true field magnitude (a rotation part of D is unobservable).
///
/// The fits are function templates over the range of readings, so that a
/// translation unit that merely includes this header does not compile their
/// eigen-solvers (which cost several seconds of compile time per TU).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <iterator>
#include <numbers>
#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>
#include <ranges>
#include <string>
#include <type_traits>

namespace posefuse {

/// A range of magnetometer readings: any forward range (std::vector,
/// std::span, a std::views::transform over ImuSample::mag_uT, ...) whose
/// elements are fixed-size Eigen column vectors of `Dim` entries that convert
/// to `Eigen::Matrix<double, Dim, 1>` (µT, sensor frame).
template <class R, int Dim>
concept MagnetometerReadings =
    std::ranges::forward_range<R> &&
    requires {
      requires int(std::remove_cvref_t<std::ranges::range_reference_t<R>>::RowsAtCompileTime) == Dim;
      requires int(std::remove_cvref_t<std::ranges::range_reference_t<R>>::ColsAtCompileTime) == 1;
    } &&
    std::convertible_to<std::ranges::range_reference_t<R>, Eigen::Matrix<double, Dim, 1>>;

/// Hard- and soft-iron correction of a magnetometer, \f$ \hat b = S (m - h) \f$.
struct MagnetometerCalibration {
  Eigen::Vector3d hard_iron = Eigen::Vector3d::Zero();      ///< offset h, µT (sensor frame)
  Eigen::Matrix3d soft_iron = Eigen::Matrix3d::Identity();  ///< symmetric S, dimensionless

  /// The calibrated field \f$ S (m - h) \f$.
  /// @param[in] m raw reading, µT (sensor frame)
  /// @return calibrated reading, µT (sensor frame)
  template <class Lazy = void>  // compiled only where called (compile cost, core/lazy.hpp)
  [[nodiscard]] Eigen::Vector3d apply(const Eigen::Vector3d& m) const {
    const detail::dependent_t<Eigen::Matrix3d, Lazy>& S = soft_iron;
    return S * (m - hard_iron);
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
/// @param[in] samples raw readings (a MagnetometerReadings range of 3-vectors),
///            µT (at least 9, spread over orientations)
/// @param[in] field_norm_uT magnitude the calibrated readings should have
///            (e.g. the local field strength); 0 keeps the geometric mean
///            radius of the fitted ellipsoid
/// @return hard-iron offset and symmetric positive-definite soft-iron matrix
/// @throws posefuse::invalid_argument with fewer than 9 samples, non-finite
///         samples, a negative field_norm_uT, samples that do not span an
///         ellipsoid (e.g. all in one plane), or a fit that is not an ellipsoid
template <class Readings>
  requires MagnetometerReadings<const Readings&, 3>
[[nodiscard]] MagnetometerCalibration fit_ellipsoid(const Readings& samples,
                                                    double field_norm_uT = 0.0) {
  // Dependent types: nothing below is compiled unless the fit is called.
  using T = detail::dependent_t<double, Readings>;
  using Vec9 = Eigen::Matrix<T, 9, 1>;
  using Mat9 = Eigen::Matrix<T, 9, 9>;
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  using Mat3 = Eigen::Matrix<T, 3, 3>;
  const auto count = std::size_t(std::ranges::distance(samples));
  if (count < 9)
    throw invalid_argument("posefuse: fit_ellipsoid needs at least 9 samples, got " +
                           std::to_string(count));
  if (!(std::isfinite(field_norm_uT) && field_norm_uT >= 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid field_norm_uT must be finite and >= 0");
  Vec3 c = Vec3::Zero();
  for (const auto& r : samples) {
    const Vec3& m = r;
    if (!m.allFinite()) throw invalid_argument("posefuse: fit_ellipsoid got a non-finite sample");
    c += m;
  }
  c /= double(count);
  double s2 = 0.0;
  for (const auto& r : samples) {
    const Vec3& m = r;
    s2 += (m - c).squaredNorm();
  }
  const double s = std::sqrt(s2 / double(count));
  if (!(s > 0.0)) throw invalid_argument("posefuse: fit_ellipsoid samples are all equal");

  Mat9 N = Mat9::Zero();
  Vec9 rhs = Vec9::Zero();
  for (const auto& r : samples) {
    const Vec3& m = r;
    const Vec3 p = (m - c) / s;
    Vec9 v;
    v << p.x() * p.x(), p.y() * p.y(), p.z() * p.z(), 2 * p.x() * p.y(), 2 * p.x() * p.z(),
        2 * p.y() * p.z(), 2 * p.x(), 2 * p.y(), 2 * p.z();
    N.template selfadjointView<Eigen::Lower>().rankUpdate(v);
    rhs += v;
  }
  N.template triangularView<Eigen::StrictlyUpper>() = N.transpose();
  const Eigen::SelfAdjointEigenSolver<Mat9> es(N);
  const double lmax = es.eigenvalues().maxCoeff();
  if (es.info() != Eigen::Success || !(es.eigenvalues().minCoeff() > 1e-10 * lmax))
    throw invalid_argument(
        "posefuse: fit_ellipsoid samples do not determine an ellipsoid (too few orientations, "
        "e.g. all in one plane)");
  const Vec9 beta = es.eigenvectors() *
                    (es.eigenvalues().cwiseInverse().asDiagonal() *
                     (es.eigenvectors().transpose() * rhs));
  Mat3 A;
  A << beta(0), beta(3), beta(4), beta(3), beta(1), beta(5), beta(4), beta(5), beta(2);
  const Vec3 u(beta(6), beta(7), beta(8));
  const Eigen::SelfAdjointEigenSolver<Mat3> ea(A);
  if (!(ea.eigenvalues().minCoeff() > 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid: the fitted quadric is not an ellipsoid");
  const Vec3 h = -(ea.eigenvectors() * (ea.eigenvalues().cwiseInverse().asDiagonal() *
                                                   (ea.eigenvectors().transpose() * u)));
  const double g = 1.0 + h.dot(A * h);
  if (!(g > 0.0))
    throw invalid_argument("posefuse: fit_ellipsoid: the fitted quadric is not an ellipsoid");
  // Back to raw units: Q_raw = A / (g s^2); S = k Q_raw^{1/2}.
  const Vec3 q = ea.eigenvalues() / (g * s * s);
  const double k = field_norm_uT > 0.0 ? field_norm_uT : std::cbrt(1.0 / std::sqrt(q.prod()));
  MagnetometerCalibration cal;
  cal.hard_iron = c + s * h;
  cal.soft_iron = k * ea.eigenvectors() * q.cwiseSqrt().asDiagonal() * ea.eigenvectors().transpose();
  return cal;
}

/// Why fit_horizontal_ellipse() did or did not calibrate.
enum class EllipseFitStatus {
  kOk,                 ///< calibrated
  kTooFewReadings,     ///< fewer than HorizontalEllipseFitOptions::min_readings
  kNonFinite,          ///< a reading is NaN or infinite
  kConstantReadings,   ///< all readings equal (no spread to fit)
  kNotAnEllipse,       ///< the fitted conic is not an ellipse of plausible shape
  kTooLittleTurning,   ///< the readings cover too small an arc around the centre
};

/// The reason of a status as a short phrase ("fewer than 20 readings", ...),
/// for notes and messages.
/// @param[in] s the status
/// @param[in] min_readings the minimum used (for kTooFewReadings)
/// @param[in] min_coverage_deg the coverage required (for kTooLittleTurning)
[[nodiscard]] inline std::string to_string(EllipseFitStatus s, std::size_t min_readings = 20,
                                           double min_coverage_deg = 270.0) {
  switch (s) {
    case EllipseFitStatus::kOk: return "calibrated";
    case EllipseFitStatus::kTooFewReadings:
      return "fewer than " + std::to_string(min_readings) + " readings";
    case EllipseFitStatus::kNonFinite: return "a reading is not finite";
    case EllipseFitStatus::kConstantReadings: return "constant readings";
    case EllipseFitStatus::kNotAnEllipse: return "readings are not on a plausible ellipse";
    case EllipseFitStatus::kTooLittleTurning:
      return "the robot turned through less than " +
             std::to_string(int(std::lround(min_coverage_deg))) + " deg";
  }
  return "unknown";
}

/// Acceptance limits of fit_horizontal_ellipse().
struct HorizontalEllipseFitOptions {
  std::size_t min_readings = 20;      ///< fewer readings are not fitted
  double max_eigenvalue_ratio = 4.0;  ///< largest / smallest eigenvalue of Q (axis ratio², 4: axes 2:1)
  double min_coverage_deg = 270.0;    ///< arc of 10° direction bins (about the centre) the readings must fill
};

/// Result of fit_horizontal_ellipse().
struct HorizontalEllipseFit {
  EllipseFitStatus status = EllipseFitStatus::kTooFewReadings;  ///< kOk when calibrated
  /// The calibration: hard iron (h_x, h_y, 0), soft iron with the fitted 2x2
  /// block and 1 for z; identity / zero unless status is kOk.
  MagnetometerCalibration calibration;
  double coverage_deg = 0;    ///< arc covered by the readings (10° bins about the centre)
  std::size_t readings = 0;   ///< number of readings given
  /// True when calibrated.
  [[nodiscard]] bool ok() const noexcept { return status == EllipseFitStatus::kOk; }
};

/// Horizontal hard- and soft-iron calibration for a robot that only turns
/// about its z axis (a ground robot): the 3-D ellipsoid of fit_ellipsoid()
/// is then undetermined, but the horizontal components \f$ (m_x, m_y) \f$
/// of the readings lie on an ellipse, \f$ (m - h)^\top Q (m - h) = 1 \f$.
///
/// On readings centred at their mean c and scaled by their RMS spread s
/// (conditioning), solves the algebraic least-squares conic
/// \f$ \min_\beta \sum_i (v_i^\top\beta - 1)^2 \f$,
/// \f$ v = (x^2, xy, y^2, x, y) \f$, i.e. \f$ a x^2 + b xy + c y^2 + d x + e y = 1 \f$
/// (Fitzgibbon, Pilu, Fisher, "Direct least square fitting of ellipses",
/// IEEE TPAMI 21(5), 1999, eq 1, with the constant term fixed instead of
/// their ellipse constraint, hence the shape check). With
/// \f$ M = \begin{pmatrix} a & b/2 \\ b/2 & c \end{pmatrix} \f$ the centre is
/// \f$ x_0 = -\tfrac12 M^{-1} (d, e)^\top \f$ and
/// \f$ Q = M / (1 + x_0^\top M x_0) \f$; the calibration is
/// \f$ h = c + s\,x_0 \f$ and \f$ S = k\,Q^{1/2} \f$ with k keeping the
/// geometric-mean radius (\f$ k = (\lambda_1\lambda_2)^{-1/4} \f$ in the
/// scaled units: S maps the ellipse onto a circle of that radius, so headings
/// are corrected and magnitudes stay those of the scaled readings). z is
/// left uncalibrated (hard iron 0, scale 1).
///
/// The fit is accepted when it is an ellipse (both eigenvalues of Q
/// positive) of plausible shape (eigenvalue ratio at most
/// `max_eigenvalue_ratio`) and the readings' directions about the fitted
/// centre fill at least `min_coverage_deg` of 36 bins of 10° — the robot
/// turned far enough for the ellipse to be determined.
/// @param[in] readings horizontal readings (m_x, m_y) in µT, a
///            MagnetometerReadings range of 2-vectors (e.g. a transform view
///            of ImuSample::mag_uT's head<2>())
/// @param[in] options acceptance limits
/// @return the status, the calibration (identity unless kOk), the coverage
///         and the number of readings; never throws for bad data
template <class Readings>
  requires MagnetometerReadings<const Readings&, 2>
[[nodiscard]] HorizontalEllipseFit fit_horizontal_ellipse(
    const Readings& readings, const HorizontalEllipseFitOptions& options = {}) {
  // Dependent types: nothing below is compiled unless the fit is called.
  using T = detail::dependent_t<double, Readings>;
  using Vec2 = Eigen::Matrix<T, 2, 1>;
  using Mat2 = Eigen::Matrix<T, 2, 2>;
  using Vec5 = Eigen::Matrix<T, 5, 1>;
  using Mat5 = Eigen::Matrix<T, 5, 5>;
  HorizontalEllipseFit out;
  out.readings = std::size_t(std::ranges::distance(readings));
  const auto fail = [&out](EllipseFitStatus why) {
    out.status = why;
    out.calibration = {};
    return out;
  };
  if (out.readings < options.min_readings || out.readings == 0)
    return fail(EllipseFitStatus::kTooFewReadings);
  const double n = double(out.readings);
  Vec2 c = Vec2::Zero();
  for (const auto& r : readings) {
    const Vec2& m = r;
    if (!m.allFinite()) return fail(EllipseFitStatus::kNonFinite);
    c += m;
  }
  c /= n;
  double s = 0;
  for (const auto& r : readings) {
    const Vec2& m = r;
    s += (m - c).squaredNorm();
  }
  s = std::sqrt(s / n);
  if (!(s > 0)) return fail(EllipseFitStatus::kConstantReadings);
  Mat5 N = Mat5::Zero();
  Vec5 rhs = Vec5::Zero();
  for (const auto& r : readings) {
    const Vec2& m = r;
    const Vec2 p = (m - c) / s;
    const Vec5 v(p.x() * p.x(), p.x() * p.y(), p.y() * p.y(), p.x(), p.y());
    N += v * v.transpose();
    rhs += v;
  }
  const Vec5 b = N.ldlt().solve(rhs);
  Mat2 M;
  M << b(0), b(1) / 2, b(1) / 2, b(2);
  const double det = M(0, 0) * M(1, 1) - M(0, 1) * M(1, 0);
  const Vec2 ctr =
      -0.5 * Vec2(M(1, 1) * b(3) - M(0, 1) * b(4), M(0, 0) * b(4) - M(1, 0) * b(3)) / det;
  const Mat2 Q = M / (1.0 + ctr.dot(M * ctr));
  Eigen::SelfAdjointEigenSolver<Mat2> es;
  es.computeDirect(Q);
  const Vec2 ev = es.eigenvalues();
  if (!b.allFinite() || !(ev.minCoeff() > 0) ||
      !(ev.maxCoeff() / ev.minCoeff() <= options.max_eigenvalue_ratio))
    return fail(EllipseFitStatus::kNotAnEllipse);
  std::array<bool, 36> seen{};  // 10° bins of the reading's direction about the centre
  for (const auto& r : readings) {
    const Vec2& m = r;
    const Vec2 p = (m - c) / s - ctr;
    const double a = std::atan2(p.y(), p.x()) + std::numbers::pi;
    seen[std::size_t(std::min(35.0, a / (2 * std::numbers::pi) * 36))] = true;
  }
  out.coverage_deg = 10.0 * double(std::count(seen.begin(), seen.end(), true));
  if (out.coverage_deg < options.min_coverage_deg) return fail(EllipseFitStatus::kTooLittleTurning);
  const double k = 1.0 / std::sqrt(std::sqrt(ev.prod()));  // keep the geometric-mean radius
  const Mat2 S = k * es.eigenvectors() * ev.cwiseSqrt().asDiagonal() *
                            es.eigenvectors().transpose();
  out.calibration.hard_iron << c + s * ctr, 0.0;
  out.calibration.soft_iron.setIdentity();
  out.calibration.soft_iron.topLeftCorner<2, 2>() = S;
  out.status = EllipseFitStatus::kOk;
  return out;
}

}  // namespace posefuse

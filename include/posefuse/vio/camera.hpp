#pragma once
/// @file
/// The pinhole camera with radial-tangential distortion (EuRoC's cameras,
/// OpenCV's `k1 k2 p1 p2` model): projection, its Jacobian, undistortion,
/// and the camera read from a EuRoC `sensor.yaml` (io/euroc_camera.hpp).
///
/// **Model.** A point \f$ p_C = (X, Y, Z) \f$ in the camera frame (z forward,
/// x right, y down) with \f$ Z > 0 \f$ has normalised coordinates
/// \f$ (x, y) = (X/Z, Y/Z) \f$; with \f$ r^2 = x^2 + y^2 \f$ the distorted
/// coordinates are
/// \f[ x_d = x (1 + k_1 r^2 + k_2 r^4) + 2 p_1 x y + p_2 (r^2 + 2x^2), \f]
/// \f[ y_d = y (1 + k_1 r^2 + k_2 r^4) + p_1 (r^2 + 2y^2) + 2 p_2 x y, \f]
/// and the pixel is \f$ (u, v) = (f_u x_d + c_u, f_v y_d + c_v) \f$.
///
/// **Image.** Pixel centres are at integer coordinates (OpenCV's and
/// EuRoC's convention), so the image covers \f$ u \in [-0.5, w - 0.5] \f$,
/// \f$ v \in [-0.5, h - 0.5] \f$; `in_image` tests that rectangle.
///
/// **Validity.** The radial factor folds back (a farther point lands closer
/// to the centre) beyond the first radius where
/// \f$ d r_d / d r = 1 + 3k_1 r^2 + 5k_2 r^4 \f$ vanishes; `project` refuses
/// points beyond it (and behind the camera or outside the image), so it
/// never reports a pixel for a point that another, nearer-the-axis point
/// also maps to. `undistort` inverts the distortion by Newton's method and
/// returns NaN when it does not converge to 1e-12 (normalised units) within
/// 20 steps; `from_calibration` checks that it converges on a grid of pixels
/// covering the image, so for a camera it accepted this happens only far
/// outside the image.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/message_number.hpp>
#include <posefuse/io/euroc_camera.hpp>

namespace posefuse {

/// Largest focal length (px) a camera may have: a 1000-pixel image then
/// spans about 0.6 degrees, and beyond it the distortion's inversion cannot
/// reach pixel accuracy.
inline constexpr double kMaxFocalPx = 1e5;

/// A pinhole camera with radial-tangential distortion (see the file comment).
struct PinholeRadtan {
  double fu = 0, fv = 0;  ///< focal lengths (px)
  double cu = 0, cv = 0;  ///< principal point (px)
  std::array<double, 4> distortion{0, 0, 0, 0};  ///< k1, k2, p1, p2
  int width = 0, height = 0;                     ///< resolution (px)
  double rate_hz = 0;                            ///< frame rate (Hz), 0 when unknown
  /// Camera (sensor S) to body (IMU) frame: \f$ p_B = T_{BS}\,p_C \f$.
  Eigen::Isometry3d T_BS = Eigen::Isometry3d::Identity();

  /// The camera of a calibration, after checking that its distortion can be
  /// inverted over the whole image (see the file comment).
  /// @throws posefuse::invalid_argument for non-positive focal lengths or
  ///         resolution, a non-finite value, or a distortion that folds or
  ///         cannot be inverted inside the image
  [[nodiscard]] static PinholeRadtan from_calibration(const CameraCalibration& c) {
    PinholeRadtan cam;
    cam.fu = c.fu;
    cam.fv = c.fv;
    cam.cu = c.cu;
    cam.cv = c.cv;
    cam.distortion = c.distortion;
    cam.width = c.width;
    cam.height = c.height;
    cam.rate_hz = c.rate_hz;
    cam.T_BS = c.T_BS;
    cam.validate();
    return cam;
  }

  /// Checks the camera (see from_calibration).
  /// @throws posefuse::invalid_argument naming what is wrong
  void validate() const {
    const bool finite = std::isfinite(fu) && std::isfinite(fv) && std::isfinite(cu) &&
                        std::isfinite(cv) && std::isfinite(rate_hz) &&
                        std::isfinite(distortion[0]) && std::isfinite(distortion[1]) &&
                        std::isfinite(distortion[2]) && std::isfinite(distortion[3]) &&
                        T_BS.matrix().allFinite();
    if (!finite) throw invalid_argument("PinholeRadtan: a parameter is not finite");
    if (!(fu > 0 && fv > 0)) throw invalid_argument("PinholeRadtan: focal lengths must be > 0");
    // Below 1 px the image would span nearly 180 degrees (a pinhole cannot
    // see 180); above kMaxFocalPx see its comment.
    if (!(fu >= 1.0 && fv >= 1.0 && fu <= kMaxFocalPx && fv <= kMaxFocalPx))
      throw invalid_argument("PinholeRadtan: focal lengths (" + detail::message_number(fu) + ", " +
                             detail::message_number(fv) + " px) must be from 1 to " +
                             detail::message_number(kMaxFocalPx) + " px");
    if (width <= 0 || height <= 0) throw invalid_argument("PinholeRadtan: resolution must be positive");
    if (rate_hz < 0) throw invalid_argument("PinholeRadtan: rate_hz must be >= 0");
    // Newton must converge, the result lie inside the unfolded region, and
    // project back to the pixel, on a 17 x 17 grid over the image.
    const double r2max = max_valid_r2();
    for (int i = 0; i <= 16; ++i) {
      for (int j = 0; j <= 16; ++j) {
        const Eigen::Vector2d uv(-0.5 + (width * i) / 16.0, -0.5 + (height * j) / 16.0);
        const Eigen::Vector2d xy = undistort(uv);
        if (!xy.allFinite() || !(xy.squaredNorm() < r2max) ||
            (pixel_of_normalised(xy) - uv).norm() > 1e-6)
          throw invalid_argument(
              "PinholeRadtan: the distortion cannot be inverted at pixel (" + detail::message_number(uv.x()) +
              ", " + detail::message_number(uv.y()) + "): it folds inside the image");
      }
    }
  }

  /// Largest \f$ r^2 \f$ before the radial factor folds (+inf when it never does).
  [[nodiscard]] double max_valid_r2() const noexcept {
    // 1 + 3 k1 s + 5 k2 s^2 = 0 for s = r^2 >= 0: the smallest positive root.
    const double a = 5 * distortion[1], b = 3 * distortion[0];
    double s = std::numeric_limits<double>::infinity();
    if (a == 0) {
      if (b < 0) s = -1.0 / b;
    } else {
      const double disc = b * b - 4 * a;
      if (disc >= 0) {
        const double q = std::sqrt(disc);
        for (const double root : {(-b - q) / (2 * a), (-b + q) / (2 * a)})
          if (root > 0 && root < s) s = root;
      }
    }
    return s;
  }

  /// Distorted normalised coordinates of normalised (x, y), and optionally
  /// the 2x2 Jacobian \f$ \partial(x_d, y_d) / \partial(x, y) \f$.
  [[nodiscard]] Eigen::Vector2d distort(const Eigen::Vector2d& xy,
                                        Eigen::Matrix2d* J = nullptr) const noexcept {
    const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3];
    const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
    const double radial = 1 + k1 * r2 + k2 * r2 * r2;
    if (J != nullptr) {
      const double dradial = 2 * k1 + 4 * k2 * r2;  // d radial / d r2 * 2 (times x or y below)
      (*J)(0, 0) = radial + x * x * dradial + 2 * p1 * y + 6 * p2 * x;
      (*J)(0, 1) = x * y * dradial + 2 * p1 * x + 2 * p2 * y;
      (*J)(1, 0) = x * y * dradial + 2 * p1 * x + 2 * p2 * y;
      (*J)(1, 1) = radial + y * y * dradial + 6 * p1 * y + 2 * p2 * x;
    }
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  }

  /// The pixel of normalised (x, y) (no validity check).
  [[nodiscard]] Eigen::Vector2d pixel_of_normalised(const Eigen::Vector2d& xy) const noexcept {
    const Eigen::Vector2d d = distort(xy);
    return {fu * d.x() + cu, fv * d.y() + cv};
  }

  /// The pixel of a point in the camera frame.
  /// @param[in]  p_C point in the camera frame (m)
  /// @param[out] J   optional \f$ \partial(u, v) / \partial p_C \f$ (2x3), set
  ///                 when a pixel is returned
  /// @return the pixel; nullopt when Z <= 0, the point is beyond the
  ///         distortion's valid radius, or the pixel is outside the image
  [[nodiscard]] std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_C,
                                                       Eigen::Matrix<double, 2, 3>* J = nullptr) const {
    if (!(p_C.z() > 0)) return std::nullopt;
    const double iz = 1.0 / p_C.z();
    const Eigen::Vector2d xy(p_C.x() * iz, p_C.y() * iz);
    if (!(xy.squaredNorm() < max_valid_r2())) return std::nullopt;
    Eigen::Matrix2d Jd;
    const Eigen::Vector2d d = distort(xy, J != nullptr ? &Jd : nullptr);
    const Eigen::Vector2d uv(fu * d.x() + cu, fv * d.y() + cv);
    if (!in_image(uv)) return std::nullopt;
    if (J != nullptr) {
      Eigen::Matrix<double, 2, 3> Jn;  // d(x, y) / d p_C
      Jn << iz, 0, -xy.x() * iz, 0, iz, -xy.y() * iz;
      *J = Eigen::Vector2d(fu, fv).asDiagonal() * Jd * Jn;
    }
    return uv;
  }

  /// Normalised coordinates (x/z, y/z) of a pixel, inverting the distortion
  /// by Newton's method; NaN when it does not converge (file comment).
  [[nodiscard]] Eigen::Vector2d undistort(const Eigen::Vector2d& uv) const noexcept {
    const Eigen::Vector2d target((uv.x() - cu) / fu, (uv.y() - cv) / fv);
    Eigen::Vector2d xy = target;
    for (int k = 0; k < 20; ++k) {
      Eigen::Matrix2d J;
      const Eigen::Vector2d r = distort(xy, &J) - target;
      if (r.cwiseAbs().maxCoeff() <= 1e-12) return xy;
      const double det = J.determinant();
      if (!(std::abs(det) > 1e-12)) break;
      xy -= J.inverse() * r;
      if (!xy.allFinite()) break;
    }
    const Eigen::Vector2d r = distort(xy) - target;
    if (r.allFinite() && r.cwiseAbs().maxCoeff() <= 1e-12) return xy;
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  }

  /// True when the pixel lies in the image (file comment).
  [[nodiscard]] bool in_image(const Eigen::Vector2d& uv) const noexcept {
    return uv.x() >= -0.5 && uv.x() <= width - 0.5 && uv.y() >= -0.5 && uv.y() <= height - 0.5;
  }
};

/// The camera of a EuRoC `sensor.yaml` (io/euroc_camera.hpp).
/// @throws posefuse::io_error naming file:line for a malformed or incomplete
///         file, and naming the file when the distortion cannot be inverted
///         over the image
template <class Lazy = void>
[[nodiscard]] PinholeRadtan read_euroc_camera(const std::filesystem::path& file) {
  const CameraCalibration c = read_euroc_camera_calibration(file);
  try {
    return PinholeRadtan::from_calibration(c);
  } catch (const invalid_argument& e) {
    // The file, not the class that checked it, is at fault.
    std::string why = e.what();
    const std::string_view prefix = "PinholeRadtan: ";
    if (why.rfind(prefix, 0) == 0) why.erase(0, prefix.size());
    throw io_error(file, "the camera is not usable: " + why);
  }
}

}  // namespace posefuse

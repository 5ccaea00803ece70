#pragma once
/// @file
/// Robust losses of a reprojection residual: \f$ \rho(s) \f$ of its squared
/// whitened norm \f$ s = |r|^2 \f$ (r in units of the pixel noise σ), with
/// \f$ \rho'(s) \f$ and \f$ \rho''(s) \f$.
///
/// * Cauchy, \f$ \rho(s) = c^2 \log(1 + s/c^2) \f$: redescending, so the pull
///   of a gross outlier fades (VINS-Mono's code uses it with c = 1 on
///   residuals whitened by focal / 1.5 px, i.e. c = 1.5 px);
/// * Huber, \f$ \rho(s) = s \f$ for \f$ s \le \delta^2 \f$, else
///   \f$ 2\delta\sqrt{s} - \delta^2 \f$: linear beyond δ, so an outlier's pull
///   is bounded (VINS-Mono's paper, Qin et al., T-RO 2018, eq 22).
///
/// **Use in least squares.** Both have \f$ \rho'' \le 0 \f$ wherever they
/// differ from the square, so the second-order (Triggs) correction of the
/// Jacobian is dropped and the residual and its Jacobian are scaled by
/// \f$ \sqrt{\rho'(s)} \f$ (iteratively re-weighted least squares) — the
/// choice Ceres makes for \f$ \rho'' \le 0 \f$, so a solver fed the same
/// residuals takes the same steps. The scaled system stays PSD.

#include <cmath>

namespace posefuse {

/// A robust loss for reprojection residuals (see the file comment).
struct ReprojectionLoss {
  /// Which loss.
  enum class Kind {
    kNone,    ///< \f$ \rho(s) = s \f$
    kHuber,   ///< quadratic to δ, then linear in |r|
    kCauchy,  ///< \f$ c^2 \log(1 + s/c^2) \f$
  };
  Kind kind = Kind::kCauchy;  ///< which loss
  double scale = 1.0;         ///< δ or c, in units of σ (whitened), > 0

  /// \f$ \rho(s) \f$.
  [[nodiscard]] double rho(double s) const noexcept {
    const double c2 = scale * scale;
    switch (kind) {
      case Kind::kNone: return s;
      case Kind::kHuber: return s <= c2 ? s : 2.0 * scale * std::sqrt(s) - c2;
      case Kind::kCauchy: return c2 * std::log1p(s / c2);
    }
    return s;
  }
  /// \f$ \rho'(s) \f$, in (0, 1].
  [[nodiscard]] double d_rho(double s) const noexcept {
    const double c2 = scale * scale;
    switch (kind) {
      case Kind::kNone: return 1.0;
      case Kind::kHuber: return s <= c2 ? 1.0 : scale / std::sqrt(s);
      case Kind::kCauchy: return 1.0 / (1.0 + s / c2);
    }
    return 1.0;
  }
  /// \f$ \rho''(s) \f$ (\f$ \le 0 \f$ for all three).
  [[nodiscard]] double d2_rho(double s) const noexcept {
    const double c2 = scale * scale;
    switch (kind) {
      case Kind::kNone: return 0.0;
      case Kind::kHuber: return s <= c2 ? 0.0 : -0.5 * scale / (s * std::sqrt(s));
      case Kind::kCauchy: {
        const double q = 1.0 + s / c2;
        return -1.0 / (c2 * q * q);
      }
    }
    return 0.0;
  }
  /// The factor \f$ \sqrt{\rho'(s)} \f$ that scales the residual and its Jacobian.
  [[nodiscard]] double scaling(double s) const noexcept { return std::sqrt(d_rho(s)); }
};

}  // namespace posefuse

#pragma once
/// @file
/// Robust losses of a pose-graph edge: \f$ \rho(s) \f$ of the edge's squared
/// error \f$ s = e^\top \Omega e \f$ and the iteratively-reweighted least
/// squares weight \f$ \rho'(s) \f$ the optimiser gives the edge.
///
/// Huber grows linearly beyond \f$ \delta \f$, so an outlier's pull is
/// bounded; Cauchy is redescending, so a gross outlier's pull fades. For
/// errors well inside the scale, Huber is the plain square and Cauchy close
/// to it (\f$ \rho(s) \approx s \f$, \f$ \rho' \approx 1 \f$).

#include <cmath>

namespace posefuse {

/// Robust loss \f$ \rho(s) \f$ of an edge's squared error \f$ s = e^\top\Omega e \f$.
enum class RobustLoss {
  kNone,    ///< \f$ \rho(s) = s \f$
  kHuber,   ///< \f$ \rho(s) = s \f$ for \f$ s \le \delta^2 \f$, else \f$ 2\delta\sqrt{s} - \delta^2 \f$
  kCauchy,  ///< \f$ \rho(s) = c^2 \log(1 + s/c^2) \f$
};

/// A robust loss with its scale (\f$ \delta \f$ or \f$ c \f$, in whitened units).
struct RobustKernel {
  RobustLoss type = RobustLoss::kNone;  ///< which loss
  double scale = 1.0;                   ///< \f$ \delta \f$ (Huber) or \f$ c \f$ (Cauchy), > 0

  /// \f$ \rho(s) \f$.
  [[nodiscard]] double rho(double s) const noexcept {
    switch (type) {
      case RobustLoss::kNone: return s;
      case RobustLoss::kHuber: {
        const double d2 = scale * scale;
        return s <= d2 ? s : 2.0 * scale * std::sqrt(s) - d2;
      }
      case RobustLoss::kCauchy: {
        const double c2 = scale * scale;
        return c2 * std::log1p(s / c2);
      }
    }
    return s;
  }
  /// \f$ \rho'(s) \f$, the iteratively-reweighted least-squares weight (in (0, 1]).
  [[nodiscard]] double weight(double s) const noexcept {
    switch (type) {
      case RobustLoss::kNone: return 1.0;
      case RobustLoss::kHuber: return s <= scale * scale ? 1.0 : scale / std::sqrt(s);
      case RobustLoss::kCauchy: return 1.0 / (1.0 + s / (scale * scale));
    }
    return 1.0;
  }
};

}  // namespace posefuse

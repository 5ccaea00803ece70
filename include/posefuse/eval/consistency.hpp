#pragma once
/// @file
/// Filter consistency against ground truth: the normalised estimation error
/// squared (NEES) per pose and its average against chi-square bounds
/// (Bar-Shalom, Li and Kirubarajan, "Estimation with Applications to
/// Tracking and Navigation", 2001, §5.4.2), the check OpenVINS users run on
/// their estimators.
///
/// For an estimate with covariance \f$ \Sigma_k \f$ and error \f$ e_k \f$ of
/// dimension d, \f$ \epsilon_k = e_k^\top \Sigma_k^{-1} e_k \f$. When the
/// estimator is consistent, \f$ \epsilon_k \sim \chi^2_d \f$ and the average
/// over N independent poses satisfies \f$ N \bar\epsilon \sim \chi^2_{Nd} \f$,
/// so its two-sided bounds at confidence \f$ 1-\alpha \f$ are
/// \f$ [\chi^2_{Nd}(\alpha/2),\ \chi^2_{Nd}(1-\alpha/2)] / N \f$. Errors of a
/// trajectory are correlated in time, so read the bounds as a guide: an
/// average far above them means the covariance is too small (overconfident),
/// far below, too large.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <posefuse/core/chi_square.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// NEES per pose with the average and its chi-square bounds.
struct NeesResult {
  std::vector<double> nees;  ///< \f$ \epsilon_k \f$ per pose
  int dim = 0;               ///< d: 3 (position) or 6 (position and rotation)
  double mean = 0.0;         ///< \f$ \bar\epsilon \f$
  double lower = 0.0;        ///< lower bound of \f$ \bar\epsilon \f$ at `confidence`
  double upper = 0.0;        ///< upper bound of \f$ \bar\epsilon \f$ at `confidence`
  double confidence = 0.95;  ///< two-sided confidence of the bounds
  /// True when the average lies within the bounds.
  [[nodiscard]] bool consistent() const noexcept { return mean >= lower && mean <= upper; }
};

namespace detail {

/// Standard normal quantile by bisection on erfc (to about 1e-15).
template <class Lazy = void>
double normal_quantile(double p) {
  double lo = -40.0, hi = 40.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace detail

/// Quantile of \f$ \chi^2_k \f$, exact (`chi_square_quantile`) up to k = 1000
/// and by the Wilson–Hilferty cube-root normal approximation beyond
/// (\f$ k (1 - \tfrac{2}{9k} + z_p \sqrt{2/(9k)})^3 \f$, relative error below
/// 1e-4 there), where the incomplete-gamma series would need too many terms.
/// @throws posefuse::invalid_argument unless 0 < p < 1 and k > 0
template <class Lazy = void>
[[nodiscard]] double chi_square_quantile_any(double p, long long k) {
  if (!(p > 0.0 && p < 1.0) || k <= 0)
    throw invalid_argument("chi_square_quantile_any: need 0 < p < 1 and k > 0");
  if (k <= 1000) return chi_square_quantile(p, static_cast<int>(k));
  const double kd = static_cast<double>(k);
  const double c = 2.0 / (9.0 * kd);
  const double z = detail::normal_quantile(p);
  const double base = 1.0 - c + z * std::sqrt(c);
  return kd * base * base * base;
}

/// NEES of an aligned estimate with covariance against a reference.
///
/// The alignment \f$ y = c R x + t \f$ that maps the estimate onto the
/// reference also moves its covariance: the position block becomes
/// \f$ c^2 R \Sigma_{pp} R^\top \f$, the cross block \f$ c R \Sigma_{p\theta} \f$;
/// the body-frame rotation block is unchanged. Errors: position
/// \f$ p_{ref} - (c R p + t) \f$, rotation
/// \f$ \mathrm{Log}((R R_{est})^\top R_{ref}) \f$ (right perturbation).
/// @param[in] ref reference, pose k associated with `est` pose k
/// @param[in] est estimate (before alignment)
/// @param[in] covariance per estimate pose (see TumWithCovariance)
/// @param[in] dim 3 (position only) or 6 (position and rotation)
/// @param[in] alignment the similarity applied to `est` (identity if none)
/// @param[in] confidence two-sided confidence of the bounds (0 < c < 1)
/// @return per-pose NEES, the average and its bounds
/// @throws posefuse::invalid_argument for mismatched sizes, a bad `dim` or
///         confidence, or a covariance that is not positive definite after
///         the alignment (naming the pose)
template <class Lazy = void>
[[nodiscard]] NeesResult nees(const Trajectory& ref, const Trajectory& est,
                              const std::vector<Eigen::Matrix<double, 6, 6>>& covariance, int dim,
                              const AlignmentResult& alignment = {}, double confidence = 0.95) {
  if (ref.size() != est.size() || est.size() != covariance.size() || ref.empty())
    throw invalid_argument("nees: reference, estimate and covariances need the same, non-zero count");
  if (dim != 3 && dim != 6) throw invalid_argument("nees: dim must be 3 or 6");
  if (!(confidence > 0.0 && confidence < 1.0))
    throw invalid_argument("nees: confidence must be in (0, 1)");
  NeesResult r;
  r.dim = dim;
  r.confidence = confidence;
  r.nees.reserve(ref.size());
  const Eigen::Matrix3d& R = alignment.rotation;
  const double c = alignment.scale;
  double sum = 0.0;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Eigen::Vector3d p = alignment.apply(est.poses[k].translation());
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = ref.poses[k].translation() - p;
    const Eigen::Matrix3d R_est = R * est.poses[k].linear();
    e.tail<3>() = SO3<double>(Eigen::Quaterniond(R_est.transpose() * ref.poses[k].linear())).log();
    Eigen::Matrix<double, 6, 6> S = covariance[k];
    S.topLeftCorner<3, 3>() = c * c * R * S.topLeftCorner<3, 3>() * R.transpose();
    S.topRightCorner<3, 3>() = c * R * S.topRightCorner<3, 3>();
    S.bottomLeftCorner<3, 3>() = S.topRightCorner<3, 3>().transpose();
    double value = 0.0;
    if (dim == 3) {
      const Eigen::LLT<Eigen::Matrix3d> llt(S.topLeftCorner<3, 3>());
      if (llt.info() != Eigen::Success)
        throw invalid_argument("nees: covariance of pose " + std::to_string(k) + " is not positive definite");
      value = e.head<3>().dot(llt.solve(e.head<3>()));
    } else {
      const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(S);
      if (llt.info() != Eigen::Success)
        throw invalid_argument("nees: covariance of pose " + std::to_string(k) + " is not positive definite");
      value = e.dot(llt.solve(e));
    }
    r.nees.push_back(value);
    sum += value;
  }
  const double n = static_cast<double>(r.nees.size());
  r.mean = sum / n;
  const long long dof = static_cast<long long>(r.nees.size()) * dim;
  const double alpha = 1.0 - confidence;
  r.lower = chi_square_quantile_any(0.5 * alpha, dof) / n;
  r.upper = chi_square_quantile_any(1.0 - 0.5 * alpha, dof) / n;
  return r;
}

}  // namespace posefuse

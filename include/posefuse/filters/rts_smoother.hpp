#pragma once
/// @file
/// Rauch-Tung-Striebel fixed-interval smoothing of a recorded EKF run.
///
/// With filtered beliefs \f$ (x_k, P_k) \f$, one-step predictions
/// \f$ (\bar x_{k+1}, \bar P_{k+1}) \f$ and the Jacobians \f$ F_k \f$ of those
/// predictions, the backward pass is (Rauch, Tung & Striebel, AIAA J. 3(8),
/// 1965; Särkkä, *Bayesian Filtering and Smoothing*, 2013, Thm 8.2):
/// \f[ C_k = P_k F_k^\top \bar P_{k+1}^{-1},\quad
///     x^s_k = x_k \boxplus C_k (x^s_{k+1} \boxminus \bar x_{k+1}),\quad
///     P^s_k = P_k + C_k (P^s_{k+1} - \bar P_{k+1}) C_k^\top \f]
/// It needs the whole run, so it is for offline post-processing (as seed 000
/// is): each smoothed estimate uses past *and* future measurements.

#include <Eigen/Cholesky>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <vector>

namespace posefuse {

/// One recorded filter step k: the prediction into k and the filtered belief
/// after k's updates. For k = 0, `predicted` is the prior and F is unused.
template <State S>
struct SmootherStep {
  S predicted_mean{};
  CovarianceOf<S> predicted_cov = CovarianceOf<S>::Identity();
  CovarianceOf<S> F = CovarianceOf<S>::Identity();  ///< Jacobian of the prediction k-1 -> k
  S filtered_mean{};
  CovarianceOf<S> filtered_cov = CovarianceOf<S>::Identity();
};

/// Runs the backward RTS pass over a recorded forward run.
/// @param[in] steps the forward run, in time order
/// @return smoothed beliefs, one per step
/// @throws posefuse::invalid_argument if a predicted covariance is not
///         positive definite
template <State S>
[[nodiscard]] std::vector<Gaussian<S>> rts_smooth(const std::vector<SmootherStep<S>>& steps) {
  using Cov = CovarianceOf<S>;
  std::vector<Gaussian<S>> out(steps.size());
  if (steps.empty()) return out;
  S xs = steps.back().filtered_mean;
  Cov Ps = steps.back().filtered_cov;
  out.back().mean = xs;
  out.back().cov = Ps;
  for (std::size_t k = steps.size() - 1; k-- > 0;) {
    const SmootherStep<S>& now = steps[k];
    const SmootherStep<S>& next = steps[k + 1];
    const Eigen::LLT<Cov> llt(next.predicted_cov);
    if (llt.info() != Eigen::Success)
      throw invalid_argument("rts_smooth: a predicted covariance is not positive definite");
    // C = P F^T Pbar^-1  <=>  C^T = Pbar^-1 F P   (P, Pbar symmetric)
    const Cov C = llt.solve(next.F * now.filtered_cov).transpose();
    xs = plus(now.filtered_mean, TangentOf<S>(C * minus(xs, next.predicted_mean)));
    Ps = now.filtered_cov + C * (Ps - next.predicted_cov) * C.transpose();
    Ps = ScalarOf<S>(0.5) * (Ps + Ps.transpose());
    out[k].mean = xs;
    out[k].cov = Ps;
  }
  return out;
}

}  // namespace posefuse

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
#include <posefuse/filters/detail/rts_gain.hpp>
#include <string>
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
///
/// Up to 4 states the gain is computed from a 2x2-block factorisation of
/// \f$ \bar P_{k+1} \f$ in closed form (filters/detail/rts_gain.hpp), which
/// refuses a predicted covariance whose pivots are not above round-off
/// (\f$ d_j > N \epsilon \bar P_{jj} \f$, as the EKF's innovation test);
/// larger states use a Cholesky factorisation (pivots > 0). Only the lower
/// triangle of a predicted covariance is read. Smoothed covariances are
/// exactly symmetric.
/// @param[in] steps the forward run, in time order
/// @return smoothed beliefs, one per step
/// @throws posefuse::invalid_argument if a predicted covariance is not
///         positive definite (or not finite)
template <State S>
[[nodiscard]] std::vector<Gaussian<S>> rts_smooth(const std::vector<SmootherStep<S>>& steps) {
  using Cov = CovarianceOf<S>;
  constexpr int N = DimOf<S>;
  std::vector<Gaussian<S>> out(steps.size());
  if (steps.empty()) return out;
  S xs = steps.back().filtered_mean;
  Cov Ps = steps.back().filtered_cov;
  out.back().mean = xs;
  out.back().cov = Ps;
  for (std::size_t k = steps.size() - 1; k-- > 0;) {
    const SmootherStep<S>& now = steps[k];
    const SmootherStep<S>& next = steps[k + 1];
    // C = P F^T Pbar^-1
    Cov C;
    if constexpr (N >= 1 && N <= 4) {
      if (!detail::rts_gain_small(Cov(now.filtered_cov * next.F.transpose()), next.predicted_cov, C))
        throw invalid_argument("rts_smooth: predicted covariance " + std::to_string(k + 1) +
                               " is not positive definite");
    } else {
      const Eigen::LLT<Cov> llt(next.predicted_cov);
      if (llt.info() != Eigen::Success || !next.predicted_cov.allFinite())
        throw invalid_argument("rts_smooth: predicted covariance " + std::to_string(k + 1) +
                               " is not positive definite");
      C = llt.solve(next.F * now.filtered_cov).transpose();  // C^T = Pbar^-1 F P (P, Pbar symmetric)
    }
    xs = plus(now.filtered_mean, TangentOf<S>(C * minus(xs, next.predicted_mean)));
    const Cov Pk = now.filtered_cov + C * (Ps - next.predicted_cov) * C.transpose();
    Ps = ScalarOf<S>(0.5) * (Pk + Pk.transpose());  // from a copy: Ps + Ps^T into Ps would alias
    out[k].mean = xs;
    out[k].cov = Ps;
  }
  return out;
}

}  // namespace posefuse

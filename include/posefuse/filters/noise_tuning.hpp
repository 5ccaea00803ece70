#pragma once
/// @file
/// Choosing a filter's process and measurement noise without ground truth:
/// maximise the innovation log-likelihood of the filter's own run.
///
/// A Kalman filter whose noise matches the data produces innovations
/// \f$ \nu_k \f$ that are zero-mean with covariance \f$ S_k \f$; the
/// log-likelihood of the measurements under the filter is, up to a constant,
/// \f[ \ell = \sum_k -\tfrac12 \left( \nu_k^\top S_k^{-1} \nu_k + \log\det S_k \right) \f]
/// (the prediction-error decomposition; Harvey, *Forecasting, Structural
/// Time Series Models and the Kalman Filter*, 1989, §3.4; Särkkä, *Bayesian
/// Filtering and Smoothing*, 2013, §12.3). The constant \f$ -\tfrac{m}{2}\log 2\pi \f$
/// per step is left out: it does not move the maximum. Only the filter's
/// inputs enter \f$ \ell \f$, never a reference trajectory.
///
/// `tune_noise` maximises a caller's \f$ \ell(p, m) \f$ over two positive
/// scalars (a process and a measurement noise level, in whatever units the
/// caller's filter takes) inside a box: a coarse log-spaced grid first, then
/// Nelder–Mead in \f$ (\log p, \log m) \f$ started at the best grid point,
/// with every trial clamped to the box. A result on the box's edge is
/// flagged: the likelihood then still rises outside the range searched (or
/// is flat, as for a filter whose innovations are all zero).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <posefuse/core/error.hpp>
#include <posefuse/filters/ekf_update_result.hpp>
#include <string>
#include <vector>

namespace posefuse {

/// One update's term \f$ -\tfrac12 (\nu^\top S^{-1} \nu + \log\det S) \f$.
/// @param[in] nu innovation
/// @param[in] S  innovation covariance, symmetric positive definite
/// @return the term, or -infinity when S is not positive definite or a
///         value is not finite (such a noise setting can never be chosen)
template <class Vec, class Mat>
[[nodiscard]] double innovation_log_likelihood(const Eigen::MatrixBase<Vec>& nu,
                                               const Eigen::MatrixBase<Mat>& S) {
  constexpr double kMinusInf = -std::numeric_limits<double>::infinity();
  if (!nu.allFinite() || !S.allFinite()) return kMinusInf;
  using Plain = typename Mat::PlainObject;
  const Eigen::LLT<Plain> llt(S.eval());
  if (llt.info() != Eigen::Success) return kMinusInf;
  const auto L = llt.matrixL();
  double log_det = 0;
  for (Eigen::Index i = 0; i < S.rows(); ++i) {
    const double d = llt.matrixLLT()(i, i);
    if (!(d > 0)) return kMinusInf;
    log_det += 2.0 * std::log(d);
  }
  const double mahalanobis = L.solve(nu.derived().eval()).squaredNorm();
  const double term = -0.5 * (mahalanobis + log_det);
  return std::isfinite(term) ? term : kMinusInf;
}

/// The term of one EKF update (filters/ekf_update_result.hpp): from its
/// innovation and S, whether or not the update was applied; -infinity when
/// S could not be formed.
template <MeasurementModel H>
[[nodiscard]] double innovation_log_likelihood(const UpdateResult<H>& r) {
  if (r.status == FilterStatus::kNonFinite || r.status == FilterStatus::kNotPositiveDefinite ||
      r.status == FilterStatus::kNotInitialised)
    return -std::numeric_limits<double>::infinity();
  return innovation_log_likelihood(r.innovation, r.S);
}

/// `n` values from `lo` to `hi` (both > 0, finite), equally spaced in
/// log: `lo`, ..., `hi` (n = 1 gives `lo`).
/// @throws posefuse::invalid_argument unless 0 < lo <= hi are finite and n >= 1
[[nodiscard]] inline std::vector<double> log_spaced(double lo, double hi, std::size_t n) {
  if (!(lo > 0) || !(hi >= lo) || !std::isfinite(hi) || n == 0)
    throw invalid_argument("log_spaced: need 0 < lo <= hi finite and n >= 1");
  std::vector<double> v(n);
  const double a = std::log(lo), b = std::log(hi);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = n == 1 ? lo : std::exp(a + (b - a) * static_cast<double>(i) / static_cast<double>(n - 1));
  v.front() = lo;
  v.back() = n == 1 ? lo : hi;
  return v;
}

/// A closed positive search interval [lo, hi] for one noise level.
struct NoiseRange {
  double lo = 1e-6;  ///< smallest value tried, > 0
  double hi = 1e2;   ///< largest value tried, >= lo
};

/// How `tune_noise` searches.
struct NoiseTuningOptions {
  std::size_t grid = 9;              ///< grid points per axis (log-spaced), >= 2
  std::size_t max_evaluations = 200; ///< Nelder–Mead budget after the grid
  double log_tolerance = 1e-3;       ///< stop when the simplex is this small in log units
};

/// What `tune_noise` chose.
struct NoiseTuningResult {
  double process = 0;          ///< chosen process noise level
  double measurement = 0;      ///< chosen measurement noise level
  double log_likelihood = 0;   ///< \f$ \ell \f$ there
  std::size_t evaluations = 0; ///< calls of the objective (grid + refinement)
  bool process_at_bound = false;      ///< `process` is on an edge of its range
  bool measurement_at_bound = false;  ///< `measurement` is on an edge of its range
};

/// Maximises `log_likelihood(process, measurement)` over the box
/// @param[in] process search interval of the process noise level
/// @param[in] measurement search interval of the measurement noise level
/// @param[in] options grid size, evaluation budget and tolerance
/// `process` x `measurement` (see the file comment). A non-finite value
/// counts as -infinity.
/// @param[in] log_likelihood callable `double(double p, double m)`
/// @throws posefuse::invalid_argument for an empty or non-positive range,
///         fewer than 2 grid points, or when no point of the grid gives a
///         finite log-likelihood
template <class F>
[[nodiscard]] NoiseTuningResult tune_noise(F&& log_likelihood, NoiseRange process,
                                           NoiseRange measurement,
                                           const NoiseTuningOptions& options = {}) {
  if (!(process.lo > 0) || !(process.hi >= process.lo) || !std::isfinite(process.hi) ||
      !(measurement.lo > 0) || !(measurement.hi >= measurement.lo) || !std::isfinite(measurement.hi))
    throw invalid_argument("tune_noise: each range needs 0 < lo <= hi, finite");
  if (options.grid < 2) throw invalid_argument("tune_noise: the grid needs at least 2 points per axis");
  const std::array<double, 2> lo{std::log(process.lo), std::log(measurement.lo)};
  const std::array<double, 2> hi{std::log(process.hi), std::log(measurement.hi)};
  using P = std::array<double, 2>;
  NoiseTuningResult out;
  const auto clamp = [&](P x) {
    for (int i = 0; i < 2; ++i) x[i] = std::clamp(x[i], lo[i], hi[i]);
    return x;
  };
  // Objective in log space, to be minimised.
  const auto cost = [&](const P& x) {
    ++out.evaluations;
    const double v = log_likelihood(std::exp(x[0]), std::exp(x[1]));
    return std::isfinite(v) ? -v : std::numeric_limits<double>::infinity();
  };

  // 1. The coarse grid.
  const std::size_t n = options.grid;
  P best{lo[0], lo[1]};
  double best_cost = std::numeric_limits<double>::infinity();
  std::array<double, 2> cell{};
  for (int i = 0; i < 2; ++i) cell[i] = (hi[i] - lo[i]) / static_cast<double>(n - 1);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      const P x{lo[0] + cell[0] * static_cast<double>(a), lo[1] + cell[1] * static_cast<double>(b)};
      const double c = cost(x);
      if (c < best_cost) best_cost = c, best = x;
    }
  if (!std::isfinite(best_cost))
    throw invalid_argument("tune_noise: no noise setting of the grid gives a finite log-likelihood");

  // 2. Nelder–Mead from the best grid point, steps of half a grid cell.
  std::array<P, 3> s{best, clamp({best[0] + 0.5 * cell[0], best[1]}),
                     clamp({best[0], best[1] + 0.5 * cell[1]})};
  if (s[1] == s[0]) s[1] = clamp({best[0] - 0.5 * cell[0], best[1]});
  if (s[2] == s[0]) s[2] = clamp({best[0], best[1] - 0.5 * cell[1]});
  std::array<double, 3> f{best_cost, cost(s[1]), cost(s[2])};
  const std::size_t budget = out.evaluations + options.max_evaluations;
  while (out.evaluations + 2 < budget) {
    std::array<int, 3> idx{0, 1, 2};
    std::sort(idx.begin(), idx.end(), [&](int i, int j) { return f[i] < f[j]; });
    const P b = s[idx[0]], m = s[idx[1]], w = s[idx[2]];
    const double fb = f[idx[0]], fm = f[idx[1]], fw = f[idx[2]];
    double size = 0;
    for (int i = 0; i < 2; ++i)
      size = std::max({size, std::abs(m[i] - b[i]), std::abs(w[i] - b[i])});
    if (size < options.log_tolerance) break;
    const P c{0.5 * (b[0] + m[0]), 0.5 * (b[1] + m[1])};
    const auto along = [&](double t) { return clamp({c[0] + t * (w[0] - c[0]), c[1] + t * (w[1] - c[1])}); };
    const P r = along(-1.0);
    const double fr = cost(r);
    P next = r;
    double fnext = fr;
    if (fr < fb) {
      const P e = along(-2.0);
      const double fe = cost(e);
      if (fe < fr) next = e, fnext = fe;
    } else if (fr >= fm) {
      const P k = fr < fw ? along(-0.5) : along(0.5);
      const double fk = cost(k);
      if (fk < std::min(fr, fw)) {
        next = k, fnext = fk;
      } else {  // shrink towards the best
        s = {b, P{0.5 * (b[0] + m[0]), 0.5 * (b[1] + m[1])}, P{0.5 * (b[0] + w[0]), 0.5 * (b[1] + w[1])}};
        f = {fb, cost(s[1]), cost(s[2])};
        continue;
      }
    }
    s = {b, m, next};
    f = {fb, fm, fnext};
  }
  const int i_best = static_cast<int>(std::min_element(f.begin(), f.end()) - f.begin());
  const P x = f[i_best] <= best_cost ? s[i_best] : best;
  out.process = std::exp(x[0]);
  out.measurement = std::exp(x[1]);
  out.log_likelihood = -std::min(f[i_best], best_cost);
  const double edge = 1e-6 + 0.5 * options.log_tolerance;
  out.process_at_bound = x[0] - lo[0] < edge || hi[0] - x[0] < edge;
  out.measurement_at_bound = x[1] - lo[1] < edge || hi[1] - x[1] < edge;
  return out;
}

}  // namespace posefuse

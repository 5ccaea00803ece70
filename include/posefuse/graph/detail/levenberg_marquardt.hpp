#pragma once
/// @file
/// Levenberg–Marquardt (or undamped Gauss–Newton) on a pose graph's block
/// normal equations (not API).
///
/// Each iteration that follows an accepted step relinearises every edge,
/// then solves \f$ (H + \lambda\,\mathrm{diag}(H)) \Delta = -b \f$ with the
/// block sparse Cholesky (symbolic analysis once per solve). A step is taken
/// only when it lowers the cost; \f$ \lambda \f$ follows Nielsen's rule
/// (Nielsen, "Damping parameter in Marquardt's method", IMM DTU 1999):
/// shrunk by \f$ \max(1/3, 1 - (2\rho - 1)^3) \f$ after a step with gain
/// ratio \f$ \rho \f$, multiplied by a doubling \f$ \nu \f$ after a failed one.
/// After every iteration PoseGraphOptions::progress, when set, is told the
/// iteration, the cost, the step norm, λ and whether the step was taken.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/graph/detail/pose_graph_assembly.hpp>
#include <posefuse/graph/detail/pose_graph_layout.hpp>
#include <posefuse/graph/pose_graph_options.hpp>
#include <posefuse/graph/pose_graph_workspace.hpp>

namespace posefuse::detail {

/// The Levenberg–Marquardt damping \f$ \lambda \f$ and its growth factor \f$ \nu \f$.
struct LmDamping {
  static constexpr double kFloor = 1e-12;         ///< λ never shrinks below this
  static constexpr double kRaiseFrom = 1e-8;      ///< a failed step raises λ from at least this
  static constexpr double kCeiling = 1e16;        ///< beyond this no damping will make progress

  double lambda = 0.0;  ///< 0: undamped Gauss–Newton
  double nu = 2.0;

  /// After a step that lowered the cost with gain ratio `rho` (actual / predicted decrease).
  void shrink(double rho) {
    const double f = 2.0 * rho - 1.0;
    lambda *= std::max(1.0 / 3.0, 1.0 - f * f * f);
    lambda = std::max(lambda, kFloor);
    nu = 2.0;
  }

  /// After a failed step (a singular system, or a cost that did not drop).
  /// @return false when λ passed the ceiling: the solver makes no progress
  [[nodiscard]] bool raise() {
    lambda = std::max(lambda, kRaiseFrom) * nu;
    nu *= 2.0;
    return lambda <= kCeiling;
  }
};

/// x ⊞ Δ on the free nodes (yaw wrapped); fixed nodes untouched.
template <int B>
void apply_step(const PoseGraphLayout& L, const Eigen::VectorXd& dx, std::vector<NodeState<B>>& x) {
  for (std::size_t a = 0; a < x.size(); ++a) {
    const int v = L.var[a];
    if (v < 0) continue;
    x[a] += dx.template segment<B>(B * v);
    x[a](B - 1) = wrap_angle(x[a](B - 1));
  }
}

/// The parameter-tolerance test: \f$ \|\Delta\| < \mathrm{tol} (\|x_{free}\| + \mathrm{tol}) \f$.
template <int B>
[[nodiscard]] bool step_below_tolerance(const PoseGraphLayout& L, const Eigen::VectorXd& dx,
                                        const std::vector<NodeState<B>>& x, double tol) {
  double sq = 0.0;
  for (std::size_t a = 0; a < x.size(); ++a)
    if (L.var[a] >= 0) sq += x[a].squaredNorm();
  return dx.norm() < tol * (std::sqrt(sq) + tol);
}

/// Solves \f$ (H + \lambda\,\mathrm{diag}(H)) \Delta = -b \f$ into w.dx (H
/// is left undamped; w.diag holds diag(H)).
/// @return false when the damped H is not positive definite or Δ is not finite
template <class Buffers>
[[nodiscard]] bool solve_damped(Buffers& w, double lambda) {
  if (lambda > 0) {
    w.delta.resize(w.diag.size());
    for (Eigen::Index c = 0; c < w.diag.size(); ++c) w.delta(c) = lambda * std::clamp(w.diag(c), 1e-6, 1e32);
    w.sys.add_to_diagonal(w.delta);
  }
  const bool factored = w.chol.factorize(w.sys);
  if (factored) {
    w.dx = -w.sys.b;
    w.chol.solve_in_place(w.dx);
  }
  if (lambda > 0) w.sys.add_to_diagonal(-w.delta);
  return factored && w.dx.allFinite();
}

/// Minimises the cost from the state w.x (left at the solution), on the
/// layout L. Fills every field of the summary but the time and `planar`.
/// @throws posefuse::invalid_argument as PoseGraphOptions::validate(), before any work
///
/// `Assembly` gives cost(x), num_edges(), linearize(x) (into w.sys) and
/// set_trigonometry(x) (the per-node quantities linearize() reads);
/// `Buffers` holds sys, chol, x, trial, diag, delta and dx (SolverBuffers<B>
/// for the 4-DoF graph, SolverBuffersSE3 for the SE(3) one). apply_step<B>
/// and step_below_tolerance<B> are found for the state type of w.x.
template <int B, class Assembly, class Buffers>
[[nodiscard]] PoseGraphSummary levenberg_marquardt(Assembly& f, Buffers& w,
                                                   const PoseGraphLayout& L, const PoseGraphOptions& options) {
  options.validate();
  PoseGraphSummary s;
  s.initial_cost = s.final_cost = f.cost(w.x);  // leaves the trigonometry at w.x
  if (L.n == 0 || f.num_edges() == 0) {
    s.termination = Termination::kGradientTolerance;
    return s;
  }
  w.sys.build(L.n, L.pairs);
  w.chol.analyze(w.sys);
  const bool damped = options.levenberg_marquardt;
  LmDamping damping{damped ? options.initial_lambda : 0.0};
  double cost_now = s.initial_cost;
  bool relinearise = true;
  s.termination = Termination::kMaxIterations;
  // Progress: built only when a callback is set (it reads, never writes).
  double lambda_used = 0.0;
  const auto report = [&](bool accepted, const Eigen::VectorXd* dx) {
    if (!options.progress) return;
    options.progress(PoseGraphIteration{s.iterations, cost_now, dx != nullptr ? dx->norm() : 0.0,
                                        lambda_used, accepted});
  };
  while (s.iterations < options.max_iterations) {
    if (relinearise) {
      f.linearize(w.x);
      w.diag = w.sys.diagonal();
      if (w.sys.b.template lpNorm<Eigen::Infinity>() < options.gradient_tolerance) {
        s.termination = Termination::kGradientTolerance;
        break;
      }
      relinearise = false;
    }
    ++s.iterations;
    lambda_used = damping.lambda;
    if (!solve_damped(w, damping.lambda)) {
      report(false, nullptr);
      if (!damped || !damping.raise()) {
        s.termination = Termination::kNoProgress;
        break;
      }
      continue;
    }
    const Eigen::VectorXd& dx = w.dx;
    w.trial = w.x;
    apply_step<B>(L, dx, w.trial);
    const double cost_new = f.cost(w.trial);  // the trigonometry is now the trial's
    // Predicted decrease of the quadratic model of F = Σ ρ(s): -(2 Δᵀb + Δᵀ H Δ).
    const double predicted = -(2.0 * dx.dot(w.sys.b) + w.sys.quadratic_form(dx));
    // Near the minimum the cost change drops below its rounding error
    // (F ~ 3 moves by 1e-20 when a pose moves by 1e-10): a step whose
    // predicted decrease is at rounding level is taken once (the quadratic
    // model is exact there) and the optimiser stops.
    const double rounding = 64.0 * std::numeric_limits<double>::epsilon() * cost_now;
    const bool polish = std::isfinite(cost_new) && !(cost_new < cost_now) && predicted >= 0 &&
                        predicted <= rounding && cost_new <= cost_now + rounding;
    if (polish) {
      w.x.swap(w.trial);
      ++s.accepted;
      cost_now = std::min(cost_now, cost_new);
      report(true, &dx);
      s.termination = Termination::kFunctionTolerance;
      break;
    }
    if (std::isfinite(cost_new) && cost_new < cost_now) {
      const double decrease = cost_now - cost_new;
      w.x.swap(w.trial);  // the trigonometry is the new state's
      ++s.accepted;
      relinearise = true;
      if (damped) damping.shrink(predicted > 0 ? decrease / predicted : 1.0);
      const double prev = cost_now;
      cost_now = cost_new;
      report(true, &dx);
      if (decrease < options.function_tolerance * prev) {
        s.termination = Termination::kFunctionTolerance;
        break;
      }
      if (step_below_tolerance<B>(L, dx, w.x, options.parameter_tolerance)) {
        s.termination = Termination::kParameterTolerance;
        break;
      }
      continue;
    }
    f.set_trigonometry(w.x);  // back to the current state's
    report(false, &dx);
    if (!damped) {
      s.termination = Termination::kNoProgress;
      break;
    }
    // A step that does not lower the cost but is below the parameter
    // tolerance means the state is at the minimum to rounding.
    if (step_below_tolerance<B>(L, dx, w.x, options.parameter_tolerance)) {
      s.termination = Termination::kParameterTolerance;
      break;
    }
    if (!damping.raise()) {
      s.termination = Termination::kNoProgress;
      break;
    }
  }
  s.final_cost = cost_now;
  return s;
}

}  // namespace posefuse::detail

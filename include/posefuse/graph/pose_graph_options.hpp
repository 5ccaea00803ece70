#pragma once
/// @file
/// What a pose-graph optimisation is asked to do (PoseGraphOptions) and what
/// it reports (PoseGraphSummary, Termination).
///
/// The cost is g2o's χ², \f$ F = \sum_k \rho_k(e_k^\top \Omega_k e_k) \f$
/// (graph/edge_error_4dof.hpp, graph/robust_loss.hpp); Ceres reports
/// \f$ F/2 \f$.

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// Why the optimiser stopped.
enum class Termination {
  kFunctionTolerance,   ///< relative cost decrease below the tolerance
  kGradientTolerance,   ///< largest gradient entry below the tolerance
  kParameterTolerance,  ///< step below the tolerance relative to the state
  kMaxIterations,       ///< iteration limit reached
  kNoProgress,          ///< no step decreased the cost (damping exhausted, or a GN step increased it)
};

/// Name of a termination reason ("function_tolerance", ...).
[[nodiscard]] constexpr std::string_view to_string(Termination t) noexcept {
  switch (t) {
    case Termination::kFunctionTolerance: return "function_tolerance";
    case Termination::kGradientTolerance: return "gradient_tolerance";
    case Termination::kParameterTolerance: return "parameter_tolerance";
    case Termination::kMaxIterations: return "max_iterations";
    case Termination::kNoProgress: return "no_progress";
  }
  return "?";
}

/// What one iteration of the optimiser did, passed to
/// PoseGraphOptions::progress.
struct PoseGraphIteration {
  int iteration = 0;       ///< linear solves so far, this one included (1-based)
  double cost = 0.0;       ///< \f$ F \f$ at the state after this iteration
  double step_norm = 0.0;  ///< \f$ \|\Delta\| \f$ of the step tried (0 when the system could not be solved)
  double lambda = 0.0;     ///< LM damping \f$ \lambda \f$ of the step (0 for Gauss–Newton)
  bool accepted = false;   ///< the step lowered the cost and was taken
};

/// Optimiser settings.
struct PoseGraphOptions {
  bool levenberg_marquardt = true;    ///< false: undamped Gauss–Newton (stops when a step increases the cost)
  int max_iterations = 100;           ///< linear solves at most
  double function_tolerance = 1e-10;  ///< stop when \f$ (F_k - F_{k+1}) < \mathrm{tol}\, F_k \f$
  double gradient_tolerance = 1e-12;  ///< stop when \f$ \|J^\top W \Omega e\|_\infty < \mathrm{tol} \f$
  double parameter_tolerance = 1e-10;  ///< stop when \f$ \|\Delta\| < \mathrm{tol} (\|x\| + \mathrm{tol}) \f$
  double initial_lambda = 1e-5;       ///< LM damping \f$ \lambda \f$: \f$ H + \lambda\,\mathrm{diag}(H) \f$
  /// Solve a planar graph (PoseGraph4Dof::is_planar()) on (x, y, yaw) with
  /// 3x3 blocks instead of 4x4; the same iterations and optimum up to
  /// rounding (the z rows decouple exactly); 1.4-1.5x faster on the real
  /// g2o files (bench_graph BM_G2o/posefuse vs posefuse_4dof).
  bool planar_fast_path = true;
  /// Called after every iteration when set (e.g. to show progress on a
  /// terminal); it only observes: the iterations and the result are the
  /// same with or without it. Empty (the default): one test per iteration.
  std::function<void(const PoseGraphIteration&)> progress;

  /// Checks the settings (optimize() calls it first): max_iterations >= 1,
  /// every tolerance and initial_lambda finite and >= 0 (a NaN would make
  /// every stopping test false, a negative one never true).
  /// @throws posefuse::invalid_argument naming the first offending option
  void validate() const {
    if (max_iterations < 1)
      throw invalid_argument("PoseGraphOptions: max_iterations must be >= 1, got " + std::to_string(max_iterations));
    const auto check = [](double v, const char* name) {
      if (std::isfinite(v) && v >= 0.0) return;
      char text[32];
      std::snprintf(text, sizeof text, "%g", v);
      throw invalid_argument(std::string("PoseGraphOptions: ") + name + " must be finite and >= 0, got " + text);
    };
    check(function_tolerance, "function_tolerance");
    check(gradient_tolerance, "gradient_tolerance");
    check(parameter_tolerance, "parameter_tolerance");
    check(initial_lambda, "initial_lambda");
  }
};

/// What an optimisation did.
struct PoseGraphSummary {
  double initial_cost = 0.0;  ///< \f$ F \f$ before (χ² without robust losses)
  double final_cost = 0.0;    ///< \f$ F \f$ after
  int iterations = 0;         ///< linear solves (accepted and rejected steps)
  int accepted = 0;           ///< steps that decreased the cost
  Termination termination = Termination::kMaxIterations;  ///< why it stopped
  double solve_time_s = 0.0;  ///< wall time of optimize() (s)
  bool planar = false;        ///< solved by the planar (3x3-block) path
};

}  // namespace posefuse

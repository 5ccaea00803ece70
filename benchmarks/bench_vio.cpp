// bench_vio: one solve of the visual-inertial window (vio/window_problem.hpp),
// posefuse against Ceres 2.1 on the same residuals from the same start.
//
// The window: VioEstimator (default options but the window size N, the
// argument of each row, and the raw-parallax keyframe test, so that the
// N = 10 problem is the one measured before the rotation-compensated test
// existed; explicit initial state) run for 0.3 N s on the synthetic flight
// (sim::synthetic_flight, EuRoC-like IMU noise) with simulated tracks
// (sim/feature_tracks.hpp defaults: 20 Hz, 1 px noise, 5 % wrong
// associations, 150 features per frame); its window after the last frame
// (N keyframes + the newest frame, its marginalisation prior, the
// triangulated features; counters `keyframes`, `features`, `observations`)
// is the problem. The start: every frame moved by 0.05 m in a random
// direction and 1° about a random axis, velocities by 0.02 m/s, inverse
// depths by 2 % (seeded normal draws). The solve uses the true Jacobians
// (first-estimate Jacobians off) and the pre-integrations are never
// re-integrated (thresholds 1e9; the bias Jacobians correct them to first
// order), so that both solvers minimise one function with the same
// derivatives; a row fails if posefuse re-integrated anyway.
//
//   BM_WindowSolve/posefuse/N copy of the start + WindowProblem::solve (LM,
//                             inverse depths eliminated by a Schur complement
//                             on 6x6 blocks, block-profile Cholesky of the
//                             reduced system or dense LLT when the profile is
//                             wide; function tolerance 1e-10, at most 100
//                             trials)
//   BM_WindowSolve/ceres/N    build a ceres::Problem from the start + Solve
//                             (only when Ceres is found): LM, DENSE_SCHUR with
//                             the inverse depths eliminated first, one thread,
//                             function tolerance 1e-10, at most 100 iterations;
//                             the same residuals: the prior r0 + J (x - x̄)
//                             with Jacobian J, the whitened IMU factor
//                             (ImuFactor::whitened_residual) and the
//                             reprojection factor with Ceres's CauchyLoss at the
//                             window's loss scale (√2 σ by default),
//                             which scales residual and Jacobian by √ρ′ as
//                             posefuse does (ρ″ ≤ 0); an observation nearer
//                             than 0.05 m to its camera contributes zero in both
//   BM_Marginalize/posefuse/N copy of the solved window + marginalize_oldest
//                             (the step that follows a keyframe)
//
// Counters: cost = posefuse's F (= 2x Ceres's cost) at the end, iterations
// (posefuse: LM trials; Ceres: its iterations, iteration 0 not counted). A
// row fails unless both solvers' final costs agree within a relative 1e-6.
// N: 10 and 20 (the default window_size of SlidingWindowOptions).
// Run: bench_vio --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
//      --benchmark_report_aggregates_only=true (results in docs/benchmarks-inertial-vio.md).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/vio/estimator.hpp>
#include <posefuse/vio/sliding_window.hpp>
#include <posefuse/vio/window_problem.hpp>

#ifdef POSEFUSE_HAVE_CERES
#include <ceres/ceres.h>
#endif

namespace {

using namespace posefuse;

constexpr double kCostTolerance = 1e-6;  // relative agreement of the final costs
constexpr int kMaxIterations = 100;

WindowSolveOptions solve_options() {
  WindowSolveOptions o;
  o.max_iterations = kMaxIterations;
  o.function_tolerance = 1e-10;
  o.first_estimate_jacobians = false;
  return o;
}

struct Problem {
  VioWindow solved;  // the estimator's window
  VioWindow start;   // perturbed
  int features = 0, observations = 0;
};

Problem make_problem(int window) {
  {
    Problem pr;
    const double duration_s = 0.3 * window;
    sim::ImuSimConfig flight = sim::synthetic_flight();
    flight.noise = ImuNoise{};
    flight.initial_bias = ImuBias{Eigen::Vector3d(0.05, -0.04, 0.03), Eigen::Vector3d(0.002, -0.003, 0.001)};
    const sim::ImuSequence seq = sim::simulate_imu(flight, duration_s + 0.1);
    const PinholeRadtan cam = sim::synthetic_camera();
    const sim::SimulatedTracks st = sim::simulate_feature_tracks(flight, duration_s, cam, sim::TrackSimConfig{});
    VioEstimatorOptions eo;
    eo.noise = flight.noise;
    eo.window.window_size = window;
    eo.window.rotation_compensated_parallax = false;
    // No re-integration: the IMU residuals stay one function during a solve
    // (Ceres cannot re-integrate); the bias Jacobians correct them to first order.
    eo.preintegration.reintegrate_accel_threshold = 1e9;
    eo.preintegration.reintegrate_gyro_threshold = 1e9;
    VioEstimator est(cam, eo);
    const sim::ImuTruth& t0 = seq.truth[0];
    est.set_initial_state(ImuState{t0.p_w, t0.R_w_b, t0.v_w, t0.bias});
    std::size_t k = 0;
    for (const TrackFrame& f : st.tracks) {
      while (k < seq.samples.size() && seq.samples[k].t_ns <= f.t_ns + 5'000'000) est.add_imu(seq.samples[k++]);
      (void)est.add_frame(f);
    }
    pr.solved = est.window();
    pr.start = pr.solved;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n(0.0, 1.0);
    const auto dir = [&] { return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized(); };
    for (VioFrame& f : pr.start.frames) {
      f.x.p += 0.05 * dir();
      f.x.R = f.x.R.plus((M_PI / 180.0) * dir());
      f.x.v += 0.02 * dir();
    }
    for (auto& [id, l] : pr.start.landmarks) {
      l.inv_depth *= 1.0 + 0.02 * n(rng);
      if (!l.initialised) continue;
      ++pr.features;
      pr.observations += int(l.obs.size()) - 1;
    }
    return pr;
  }
}

// The problem of each window size, built once.
const Problem& problem(int window) {
  static std::map<int, Problem> cache;
  auto it = cache.find(window);
  if (it == cache.end()) it = cache.emplace(window, make_problem(window)).first;
  return it->second;
}

struct Result {
  double cost = 0.0;
  int iterations = 0;
  int repropagated = 0;
};

Result solve_posefuse(WindowProblem& P, VioWindow& w) {
  const WindowSolveSummary s = P.solve(w, solve_options());
  return {s.final_cost, s.iterations, s.repropagated};
}

#ifdef POSEFUSE_HAVE_CERES

// A keyframe's state as Ceres holds it: [p(3), v(3), b_a(3), b_g(3), q(x, y, z, w)].
constexpr int kAmbient = 16;
ImuState from_block(const double* x) {
  ImuState s;
  s.p = Eigen::Vector3d(x[0], x[1], x[2]);
  s.v = Eigen::Vector3d(x[3], x[4], x[5]);
  s.bias.accel = Eigen::Vector3d(x[6], x[7], x[8]);
  s.bias.gyro = Eigen::Vector3d(x[9], x[10], x[11]);
  s.R = SO3d(Eigen::Quaterniond(x[15], x[12], x[13], x[14]));
  return s;
}
void to_block(const ImuState& s, double* x) {
  const Eigen::Quaterniond& q = s.R.quaternion();
  const double v[kAmbient] = {s.p.x(), s.p.y(), s.p.z(), s.v.x(), s.v.y(), s.v.z(),
                              s.bias.accel.x(), s.bias.accel.y(), s.bias.accel.z(),
                              s.bias.gyro.x(), s.bias.gyro.y(), s.bias.gyro.z(),
                              q.x(), q.y(), q.z(), q.w()};
  std::copy(v, v + kAmbient, x);
}

// ImuState's ⊕ and ⊖ on the 16-vector; the cost functions give their
// Jacobians with respect to the tangent in the first 15 ambient columns
// (the 16th zero), so PlusJacobian is [I15; 0] (VINS-Mono's device).
class ImuStateManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kAmbient; }
  int TangentSize() const override { return 15; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    to_block(from_block(x).plus(Eigen::Map<const ImuState::Tangent>(delta)), x_plus_delta);
    return true;
  }
  bool PlusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kAmbient, 15, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topRows<15>().setIdentity();
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<ImuState::Tangent> out(y_minus_x);
    out = from_block(y).minus(from_block(x));
    return true;
  }
  bool MinusJacobian(const double*, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 15, kAmbient, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.leftCols<15>().setIdentity();
    return true;
  }
};

using JacRow = Eigen::Matrix<double, Eigen::Dynamic, kAmbient, Eigen::RowMajor>;

class ImuCost final : public ceres::SizedCostFunction<15, kAmbient, kAmbient> {
 public:
  explicit ImuCost(const ImuFactor& f) : f_(f) {}
  bool Evaluate(double const* const* x, double* residuals, double** jac) const override {
    ImuFactor::Jacobian Ji, Jj;
    const bool want = jac != nullptr && (jac[0] != nullptr || jac[1] != nullptr);
    Eigen::Map<ImuFactor::Residual> r(residuals);
    r = f_.whitened_residual(from_block(x[0]), from_block(x[1]), want ? &Ji : nullptr, want ? &Jj : nullptr);
    for (int b = 0; b < 2 && want; ++b) {
      if (jac[b] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, 15, kAmbient, Eigen::RowMajor>> J(jac[b]);
      J.leftCols<15>() = b == 0 ? Ji : Jj;
      J.col(15).setZero();
    }
    return true;
  }

 private:
  ImuFactor f_;
};

class ReprojectionCost final : public ceres::SizedCostFunction<2, kAmbient, kAmbient, 1> {
 public:
  ReprojectionCost(const ReprojectionFactor& f, const RigidPose& T_bc, double min_depth)
      : f_(f), T_bc_(T_bc), min_depth_(min_depth) {}
  bool Evaluate(double const* const* x, double* residuals, double** jac) const override {
    const ImuState si = from_block(x[0]), sj = from_block(x[1]);
    const RigidPose Ti = VioFrame::pose(si), Tj = VioFrame::pose(sj);
    const double lambda = x[2][0];
    Eigen::Map<Eigen::Vector2d> r(residuals);
    const bool seen = lambda > 0 && f_.point_in_observer(Ti, Tj, T_bc_, lambda).z() > min_depth_;
    ReprojectionFactor::PoseJacobian Ji, Jj;
    Eigen::Vector2d Jl;
    const bool want = jac != nullptr;
    if (seen) r = f_.residual(Ti, Tj, T_bc_, lambda, want ? &Ji : nullptr, want ? &Jj : nullptr, nullptr,
                              want ? &Jl : nullptr);
    else r.setZero();
    if (!want) return true;
    for (int b = 0; b < 2; ++b) {
      if (jac[b] == nullptr) continue;
      Eigen::Map<Eigen::Matrix<double, 2, kAmbient, Eigen::RowMajor>> J(jac[b]);
      J.setZero();
      if (seen) J.leftCols<6>() = b == 0 ? Ji : Jj;
    }
    if (jac[2] != nullptr) {
      Eigen::Map<Eigen::Vector2d> J(jac[2]);
      if (seen) J = Jl;
      else J.setZero();
    }
    return true;
  }

 private:
  ReprojectionFactor f_;
  RigidPose T_bc_;
  double min_depth_;
};

// The prior r0 + J (x ⊖ x̄) over its keyframe blocks, Jacobian J (as posefuse).
class PriorCost final : public ceres::CostFunction {
 public:
  explicit PriorCost(const VioPrior& p) : p_(p) {
    set_num_residuals(int(p.linear.J.rows()));
    for (std::size_t b = 0; b < p.blocks.size(); ++b) mutable_parameter_block_sizes()->push_back(kAmbient);
  }
  bool Evaluate(double const* const* x, double* residuals, double** jac) const override {
    Eigen::VectorXd d(p_.linear.J.cols());
    for (std::size_t b = 0; b < p_.blocks.size(); ++b)
      d.segment<15>(15 * Eigen::Index(b)) = from_block(x[b]).minus(p_.blocks[b].frame_ref);
    Eigen::Map<Eigen::VectorXd> r(residuals, p_.linear.J.rows());
    r = p_.linear.r0 + p_.linear.J * d;
    if (jac == nullptr) return true;
    for (std::size_t b = 0; b < p_.blocks.size(); ++b) {
      if (jac[b] == nullptr) continue;
      Eigen::Map<JacRow> J(jac[b], p_.linear.J.rows(), kAmbient);
      J.leftCols<15>() = p_.linear.J.middleCols<15>(15 * Eigen::Index(b));
      J.col(15).setZero();
    }
    return true;
  }

 private:
  const VioPrior& p_;
};

Result solve_ceres(const VioWindow& w, std::vector<double>& frames, std::map<std::uint64_t, double>& depths) {
  const WindowSolveOptions o = solve_options();
  frames.resize(w.frames.size() * kAmbient);
  for (std::size_t k = 0; k < w.frames.size(); ++k) to_block(w.frames[k].x, &frames[k * kAmbient]);
  const auto block = [&](std::uint64_t id) { return &frames[std::size_t(w.slot_of(id)) * kAmbient]; };
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  ImuStateManifold manifold;
  ceres::CauchyLoss loss(o.loss.scale);
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (std::size_t k = 0; k < w.frames.size(); ++k) {
    problem.AddParameterBlock(&frames[k * kAmbient], kAmbient, &manifold);
    ordering->AddElementToGroup(&frames[k * kAmbient], 1);
  }
  if (w.prior) {
    std::vector<double*> blocks;
    for (const VioPriorBlock& b : w.prior->blocks) blocks.push_back(block(b.frame_id));
    problem.AddResidualBlock(new PriorCost(*w.prior), nullptr, blocks);
  }
  for (std::size_t k = 1; k < w.frames.size(); ++k)
    if (w.frames[k].imu)
      problem.AddResidualBlock(new ImuCost(*w.frames[k].imu), nullptr, &frames[(k - 1) * kAmbient],
                               &frames[k * kAmbient]);
  for (const auto& [id, l] : w.landmarks) {
    if (!l.initialised || !(l.inv_depth > 0)) continue;
    double* lambda = &(depths[id] = l.inv_depth);
    problem.AddParameterBlock(lambda, 1);
    ordering->AddElementToGroup(lambda, 0);
    for (std::size_t j = 1; j < l.obs.size(); ++j)
      problem.AddResidualBlock(
          new ReprojectionCost(ReprojectionFactor(l.obs[0].m, l.obs[j].m, w.sqrt_info), w.T_bc, o.min_depth),
          &loss, block(l.obs[0].frame_id), block(l.obs[j].frame_id), lambda);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.linear_solver_ordering.reset(ordering);
  so.max_num_iterations = kMaxIterations;
  so.function_tolerance = o.function_tolerance;
  so.gradient_tolerance = 1e-20;
  so.parameter_tolerance = 1e-20;
  so.initial_trust_region_radius = 1.0 / o.initial_damping;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  return {2.0 * summary.final_cost, int(summary.iterations.size()) - 1, 0};
}

#endif

struct Reference {
  Result posefuse;
  bool have_ceres = false;
  Result ceres;
};

// One solve of each, to compare the final costs in every row.
const Reference& reference(int window) {
  static std::map<int, Reference> cache;
  if (const auto it = cache.find(window); it != cache.end()) return it->second;
  const Reference& r = cache[window] = [window] {
    Reference ref;
    VioWindow w = problem(window).start;
    WindowProblem P;
    ref.posefuse = solve_posefuse(P, w);
#ifdef POSEFUSE_HAVE_CERES
    std::vector<double> frames;
    std::map<std::uint64_t, double> depths;
    ref.ceres = solve_ceres(problem(window).start, frames, depths);
    ref.have_ceres = true;
#endif
    return ref;
  }();
  return r;
}

bool check(benchmark::State& state, int window, const Result& mine) {
  const Reference& ref = reference(window);
  const Problem& p = problem(window);
  state.counters["cost"] = mine.cost;
  state.counters["iterations"] = mine.iterations;
  state.counters["keyframes"] = double(p.start.frames.size());
  state.counters["features"] = p.features;
  state.counters["observations"] = p.observations;
  state.counters["initial_cost"] = WindowProblem::cost(p.start, solve_options());
  if (ref.posefuse.repropagated > 0 || (p.start.prior && std::any_of(p.start.prior->blocks.begin(),
                                                                      p.start.prior->blocks.end(),
                                                                      [](const VioPriorBlock& b) { return b.extrinsic; }))) {
    state.SkipWithError("a pre-integration was re-integrated during the posefuse solve, or the prior holds the extrinsic");
    return false;
  }
  if (ref.have_ceres) {
    const double rel = std::abs(ref.posefuse.cost - ref.ceres.cost) / ref.ceres.cost;
    if (!(rel <= kCostTolerance)) {
      state.SkipWithError(("final costs differ: posefuse " + std::to_string(ref.posefuse.cost) + ", Ceres " +
                           std::to_string(ref.ceres.cost))
                              .c_str());
      return false;
    }
  }
  return true;
}

void BM_WindowSolve_posefuse(benchmark::State& state) {
  const Problem& p = problem(int(state.range(0)));
  WindowProblem P;
  VioWindow w;
  Result r;
  for (auto _ : state) {
    w = p.start;
    r = solve_posefuse(P, w);
    benchmark::DoNotOptimize(w.frames.back().x.p.data());
  }
  (void)check(state, int(state.range(0)), r);
}
BENCHMARK(BM_WindowSolve_posefuse)->Name("BM_WindowSolve/posefuse")->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);

#ifdef POSEFUSE_HAVE_CERES
void BM_WindowSolve_ceres(benchmark::State& state) {
  const Problem& p = problem(int(state.range(0)));
  std::vector<double> frames;
  std::map<std::uint64_t, double> depths;
  Result r;
  for (auto _ : state) {
    r = solve_ceres(p.start, frames, depths);
    benchmark::DoNotOptimize(frames.data());
  }
  (void)check(state, int(state.range(0)), r);
}
BENCHMARK(BM_WindowSolve_ceres)->Name("BM_WindowSolve/ceres")->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);
#endif

void BM_Marginalize_posefuse(benchmark::State& state) {
  const Problem& p = problem(int(state.range(0)));
  const SlidingWindowOptions o;
  WindowProblem P;
  VioWindow w;
  for (auto _ : state) {
    w = p.solved;
    marginalize_oldest(w, o, P);
    benchmark::DoNotOptimize(w.frames.data());
  }
  state.counters["prior_dim"] = w.prior ? double(w.prior->linear.J.cols()) : 0.0;
}
BENCHMARK(BM_Marginalize_posefuse)->Name("BM_Marginalize/posefuse")->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond);

}  // namespace

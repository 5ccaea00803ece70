// bench_graph: 4-DoF pose-graph optimisation, posefuse against Ceres 2.1 on
// the same seeded problems (include/posefuse/sim/pose_graph_4dof.hpp: laps of a
// hilly track, odometry + a loop edge on every 4th pose, start = chained
// odometry).
//
//   BM_PoseGraph4Dof/posefuse/N  build the graph + PoseGraph4Dof::optimize()
//                                (LM from the odometry start, function
//                                tolerance 1e-10), with one PoseGraphWorkspace
//                                that the program holds for all its rows and
//                                repetitions, as a program solving graph after
//                                graph would hold it (a 100 000-node row runs
//                                one iteration per repetition)
//   BM_PoseGraph4Dof/posefuse_own_workspace/N  the same with each graph's own
//                                workspace: its buffers are fresh memory on
//                                every iteration (the cost of a one-off
//                                solve). Run it alone to see that cost: glibc
//                                returns the freed buffers to the kernel and
//                                every iteration pages them in again (2-core
//                                Debian 12 VM, Release, CPU time, median of 5,
//                                each row alone: 5.5-5.9 ms against 2.9 ms
//                                at 1 000 nodes, --benchmark_filter=
//                                'posefuse_own_workspace/1000$' and 'posefuse/1000$').
//                                After other rows in the same process, glibc's
//                                adaptive heap thresholds keep freed memory
//                                and the two rows take the same time.
//   BM_PoseGraph4Dof/posefuse_rotation_first/N  the same after
//                                initialize_rotation_first() (the start is
//                                inside the timing)
//   BM_PoseGraph4Dof/ceres/N     build a ceres::Problem + Solve (only when
//                                Ceres is found): the same residual with
//                                automatic differentiation, one [x y z yaw]
//                                block per pose, LM, SPARSE_NORMAL_CHOLESKY,
//                                function tolerance 1e-10, one thread
//   BM_PoseGraph4Dof/ceres_rotation_first/N  the same Ceres solve started
//                                from posefuse's rotation-first poses
//                                (computed once, outside the timing)
//
//   BM_G2o/posefuse/G            the real planar g2o file G (manhattan, mit) end
//                                to end from its parsed contents: build the
//                                graph, rotation-first start, optimize() (the
//                                planar 3x3-block path; the program's one
//                                workspace, as above)
//   BM_G2o/posefuse_4dof/G       the same on the general 4x4-block path
//                                (planar_fast_path = false), for comparison
//   BM_G2o/ceres_file/G          Ceres from the file's poses, as Ceres's own
//                                pose_graph_2d example starts: one [x y yaw]
//                                block per vertex, autodiff of g2o's EDGE_SE2
//                                error (translation error in the
//                                measurement's frame), LM,
//                                SPARSE_NORMAL_CHOLESKY, function tolerance
//                                1e-10, at most 100 iterations, one thread
//   BM_G2o/ceres_rotation_first/G  the same Ceres solve started from
//                                posefuse's rotation-first poses (computed
//                                once, outside the timing)
//
// 6-DoF (SE(3)) pose graphs, g2o's EdgeSE3 error [t; q_xyz] of Z⁻¹ X_i⁻¹ X_j
// (include/posefuse/graph/edge_error_se3.hpp) in both solvers, on the seeded
// problems of include/posefuse/sim/pose_graph_se3.hpp (laps of a banked,
// climbing track, odometry + a loop edge on every 4th pose) and on
// parking-garage.g2o:
//
//   BM_PoseGraphSE3/posefuse/N   build the graph + PoseGraphSE3::optimize()
//                                from the chained odometry (LM, function
//                                tolerance 1e-10), with one
//                                PoseGraphSE3Workspace the program holds for
//                                all its SE(3) rows, as the 4-DoF rows
//   BM_PoseGraphSE3/posefuse_chordal/N  the same after initialize_chordal()
//                                (the start is inside the timing)
//   BM_PoseGraphSE3/ceres/N      build a ceres::Problem + Solve from the
//                                odometry: one position block and one
//                                quaternion block (EigenQuaternionManifold)
//                                per pose, the same residual by automatic
//                                differentiation, LM, SPARSE_NORMAL_CHOLESKY,
//                                function tolerance 1e-10, at most 100
//                                iterations, one thread
//   BM_PoseGraphSE3/ceres_chordal/N  the same Ceres solve from posefuse's
//                                chordal poses (computed once, outside the
//                                timing)
//   BM_G2o3d/posefuse_file, posefuse_chordal, ceres_file, ceres_chordal
//                                the same four on parking-garage.g2o (parsed
//                                once, outside the timing)
//
// The files are found as $POSEFUSE_DATA_DIR/posegraph, else in the data
// folder configured at build time (the CMake cache variable
// POSEFUSE_DATA_DIR); without them those rows stop with "SKIPPED: ...".
// File parsing is outside the timing of every row; the first vertex is
// held fixed in both solvers (the files have no FIX line).
//
// Counters: chi2 (g2o convention, = 2x Ceres's cost), iterations. Run Ceres
// with OMP_THREAD_LIMIT=1 (Debian's CHOLMOD otherwise starts OpenMP threads):
//
//   OMP_THREAD_LIMIT=1 ./build-release/benchmarks/bench_graph --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <random>
#include <numbers>

#include <posefuse/sim/pose_graph_4dof.hpp>
#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/g2o_se3.hpp>
#include <posefuse/sim/pose_graph_se3.hpp>

#ifdef POSEFUSE_HAVE_CERES
#include <ceres/ceres.h>
#include <ceres/manifold.h>

#include "ceres_pose_graph_4dof.hpp"
#endif

namespace {

using namespace posefuse;

const sim::PoseGraphProblem& problem(int n) {
  static std::map<int, sim::PoseGraphProblem> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    sim::PoseGraphProblemConfig c;
    c.nodes = n;
    c.seed = 42;
    it = cache.emplace(n, sim::make_pose_graph_problem(c)).first;
  }
  return it->second;
}

/// The solver buffers every posefuse row but posefuse_own_workspace shares
/// (see the file comment).
PoseGraphWorkspace& program_workspace() {
  static PoseGraphWorkspace workspace;
  return workspace;
}

void run_posefuse(benchmark::State& state, bool held_workspace, bool rotation_first = false) {
  const sim::PoseGraphProblem& pr = problem(static_cast<int>(state.range(0)));
  PoseGraphWorkspace& workspace = program_workspace();
  PoseGraphSummary s;
  for (auto _ : state) {
    PoseGraph4Dof g = sim::to_pose_graph(pr);
    if (rotation_first) g.initialize_rotation_first(workspace);
    s = held_workspace ? g.optimize({}, workspace) : g.optimize();
    benchmark::DoNotOptimize(s);
  }
  state.counters["chi2"] = s.final_cost;
  state.counters["iterations"] = s.iterations;
}
void BM_PoseGraph4Dof_posefuse(benchmark::State& state) { run_posefuse(state, true); }
void BM_PoseGraph4Dof_posefuse_own_workspace(benchmark::State& state) { run_posefuse(state, false); }
BENCHMARK(BM_PoseGraph4Dof_posefuse)
    ->Name("BM_PoseGraph4Dof/posefuse")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);
void BM_PoseGraph4Dof_posefuse_rotation_first(benchmark::State& state) { run_posefuse(state, true, true); }
BENCHMARK(BM_PoseGraph4Dof_posefuse_rotation_first)
    ->Name("BM_PoseGraph4Dof/posefuse_rotation_first")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PoseGraph4Dof_posefuse_own_workspace)
    ->Name("BM_PoseGraph4Dof/posefuse_own_workspace")
    ->Arg(1000)->Arg(10000)
    ->Unit(benchmark::kMillisecond);

/// The real g2o files (see the file comment), parsed once; nullopt when absent.
const std::optional<G2oGraph2d>& real_graph(const std::string& file) {
  static std::map<std::string, std::optional<G2oGraph2d>> cache;
  auto it = cache.find(file);
  if (it != cache.end()) return it->second;
  std::vector<std::filesystem::path> dirs;
  if (const char* d = std::getenv("POSEFUSE_DATA_DIR"); d != nullptr && *d != '\0') dirs.emplace_back(d);
#ifdef POSEFUSE_DEFAULT_DATA_DIR
  dirs.emplace_back(POSEFUSE_DEFAULT_DATA_DIR);
#endif
  std::optional<G2oGraph2d> g;
  for (const auto& d : dirs) {
    const std::filesystem::path p = d / "posegraph" / file;
    if (std::filesystem::is_regular_file(p)) {
      g = read_g2o_2d(p);
      break;
    }
  }
  return cache.emplace(file, std::move(g)).first->second;
}

const char* g2o_file(int which) { return which == 0 ? "manhattanOlson3500.g2o" : "input_MITb_g2o.g2o"; }

bool skip_without(benchmark::State& state, const std::optional<G2oGraph2d>& g, int which) {
  if (g) return false;
  state.SkipWithError((std::string("SKIPPED: posegraph/") + g2o_file(which) +
                       " not found (set POSEFUSE_DATA_DIR to the folder holding posegraph/)")
                          .c_str());
  return true;
}

void run_g2o_posefuse(benchmark::State& state, bool planar) {
  const int which = static_cast<int>(state.range(0));
  const std::optional<G2oGraph2d>& g = real_graph(g2o_file(which));
  if (skip_without(state, g, which)) return;
  PoseGraphOptions o;
  o.planar_fast_path = planar;
  PoseGraphWorkspace& workspace = program_workspace();
  PoseGraphSummary s;
  for (auto _ : state) {
    PoseGraph4Dof graph = pose_graph_from_g2o(*g);
    graph.initialize_rotation_first(workspace);
    s = graph.optimize(o, workspace);
    benchmark::DoNotOptimize(s);
  }
  state.counters["chi2"] = s.final_cost;
  state.counters["iterations"] = s.iterations;
  state.counters["planar"] = s.planar ? 1 : 0;
  state.SetLabel(which == 0 ? "manhattan" : "mit");
}
void BM_G2o_posefuse(benchmark::State& state) { run_g2o_posefuse(state, true); }
void BM_G2o_posefuse_4dof(benchmark::State& state) { run_g2o_posefuse(state, false); }
// Arg 0 = Manhattan 3500, 1 = MIT Killian Court.
BENCHMARK(BM_G2o_posefuse)->Name("BM_G2o/posefuse")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_G2o_posefuse_4dof)->Name("BM_G2o/posefuse_4dof")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

const sim::PoseGraphProblemSE3& problem_se3(int n) {
  static std::map<int, sim::PoseGraphProblemSE3> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    sim::PoseGraphProblemSE3Config c;
    c.nodes = n;
    c.seed = 42;
    it = cache.emplace(n, sim::make_pose_graph_problem_se3(c)).first;
  }
  return it->second;
}

/// The solver buffers the SE(3) posefuse rows share (see the file comment).
PoseGraphSE3Workspace& se3_workspace() {
  static PoseGraphSE3Workspace workspace;
  return workspace;
}

void run_se3_posefuse(benchmark::State& state, bool chordal) {
  const sim::PoseGraphProblemSE3& pr = problem_se3(static_cast<int>(state.range(0)));
  PoseGraphSE3Workspace& workspace = se3_workspace();
  PoseGraphSummary s;
  for (auto _ : state) {
    PoseGraphSE3 g = sim::to_pose_graph_se3(pr);
    if (chordal) g.initialize_chordal(workspace);
    s = g.optimize({}, workspace);
    benchmark::DoNotOptimize(s);
  }
  state.counters["chi2"] = s.final_cost;
  state.counters["iterations"] = s.iterations;
}
void BM_PoseGraphSE3_posefuse(benchmark::State& state) { run_se3_posefuse(state, false); }
void BM_PoseGraphSE3_posefuse_chordal(benchmark::State& state) { run_se3_posefuse(state, true); }
BENCHMARK(BM_PoseGraphSE3_posefuse)
    ->Name("BM_PoseGraphSE3/posefuse")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PoseGraphSE3_posefuse_chordal)
    ->Name("BM_PoseGraphSE3/posefuse_chordal")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);

/// parking-garage.g2o, parsed once; nullopt when absent.
const std::optional<G2oGraph3d>& garage() {
  static const std::optional<G2oGraph3d> g = [] {
    std::vector<std::filesystem::path> dirs;
    if (const char* d = std::getenv("POSEFUSE_DATA_DIR"); d != nullptr && *d != '\0') dirs.emplace_back(d);
#ifdef POSEFUSE_DEFAULT_DATA_DIR
    dirs.emplace_back(POSEFUSE_DEFAULT_DATA_DIR);
#endif
    for (const auto& d : dirs) {
      const std::filesystem::path p = d / "posegraph" / "parking-garage.g2o";
      if (std::filesystem::is_regular_file(p)) return std::optional<G2oGraph3d>(read_g2o_3d(p));
    }
    return std::optional<G2oGraph3d>();
  }();
  return g;
}

bool skip_without_garage(benchmark::State& state) {
  if (garage()) return false;
  state.SkipWithError("SKIPPED: posegraph/parking-garage.g2o not found (set POSEFUSE_DATA_DIR to the folder "
                      "holding posegraph/)");
  return true;
}

void run_garage_posefuse(benchmark::State& state, bool chordal) {
  if (skip_without_garage(state)) return;
  PoseGraphSE3Workspace& workspace = se3_workspace();
  PoseGraphSummary s;
  for (auto _ : state) {
    PoseGraphSE3 g = pose_graph_from_g2o(*garage());
    if (chordal) g.initialize_chordal(workspace);
    s = g.optimize({}, workspace);
    benchmark::DoNotOptimize(s);
  }
  state.counters["chi2"] = s.final_cost;
  state.counters["iterations"] = s.iterations;
  state.SetLabel("parking-garage");
}
void BM_G2o3d_posefuse_file(benchmark::State& state) { run_garage_posefuse(state, false); }
void BM_G2o3d_posefuse_chordal(benchmark::State& state) { run_garage_posefuse(state, true); }
BENCHMARK(BM_G2o3d_posefuse_file)->Name("BM_G2o3d/posefuse_file")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_G2o3d_posefuse_chordal)->Name("BM_G2o3d/posefuse_chordal")->Unit(benchmark::kMillisecond);

#ifdef POSEFUSE_HAVE_CERES

using bench::CeresRun;
using bench::solve_with_ceres;
using bench::wrap;

/// The counters and label of a Ceres row; the label warns when
/// OMP_THREAD_LIMIT is not 1 (CHOLMOD would start threads).
void report_ceres(benchmark::State& state, const CeresRun& run, std::string label) {
  state.counters["chi2"] = run.chi2;
  state.counters["iterations"] = run.iterations;
  const char* limit = std::getenv("OMP_THREAD_LIMIT");
  if (limit == nullptr || std::string(limit) != "1")
    label += label.empty() ? "OMP_THREAD_LIMIT is not 1" : " OMP_THREAD_LIMIT is not 1";
  if (!label.empty()) state.SetLabel(label);
}

/// Ceres solving simulated problem pr from the poses `start`, timed.
void time_ceres_from(benchmark::State& state, const sim::PoseGraphProblem& pr,
                     const std::vector<Pose4Dof>& start) {
  CeresRun run{};
  for (auto _ : state) {
    std::vector<std::array<double, 4>> x = bench::ceres_blocks_4dof(start);
    run = bench::solve_4dof_with_ceres(pr.edges, pr.initial, x);
    benchmark::DoNotOptimize(x.data());
  }
  report_ceres(state, run, "");
}

void BM_PoseGraph4Dof_ceres(benchmark::State& state) {
  const sim::PoseGraphProblem& pr = problem(static_cast<int>(state.range(0)));
  time_ceres_from(state, pr, pr.initial);
}
BENCHMARK(BM_PoseGraph4Dof_ceres)
    ->Name("BM_PoseGraph4Dof/ceres")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);

/// posefuse's rotation-first poses of simulated problem n (computed once).
const std::vector<Pose4Dof>& rotation_first_poses(int n) {
  static std::map<int, std::vector<Pose4Dof>> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    PoseGraph4Dof g = sim::to_pose_graph(problem(n));
    g.initialize_rotation_first();
    it = cache.emplace(n, g.poses()).first;
  }
  return it->second;
}

void BM_PoseGraph4Dof_ceres_rotation_first(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  time_ceres_from(state, problem(n), rotation_first_poses(n));
}
BENCHMARK(BM_PoseGraph4Dof_ceres_rotation_first)
    ->Name("BM_PoseGraph4Dof/ceres_rotation_first")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);


/// g2o's EDGE_SE2 error t2v(Z⁻¹ X_a⁻¹ X_b) on [x y yaw] blocks, whitened
/// by the information's upper Cholesky factor (for Ceres's autodiff).
struct EdgeSE2Error {
  double dx, dy, dyaw;
  Eigen::Matrix3d sqrt_info;

  template <class T>
  bool operator()(const T* a, const T* b, T* residual) const {
    const T d0 = b[0] - a[0], d1 = b[1] - a[1];
    const T ca = ceres::cos(a[2]), sa = ceres::sin(a[2]);
    const T u0 = ca * d0 + sa * d1 - dx, u1 = -sa * d0 + ca * d1 - dy;
    const double cm = std::cos(dyaw), sm = std::sin(dyaw);
    T e[3];
    e[0] = cm * u0 + sm * u1;
    e[1] = -sm * u0 + cm * u1;
    e[2] = wrap(b[2] - a[2] - T(dyaw));
    for (int r = 0; r < 3; ++r) {
      residual[r] = T(0);
      for (int c = r; c < 3; ++c) residual[r] += T(sqrt_info(r, c)) * e[c];
    }
    return true;
  }
};

/// posefuse's rotation-first start of a file (computed once per file).
const std::vector<std::array<double, 3>>& rotation_first_start(int which) {
  static std::map<int, std::vector<std::array<double, 3>>> cache;
  auto it = cache.find(which);
  if (it == cache.end()) {
    PoseGraph4Dof graph = pose_graph_from_g2o(*real_graph(g2o_file(which)));
    graph.initialize_rotation_first();
    std::vector<std::array<double, 3>> x;
    for (const Pose4Dof& p : graph.poses()) x.push_back({p.p.x(), p.p.y(), p.yaw});
    it = cache.emplace(which, std::move(x)).first;
  }
  return it->second;
}

void run_g2o_ceres(benchmark::State& state, bool from_file) {
  const int which = static_cast<int>(state.range(0));
  const std::optional<G2oGraph2d>& g = real_graph(g2o_file(which));
  if (skip_without(state, g, which)) return;
  std::vector<std::array<double, 3>> start;
  if (from_file) {
    for (const G2oVertexSE2& v : g->vertices) start.push_back({v.x, v.y, v.theta});
  } else {
    start = rotation_first_start(which);
  }
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t k = 0; k < g->vertices.size(); ++k) index[g->vertices[k].id] = k;
  double chi2 = 0;
  int iterations = 0;
  for (auto _ : state) {
    std::vector<std::array<double, 3>> x = start;
    ceres::Problem problem;
    for (const G2oEdgeSE2& e : g->edges) {
      EdgeSE2Error f{e.dx, e.dy, e.dtheta, e.information.llt().matrixU()};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EdgeSE2Error, 3, 3, 3>(new EdgeSE2Error(f)),
                               nullptr, x[index.at(e.from)].data(), x[index.at(e.to)].data());
    }
    problem.SetParameterBlockConstant(x[0].data());
    const CeresRun run = solve_with_ceres(problem);
    chi2 = run.chi2;
    iterations = run.iterations;
    benchmark::DoNotOptimize(x.data());
  }
  report_ceres(state, {chi2, iterations}, which == 0 ? "manhattan" : "mit");
}
void BM_G2o_ceres_file(benchmark::State& state) { run_g2o_ceres(state, true); }
void BM_G2o_ceres_rotation_first(benchmark::State& state) { run_g2o_ceres(state, false); }
BENCHMARK(BM_G2o_ceres_file)->Name("BM_G2o/ceres_file")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_G2o_ceres_rotation_first)
    ->Name("BM_G2o/ceres_rotation_first")
    ->Arg(0)->Arg(1)
    ->Unit(benchmark::kMillisecond);

/// g2o's EdgeSE3 error [t; q_xyz] of Z⁻¹ X_i⁻¹ X_j (q with w >= 0) on a
/// position block and an Eigen-order quaternion block per pose, whitened
/// by the information's upper Cholesky factor (for Ceres's autodiff).
struct EdgeSE3Error {
  Eigen::Vector3d tz;
  Eigen::Quaterniond qz_inv;
  Eigen::Matrix<double, 6, 6> sqrt_info;

  template <class T>
  bool operator()(const T* ti, const T* qi, const T* tj, const T* qj, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pi(ti), pj(tj);
    const Eigen::Map<const Eigen::Quaternion<T>> Qi(qi), Qj(qj);
    const Eigen::Quaternion<T> Qz_inv = qz_inv.template cast<T>();
    Eigen::Quaternion<T> qe = Qz_inv * (Qi.conjugate() * Qj);
    const Eigen::Matrix<T, 3, 1> te = Qz_inv * (Qi.conjugate() * (pj - pi) - tz.template cast<T>());
    if (qe.w() < T(0)) qe.coeffs() = -qe.coeffs();
    Eigen::Matrix<T, 6, 1> e;
    e << te, qe.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = sqrt_info.template cast<T>() * e;
    return true;
  }
};

/// One pose in Ceres's blocks: position, quaternion (x, y, z, w).
struct CeresPose {
  std::array<double, 3> t;
  std::array<double, 4> q;
};

CeresPose ceres_pose(const SE3d& x) {
  const Eigen::Quaterniond& q = x.so3().quaternion();
  return {{x.translation().x(), x.translation().y(), x.translation().z()}, {q.x(), q.y(), q.z(), q.w()}};
}

/// Builds and solves the Ceres problem of `edges` from `start` (the first
/// pose held fixed).
CeresRun solve_se3_with_ceres(std::vector<CeresPose> x, const std::vector<EdgeSE3>& edges) {
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::EigenQuaternionManifold quaternion;
  ceres::Problem problem(po);
  for (const EdgeSE3& e : edges) {
    const Eigen::Quaterniond& qz = e.measurement.so3().quaternion();
    EdgeSE3Error f{e.measurement.translation(), qz.conjugate(), e.information.llt().matrixU()};
    CeresPose& a = x[std::size_t(e.from)];
    CeresPose& b = x[std::size_t(e.to)];
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EdgeSE3Error, 6, 3, 4, 3, 4>(new EdgeSE3Error(f)),
                             nullptr, a.t.data(), a.q.data(), b.t.data(), b.q.data());
  }
  for (CeresPose& p : x)
    if (problem.HasParameterBlock(p.q.data())) problem.SetManifold(p.q.data(), &quaternion);
  problem.SetParameterBlockConstant(x[0].t.data());
  problem.SetParameterBlockConstant(x[0].q.data());
  const CeresRun run = solve_with_ceres(problem);
  benchmark::DoNotOptimize(x.data());
  return run;
}

/// posefuse's chordal start of a graph, as Ceres blocks.
std::vector<CeresPose> chordal_start(PoseGraphSE3 g) {
  g.initialize_chordal();
  std::vector<CeresPose> x;
  for (const SE3d& p : g.poses()) x.push_back(ceres_pose(p));
  return x;
}

void run_se3_ceres(benchmark::State& state, bool chordal) {
  const sim::PoseGraphProblemSE3& pr = problem_se3(static_cast<int>(state.range(0)));
  std::vector<CeresPose> start;
  if (chordal) {
    start = chordal_start(sim::to_pose_graph_se3(pr));
  } else {
    for (const SE3d& p : pr.initial) start.push_back(ceres_pose(p));
  }
  CeresRun run{};
  for (auto _ : state) run = solve_se3_with_ceres(start, pr.edges);
  report_ceres(state, run, "");
}
void BM_PoseGraphSE3_ceres(benchmark::State& state) { run_se3_ceres(state, false); }
void BM_PoseGraphSE3_ceres_chordal(benchmark::State& state) { run_se3_ceres(state, true); }
BENCHMARK(BM_PoseGraphSE3_ceres)
    ->Name("BM_PoseGraphSE3/ceres")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PoseGraphSE3_ceres_chordal)
    ->Name("BM_PoseGraphSE3/ceres_chordal")
    ->Arg(1000)->Arg(10000)->Arg(100000)
    ->Unit(benchmark::kMillisecond);

void run_garage_ceres(benchmark::State& state, bool chordal) {
  if (skip_without_garage(state)) return;
  // The file's ids are 0..n-1 in order (checked), so they index the blocks.
  const G2oGraph3d& file = *garage();
  for (std::size_t k = 0; k < file.vertices.size(); ++k)
    if (file.vertices[k].id != std::int64_t(k)) {
      state.SkipWithError("parking-garage.g2o: vertex ids are not 0..n-1 in order");
      return;
    }
  const PoseGraphSE3 graph = pose_graph_from_g2o(file);
  std::vector<CeresPose> start;
  if (chordal) {
    start = chordal_start(graph);
  } else {
    for (const SE3d& p : graph.poses()) start.push_back(ceres_pose(p));
  }
  CeresRun run{};
  for (auto _ : state) run = solve_se3_with_ceres(start, graph.edges());
  report_ceres(state, run, "parking-garage");
}
void BM_G2o3d_ceres_file(benchmark::State& state) { run_garage_ceres(state, false); }
void BM_G2o3d_ceres_chordal(benchmark::State& state) { run_garage_ceres(state, true); }
BENCHMARK(BM_G2o3d_ceres_file)->Name("BM_G2o3d/ceres_file")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_G2o3d_ceres_chordal)->Name("BM_G2o3d/ceres_chordal")->Unit(benchmark::kMillisecond);

#endif

}  // namespace

#include <posefuse/graph/marginalization.hpp>

namespace {

/// One marginalisation of a VINS-Mono-sized window: 10 keyframes of 15
/// states and 100 landmarks (250 variables, dense); the oldest keyframe and
/// the 30 landmarks it anchors are removed (45 of 250).
void BM_Marginalization_Window10(benchmark::State& state) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int n = 10 * 15 + 100;
  Eigen::MatrixXd A(400, n);
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < 400; ++r) A(r, c) = n01(rng);
  const Eigen::MatrixXd H = A.transpose() * A;
  Eigen::VectorXd b(n);
  for (int r = 0; r < n; ++r) b(r) = n01(rng);
  std::vector<int> remove;
  for (int k = 0; k < 15; ++k) remove.push_back(k);
  for (int k = 0; k < 30; ++k) remove.push_back(150 + k);
  for (auto _ : state) {
    const MarginalizationPrior p = marginalize(H, b, remove);
    benchmark::DoNotOptimize(p.J.data());
  }
}
BENCHMARK(BM_Marginalization_Window10)->Unit(benchmark::kMillisecond);

}  // namespace

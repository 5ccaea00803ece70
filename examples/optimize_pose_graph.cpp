// optimize_pose_graph: optimises a planar g2o pose graph with posefuse's
// 4-DoF pose graph (seed 003, docs/pose-graph.md; a planar graph is the 4-DoF graph
// with z = 0), or a 3-D one (VERTEX_SE3:QUAT / EDGE_SE3:QUAT, detected from
// the file) with its SE(3) pose graph, and reports g2o's chi2 before and after.
//
// Scenario: a SLAM back end hands over a g2o file (VERTEX_SE2 / EDGE_SE2).
// The program starts from the rotation-first initialisation (chordal yaw,
// then the linear translation solve; Carlone et al. 2015) unless
// `--init file`, runs Levenberg-Marquardt, writes the optimised g2o file
// with --out, and with --groundtruth prints the position RMSE after a rigid
// alignment. Cost convention: g2o's chi2, sum of e^T Omega e with g2o's
// EDGE_SE2 error (translation error in the measurement's frame); Ceres
// reports half of it.
//
// With no --input it runs on a built-in seeded planar graph (2000 poses,
// 20 laps of a track, loop closures every 4th pose) and prints, e.g.:
//
//   input        nodes  edges  init           initial_cost   final_cost   iterations  solve_time_s
//   built-in      2000   2449  rotation-first     3.5e+07       2364.1         4        0.01
//
// On the public graphs (posegraph/ of the data folder, docs/programs.md):
//
//   optimize_pose_graph --input manhattanOlson3500.g2o
//       --groundtruth manhattanOlson3500_groundtruth.txt --out manhattan_opt.g2o
//   optimize_pose_graph --input input_MITb_g2o.g2o --json
//   optimize_pose_graph --input parking-garage.g2o --init file
//
// A 3-D file starts from the chordal initialisation (rotations by the
// chordal relaxation projected to SO(3), then the linear translation solve;
// --init rotation-first names the same start) unless --init file; its cost
// is g2o's chi2 with the EDGE_SE3 error [t; q_xyz] of Z^-1 Xi^-1 Xj.
//
// Options: see --help. Exit status 0 ok, 1 bad data (one line on stderr,
// naming file:line where a file is at fault), 2 bad usage. --out is written
// only when everything was computed, through a temporary file.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <apps/spooled_input.hpp>
#include <posefuse/sim/pose_graph_4dof.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/g2o_se3.hpp>
#include <posefuse/lie/se2.hpp>

namespace {

using namespace posefuse;

struct Options {
  std::optional<std::filesystem::path> input, out, groundtruth;
  bool rotation_first = true;
  bool json = false;
  PoseGraphOptions solver;
  RobustKernel loss;
  std::string input_name;  ///< --input's file name as given (the reader may read a copy of a pipe)
};

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  apps::Parser cli(cmd.program, "[--input GRAPH.g2o] [options]",
                   "Optimises a planar g2o pose graph (VERTEX_SE2 / EDGE_SE2) or a 3-D one\n"
                   "(VERTEX_SE3:QUAT / EDGE_SE3:QUAT, detected from the file) and reports g2o's chi2.\n"
                   "Without --input it uses a built-in seeded planar graph.");
  cli.input({.name = "--input", .value = "FILE.g2o", .help = "the graph"}, o.input);
  cli.output({.name = "--out", .value = "FILE.g2o", .help = "write the optimised graph"}, o.out);
  cli.input({.name = "--groundtruth", .value = "FILE",
            .help = "true poses, one per vertex in file order: 'x y theta' or VERTEX_SE2\n"
                    "lines, or TORO 'EDGE2 i j dx dy dtheta ...' lines whose (i, i+1) edges\n"
                    "chained from the origin give the poses"},
           o.groundtruth);
  cli.custom({.name = "--init", .value = "rotation-first|chordal|file",
              .help = "starting point (3-D graphs: rotation-first and chordal are the chordal start)",
              .default_text = "rotation-first"},
             [&](std::string_view v) {
               if (v == "rotation-first" || v == "chordal") o.rotation_first = true;
               else if (v == "file") o.rotation_first = false;
               else throw apps::usage_error("expected rotation-first or file, got '" + std::string(v) + "'");
             });
  cli.custom({.name = "--method", .value = "lm|gn", .help = "Levenberg-Marquardt or Gauss-Newton",
              .default_text = "lm"},
             [&](std::string_view v) {
               if (v == "lm") o.solver.levenberg_marquardt = true;
               else if (v == "gn") o.solver.levenberg_marquardt = false;
               else throw apps::usage_error("expected lm or gn, got '" + std::string(v) + "'");
             });
  cli.integer({.name = "--max-iterations", .value = "N", .help = "linear solves at most"},
              o.solver.max_iterations, 1, 1000000);
  cli.custom({.name = "--robust", .value = "none|huber|cauchy", .help = "robust loss on every edge",
              .default_text = "none"},
             [&](std::string_view v) {
               if (v == "none") o.loss.type = RobustLoss::kNone;
               else if (v == "huber") o.loss.type = RobustLoss::kHuber;
               else if (v == "cauchy") o.loss.type = RobustLoss::kCauchy;
               else throw apps::usage_error("expected none, huber or cauchy, got '" + std::string(v) + "'");
             });
  cli.real({.name = "--robust-scale", .value = "S", .help = "robust-loss scale (whitened units)",
            .default_text = "1"},
           o.loss.scale, apps::Domain::kPositive);
  cli.flag({.name = "--json", .help = "print the results as JSON instead of a table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (one line on stderr, file:line where a file is at fault),\n"
               "2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (o.groundtruth && !o.input) throw apps::usage_error("--groundtruth needs --input");
  if (cli.given("--robust-scale") && o.loss.type == RobustLoss::kNone)
    throw apps::usage_error("--robust-scale needs a robust loss (--robust huber|cauchy)");
  return o;
}

/// Ground-truth poses (x, y, theta), one per vertex (see --help).
std::vector<SE2<double>> read_groundtruth(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw io_error(file, "cannot open file for reading");
  std::vector<SE2<double>> poses;
  std::string line;
  std::size_t n = 0;
  bool toro = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream s(line);
    std::vector<std::string> tok;
    for (std::string t; s >> t;) tok.push_back(t);
    if (tok.empty() || tok[0][0] == '#') continue;
    const auto num = [&](std::size_t c) {
      try {
        return apps::parse_real(tok[c]);
      } catch (const apps::usage_error&) {
        throw io_error(file, n, "cannot parse '" + tok[c] + "' in column " + std::to_string(c + 1) + " as a number");
      }
    };
    const auto index = [&](std::size_t c) {
      try {
        return apps::parse_integer<long>(tok[c], 0);
      } catch (const apps::usage_error&) {
        throw io_error(file, n, "cannot parse '" + tok[c] + "' in column " + std::to_string(c + 1) +
                                    " as a vertex id (a non-negative integer)");
      }
    };
    if (tok[0] == "EDGE2" || tok[0] == "EDGE_SE2") {
      if (tok.size() < 6) throw io_error(file, n, tok[0] + " expects at least i j dx dy dtheta");
      const long i = index(1), j = index(2);
      if (j != i + 1) continue;  // only the odometry chain
      toro = true;
      if (poses.empty()) poses.push_back(SE2<double>());
      if (i != static_cast<long>(poses.size()) - 1)
        throw io_error(file, n, "odometry edge " + tok[1] + " -> " + tok[2] + " is out of order");
      poses.push_back(poses.back() * SE2<double>(num(3), num(4), num(5)));
    } else if (tok[0] == "VERTEX_SE2" || tok[0] == "VERTEX2") {
      if (tok.size() != 5) throw io_error(file, n, tok[0] + " expects id x y theta");
      poses.emplace_back(num(2), num(3), num(4));
    } else if (tok.size() == 3 && !toro) {
      poses.emplace_back(num(0), num(1), num(2));
    } else if (tok[0].rfind("EDGE", 0) == 0 || tok[0].rfind("VERTEX", 0) == 0) {
      continue;
    } else {
      throw io_error(file, n, "expected 'x y theta', VERTEX_SE2 or EDGE2 line");
    }
  }
  if (poses.empty()) throw io_error(file, "no poses");
  return poses;
}

/// Position RMSE (m) after the rigid alignment (Umeyama) of the estimate onto the truth.
double aligned_rmse(const PoseGraph4Dof& graph, const std::vector<SE2<double>>& truth,
                    const std::filesystem::path& file) {
  if (truth.size() != graph.num_nodes())
    throw apps::data_error(file.string() + " has " + std::to_string(truth.size()) + " poses but the graph has " +
                           std::to_string(graph.num_nodes()) + " vertices");
  std::vector<Eigen::Vector3d> est, ref;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    est.push_back(graph.poses()[k].p);
    ref.emplace_back(truth[k].x(), truth[k].y(), 0.0);
  }
  const AlignmentResult a = umeyama_alignment(est, ref, false);
  double s = 0.0;
  for (std::size_t k = 0; k < est.size(); ++k) s += (a.apply(est[k]) - ref[k]).squaredNorm();
  return std::sqrt(s / double(est.size()));
}

/// Values the solver's normal equations can hold: coordinates (m) up to
/// 1e50 and information entries up to 1e100, so that information times
/// squared lever arms stays far below the largest double. Larger values are
/// refused naming the line (a standard deviation below 1e-50 or a pose
/// 1e50 m away is no measurement).
void check_magnitudes(const G2oGraph2d& g, const std::filesystem::path& file) {
  constexpr double kMaxCoordinate = 1e50, kMaxInformation = 1e100;
  const auto refuse = [&](std::size_t line, const char* what, double v, double limit) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s %g is beyond %g, which the solver cannot hold", what, v, limit);
    throw io_error(file, line, buf);
  };
  for (const G2oVertexSE2& v : g.vertices)
    for (const double c : {v.x, v.y})
      if (std::abs(c) > kMaxCoordinate) refuse(v.line, "a coordinate of", c, kMaxCoordinate);
  for (const G2oEdgeSE2& e : g.edges) {
    for (const double c : {e.dx, e.dy})
      if (std::abs(c) > kMaxCoordinate) refuse(e.line, "a translation of", c, kMaxCoordinate);
    const double info = e.information.cwiseAbs().maxCoeff();
    if (info > kMaxInformation) refuse(e.line, "an information entry of", info, kMaxInformation);
  }
}

/// Refuses a graph whose information leaves a node free (its pose would be
/// whatever the start is), naming the node's VERTEX_SE2 line: a node tied
/// to the fixed nodes only through edges of zero information, or one whose
/// edges all have zero heading (theta-theta) or zero position (x, y)
/// information. The same graph is refused from every start.
void check_nodes_are_fixed(const G2oGraph2d& g, const std::filesystem::path& file) {
  const std::size_t n = g.vertices.size();
  std::unordered_map<std::int64_t, std::size_t> index;
  index.reserve(n);
  for (std::size_t k = 0; k < n; ++k) index.emplace(g.vertices[k].id, k);
  // Components through edges of non-zero information (`informed`) and
  // through any edge (`linked`: a node outside the fixed nodes' one is
  // disconnected, which PoseGraph4Dof::validate() reports).
  std::vector<std::size_t> informed(n), linked(n);
  for (std::size_t k = 0; k < n; ++k) informed[k] = linked[k] = k;
  const auto find = [](std::vector<std::size_t>& parent, std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<double> heading(n, 0.0), position(n, 0.0);
  for (const G2oEdgeSE2& e : g.edges) {
    const std::size_t a = index.at(e.from), b = index.at(e.to);
    const Eigen::Matrix3d& I = e.information;
    linked[find(linked, a)] = find(linked, b);
    if (I.cwiseAbs().maxCoeff() > 0) informed[find(informed, a)] = find(informed, b);
    for (const std::size_t k : {a, b}) {
      heading[k] += I(2, 2);
      position[k] += I(0, 0) + I(1, 1);
    }
  }
  std::vector<char> fixed(n, 0);
  if (g.fixed.empty() && n > 0) fixed[0] = 1;
  for (const std::int64_t id : g.fixed) fixed[index.at(id)] = 1;
  std::vector<char> anchored(n, 0), reached(n, 0);
  for (std::size_t k = 0; k < n; ++k)
    if (fixed[k]) {
      anchored[find(informed, k)] = 1;
      reached[find(linked, k)] = 1;
    }
  const auto refuse = [&](std::size_t k, const std::string& why) {
    throw io_error(file, g.vertices[k].line,
                   "node " + std::to_string(g.vertices[k].id) + " " + why +
                       ", so the information does not determine its pose and the answer would depend on the start");
  };
  for (std::size_t k = 0; k < n; ++k) {
    if (fixed[k] || !reached[find(linked, k)]) continue;
    if (!anchored[find(informed, k)]) refuse(k, "is tied to the fixed node only through edges of zero information");
    if (heading[k] == 0) refuse(k, "has no heading information (every edge at it has a zero theta-theta entry)");
    if (position[k] == 0) refuse(k, "has no position information (every edge at it has zero x and y entries)");
  }
}

/// check_nodes_are_fixed for a 3-D graph: a node tied to the fixed nodes
/// only through edges of zero information, or only through edges of zero
/// rotation information (its orientation would be free: the rotation block
/// qx, qy, qz of every edge on each path is zero), or whose edges all have
/// zero position (x, y, z) information, is refused at its VERTEX_SE3 line.
void check_nodes_are_fixed_3d(const G2oGraph3d& g, const std::filesystem::path& file) {
  const std::size_t n = g.vertices.size();
  std::unordered_map<std::int64_t, std::size_t> index;
  index.reserve(n);
  for (std::size_t k = 0; k < n; ++k) index.emplace(g.vertices[k].id, k);
  std::vector<std::size_t> informed(n), rotated(n), linked(n);
  for (std::size_t k = 0; k < n; ++k) informed[k] = rotated[k] = linked[k] = k;
  const auto find = [](std::vector<std::size_t>& parent, std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<double> position(n, 0.0);
  for (const G2oEdgeSE3& e : g.edges) {
    const auto ia = index.find(e.from), ib = index.find(e.to);
    if (ia == index.end() || ib == index.end()) continue;  // reported by the graph's own checks
    const std::size_t a = ia->second, b = ib->second;
    const Eigen::Matrix<double, 6, 6>& I = e.information;
    linked[find(linked, a)] = find(linked, b);
    if (I.cwiseAbs().maxCoeff() > 0) informed[find(informed, a)] = find(informed, b);
    if (I.bottomRightCorner<3, 3>().cwiseAbs().maxCoeff() > 0) rotated[find(rotated, a)] = find(rotated, b);
    for (const std::size_t k : {a, b}) position[k] += I.topLeftCorner<3, 3>().trace();
  }
  std::vector<char> fixed(n, 0);
  if (g.fixed.empty() && n > 0) fixed[0] = 1;
  for (const std::int64_t id : g.fixed)
    if (const auto it = index.find(id); it != index.end()) fixed[it->second] = 1;
  std::vector<char> anchored(n, 0), oriented(n, 0), reached(n, 0);
  for (std::size_t k = 0; k < n; ++k)
    if (fixed[k]) {
      anchored[find(informed, k)] = 1;
      oriented[find(rotated, k)] = 1;
      reached[find(linked, k)] = 1;
    }
  const auto refuse = [&](std::size_t k, const std::string& why) {
    throw io_error(file, g.vertices[k].line,
                   "node " + std::to_string(g.vertices[k].id) + " " + why +
                       ", so the information does not determine its pose and the answer would depend on the start");
  };
  for (std::size_t k = 0; k < n; ++k) {
    if (fixed[k] || !reached[find(linked, k)]) continue;
    if (!anchored[find(informed, k)]) refuse(k, "is tied to the fixed node only through edges of zero information");
    if (!oriented[find(rotated, k)])
      refuse(k, "is tied to the fixed node only through edges of zero rotation information (qx, qy, qz block)");
    if (position[k] == 0) refuse(k, "has no position information (every edge at it has a zero x, y, z block)");
  }
}

/// The sentence for a graph whose information does not fix every node
/// (the rotation-first systems are singular), from any start.
[[noreturn]] void refuse_unfixed(const std::string& name) {
  throw apps::data_error(name +
                         ": the information does not fix every node (rank-deficient information leaves "
                         "a heading or position free), so the answer would depend on the start");
}

/// A 3-D file: the SE(3) graph, the chordal start (unless --init file), LM.
int run_3d(const Options& o) {
  apps::TerminalProgress progress("optimize_pose_graph");
  if (o.groundtruth) throw apps::usage_error("--groundtruth takes planar graphs only");
  progress.stage("reading " + o.input->string());
  const G2oGraph3d file_graph = read_g2o_3d(*o.input);
  constexpr double kMaxCoordinate = 1e50, kMaxInformation = 1e100;  // as check_magnitudes
  for (const G2oVertexSE3& v : file_graph.vertices)
    if (v.t.cwiseAbs().maxCoeff() > kMaxCoordinate)
      throw io_error(*o.input, v.line, "a coordinate is beyond 1e+50, which the solver cannot hold");
  for (const G2oEdgeSE3& e : file_graph.edges)
    if (e.t.cwiseAbs().maxCoeff() > kMaxCoordinate || e.information.cwiseAbs().maxCoeff() > kMaxInformation)
      throw io_error(*o.input, e.line,
                     "a translation beyond 1e+50 or an information entry beyond 1e+100, which the solver cannot hold");
  const std::string name = o.input_name;
  PoseGraphSE3 graph;
  try {
    graph = pose_graph_from_g2o(file_graph, o.loss);
    graph.validate();
  } catch (const posefuse::invalid_argument& e) {
    throw apps::data_error(o.input->string() + ": " + e.what());
  }
  progress.stage("checking the information");
  check_nodes_are_fixed_3d(file_graph, *o.input);
  const double file_cost = graph.cost();
  const auto t0 = std::chrono::steady_clock::now();
  // The chordal systems are solvable exactly when the information fixes
  // every rotation and position; from the file's poses the same check runs
  // on a copy, so that both starts refuse the same graphs.
  {
    progress.stage(o.rotation_first ? "chordal initialisation" : "checking the information");
    PoseGraphSE3 copy;
    PoseGraphSE3& target = o.rotation_first ? graph : copy;
    if (!o.rotation_first) copy = graph;
    try {
      target.initialize_chordal();
    } catch (const posefuse::invalid_argument& e) {
      if (std::string_view(e.what()).find("singular") == std::string_view::npos)
        throw apps::data_error(name + ": " + e.what());
      refuse_unfixed(o.input->string());
    }
  }
  const double init_time =
      o.rotation_first ? std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() : 0.0;
  const double init_cost = graph.cost();
  PoseGraphOptions solver = o.solver;
  if (progress.enabled()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "solving (SE(3)): %zu nodes, %zu edges, cost %.6g", graph.num_nodes(),
                  graph.num_edges(), init_cost);
    progress.stage(buf);
    solver.progress = apps::solver_progress<PoseGraphIteration>(progress, o.solver.max_iterations);
  }
  const PoseGraphSummary s = graph.optimize(solver);
  progress.clear();
  const double solve_time = init_time + s.solve_time_s;
  if (!std::isfinite(s.final_cost)) throw apps::data_error(name + ": the final cost is not finite");
  apps::OutputFiles files;
  if (o.out) {
    files.add_with(*o.out, [g = with_graph_poses(file_graph, graph)](const std::filesystem::path& p) {
      write_g2o_3d(p, g);
    });
  }
  files.commit();
  const char* init = o.rotation_first ? "chordal" : "file";
  if (o.json) {
    apps::JsonWriter j(std::cout);
    j.begin_object();
    j.member("input", name).member("dof", 6).member("nodes", graph.num_nodes()).member("edges", graph.num_edges());
    j.member("init", std::string(init)).member("file_cost", file_cost).member("initial_cost", init_cost);
    j.member("final_cost", s.final_cost).member("iterations", s.iterations);
    j.member("termination", std::string(to_string(s.termination)));
    j.member("init_time_s", init_time).member("solve_time_s", solve_time);
    j.end_object().finish();
  } else {
    std::printf("3-D graph (VERTEX_SE3:QUAT), solved in SE(3).\n"
                "cost = g2o chi2 (sum of e^T Omega e, EDGE_SE3 error [t; q_xyz]); file_cost at the file's poses,\n"
                "initial_cost after the initialisation; solve_time_s includes the initialisation.\n\n");
    std::printf("%-24s %7s %7s %-15s %13s %13s %13s %10s %12s %-20s\n", "input", "nodes", "edges", "init",
                "file_cost", "initial_cost", "final_cost", "iterations", "solve_time_s", "termination");
    std::printf("%-24s %7zu %7zu %-15s %13.6g %13.6g %13.10g %10d %12.4f %-20s\n", name.c_str(), graph.num_nodes(),
                graph.num_edges(), init, file_cost, init_cost, s.final_cost, s.iterations, solve_time,
                std::string(to_string(s.termination)).c_str());
  }
  return 0;
}

int run_2d(const Options& o) {
  // On a terminal, standard error shows the stage and the solver's iterations.
  apps::TerminalProgress progress("optimize_pose_graph");
  G2oGraph2d file_graph;
  PoseGraph4Dof graph;
  std::string name = "built-in";
  if (o.input) {
    progress.stage("reading " + o.input->string());
    file_graph = read_g2o_2d(*o.input);
    progress.stage("checking " + std::to_string(file_graph.vertices.size()) + " vertices, " +
                   std::to_string(file_graph.edges.size()) + " edges");
    check_magnitudes(file_graph, *o.input);
    check_nodes_are_fixed(file_graph, *o.input);
    name = o.input_name;
    try {
      graph = pose_graph_from_g2o(file_graph, o.loss);
    } catch (const posefuse::invalid_argument& e) {
      throw apps::data_error(o.input->string() + ": " + e.what());
    }
  } else {
    sim::PoseGraphProblemConfig c;
    c.nodes = 2000;
    c.planar = true;
    c.seed = 3;
    graph = sim::to_pose_graph(sim::make_pose_graph_problem(c));
    for (std::size_t k = 0; k < graph.num_nodes(); ++k) {
      const Pose4Dof& x = graph.poses()[k];
      file_graph.vertices.push_back({graph.ids()[k], x.p.x(), x.p.y(), x.yaw, 0});
    }
  }
  const std::optional<std::vector<SE2<double>>> truth =
      o.groundtruth ? std::optional<std::vector<SE2<double>>>(read_groundtruth(*o.groundtruth)) : std::nullopt;

  const double file_cost = graph.cost();
  progress.stage(o.rotation_first ? "rotation-first initialisation" : "checking the information");
  const auto t0 = std::chrono::steady_clock::now();
  try {
    graph.validate();
  } catch (const posefuse::invalid_argument& e) {
    throw apps::data_error(name + ": " + e.what());
  }
  // The rotation-first systems are solvable exactly when the information
  // fixes every heading and position; from the file's poses the same check
  // runs on a copy of them, which are then put back.
  const std::vector<Pose4Dof> file_poses = o.rotation_first ? std::vector<Pose4Dof>() : graph.poses();
  try {
    graph.initialize_rotation_first();
  } catch (const posefuse::invalid_argument& e) {
    if (std::string_view(e.what()).find("singular") == std::string_view::npos)
      throw apps::data_error(name + ": " + e.what());
    refuse_unfixed(o.input ? o.input->string() : name);
  }
  if (!o.rotation_first)
    for (std::size_t k = 0; k < file_poses.size(); ++k) graph.set_pose(graph.ids()[k], file_poses[k]);
  // From the file's poses nothing was initialised: the check is not timed.
  const double init_time =
      o.rotation_first ? std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() : 0.0;
  const double init_cost = graph.cost();
  PoseGraphOptions solver = o.solver;
  if (progress.enabled()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "solving: %zu nodes, %zu edges, cost %.6g", graph.num_nodes(),
                  graph.num_edges(), init_cost);
    progress.stage(buf);
    solver.progress = apps::solver_progress<PoseGraphIteration>(progress, o.solver.max_iterations);
  }
  const PoseGraphSummary s = graph.optimize(solver);
  progress.clear();
  const double solve_time = init_time + s.solve_time_s;
  if (!std::isfinite(s.final_cost)) throw apps::data_error(name + ": the final cost is not finite");
  const std::optional<double> rmse =
      truth ? std::optional<double>(aligned_rmse(graph, *truth, *o.groundtruth)) : std::nullopt;

  apps::OutputFiles files;
  if (o.out) {
    files.add_with(*o.out, [g = with_graph_poses(file_graph, graph)](const std::filesystem::path& p) {
      write_g2o_2d(p, g);
    });
  }
  files.commit();

  const char* init = o.rotation_first ? "rotation-first" : "file";
  if (o.json) {
    apps::JsonWriter j(std::cout);
    j.begin_object();
    j.member("input", name).member("nodes", graph.num_nodes()).member("edges", graph.num_edges());
    j.member("init", std::string(init)).member("file_cost", file_cost).member("initial_cost", init_cost);
    j.member("final_cost", s.final_cost).member("iterations", s.iterations);
    j.member("termination", std::string(to_string(s.termination)));
    j.member("init_time_s", init_time).member("solve_time_s", solve_time);
    if (rmse) j.member("rmse", *rmse);
    j.end_object().finish();
  } else {
    std::printf("cost = g2o chi2 (sum of e^T Omega e, EDGE_SE2 error); file_cost at the file's poses,\n"
                "initial_cost after the initialisation; solve_time_s includes the initialisation.\n\n");
    std::printf("%-24s %7s %7s %-15s %13s %13s %13s %10s %12s %-20s", "input", "nodes", "edges", "init",
                "file_cost", "initial_cost", "final_cost", "iterations", "solve_time_s", "termination");
    if (rmse) std::printf(" %9s", "rmse [m]");
    std::printf("\n%-24s %7zu %7zu %-15s %13.6g %13.6g %13.10g %10d %12.4f %-20s", name.c_str(),
                graph.num_nodes(), graph.num_edges(), init, file_cost, init_cost, s.final_cost, s.iterations,
                solve_time, std::string(to_string(s.termination)).c_str());
    if (rmse) std::printf(" %9.4f", *rmse);
    std::printf("\n");
  }
  return 0;
}

/// Detects the file's format (2-D or 3-D) and runs. Detection reads the
/// file before its reader does: a pipe or <(command) is copied once
/// (apps/spooled_input.hpp), and messages name the path as given.
int run(const Options& given) {
  apps::SpooledInputs spool;
  Options o = given;
  if (o.input) {
    o.input_name = o.input->filename().string();
    o.input = spool.readable(*given.input);
  }
  try {
    return o.input && g2o_dimension(*o.input) == 3 ? run_3d(o) : run_2d(o);
  } catch (const apps::usage_error&) {
    throw;
  } catch (const std::exception& e) {
    if (!o.input || *o.input == *given.input) throw;
    throw apps::data_error(spool.shown(std::string(e.what())));
  }
}

}  // namespace

int main(int argc, char** argv) {
  return posefuse::apps::run_main(argc, argv, [](const posefuse::apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

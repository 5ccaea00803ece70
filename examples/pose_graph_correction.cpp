// pose_graph_correction: corrects a drifting odometry trajectory with loop
// closures on posefuse's 4-DoF pose graph (VINS-Mono's global pose graph,
// seed 003, docs/pose-graph.md) or, with --dof 6, on its SE(3) pose graph,
// and compares the absolute position error before and after.
//
// Scenario: a visual(-inertial) odometry ran; its trajectory drifts in x, y,
// z and yaw (roll and pitch are observable from gravity and held fixed: the
// 4-DoF graph, the default). A visual-only odometry drifts in roll and
// pitch too: --dof 6 lets the graph move all six directions.
// Sequential edges are the odometry's relative motions; loop edges come from
// a file (posefuse's 4-DoF loop-edge format, node ids = pose indices) or,
// with --oracle-loops, from ground-truth revisits: an ORACLE for evaluating
// the optimiser, not a loop detector. --outliers N adds N false loop edges
// (two far-apart poses claimed to be the same place) to exercise the robust
// loss (Cauchy on loop edges by default).
//
// APE is the position RMSE against ground truth after an SE(3) alignment
// (evo_ape -a) and after a 4-DoF position + yaw alignment (align_posyaw).
// KITTI files are in the camera frame (y down); they are turned into a
// z-up frame for the graph (--up).
//
// With no arguments it runs on a built-in simulated drive (10 laps of a
// hilly track, drifting odometry, the simulator's loop edges, 5 outliers):
//
//   input       frames  loops  outliers  APE se3 before  after  APE posyaw before  after
//   simulated     1000    225         5           ...     ...             ...      ...
//
// On KITTI 06 (kitti/06 of the data folder, docs/programs.md):
//
//   pose_graph_correction --odometry cvo_vo.txt --groundtruth groundtruth.txt
//       --oracle-loops --outliers 10 --out corrected.txt --svg kitti06_graph.svg
//   pose_graph_correction --odometry cvo_vo.txt --groundtruth groundtruth.txt
//       --oracle-loops --dof 6
//
// Exit status 0 ok, 1 bad data (one line on stderr, file:line where a file
// is at fault), 2 bad usage. --out and --svg are written only when
// everything was computed, each through a temporary file.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <posefuse/sim/pose_graph_4dof.hpp>
#include <apps/svg.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/lie/rotation.hpp>

namespace {

using namespace posefuse;

struct Options {
  std::optional<std::filesystem::path> odometry, groundtruth, loops, out, svg;
  Format format = Format::kKitti;
  std::string up;  ///< "-y" (KITTI camera frame) or "z"; empty: by format
  bool oracle = false;
  int outliers = -1;  ///< -1: default (5 on the built-in drive, 0 otherwise)
  std::uint32_t seed = 1;
  RobustKernel loss{RobustLoss::kCauchy, 1.0};
  double sigma_odo_p = 0.1, sigma_odo_yaw_deg = 0.5;
  double sigma_loop_p = 0.1, sigma_loop_yaw_deg = 0.5;
  bool json = false;
  int dof = 4;  ///< 4: PoseGraph4Dof, 6: PoseGraphSE3
};

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  apps::Parser cli(cmd.program, "[--odometry FILE --groundtruth FILE (--loops FILE | --oracle-loops)] [options]",
                   "Corrects drifting odometry with loop closures on a 4-DoF pose graph and prints the\n"
                   "APE before and after. Without files it uses a built-in simulated drive.");
  cli.input({.name = "--odometry", .value = "FILE", .help = "the drifting trajectory"}, o.odometry);
  cli.input({.name = "--groundtruth", .value = "FILE", .help = "reference, one pose per odometry pose"},
           o.groundtruth);
  cli.input({.name = "--loops", .value = "FILE", .help = "4-DoF loop edges (i j x y z yaw + 10 information values)"},
           o.loops);
  cli.flag({.name = "--oracle-loops",
            .help = "propose loop edges from ground-truth revisits (an ORACLE for evaluating\n"
                    "the optimiser, not a loop detector)"},
           o.oracle);
  cli.integer({.name = "--outliers", .value = "N", .help = "add N false loop edges", .default_text = "0 (5 built-in)"},
              o.outliers, 0, 100000);
  cli.integer({.name = "--seed", .value = "S", .help = "seed of the outliers and of the built-in drive"}, o.seed);
  cli.custom({.name = "--format", .value = "kitti|tum", .help = "format of the trajectories",
              .default_text = "kitti"},
             [&](std::string_view v) { o.format = parse_format(v); });
  cli.custom({.name = "--up", .value = "-y|z", .help = "the world axis opposite to gravity",
              .default_text = "-y for KITTI (camera frame), z for TUM"},
             [&](std::string_view v) {
               if (v != "-y" && v != "z") throw apps::usage_error("expected -y or z, got '" + std::string(v) + "'");
               o.up = std::string(v);
             });
  cli.custom({.name = "--robust", .value = "none|huber|cauchy", .help = "robust loss on loop edges",
              .default_text = "cauchy"},
             [&](std::string_view v) {
               if (v == "none") o.loss.type = RobustLoss::kNone;
               else if (v == "huber") o.loss.type = RobustLoss::kHuber;
               else if (v == "cauchy") o.loss.type = RobustLoss::kCauchy;
               else throw apps::usage_error("expected none, huber or cauchy, got '" + std::string(v) + "'");
             });
  cli.real({.name = "--robust-scale", .value = "S", .help = "robust-loss scale (whitened units)"}, o.loss.scale,
           apps::Domain::kPositive);
  cli.output({.name = "--out", .value = "FILE", .help = "write the corrected trajectory (input format)"}, o.out);
  cli.output({.name = "--svg", .value = "FILE.svg", .help = "top view: truth, before, after, loop edges"}, o.svg);
  cli.custom({.name = "--dof", .value = "4|6",
              .help = "4: x, y, z, yaw (roll and pitch held, visual-inertial odometry);\n"
                      "6: SE(3), every direction free (visual-only odometry)",
              .default_text = "4"},
             [&](std::string_view v) {
               if (v == "4") o.dof = 4;
               else if (v == "6") o.dof = 6;
               else throw apps::usage_error("expected 4 or 6, got '" + std::string(v) + "'");
             });
  cli.flag({.name = "--json", .help = "print the results as JSON instead of a table"}, o.json);
  cli.epilogue("Odometry edges: 0.1 m, 0.5 deg (1 sigma, about every rotation axis with --dof 6) per frame;\n"
               "loop edges 0.1 m, 0.5 deg.\n"
               "Exit status: 0 ok, 1 bad data (one line on stderr, file:line where a file is at fault),\n"
               "2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (o.odometry.has_value() != o.groundtruth.has_value())
    throw apps::usage_error("give --odometry and --groundtruth together, or neither (built-in drive)");
  if (o.odometry && !o.loops && !o.oracle) throw apps::usage_error("give --loops FILE or --oracle-loops");
  if (!o.odometry && (o.loops || o.oracle)) throw apps::usage_error("--loops and --oracle-loops need --odometry");
  if (o.up.empty()) o.up = o.format == Format::kKitti ? "-y" : "z";
  if (o.dof == 6 && o.loops)
    throw apps::usage_error("--loops holds 4-DoF edges (no roll or pitch); with --dof 6 use --oracle-loops");
  if (cli.given("--robust-scale") && o.loss.type == RobustLoss::kNone)
    throw apps::usage_error("--robust-scale needs a robust loss (--robust huber|cauchy)");
  return o;
}

/// Maps the input world/body axes to a z-up frame: x' = z, y' = -x, z' = -y for "-y".
Eigen::Matrix3d up_rotation(const std::string& up) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  if (up == "-y") A << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return A;
}

Trajectory change_frame(const Trajectory& t, const Eigen::Matrix3d& A) {
  Trajectory out = t;
  for (Eigen::Isometry3d& T : out.poses) {
    Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
    S.linear() = A * T.linear() * A.transpose();
    S.translation() = A * T.translation();
    T = S;
  }
  return out;
}

Pose4Dof to_pose(const Eigen::Isometry3d& T) {
  const EulerZYX<double> e = euler_zyx_from_rotation(T.linear());
  return Pose4Dof{T.translation(), e.yaw, e.pitch, e.roll};
}

Eigen::Isometry3d to_isometry(const Pose4Dof& x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation_from_euler_zyx(EulerZYX<double>{x.roll, x.pitch, x.yaw});
  T.translation() = x.p;
  return T;
}

Eigen::Matrix4d information(double sp, double syaw) {
  Eigen::Matrix4d I = Eigen::Matrix4d::Zero();
  I.diagonal() << 1 / (sp * sp), 1 / (sp * sp), 1 / (sp * sp), 1 / (syaw * syaw);
  return I;
}

/// Oracle: for every 5th pose, the closest earlier pose at least 100 frames
/// back whose true position is within 3 m gives a loop edge (measured from
/// the truth).
std::vector<Edge4Dof> oracle_loops(const Trajectory& truth, const Eigen::Matrix4d& info) {
  std::vector<Edge4Dof> loops;
  const std::vector<Eigen::Vector3d> p = truth.positions();
  for (std::size_t j = 100; j < p.size(); j += 5) {
    std::size_t best = p.size();
    double best_d = 3.0;
    for (std::size_t i = 0; i + 100 <= j; ++i) {
      const double d = (p[i] - p[j]).norm();
      if (d < best_d) {
        best_d = d;
        best = i;
      }
    }
    if (best == p.size()) continue;
    Edge4Dof e = sim::relative_edge(to_pose(truth.poses[best]), to_pose(truth.poses[j]),
                                    static_cast<std::int64_t>(best), static_cast<std::int64_t>(j));
    e.information = info;
    loops.push_back(e);
  }
  return loops;
}

/// N false loop edges between poses whose true positions are > 20 m apart,
/// each claiming the same place (zero relative motion).
std::vector<Edge4Dof> outlier_loops(const Trajectory& truth, int n, std::uint32_t seed, const Eigen::Matrix4d& info) {
  std::vector<Edge4Dof> out;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, truth.size() - 1);
  const std::vector<Eigen::Vector3d> p = truth.positions();
  int attempts = 0;
  while (static_cast<int>(out.size()) < n && attempts++ < 100000) {
    const std::size_t a = pick(rng);
    const std::size_t b = pick(rng);
    if (a == b || (p[a] - p[b]).norm() < 20.0) continue;
    Edge4Dof e;
    e.from = static_cast<std::int64_t>(std::min(a, b));
    e.to = static_cast<std::int64_t>(std::max(a, b));
    e.information = info;
    out.push_back(e);
  }
  if (static_cast<int>(out.size()) < n)
    throw apps::data_error("cannot place " + std::to_string(n) + " outliers: too few poses 20 m apart");
  return out;
}

/// A loop edge of the --loops file must join two frames of the odometry and
/// have a finite cost at the odometry's poses (else the solve overflows);
/// the loops file and its line are named, never an internal edge number.
void check_loop(const LoopEdge4DofRecord& r, const std::filesystem::path& file, const Trajectory& odo_up) {
  const auto n = static_cast<std::int64_t>(odo_up.size());
  for (const std::int64_t id : {r.from, r.to})
    if (id < 0 || id >= n)
      throw io_error(file, r.line,
                     "node " + std::to_string(id) + " is not a frame of the odometry (frames 0 to " +
                         std::to_string(n - 1) + ")");
  const Edge4Dof at = sim::relative_edge(to_pose(odo_up.poses[std::size_t(r.from)]),
                                         to_pose(odo_up.poses[std::size_t(r.to)]), r.from, r.to);
  Eigen::Vector4d e;
  e << at.dp - r.dp, at.dyaw - r.dyaw;
  const double cost = e.dot(r.information * e);
  if (!std::isfinite(cost)) {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "the edge's cost at the odometry poses is not finite (largest translation component %g m, "
                  "yaw %g rad): "
                  "values too large for the solver",
                  r.dp.cwiseAbs().maxCoeff(), r.dyaw);
    throw io_error(file, r.line, buf);
  }
}

struct Ape {
  double se3 = 0, posyaw = 0;
};

Ape ape_of(const Trajectory& truth_up, const Trajectory& est_up) {
  Ape a;
  a.se3 = ape(truth_up, est_up, PoseRelation::kTranslation, Alignment::kSE3).stats.rmse;
  a.posyaw = ape(truth_up, align_posyaw(est_up, truth_up).trajectory, PoseRelation::kTranslation).stats.rmse;
  return a;
}

std::string plot(const Trajectory& truth, const Trajectory& before, const Trajectory& after,
                 const std::vector<Edge4Dof>& loops, std::size_t first_outlier) {
  const auto xy = [](const Trajectory& t) {
    std::vector<Eigen::Vector2d> v;
    for (const auto& T : t.poses) v.push_back(T.translation().head<2>());
    return v;
  };
  // Before and after, position + yaw aligned to the truth.
  const std::vector<Eigen::Vector2d> tr = xy(truth);
  apps::svg::Plot p("top view (z up), before and after aligned by position + yaw");
  p.x_axis("x", "m").y_axis("y", "m").equal_aspect();
  for (std::size_t k = 0; k < loops.size(); ++k) {
    const std::size_t i = std::size_t(loops[k].from), j = std::size_t(loops[k].to);
    const bool outlier = k >= first_outlier;
    const bool first = k == 0 || k == first_outlier;
    p.line(first ? (outlier ? "false loop edges" : "loop edges") : "", std::vector<Eigen::Vector2d>{tr[i], tr[j]},
           {outlier ? "#ff7f0e" : "#bbbbbb", 0.6, {}});
  }
  p.line("ground truth", tr, {"#000000", 1.6, {}});
  p.line("odometry", xy(align_posyaw(before, truth).trajectory), {"#d62728", 1.0, {}});
  p.line("pose graph", xy(align_posyaw(after, truth).trajectory), {"#1f77b4", 1.0, {}});
  apps::svg::Document doc(800, 700);
  doc.plot(p, {0, 0, 800, 700});
  return doc.str();
}

/// --dof 4: the 4-DoF graph of the odometry and the loop edges (outliers
/// included); the corrected poses go to after_up.
PoseGraphSummary correct_4dof(const Options& o, const Trajectory& odo_up, const std::vector<Edge4Dof>& loops,
                              const std::string& name, apps::TerminalProgress& progress, Trajectory& after_up) {
  PoseGraph4Dof graph;
  try {
    for (std::size_t k = 0; k < odo_up.size(); ++k)
      graph.add_node(static_cast<std::int64_t>(k), to_pose(odo_up.poses[k]), k == 0);
    const Eigen::Matrix4d odo_info = information(o.sigma_odo_p, o.sigma_odo_yaw_deg * std::numbers::pi / 180);
    for (std::size_t k = 0; k + 1 < odo_up.size(); ++k) {
      Edge4Dof e = sim::relative_edge(to_pose(odo_up.poses[k]), to_pose(odo_up.poses[k + 1]),
                                      static_cast<std::int64_t>(k), static_cast<std::int64_t>(k + 1));
      e.information = odo_info;
      graph.add_edge(e);
    }
    for (Edge4Dof e : loops) {
      e.loss = o.loss;
      graph.add_edge(e);
    }
  } catch (const posefuse::invalid_argument& e) {
    throw apps::data_error(name + ": " + e.what());
  }
  PoseGraphOptions solver;
  if (progress.enabled()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "solving: %zu nodes, %zu edges", graph.num_nodes(), graph.num_edges());
    progress.stage(buf);
    solver.progress = apps::solver_progress<PoseGraphIteration>(progress, solver.max_iterations);
  }
  const PoseGraphSummary s = graph.optimize(solver);
  after_up = odo_up;
  for (std::size_t k = 0; k < after_up.size(); ++k) after_up.poses[k] = to_isometry(graph.poses()[k]);
  return s;
}

SE3d to_se3(const Eigen::Isometry3d& T) {
  return SE3d(T.translation(), SO3d(Eigen::Quaterniond(T.linear())));
}

/// The SE(3) information of a measurement with sigma_p (m) per axis and
/// sigma_r (rad) about every axis: the error's quaternion part is half the
/// rotation angle, hence 4 / sigma_r^2.
Matrix6d information_se3(double sp, double sr) {
  Matrix6d I = Matrix6d::Zero();
  I.diagonal() << Eigen::Vector3d::Constant(1 / (sp * sp)), Eigen::Vector3d::Constant(4 / (sr * sr));
  return I;
}

/// --dof 6: the SE(3) graph of the odometry (relative motions), the loop
/// edges' node pairs measured from the truth (the oracle's, or the
/// simulator's) and the outliers (identity measurements); returns the
/// corrected poses (in after_up).
PoseGraphSummary correct_se3(const Options& o, const Trajectory& odo_up, const Trajectory& truth_up,
                             const std::vector<Edge4Dof>& loops, std::size_t first_outlier, const std::string& name,
                             apps::TerminalProgress& progress, Trajectory& after_up) {
  PoseGraphSE3 graph;
  const double deg = std::numbers::pi / 180;
  try {
    for (std::size_t k = 0; k < odo_up.size(); ++k)
      graph.add_node(static_cast<std::int64_t>(k), to_se3(odo_up.poses[k]), k == 0);
    const Matrix6d odo_info = information_se3(o.sigma_odo_p, o.sigma_odo_yaw_deg * deg);
    const Matrix6d loop_info = information_se3(o.sigma_loop_p, o.sigma_loop_yaw_deg * deg);
    for (std::size_t k = 0; k + 1 < odo_up.size(); ++k) {
      EdgeSE3 e;
      e.from = static_cast<std::int64_t>(k);
      e.to = static_cast<std::int64_t>(k + 1);
      e.measurement = to_se3(odo_up.poses[k]).inverse() * to_se3(odo_up.poses[k + 1]);
      e.information = odo_info;
      graph.add_edge(e);
    }
    for (std::size_t k = 0; k < loops.size(); ++k) {
      EdgeSE3 e;
      e.from = loops[k].from;
      e.to = loops[k].to;
      if (k < first_outlier)
        e.measurement = to_se3(truth_up.poses[std::size_t(e.from)]).inverse() * to_se3(truth_up.poses[std::size_t(e.to)]);
      e.information = loop_info;
      e.loss = o.loss;
      graph.add_edge(e);
    }
  } catch (const posefuse::invalid_argument& e) {
    throw apps::data_error(name + ": " + e.what());
  }
  PoseGraphOptions solver;
  if (progress.enabled()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "solving (SE(3)): %zu nodes, %zu edges", graph.num_nodes(), graph.num_edges());
    progress.stage(buf);
    solver.progress = apps::solver_progress<PoseGraphIteration>(progress, solver.max_iterations);
  }
  const PoseGraphSummary s = graph.optimize(solver);
  after_up = odo_up;
  for (std::size_t k = 0; k < after_up.size(); ++k) after_up.poses[k] = graph.poses()[k].isometry();
  return s;
}

int run(const Options& o) {
  // On a terminal, standard error shows the stage and the solver's iterations.
  apps::TerminalProgress progress("pose_graph_correction");
  Trajectory truth_up, odo_up, odo_in;
  std::vector<Edge4Dof> loops;
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  std::string name = "simulated";
  const Eigen::Matrix4d loop_info = information(o.sigma_loop_p, o.sigma_loop_yaw_deg * std::numbers::pi / 180);
  const int outliers = o.outliers >= 0 ? o.outliers : (o.odometry ? 0 : 5);
  if (!o.odometry) {
    sim::PoseGraphProblemConfig c;
    c.seed = o.seed;
    c.sigma_odo_p = 0.05;
    c.sigma_odo_yaw = 0.5 * std::numbers::pi / 180;
    const sim::PoseGraphProblem pr = sim::make_pose_graph_problem(c);
    for (std::size_t k = 0; k < pr.truth.size(); ++k) {
      truth_up.push_back(double(k), to_isometry(pr.truth[k]));
      odo_up.push_back(double(k), to_isometry(pr.initial[k]));
    }
    for (std::size_t k = pr.sequential; k < pr.edges.size(); ++k) {
      Edge4Dof e = pr.edges[k];
      e.information = loop_info;
      loops.push_back(e);
    }
    odo_in = odo_up;
  } else {
    name = o.odometry->filename().string();
    progress.stage("reading " + o.odometry->string());
    odo_in = read_trajectory(*o.odometry, o.format);
    progress.stage("reading " + o.groundtruth->string());
    const Trajectory truth_in = read_trajectory(*o.groundtruth, o.format);
    if (truth_in.size() != odo_in.size())
      throw apps::data_error(o.odometry->string() + " has " + std::to_string(odo_in.size()) +
                             " poses but the ground truth has " + std::to_string(truth_in.size()));
    A = up_rotation(o.up);
    truth_up = change_frame(truth_in, A);
    odo_up = change_frame(odo_in, A);
    if (o.oracle) loops = oracle_loops(truth_up, loop_info);
    if (o.loops) {
      for (const LoopEdge4DofRecord& r : read_loop_edges_4dof(*o.loops)) {
        check_loop(r, *o.loops, odo_up);
        Edge4Dof e;
        e.from = r.from;
        e.to = r.to;
        e.dp = r.dp;
        e.dyaw = r.dyaw;
        e.information = r.information;
        loops.push_back(e);
      }
    }
  }
  const std::size_t first_outlier = loops.size();
  const std::size_t good_loops = loops.size();
  for (const Edge4Dof& e : outlier_loops(truth_up, outliers, o.seed, loop_info)) loops.push_back(e);

  Trajectory after_up;
  const PoseGraphSummary s = o.dof == 6
                                 ? correct_se3(o, odo_up, truth_up, loops, first_outlier, name, progress, after_up)
                                 : correct_4dof(o, odo_up, loops, name, progress, after_up);
  progress.clear();
  const Ape before = ape_of(truth_up, odo_up);
  const Ape after = ape_of(truth_up, after_up);
  for (const double v : {before.se3, before.posyaw, after.se3, after.posyaw, s.final_cost})
    if (!std::isfinite(v))
      throw apps::data_error(o.loops ? o.loops->string() + ": the solve gave a non-finite result; the loop edges' values are too large"
                                     : name + ": a result is not finite");

  apps::OutputFiles files;
  if (o.out) {
    Trajectory corrected = change_frame(after_up, A.transpose());
    corrected.t_s = odo_in.t_s;
    const Format f = o.format;
    files.add_with(*o.out, [corrected, f](const std::filesystem::path& p) { write_trajectory(p, corrected, f); });
  }
  if (o.svg) files.add(*o.svg, plot(truth_up, odo_up, after_up, loops, first_outlier));
  files.commit();

  if (o.json) {
    apps::JsonWriter j(std::cout);
    using Layout = apps::JsonWriter::Layout;
    j.begin_object();
    j.member("input", name).member("frames", odo_up.size()).member("loops", good_loops);
    j.member("loop_source", std::string(o.odometry ? (o.oracle ? "oracle (ground-truth revisits)" : "file")
                                                   : "simulator"));
    j.member("outliers", static_cast<std::size_t>(outliers)).member("dof", o.dof);
    j.key("ape_before").begin_object(Layout::kInline).member("se3", before.se3).member("posyaw", before.posyaw).end_object();
    j.key("ape_after").begin_object(Layout::kInline).member("se3", after.se3).member("posyaw", after.posyaw).end_object();
    j.member("initial_cost", s.initial_cost).member("final_cost", s.final_cost);
    j.member("iterations", s.iterations).member("solve_time_s", s.solve_time_s);
    j.end_object().finish();
  } else {
    std::printf("APE = position RMSE [m] against ground truth after SE(3) or 4-DoF (position + yaw) alignment.\n");
    std::printf("Pose graph: %s.\n", o.dof == 6 ? "6-DoF (SE(3): every direction free, --dof 6)"
                                                 : "4-DoF (x, y, z, yaw; roll and pitch held, --dof 4)");
    if (o.oracle) std::printf("Loop edges: ORACLE from ground-truth revisits (evaluates the optimiser, not a detector).\n");
    std::printf("\n%-22s %7s %6s %9s %15s %9s %18s %9s %11s %12s\n", "input", "frames", "loops", "outliers",
                "APE se3 before", "after", "APE posyaw before", "after", "iterations", "solve_time_s");
    std::printf("%-22s %7zu %6zu %9d %15.3f %9.3f %18.3f %9.3f %11d %12.3f\n", name.c_str(), odo_up.size(), good_loops,
                outliers, before.se3, after.se3, before.posyaw, after.posyaw, s.iterations, s.solve_time_s);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return posefuse::apps::run_main(argc, argv, [](const posefuse::apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

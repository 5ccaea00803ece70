// g2o 2-D files and 4-DoF loop edges: round trips, file:line errors, the
// planar graph's optimum, one real file, and optimize_pose_graph end to end.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <limits>

#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/io/g2o.hpp>
#include <posefuse/io/g2o_se3.hpp>

#include "support/data_path.hpp"
#include "support/run_program.hpp"
#include "support/temp_dir.hpp"

using namespace posefuse;
using posefuse::test::TempDir;

namespace {

std::filesystem::path write_text(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::filesystem::path p = dir.path() / name;
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST_CASE("g2o: a 2-D file reads, writes and reads back exactly", "[graph][g2o]") {
  TempDir dir("g2o");
  const auto in = write_text(dir, "a.g2o",
                             "# comment\n"
                             "VERTEX_SE2 0 0 0 0\n"
                             "VERTEX_SE2 1 1.0000000000000002 -0.5 3.1\n"
                             "VERTEX_SE2 7 2 1e-300 -3.14159\n"
                             "FIX 0\n"
                             "EDGE_SE2 0 1 1 0.1 0.2 10 1 0.5 20 -0.25 30\n"
                             "EDGE_SE2 1 7 0.3 0.4 -1 1 0 0 1 0 1\n");
  const G2oGraph2d g = read_g2o_2d(in);
  REQUIRE(g.vertices.size() == 3);
  REQUIRE(g.edges.size() == 2);
  CHECK(g.fixed == std::vector<std::int64_t>{0});
  CHECK(g.vertices[2].id == 7);
  CHECK(g.vertices[1].x == 1.0000000000000002);
  // Upper triangle, row by row: xx xy xt yy yt tt.
  CHECK(g.edges[0].information(0, 1) == 1.0);
  CHECK(g.edges[0].information(1, 0) == 1.0);
  CHECK(g.edges[0].information(0, 2) == 0.5);
  CHECK(g.edges[0].information(1, 1) == 20.0);
  CHECK(g.edges[0].information(1, 2) == -0.25);
  CHECK(g.edges[0].information(2, 2) == 30.0);
  const auto out = dir.path() / "b.g2o";
  write_g2o_2d(out, g);
  const G2oGraph2d h = read_g2o_2d(out);
  REQUIRE(h.vertices.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(h.vertices[k].id == g.vertices[k].id);
    CHECK(h.vertices[k].x == g.vertices[k].x);
    CHECK(h.vertices[k].y == g.vertices[k].y);
    CHECK(h.vertices[k].theta == g.vertices[k].theta);
  }
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(h.edges[k].from == g.edges[k].from);
    CHECK(h.edges[k].dtheta == g.edges[k].dtheta);
    CHECK(h.edges[k].information == g.edges[k].information);
  }
  CHECK(h.fixed == g.fixed);
}

TEST_CASE("g2o: 4-DoF loop edges round-trip", "[graph][g2o]") {
  TempDir dir("loops");
  LoopEdge4DofRecord e;
  e.from = 3;
  e.to = 250;
  e.dp = Eigen::Vector3d(0.1, -2.5, 1e-17);
  e.dyaw = -3.0;
  e.information << 4, 1, 0, 0.5, 1, 5, 0, 0, 0, 0, 6, 0, 0.5, 0, 0, 7;
  const auto p = dir.path() / "loops.txt";
  write_loop_edges_4dof(p, {e, e});
  const std::vector<LoopEdge4DofRecord> r = read_loop_edges_4dof(p);
  REQUIRE(r.size() == 2);
  CHECK(r[1].from == 3);
  CHECK(r[1].to == 250);
  CHECK(r[1].dp == e.dp);
  CHECK(r[1].dyaw == e.dyaw);
  CHECK(r[1].information == e.information);
}

TEST_CASE("g2o: malformed lines name file:line", "[graph][g2o]") {
  TempDir dir("bad");
  const auto expect = [&](const std::string& text, const std::string& where, const std::string& what) {
    const auto p = write_text(dir, "bad.g2o", text);
    CHECK_THROWS_WITH(read_g2o_2d(p), Catch::Contains(p.string() + ":" + where) && Catch::Contains(what));
  };
  expect("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0\n", "2:", "expects 4 fields");
  expect("VERTEX_SE2 0 0 0 0\n\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 x\n", "3:", "cannot parse 'x' in column 12");
  expect("VERTEX_SE2 0.5 0 0 0\n", "1:", "node id");
  expect("VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\n", "2:", "unsupported g2o tag 'VERTEX_XY'");
  expect("VERTEX_SE2 0 0 0 nan\n", "1:", "non-finite");
  expect("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 2 0 1 0 1\n", "2:", "not positive semi-definite");
  expect("VERTEX_SE2 4 0 0 0\nVERTEX_SE2 5 1 0 0\n# again\nVERTEX_SE2 4 2 0 0\n", "4:",
         "duplicate vertex id 4 (first defined on line 1)");
  expect("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 1 1 0 0 0 1 0 0 1 0 1\n", "3:",
         "edge from vertex 1 to itself");
  // An edge may come before its vertices; a vertex no line defines is
  // reported at the (first) line that names it, once the file is read.
  expect("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nVERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n"
         "EDGE_SE2 1 7 1 0 0 1 0 0 1 0 1\n",
         "4:", "vertex id 7 is not defined by any VERTEX_SE2 line");
  expect("VERTEX_SE2 0 0 0 0\nFIX 0 3\n", "2:", "vertex id 3 is not defined");
  CHECK_NOTHROW(read_g2o_2d(write_text(dir, "late.g2o",
                                       "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nFIX 1\nVERTEX_SE2 0 0 0 0\n"
                                       "VERTEX_SE2 1 1 0 0\n")));
  const auto self = write_text(dir, "self.txt", "3 3 1 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
  CHECK_THROWS_WITH(read_loop_edges_4dof(self),
                    Catch::Contains(self.string() + ":1:") && Catch::Contains("loop edge from node 3 to itself"));
  const auto empty = write_text(dir, "empty.g2o", "# nothing\n");
  CHECK_THROWS_WITH(read_g2o_2d(empty), Catch::Contains("no VERTEX_SE2"));
  const auto loops = write_text(dir, "loops.txt", "0 1 1 0 0 0 1 0 0 0 1 0 0 1 0 1\n0 1 1 0 0\n");
  CHECK_THROWS_WITH(read_loop_edges_4dof(loops), Catch::Contains(loops.string() + ":2:") &&
                                                    Catch::Contains("expected 16 fields"));
  CHECK_THROWS_AS(read_g2o_2d(dir.path() / "missing.g2o"), io_error);
}

TEST_CASE("g2o: a planar graph gives the hand-computed optimum", "[graph][g2o]") {
  // Node 1 measured from the fixed node 0 at x = 1 (information 1) and at
  // x = 3 (information 3), with a heading of 0.2 rad both times: x = 2.5,
  // chi2 = 1 * 1.5^2 + 3 * 0.5^2 = 3, y = 0, theta = 0.2.
  TempDir dir("planar");
  const auto p = write_text(dir, "two.g2o",
                            "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 5 5 1\n"
                            "EDGE_SE2 0 1 1 0 0.2 1 0 0 1 0 1\n"
                            "EDGE_SE2 0 1 3 0 0.2 3 0 0 3 0 3\n");
  PoseGraph4Dof graph = pose_graph_from_g2o(read_g2o_2d(p));
  graph.initialize_rotation_first();
  PoseGraphOptions o;
  o.function_tolerance = 0.0;
  o.parameter_tolerance = 0.0;
  o.gradient_tolerance = 0.0;
  const PoseGraphSummary s = graph.optimize(o);
  CHECK(graph.pose(1).p.x() == Approx(2.5).margin(1e-12));
  CHECK(graph.pose(1).p.y() == Approx(0.0).margin(1e-12));
  CHECK(graph.pose(1).yaw == Approx(0.2).margin(1e-12));
  CHECK(s.final_cost == Approx(3.0).epsilon(1e-12));
  const G2oGraph2d out = with_graph_poses(read_g2o_2d(p), graph);
  CHECK(out.vertices[1].x == graph.pose(1).p.x());
}

TEST_CASE("g2o: a graph without vertices is not written (the reader refuses such a file); one without edges "
          "reads back", "[graph][g2o]") {
  TempDir dir("empty");
  const auto p2 = dir.path() / "empty2.g2o";
  const auto p3 = dir.path() / "empty3.g2o";
  CHECK_THROWS_AS(write_g2o_2d(p2, G2oGraph2d{}), invalid_argument);
  CHECK_THROWS_WITH(write_g2o_2d(p2, G2oGraph2d{}),
                    Catch::Contains("write_g2o_2d: the graph has no vertex") && Catch::Contains(p2.string()));
  CHECK_THROWS_WITH(write_g2o_3d(p3, G2oGraph3d{}),
                    Catch::Contains("write_g2o_3d: the graph has no vertex") && Catch::Contains(p3.string()));
  CHECK_FALSE(std::filesystem::exists(p2));
  CHECK_FALSE(std::filesystem::exists(p3));
  // Vertices (one fixed) and no edge: what is written reads back.
  G2oGraph2d g;
  g.vertices.push_back({5, 1.5, -2.0, 0.25, 0});
  g.fixed.push_back(5);
  write_g2o_2d(p2, g);
  const G2oGraph2d h = read_g2o_2d(p2);
  REQUIRE(h.vertices.size() == 1);
  CHECK(h.vertices[0].id == 5);
  CHECK(h.vertices[0].theta == 0.25);
  CHECK(h.fixed == g.fixed);
  CHECK(h.edges.empty());
  G2oGraph3d G;
  G.vertices.push_back({9, Eigen::Vector3d(1, 2, 3), Eigen::Quaterniond::Identity(), 0});
  write_g2o_3d(p3, G);
  const G2oGraph3d H = read_g2o_3d(p3);
  REQUIRE(H.vertices.size() == 1);
  CHECK(H.vertices[0].t == G.vertices[0].t);
}

TEST_CASE("PoseGraphOptions: NaN, infinite or negative tolerances and damping, and max_iterations < 1, are refused "
          "naming the option, before any work", "[graph][g2o][validation]") {
  TempDir dir("options");
  const auto p = write_text(dir, "two.g2o",
                            "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 5 5 1\n"
                            "EDGE_SE2 0 1 1 0 0.2 1 0 0 1 0 1\n");
  PoseGraph4Dof graph = pose_graph_from_g2o(read_g2o_2d(p));
  PoseGraphSE3 graph3;
  graph3.add_node(0, SE3d());
  graph3.add_node(1, SE3d(Eigen::Vector3d(5, 5, 0), SO3d()));
  EdgeSE3 e3;
  e3.from = 0;
  e3.to = 1;
  e3.measurement = SE3d(Eigen::Vector3d(1, 0, 0), SO3d());
  graph3.add_edge(e3);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  using Field = double PoseGraphOptions::*;
  const std::pair<Field, const char*> fields[] = {{&PoseGraphOptions::function_tolerance, "function_tolerance"},
                                                  {&PoseGraphOptions::gradient_tolerance, "gradient_tolerance"},
                                                  {&PoseGraphOptions::parameter_tolerance, "parameter_tolerance"},
                                                  {&PoseGraphOptions::initial_lambda, "initial_lambda"}};
  for (const auto& [field, name] : fields) {
    for (const double bad : {nan, -1e-5, inf, -inf}) {
      for (const bool lm : {true, false}) {
        PoseGraphOptions o;
        o.levenberg_marquardt = lm;
        o.*field = bad;
        INFO(name << " = " << bad << (lm ? " (lm)" : " (gn)"));
        CHECK_THROWS_WITH(o.validate(), Catch::Contains(std::string("PoseGraphOptions: ") + name +
                                                        " must be finite and >= 0, got "));
        CHECK_THROWS_AS(graph.optimize(o), invalid_argument);
        CHECK_THROWS_AS(graph3.optimize(o), invalid_argument);
        CHECK(graph.pose(1).p.x() == 5.0);  // untouched
        CHECK(graph3.pose(1).translation().x() == 5.0);
      }
    }
  }
  PoseGraphOptions o;
  o.initial_lambda = nan;
  CHECK_THROWS_WITH(o.validate(), Catch::EndsWith("got nan"));
  o.initial_lambda = -1e-5;
  CHECK_THROWS_WITH(o.validate(), Catch::EndsWith("got -1e-05"));
  o = PoseGraphOptions{};
  o.max_iterations = 0;
  CHECK_THROWS_WITH(graph.optimize(o), "PoseGraphOptions: max_iterations must be >= 1, got 0");
  // Zero tolerances and zero damping are settings, not errors.
  o = PoseGraphOptions{};
  o.function_tolerance = o.gradient_tolerance = o.parameter_tolerance = o.initial_lambda = 0.0;
  CHECK_NOTHROW(o.validate());
  CHECK(graph.optimize(o).final_cost < 1e-20);
  CHECK(graph3.optimize(o).final_cost < 1e-20);
}

TEST_CASE("g2o: MIT Killian Court converges from the rotation-first start", "[graph][g2o][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "posegraph");
  PoseGraph4Dof graph = pose_graph_from_g2o(read_g2o_2d(dir / "input_MITb_g2o.g2o"));
  CHECK(graph.num_nodes() == 808);
  CHECK(graph.num_edges() == 827);
  graph.initialize_rotation_first();
  const PoseGraphSummary s = graph.optimize();
  INFO("chi2 " << s.final_cost << " after " << s.iterations << " iterations, " << to_string(s.termination));
  CHECK(s.termination == Termination::kFunctionTolerance);
  CHECK(s.final_cost < 41.2);  // docs/pose-graph.md: 41.163 (from the file's poses LM stalls above 2000)
  CHECK(s.planar);
}

TEST_CASE("g2o: the planar path equals the 4-DoF path on the real files", "[graph][g2o][data][planar]") {
  POSEFUSE_REQUIRE_DATASET(dir, "posegraph");
  for (const char* name : {"input_MITb_g2o.g2o", "manhattanOlson3500.g2o"}) {
    INFO(name);
    const G2oGraph2d file = read_g2o_2d(dir / name);
    PoseGraph4Dof a = pose_graph_from_g2o(file);
    a.initialize_rotation_first();
    PoseGraph4Dof b = a;
    PoseGraphOptions general;
    general.planar_fast_path = false;
    const PoseGraphSummary sa = a.optimize();
    const PoseGraphSummary sb = b.optimize(general);
    INFO("planar " << sa.final_cost << " in " << sa.iterations << ", 4-DoF " << sb.final_cost << " in "
                   << sb.iterations);
    CHECK(sa.planar);
    CHECK_FALSE(sb.planar);
    CHECK(sa.iterations == sb.iterations);
    CHECK(sa.final_cost == Approx(sb.final_cost).epsilon(1e-12));
    double worst = 0.0;
    for (std::size_t k = 0; k < a.num_nodes(); ++k)
      worst = std::max({worst, (a.poses()[k].p - b.poses()[k].p).norm(),
                        std::abs(wrap_angle(a.poses()[k].yaw - b.poses()[k].yaw))});
    INFO("largest pose difference " << worst);
    CHECK(worst < 1e-10);  // measured 1.1e-11 (MIT, coordinates up to 249 m), 1.5e-13 (Manhattan)
  }
}

TEST_CASE("optimize_pose_graph: built-in graph, JSON, --out and errors", "[graph][examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "optimize_pose_graph");
  TempDir dir("optimize");
  const auto r = posefuse::test::run(exe, "--json", dir);
  REQUIRE(r.status == 0);
  const posefuse::test::Json j = posefuse::test::Json::parse(r.out);
  CHECK(j["nodes"].number() == 2000);
  CHECK(j["final_cost"].number() < j["initial_cost"].number());
  CHECK(j["iterations"].number() >= 1);
  CHECK(j["solve_time_s"].number() > 0);

  const auto g = write_text(dir, "g.g2o",
                            "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 5 5 1\nVERTEX_SE2 2 0 0 0\n"
                            "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nEDGE_SE2 1 2 0 1 0 1 0 0 1 0 1\n"
                            "EDGE_SE2 0 2 1 1 0 1 0 0 1 0 1\n");
  const auto gt = write_text(dir, "gt.txt", "0 0 0\n1 0 0\n1 1 0\n");
  const auto out = dir.path() / "opt.g2o";
  const auto ok = posefuse::test::run(
      exe, "--input '" + g.string() + "' --groundtruth '" + gt.string() + "' --json --out '" + out.string() + "'",
      dir);
  REQUIRE(ok.status == 0);
  const posefuse::test::Json k = posefuse::test::Json::parse(ok.out);
  CHECK(k["final_cost"].number() < 1e-12);
  CHECK(k["rmse"].number() < 1e-6);
  CHECK(read_g2o_2d(out).vertices[2].x == Approx(1.0).margin(1e-6));
  CHECK(read_g2o_2d(out).vertices[2].y == Approx(1.0).margin(1e-6));

  const auto bad = write_text(dir, "bad.g2o", "VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n");
  const auto missing = posefuse::test::run(exe, "--input '" + bad.string() + "'", dir);
  CHECK(missing.status == 1);
  CHECK_THAT(missing.err, Catch::Contains(bad.string() + ":2: vertex id 1 is not defined"));
  const auto split = write_text(dir, "split.g2o", "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n");
  const auto disconnected = posefuse::test::run(exe, "--input '" + split.string() + "'", dir);
  CHECK(disconnected.status == 1);
  CHECK_THAT(disconnected.err, Catch::Contains("disconnected") && Catch::Contains("ids 1"));
  CHECK(posefuse::test::run(exe, "--init nope", dir).status == 2);
}

TEST_CASE("pose_graph_correction: built-in drive, robust loss, loop file and errors", "[graph][examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "pose_graph_correction");
  TempDir dir("correction");
  const auto r = posefuse::test::run(exe, "--json --svg '" + (dir.path() / "g.svg").string() + "'", dir);
  REQUIRE(r.status == 0);
  const posefuse::test::Json j = posefuse::test::Json::parse(r.out);
  CHECK(j["outliers"].number() == 5);
  const double before = j["ape_before"]["se3"].number();
  const double after = j["ape_after"]["se3"].number();
  INFO("APE before " << before << " m, after " << after << " m");
  CHECK(after < 0.2 * before);  // built-in drive: 1.79 m -> 0.12 m
  CHECK(j["ape_after"]["posyaw"].number() < 0.2 * j["ape_before"]["posyaw"].number());
  CHECK(std::filesystem::file_size(dir.path() / "g.svg") > 1000);
  // Without a robust loss the 5 false loops ruin the result.
  const auto plain = posefuse::test::run(exe, "--json --robust none", dir);
  REQUIRE(plain.status == 0);
  CHECK(posefuse::test::Json::parse(plain.out)["ape_after"]["se3"].number() > before);

  // A loop file on a small KITTI-format odometry, and one naming a missing pose.
  std::string odo, gt;
  for (int k = 0; k < 30; ++k) {
    const double a = 0.2 * k;
    const std::string row = "1 0 0 " + std::to_string(10 * std::sin(a)) + " 0 1 0 0 0 0 1 " +
                            std::to_string(10 * std::cos(a)) + "\n";
    gt += row;
    odo += row;
  }
  const auto odo_file = write_text(dir, "odo.txt", odo);
  const auto gt_file = write_text(dir, "gt.txt", gt);
  const auto loops = write_text(dir, "loops.txt", "0 29 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
  const auto ok = posefuse::test::run(exe, "--odometry '" + odo_file.string() + "' --groundtruth '" + gt_file.string() +
                                               "' --loops '" + loops.string() + "'",
                                      dir);
  CHECK(ok.status == 0);
  const auto bad_loops = write_text(dir, "bad.txt", "0 99 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
  const auto bad = posefuse::test::run(exe, "--odometry '" + odo_file.string() + "' --groundtruth '" +
                                                gt_file.string() + "' --loops '" + bad_loops.string() + "'",
                                       dir);
  CHECK(bad.status == 1);
  CHECK_THAT(bad.err, Catch::Contains("bad.txt:1: node 99 is not a frame of the odometry"));
  CHECK(posefuse::test::run(exe, "--oracle-loops", dir).status == 2);
}

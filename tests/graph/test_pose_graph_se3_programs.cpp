// SE(3) pose graphs end to end: the parking garage from the chordal start,
// optimize_pose_graph on 3-D files, and pose_graph_correction --dof 6.

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/io/g2o_se3.hpp>
#include <posefuse/sim/pose_graph_se3.hpp>

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

/// A simulated 3-D graph as a g2o file (the odometry's poses as vertices).
std::filesystem::path write_sim_graph(const TempDir& dir, const std::string& name) {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 150;
  c.lap = 50;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  G2oGraph3d g;
  for (std::size_t k = 0; k < pr.initial.size(); ++k)
    g.vertices.push_back({std::int64_t(k), pr.initial[k].translation(), pr.initial[k].so3().quaternion(), 0});
  for (const EdgeSE3& e : pr.edges)
    g.edges.push_back({e.from, e.to, e.measurement.translation(), e.measurement.so3().quaternion(), e.information, 0});
  const std::filesystem::path p = dir.path() / name;
  write_g2o_3d(p, g);
  return p;
}


/// Writes poses as KITTI lines (the 3x4 [R | t] row by row).
std::filesystem::path write_kitti(const TempDir& dir, const std::string& name, const std::vector<SE3d>& poses) {
  const std::filesystem::path p = dir.path() / name;
  std::ofstream out(p);
  out.precision(17);
  for (const SE3d& x : poses) {
    const Eigen::Matrix3d R = x.so3().matrix();
    for (int r = 0; r < 3; ++r)
      out << R(r, 0) << ' ' << R(r, 1) << ' ' << R(r, 2) << ' ' << x.translation()(r) << (r < 2 ? ' ' : '\n');
  }
  return p;
}

}  // namespace

TEST_CASE("g2o 3-D: the parking garage reads, and its chordal start lands near the optimum",
          "[graph][g2o][se3][data]") {
  POSEFUSE_REQUIRE_DATASET(dir, "posegraph");
  const G2oGraph3d file = read_g2o_3d(dir / "parking-garage.g2o");
  PoseGraphSE3 g = pose_graph_from_g2o(file);
  CHECK(g.num_nodes() == 1661);
  CHECK(g.num_edges() == 6275);
  CHECK(g.cost() == Approx(16720.0).epsilon(1e-4));  // g2o's chi2 at the file's poses (Ceres: 8360, half)
  g.initialize_chordal();
  // The optimum, 1.23869058, is reached from here in 28 LM iterations and
  // from the file's poses in 30 (docs/pose-graph.md; too slow for a test
  // under the sanitizers): the start is within 14 % of it.
  CHECK(g.cost() == Approx(1.41041).epsilon(1e-5));
  PoseGraphOptions o;
  o.max_iterations = 2;
  const PoseGraphSummary s = g.optimize(o);
  CHECK(s.final_cost < s.initial_cost);
  CHECK(s.final_cost > 1.23869);
}

TEST_CASE("optimize_pose_graph: a 3-D file is detected, solved in SE(3) and written back", "[graph][se3][examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "optimize_pose_graph");
  TempDir dir("optimize3d");
  const auto in = write_sim_graph(dir, "sim.g2o");
  const auto out = dir.path() / "opt.g2o";
  double first = -1.0;
  for (const char* init : {"chordal", "file"}) {
    INFO(init);
    const auto r = posefuse::test::run(
        exe, "--input '" + in.string() + "' --init " + init + " --json --out '" + out.string() + "'", dir);
    REQUIRE(r.status == 0);
    const posefuse::test::Json j = posefuse::test::Json::parse(r.out);
    CHECK(j["dof"].number() == 6);
    CHECK(j["init"].string() == init);
    CHECK(j["final_cost"].number() < 0.1 * j["file_cost"].number());  // measured 150.5 from 2120
    if (first < 0) first = j["final_cost"].number();
    CHECK(j["final_cost"].number() == Approx(first).epsilon(1e-8));
    // The written file holds the optimum: its cost is the reported one.
    CHECK(pose_graph_from_g2o(read_g2o_3d(out)).cost() == Approx(j["final_cost"].number()).epsilon(1e-9));
  }
  const auto table = posefuse::test::run(exe, "--input '" + in.string() + "'", dir);
  REQUIRE(table.status == 0);
  CHECK_THAT(table.out, Catch::Contains("solved in SE(3)") && Catch::Contains("chordal"));

  const auto bad = write_text(dir, "bad.g2o", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 0.5\n");
  const auto r = posefuse::test::run(exe, "--input '" + bad.string() + "'", dir);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains(bad.string() + ":2: the quaternion is not unit"));
  const auto split = write_text(dir, "split.g2o", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n");
  const auto disconnected = posefuse::test::run(exe, "--input '" + split.string() + "'", dir);
  CHECK(disconnected.status == 1);
  CHECK_THAT(disconnected.err, Catch::Contains("disconnected") && Catch::Contains("ids 1"));
  CHECK(posefuse::test::run(exe, "--input '" + in.string() + "' --groundtruth '" + in.string() + "'", dir).status == 2);
}

TEST_CASE("pose_graph_correction: --dof 6 corrects in SE(3) and says so", "[graph][se3][examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "pose_graph_correction");
  TempDir dir("correction6");
  // 300 poses, six laps of a banked track; the odometry drifts in all six
  // directions (0.5 deg of rotation noise per axis and step).
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 300;
  c.lap = 50;
  c.sigma_odo_r = 0.5 * M_PI / 180.0;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  const auto gt = write_kitti(dir, "gt.txt", pr.truth);
  const auto odo = write_kitti(dir, "odo.txt", pr.initial);
  const std::string files = "--odometry '" + odo.string() + "' --groundtruth '" + gt.string() + "' --up z --oracle-loops";
  double ape_after[2] = {0.0, 0.0};
  for (const int dof : {4, 6}) {
    const auto r = posefuse::test::run(exe, files + " --dof " + std::to_string(dof) + " --json", dir);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const posefuse::test::Json j = posefuse::test::Json::parse(r.out);
    CHECK(j["dof"].number() == dof);
    CHECK(j["loops"].number() > 20);
    ape_after[dof == 6] = j["ape_after"]["se3"].number();
    INFO("dof " << dof << ": APE " << j["ape_before"]["se3"].number() << " -> " << ape_after[dof == 6]);
    CHECK(ape_after[dof == 6] < j["ape_before"]["se3"].number());
  }
  INFO("APE after: 4-DoF " << ape_after[0] << " m, 6-DoF " << ape_after[1] << " m");
  // Roll and pitch drift here, which only the SE(3) graph can move
  // (measured 0.362 m against 0.248 m).
  CHECK(ape_after[1] < 0.8 * ape_after[0]);
  const auto table = posefuse::test::run(exe, files + " --dof 6", dir);
  REQUIRE(table.status == 0);
  CHECK_THAT(table.out, Catch::Contains("Pose graph: 6-DoF"));
  const auto four = posefuse::test::run(exe, files, dir);
  REQUIRE(four.status == 0);
  CHECK_THAT(four.out, Catch::Contains("Pose graph: 4-DoF"));
  CHECK(posefuse::test::run(exe, "--dof 5", dir).status == 2);
  const auto loops = write_text(dir, "loops.txt", "0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
  const auto refused = posefuse::test::run(
      exe, "--dof 6 --odometry '" + odo.string() + "' --groundtruth '" + gt.string() + "' --loops '" + loops.string() + "'",
      dir);
  CHECK(refused.status == 2);
  CHECK_THAT(refused.err, Catch::Contains("--dof 6 use --oracle-loops"));
}

TEST_CASE("optimize_pose_graph reads a named pipe once when it detects the format", "[graph][se3][examples]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "optimize_pose_graph");
  TempDir dir("optimize_fifo");
  const auto in = write_sim_graph(dir, "sim.g2o");
  const auto bad = write_text(dir, "bad.g2o", "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nEDGE_SE3:QUAT 0 0\n");
  for (const auto& file : {in, bad}) {
    const std::filesystem::path fifo = dir.path() / "graph.fifo";
    std::filesystem::remove(fifo);
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    // The writer blocks until the program opens the pipe; `timeout` ends a
    // program that would open it a second time and wait forever.
    const std::string writer = "cat '" + file.string() + "' > '" + fifo.string() + "' &";
    REQUIRE(std::system(writer.c_str()) == 0);
    const auto r = posefuse::test::run("/usr/bin/timeout", "20 '" + exe.string() + "' --input '" + fifo.string() + "' --json", dir);
    const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // unblocks a writer never read
    if (fd >= 0) ::close(fd);
    INFO(r.err);
    if (file == in) {
      REQUIRE(r.status == 0);
      const posefuse::test::Json j = posefuse::test::Json::parse(r.out);
      CHECK(j["dof"].number() == 6);
      CHECK(j["input"].string() == "graph.fifo");
    } else {
      CHECK(r.status == 1);
      // The message names the pipe as given, not the program's copy of it.
      CHECK_THAT(r.err, Catch::Contains(fifo.string() + ":2: EDGE_SE3:QUAT expects 30 fields"));
    }
  }
}

// g2o 3-D files: round trips, file:line errors for bad files, format
// detection, and the graph built from a file.

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <posefuse/graph/g2o_graph.hpp>
#include <posefuse/io/g2o_se3.hpp>

#include "support/temp_dir.hpp"

using namespace posefuse;
using posefuse::test::TempDir;

namespace {

std::filesystem::path write_text(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::filesystem::path p = dir.path() / name;
  std::ofstream(p) << text;
  return p;
}

const char* const kUnitInfo = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";

}  // namespace

TEST_CASE("g2o 3-D: a file reads, writes and reads back", "[io][g2o][se3]") {
  TempDir dir("g2o3d");
  const auto in = write_text(dir, "a.g2o",
                             std::string("# a comment\n"
                                         "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n"
                                         "VERTEX_SE3:QUAT 1 1.5 -0.25 0.125 0.0998334 0 0 0.995004\n"
                                         "\n"
                                         "FIX 0\n"
                                         "EDGE_SE3:QUAT 0 1 1.5 -0.25 0.125 0 0 0.0499792 0.99875") +
                                 " 100 1 2 3 4 5 100 6 7 8 9 100 10 11 12 100 13 14 200 15 200\n");
  const G2oGraph3d g = read_g2o_3d(in);
  REQUIRE(g.vertices.size() == 2);
  REQUIRE(g.edges.size() == 1);
  REQUIRE(g.fixed.size() == 1);
  CHECK(g.vertices[1].id == 1);
  CHECK(g.vertices[1].t == Eigen::Vector3d(1.5, -0.25, 0.125));
  CHECK(g.vertices[1].q.norm() == Approx(1.0).epsilon(1e-15));
  CHECK(g.vertices[1].line == 3);
  CHECK(g.edges[0].information(0, 1) == 1.0);
  CHECK(g.edges[0].information(1, 0) == 1.0);
  CHECK(g.edges[0].information(4, 5) == 15.0);
  CHECK(g.edges[0].information(5, 5) == 200.0);
  CHECK(g.edges[0].line == 6);
  CHECK(g2o_dimension(in) == 3);

  const auto out = dir.path() / "b.g2o";
  write_g2o_3d(out, g);
  const G2oGraph3d h = read_g2o_3d(out);
  REQUIRE(h.vertices.size() == 2);
  REQUIRE(h.edges.size() == 1);
  CHECK(h.fixed == g.fixed);
  for (std::size_t k = 0; k < 2; ++k) {
    CHECK(h.vertices[k].t == g.vertices[k].t);
    // Normalising a unit quaternion again moves it by at most an ulp.
    CHECK((h.vertices[k].q.coeffs() - g.vertices[k].q.coeffs()).cwiseAbs().maxCoeff() <= 2.3e-16);
  }
  CHECK(h.edges[0].t == g.edges[0].t);
  CHECK(h.edges[0].information == g.edges[0].information);
  CHECK((h.edges[0].q.coeffs() - g.edges[0].q.coeffs()).cwiseAbs().maxCoeff() <= 2.3e-16);

  // The graph: node 0 fixed, the edge's cost at the file's poses by hand.
  PoseGraphSE3 graph = pose_graph_from_g2o(g);
  CHECK(graph.is_fixed(0));
  CHECK_FALSE(graph.is_fixed(1));
  const Vector6d e = edge_error_se3(graph.pose(0), graph.pose(1), graph.edges()[0].measurement);
  CHECK(graph.cost() == Approx(e.dot(g.edges[0].information * e)).epsilon(1e-14));
  // The measurement differs from the poses by 0.1 rad about x and -0.1 rad about z.
  CHECK(e.head<3>().norm() < 1e-12);
  (void)graph.optimize();
  const G2oGraph3d moved = with_graph_poses(g, graph);
  CHECK(moved.vertices[1].t.isApprox(graph.pose(1).translation()));
}

TEST_CASE("g2o 3-D: bad files name file:line and the reason", "[io][g2o][se3]") {
  TempDir dir("g2o3d_bad");
  const std::string v0 = "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n";
  const std::string v1 = "VERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\n";
  const auto expect = [&](const std::string& text, const std::string& where, const std::string& what) {
    const auto p = write_text(dir, "bad.g2o", text);
    CHECK_THROWS_WITH(read_g2o_3d(p), Catch::Contains(p.string() + ":" + where) && Catch::Contains(what));
  };
  expect(v0 + "VERTEX_SE3:QUAT 1 0 0 0 0 0 0 0\n", "2:", "the quaternion is zero");
  expect(v0 + "VERTEX_SE3:QUAT 1 0 0 0 0 0 0 2\n", "2:", "the quaternion is not unit (norm 2");
  expect(v0 + v1 + "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 0" + kUnitInfo + "\n", "3:", "the quaternion is zero");
  expect(v0 + v1 + "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 -1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", "3:",
         "not positive semi-definite");
  expect(v0 + v1 + "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 5 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n", "3:",
         "not positive semi-definite");
  expect(v0 + v1 + "EDGE_SE3:QUAT 0 7 1 0 0 0 0 0 1" + kUnitInfo + "\n", "3:",
         "vertex id 7 is not defined by any VERTEX_SE3:QUAT line");
  expect(v0 + v1 + "EDGE_SE3:QUAT 1 1 1 0 0 0 0 0 1" + kUnitInfo + "\n", "3:", "edge from vertex 1 to itself");
  expect(v0 + v1 + "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0\n", "3:", "EDGE_SE3:QUAT expects 30 fields");
  expect(v0 + "VERTEX_SE3:QUAT 0 1 0 0 0 0 0 1\n", "2:", "duplicate vertex id 0 (first defined on line 1)");
  expect(v0 + "VERTEX_SE3:QUAT 1 nan 0 0 0 0 0 1\n", "2:", "non-finite value 'nan'");
  expect(v0 + "VERTEX_SE2 1 0 0 0\n", "2:", "unsupported g2o tag 'VERTEX_SE2'");
  expect(v0 + "FIX 3\n", "2:", "vertex id 3 is not defined");
  const auto empty = write_text(dir, "empty.g2o", "# nothing\n");
  CHECK_THROWS_WITH(read_g2o_3d(empty), Catch::Contains("no VERTEX_SE3:QUAT"));
  CHECK_THROWS_WITH(g2o_dimension(empty), Catch::Contains("no vertex or edge line"));
  CHECK_THROWS_AS(read_g2o_3d(dir.path() / "missing.g2o"), io_error);
}

TEST_CASE("g2o: the format is detected from the first vertex or edge line", "[io][g2o][se3]") {
  TempDir dir("g2o_dim");
  CHECK(g2o_dimension(write_text(dir, "a.g2o", "# c\nFIX 0\nVERTEX_SE2 0 0 0 0\n")) == 2);
  CHECK(g2o_dimension(write_text(dir, "b.g2o", "\nEDGE_SE3:QUAT 0 1 0 0 0 0 0 0 1\n")) == 3);
  CHECK_THROWS_WITH(g2o_dimension(write_text(dir, "c.g2o", "VERTEX_XYZ 0 0 0 0\n")),
                    Catch::Contains("c.g2o:1") && Catch::Contains("unsupported g2o tag 'VERTEX_XYZ'"));
}

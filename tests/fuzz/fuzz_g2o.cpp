// libFuzzer harness: g2o 2-D files and 4-DoF loop-edge files (io/g2o.hpp).
//
// Input: the first byte chooses the reader (even: read_g2o_2d, odd:
// read_loop_edges_4dof), the rest is the file. Expected rejection:
// posefuse::io_error naming the file. Properties of an accepted file: every
// number is finite, every information matrix symmetric, every edge joins two
// different nodes (2-D: nodes a VERTEX_SE2 line defines), and the writer +
// reader give back the same values bit for bit.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_set>

#include <posefuse/core/error.hpp>
#include <posefuse/io/g2o.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;
using posefuse_fuzz::same_number;

template <class M>
bool same_matrix(const M& a, const M& b) {
  for (Eigen::Index r = 0; r < a.rows(); ++r)
    for (Eigen::Index c = 0; c < a.cols(); ++c)
      if (!same_number(a(r, c), b(r, c))) return false;
  return true;
}

void graph_2d(const std::filesystem::path& file, const std::filesystem::path& file2) {
  posefuse::G2oGraph2d g;
  try {
    g = posefuse::read_g2o_2d(file);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "read_g2o_2d: io_error without a file name");
    return;
  }
  require(!g.vertices.empty(), "read_g2o_2d accepted a graph without vertices");
  std::unordered_set<std::int64_t> ids;
  for (const auto& v : g.vertices) {
    require(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.theta),
            "read_g2o_2d: a vertex is not finite");
    require(ids.insert(v.id).second, "read_g2o_2d accepted a vertex id twice");
  }
  for (const auto& e : g.edges) {
    require(e.from != e.to, "read_g2o_2d accepted an edge from a vertex to itself");
    require(ids.count(e.from) == 1 && ids.count(e.to) == 1, "read_g2o_2d accepted an edge to no vertex");
    require(std::isfinite(e.dx) && std::isfinite(e.dy) && std::isfinite(e.dtheta) &&
                e.information.allFinite() && e.information == e.information.transpose(),
            "read_g2o_2d: an edge is not finite or its information not symmetric");
  }
  for (const std::int64_t id : g.fixed) require(ids.count(id) == 1, "read_g2o_2d accepted FIX of no vertex");
  posefuse::write_g2o_2d(file2, g);
  const posefuse::G2oGraph2d back = posefuse::read_g2o_2d(file2);
  require(back.vertices.size() == g.vertices.size() && back.edges.size() == g.edges.size() &&
              back.fixed == g.fixed,
          "write_g2o_2d + read_g2o_2d changed the graph's size");
  for (std::size_t k = 0; k < g.vertices.size(); ++k) {
    const auto &a = g.vertices[k], &b = back.vertices[k];
    require(a.id == b.id && same_number(a.x, b.x) && same_number(a.y, b.y) && same_number(a.theta, b.theta),
            "write_g2o_2d + read_g2o_2d changed vertex " + std::to_string(k));
  }
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    const auto &a = g.edges[k], &b = back.edges[k];
    require(a.from == b.from && a.to == b.to && same_number(a.dx, b.dx) && same_number(a.dy, b.dy) &&
                same_number(a.dtheta, b.dtheta) && same_matrix(a.information, b.information),
            "write_g2o_2d + read_g2o_2d changed edge " + std::to_string(k));
  }
}

void loops_4dof(const std::filesystem::path& file, const std::filesystem::path& file2) {
  std::vector<posefuse::LoopEdge4DofRecord> edges;
  try {
    edges = posefuse::read_loop_edges_4dof(file);
  } catch (const posefuse::io_error& e) {
    require(!e.file().empty(), "read_loop_edges_4dof: io_error without a file name");
    return;
  }
  for (const auto& e : edges) {
    require(e.from != e.to, "read_loop_edges_4dof accepted an edge from a node to itself");
    require(e.dp.allFinite() && std::isfinite(e.dyaw) && e.information.allFinite() &&
                e.information == e.information.transpose(),
            "read_loop_edges_4dof: an edge is not finite or its information not symmetric");
  }
  posefuse::write_loop_edges_4dof(file2, edges);
  const std::vector<posefuse::LoopEdge4DofRecord> back = posefuse::read_loop_edges_4dof(file2);
  require(back.size() == edges.size(), "write + read_loop_edges_4dof changed the number of edges");
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const auto &a = edges[k], &b = back[k];
    require(a.from == b.from && a.to == b.to && same_matrix(a.dp, b.dp) && same_number(a.dyaw, b.dyaw) &&
                same_matrix(a.information, b.information),
            "write + read_loop_edges_4dof changed edge " + std::to_string(k));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const posefuse_fuzz::ScratchDir dir("g2o");
  const auto file = dir / "in.txt";
  posefuse_fuzz::write_bytes(file, std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  if (data[0] % 2 == 0) graph_2d(file, dir / "back.g2o");
  else loops_4dof(file, dir / "back.txt");
  return 0;
}

#pragma once
/// @file
/// How the pose-graph solvers see a graph (not API): its edges with the
/// indices of their end nodes, and the numbering of the free nodes as block
/// columns of the normal equations.

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include <posefuse/graph/detail/block_system.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>

namespace posefuse::detail {

/// A graph's edges as the solvers read them (references into the graph).
struct PoseGraphEdges {
  const std::vector<Edge4Dof>& edges;               ///< the measurements
  const std::vector<std::pair<int, int>>& ends;     ///< node indices (i, j) of each edge
  const std::vector<Eigen::Matrix3d>& Qt;           ///< \f$ Q_i^\top \f$ per node
};

/// The numbering of a graph's free nodes: block columns in a fill-reducing
/// (block AMD) order, fixed nodes eliminated.
struct PoseGraphLayout {
  int n = 0;                               ///< free nodes
  std::vector<int> var;                    ///< node → block column (-1 fixed)
  std::vector<std::pair<int, int>> pairs;  ///< edge → block columns of its ends
};

/// The layout of a graph with `fixed[a]` != 0 for held nodes and edges
/// between the node indices `ends`.
template <class Lazy = void>
[[nodiscard]] PoseGraphLayout make_pose_graph_layout(const std::vector<char>& fixed,
                                                     const std::vector<std::pair<int, int>>& ends) {
  PoseGraphLayout L;
  std::vector<int> free_index(fixed.size(), -1);
  for (std::size_t a = 0; a < fixed.size(); ++a)
    if (!fixed[a]) free_index[a] = L.n++;
  std::vector<std::pair<int, int>> raw;
  raw.reserve(ends.size());
  for (const auto& e : ends) raw.emplace_back(free_index[std::size_t(e.first)], free_index[std::size_t(e.second)]);
  const std::vector<int> pos = block_amd_order(L.n, raw);
  L.var.assign(fixed.size(), -1);
  for (std::size_t a = 0; a < fixed.size(); ++a)
    if (free_index[a] >= 0) L.var[a] = pos[std::size_t(free_index[a])];
  L.pairs.reserve(ends.size());
  for (const auto& e : ends) L.pairs.emplace_back(L.var[std::size_t(e.first)], L.var[std::size_t(e.second)]);
  return L;
}

}  // namespace posefuse::detail

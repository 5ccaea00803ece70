#pragma once
/// @file
/// The pose-graph solver's buffers: the block normal equations, their
/// Cholesky factor and the per-node and per-edge arrays of one solve.
///
/// Every PoseGraph4Dof owns one and keeps its capacity from one solve to the
/// next (optimize() on the same graph again allocates nothing); destroying
/// the graph, or PoseGraph4Dof::release_workspace(), frees it. A program
/// that builds and solves many graphs in turn may instead hold one
/// PoseGraphWorkspace and pass it to each solve: fresh memory is then paged
/// in once rather than for every graph. A workspace holds no result: any
/// workspace, empty or used by another graph, gives the same answer to the
/// last bit. One workspace serves one solve at a time (not two threads at
/// once).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include <posefuse/graph/detail/block_system.hpp>

namespace posefuse {

class PoseGraph4Dof;

namespace detail {

/// The optimiser's state of one node on B x B blocks: [p; yaw] (B = 4) or
/// [x, y, yaw] (B = 3, planar).
template <int B>
using NodeState = Eigen::Matrix<double, B, 1>;

/// Buffers of a solve on B x B blocks (B = 2: the rotation-first yaw
/// system, which uses only `sys` and `chol`).
template <int B>
struct SolverBuffers {
  BlockSystem<B> sys;                   ///< H and b
  BlockCholesky<B> chol;                ///< factor of (damped) H
  std::vector<NodeState<B>> x, trial;   ///< current and trial state of every node
  std::vector<double> c, s;             ///< cos / sin of each node's yaw
  std::vector<double> cm, sm;           ///< cos / sin of each edge's Δψ
  std::vector<Eigen::Matrix3d> info3;   ///< planar information (x, y, yaw) of each edge
  Eigen::VectorXd diag, delta, dx;      ///< diag(H), the damping added to it, the step

  /// Bytes of heap storage held (capacity).
  [[nodiscard]] std::size_t capacity_bytes() const noexcept {
    return sys.capacity_bytes() + chol.capacity_bytes() + sizeof(NodeState<B>) * (x.capacity() + trial.capacity()) +
           sizeof(double) * (c.capacity() + s.capacity() + cm.capacity() + sm.capacity()) +
           sizeof(Eigen::Matrix3d) * info3.capacity() +
           sizeof(double) * std::size_t(diag.size() + delta.size() + dx.size());
  }
};

}  // namespace detail

/// Buffers for PoseGraph4Dof's solvers (see the file comment). Copying a
/// workspace gives an empty one: the buffers are scratch space, not state.
class PoseGraphWorkspace {
 public:
  PoseGraphWorkspace() = default;
  /// An empty workspace (the buffers are not copied).
  PoseGraphWorkspace(const PoseGraphWorkspace& /*other*/) noexcept {}
  /// Keeps this workspace's own buffers (the other's are not copied).
  PoseGraphWorkspace& operator=(const PoseGraphWorkspace& /*other*/) noexcept { return *this; }
  PoseGraphWorkspace(PoseGraphWorkspace&&) noexcept = default;
  PoseGraphWorkspace& operator=(PoseGraphWorkspace&&) noexcept = default;
  ~PoseGraphWorkspace() = default;

  /// Bytes of heap storage the buffers hold (capacity); 0 when empty.
  [[nodiscard]] std::size_t capacity_bytes() const noexcept {
    return yaw.capacity_bytes() + planar.capacity_bytes() + general.capacity_bytes();
  }

  /// Frees every buffer (capacity_bytes() is 0 afterwards).
  void release() noexcept {
    yaw = {};
    planar = {};
    general = {};
  }

 private:
  friend class PoseGraph4Dof;

  detail::SolverBuffers<2> yaw;      ///< rotation-first yaw system
  detail::SolverBuffers<3> planar;   ///< planar LM and the rotation-first translation system
  detail::SolverBuffers<4> general;  ///< 4-DoF LM
};

}  // namespace posefuse

#pragma once
/// @file
/// A seeded 6-DoF pose-graph problem (an application helper, not library
/// API): a body flies laps of a closed, banked and climbing track of `lap`
/// nodes (roll up to 0.3 rad, pitch up to 0.25 rad, 2 m of height change);
/// sequential edges are its noisy odometry, and every `loop_every`-th node
/// of lap k > 0 gets a noisy loop edge to the node at the same place on
/// lap k - 1. The initial guess chains the noisy odometry (it drifts in all
/// six directions).
///
/// Noise (1σ, applied as Z ⊞ [σ_p n_p; σ_r n_r], pose_graph_plus): odometry
/// 2 cm per axis and 0.2° per axis, loop edges 5 cm and 0.5°. Information
/// (x, y, z, qx, qy, qz) = diag(1/σ_p², 4/σ_r²): the error's quaternion
/// part is half the rotation angle. The same seed gives the same problem
/// under g++ and clang (one random draw per statement).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse::sim {

/// The generated problem.
struct PoseGraphProblemSE3 {
  std::vector<SE3d> truth;      ///< true poses, node ids 0..n-1
  std::vector<SE3d> initial;    ///< odometry chained from the true first pose
  std::vector<EdgeSE3> edges;   ///< sequential edges first, then loop edges
  std::size_t sequential = 0;   ///< number of sequential edges
};

/// Settings of make_pose_graph_problem_se3.
struct PoseGraphProblemSE3Config {
  int nodes = 1000;        ///< n
  int lap = 100;           ///< nodes per lap of the track
  int loop_every = 4;      ///< a loop edge on every this-many-th node after the first lap
  double sigma_odo_p = 0.02, sigma_odo_r = 0.2 * std::numbers::pi / 180.0;
  double sigma_loop_p = 0.05, sigma_loop_r = 0.5 * std::numbers::pi / 180.0;
  std::uint32_t seed = 1;  ///< RNG seed
};

/// Generates the problem (see the file comment).
inline PoseGraphProblemSE3 make_pose_graph_problem_se3(const PoseGraphProblemSE3Config& c) {
  std::mt19937 rng(c.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  PoseGraphProblemSE3 pr;
  const double radius = 0.5 * c.lap / std::numbers::pi;  // ~1 m between nodes
  for (int k = 0; k < c.nodes; ++k) {
    const double s = 2.0 * std::numbers::pi * (k % c.lap) / c.lap;
    const int lap = k / c.lap;
    const double r = radius + 0.3 * std::sin(0.7 * lap);
    const Eigen::Vector3d p(r * std::cos(s), r * std::sin(s), 2.0 * std::sin(2.0 * s));
    const double yaw = s + std::numbers::pi / 2;
    const double roll = 0.3 * std::sin(3.0 * s) + 0.02 * n01(rng);
    const double pitch = 0.25 * std::cos(2.0 * s);
    pr.truth.emplace_back(p, SO3d(rotation_from_euler_zyx(EulerZYX<double>{roll, pitch, yaw})));
  }
  Matrix6d info_odo = Matrix6d::Zero(), info_loop = Matrix6d::Zero();
  info_odo.diagonal() << Eigen::Vector3d::Constant(1 / (c.sigma_odo_p * c.sigma_odo_p)),
      Eigen::Vector3d::Constant(4 / (c.sigma_odo_r * c.sigma_odo_r));
  info_loop.diagonal() << Eigen::Vector3d::Constant(1 / (c.sigma_loop_p * c.sigma_loop_p)),
      Eigen::Vector3d::Constant(4 / (c.sigma_loop_r * c.sigma_loop_r));
  const auto edge = [&](int i, int j, double sp, double sr, const Matrix6d& info) {
    Vector6d n;
    for (int a = 0; a < 6; ++a) {
      const double v = n01(rng);
      n(a) = (a < 3 ? sp : sr) * v;
    }
    EdgeSE3 e;
    e.from = i;
    e.to = j;
    e.measurement = pose_graph_plus(pr.truth[std::size_t(i)].inverse() * pr.truth[std::size_t(j)], n);
    e.information = info;
    return e;
  };
  for (int k = 0; k + 1 < c.nodes; ++k) pr.edges.push_back(edge(k, k + 1, c.sigma_odo_p, c.sigma_odo_r, info_odo));
  pr.sequential = pr.edges.size();
  pr.initial.push_back(pr.truth.front());
  for (std::size_t k = 0; k < pr.sequential; ++k) pr.initial.push_back(pr.initial.back() * pr.edges[k].measurement);
  for (int k = c.lap; k < c.nodes; k += c.loop_every)
    pr.edges.push_back(edge(k - c.lap, k, c.sigma_loop_p, c.sigma_loop_r, info_loop));
  return pr;
}

/// The problem as a PoseGraphSE3 started from its initial guess (node 0 fixed).
inline PoseGraphSE3 to_pose_graph_se3(const PoseGraphProblemSE3& pr, const RobustKernel& loop_loss = {}) {
  PoseGraphSE3 g;
  g.reserve(pr.initial.size(), pr.edges.size());
  for (std::size_t k = 0; k < pr.initial.size(); ++k) g.add_node(static_cast<std::int64_t>(k), pr.initial[k], k == 0);
  for (std::size_t k = 0; k < pr.edges.size(); ++k) {
    EdgeSE3 e = pr.edges[k];
    if (k >= pr.sequential) e.loss = loop_loss;
    g.add_edge(e);
  }
  return g;
}

}  // namespace posefuse::sim

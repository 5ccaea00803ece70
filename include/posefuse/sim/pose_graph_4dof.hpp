#pragma once
/// @file
/// A seeded 4-DoF pose-graph problem (an application helper, not library
/// API): a vehicle drives laps of a closed, hilly track of `lap` nodes with
/// small roll and pitch; sequential edges are its noisy odometry, and every
/// `loop_every`-th node of lap k > 0 gets a noisy loop edge to the node at
/// the same place on lap k - 1. The initial guess chains the noisy odometry
/// (so it drifts), as a VIO front end would deliver it.
///
/// Noise (1σ): odometry 2 cm per axis and 0.2° yaw; loop edges 5 cm and 0.5°;
/// information = inverse noise covariance. Used by bench_graph, the tests and
/// the examples; the same seed gives the same problem under g++ and clang
/// (one random draw per statement).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/core/angles.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/lie/rotation.hpp>

namespace posefuse::sim {

/// The generated problem.
struct PoseGraphProblem {
  std::vector<Pose4Dof> truth;    ///< true poses, node ids 0..n-1
  std::vector<Pose4Dof> initial;  ///< odometry chained from the true first pose
  std::vector<Edge4Dof> edges;    ///< sequential edges first, then loop edges
  std::size_t sequential = 0;     ///< number of sequential edges
};

/// Settings of make_pose_graph_problem.
struct PoseGraphProblemConfig {
  int nodes = 1000;        ///< n
  int lap = 100;           ///< nodes per lap of the track
  int loop_every = 4;      ///< a loop edge on every this-many-th node after the first lap
  bool planar = false;     ///< z = roll = pitch = 0 (a 2-D graph)
  double sigma_odo_p = 0.02, sigma_odo_yaw = 0.2 * std::numbers::pi / 180.0;
  double sigma_loop_p = 0.05, sigma_loop_yaw = 0.5 * std::numbers::pi / 180.0;
  std::uint32_t seed = 1;  ///< RNG seed
};

/// The relative measurement from a to b (exact).
inline Edge4Dof relative_edge(const Pose4Dof& a, const Pose4Dof& b, std::int64_t i, std::int64_t j) {
  Edge4Dof e;
  e.from = i;
  e.to = j;
  const Eigen::Matrix3d Ri = rotation_from_euler_zyx(EulerZYX<double>{a.roll, a.pitch, a.yaw});
  e.dp = Ri.transpose() * (b.p - a.p);
  e.dyaw = wrap_angle(b.yaw - a.yaw);
  return e;
}

/// The pose reached from a by the relative measurement e.
inline Pose4Dof chain(const Pose4Dof& a, const Edge4Dof& e, const Pose4Dof& shape) {
  Pose4Dof b = shape;  // roll / pitch from the (observable) truth
  const Eigen::Matrix3d Ri = rotation_from_euler_zyx(EulerZYX<double>{a.roll, a.pitch, a.yaw});
  b.p = a.p + Ri * e.dp;
  b.yaw = wrap_angle(a.yaw + e.dyaw);
  return b;
}

/// Generates the problem (see the file comment).
inline PoseGraphProblem make_pose_graph_problem(const PoseGraphProblemConfig& c) {
  std::mt19937 rng(c.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  PoseGraphProblem pr;
  const double radius = 0.5 * c.lap / std::numbers::pi;  // ~1 m between nodes
  for (int k = 0; k < c.nodes; ++k) {
    const double s = 2.0 * std::numbers::pi * (k % c.lap) / c.lap;
    const int lap = k / c.lap;
    Pose4Dof x;
    // A slightly different line each lap (0.3 m lateral), hills of 2 m.
    const double r = radius + 0.3 * std::sin(0.7 * lap);
    x.p = Eigen::Vector3d(r * std::cos(s), r * std::sin(s), c.planar ? 0.0 : 2.0 * std::sin(2.0 * s));
    x.yaw = wrap_angle(s + std::numbers::pi / 2);
    if (!c.planar) {
      const double roll = 0.02 * n01(rng);
      const double pitch = -std::atan(4.0 * std::cos(2.0 * s) / r);
      x.roll = roll;
      x.pitch = pitch;
    }
    pr.truth.push_back(x);
  }
  const auto information = [](double sp, double sy) {
    Eigen::Matrix4d I = Eigen::Matrix4d::Zero();
    I.diagonal() << 1 / (sp * sp), 1 / (sp * sp), 1 / (sp * sp), 1 / (sy * sy);
    return I;
  };
  const auto noisy = [&](Edge4Dof e, double sp, double sy) {
    const double a = n01(rng);
    const double b = n01(rng);
    const double d = n01(rng);
    const double y = n01(rng);
    e.dp += sp * Eigen::Vector3d(a, b, c.planar ? 0.0 : d);
    e.dyaw = wrap_angle(e.dyaw + sy * y);
    e.information = information(sp, sy);
    return e;
  };
  for (int k = 0; k + 1 < c.nodes; ++k)
    pr.edges.push_back(noisy(relative_edge(pr.truth[k], pr.truth[k + 1], k, k + 1), c.sigma_odo_p, c.sigma_odo_yaw));
  pr.sequential = pr.edges.size();
  pr.initial.push_back(pr.truth.front());
  for (std::size_t k = 0; k < pr.sequential; ++k)
    pr.initial.push_back(chain(pr.initial.back(), pr.edges[k], pr.truth[k + 1]));
  for (int k = c.lap; k < c.nodes; k += c.loop_every)
    pr.edges.push_back(noisy(relative_edge(pr.truth[k - c.lap], pr.truth[k], k - c.lap, k), c.sigma_loop_p,
                             c.sigma_loop_yaw));
  return pr;
}

/// The problem as a PoseGraph4Dof started from its initial guess (node 0 fixed).
inline PoseGraph4Dof to_pose_graph(const PoseGraphProblem& pr, const RobustKernel& loop_loss = {}) {
  PoseGraph4Dof g;
  g.reserve(pr.initial.size(), pr.edges.size());
  for (std::size_t k = 0; k < pr.initial.size(); ++k)
    g.add_node(static_cast<std::int64_t>(k), pr.initial[k], k == 0);
  for (std::size_t k = 0; k < pr.edges.size(); ++k) {
    Edge4Dof e = pr.edges[k];
    if (k >= pr.sequential) e.loss = loop_loss;
    g.add_edge(e);
  }
  return g;
}

}  // namespace posefuse::sim

// quickstart_graph: a Lie-group step, a 4-DoF pose graph closing the loops
// of a drifting odometry, and the evo-style APE before and after.
#include <posefuse/eval/metrics.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/lie/se3.hpp>
#include <cstdio>
#include <numbers>

int main() {
  // Lie groups: x.plus(tau) = x Exp(tau) (a body-frame step); minus undoes it.
  using posefuse::SE3d;
  const SE3d x = SE3d::exp(SE3d::Tangent(1.0, 0.5, 0.0, 0.0, 0.0, 0.3));
  const SE3d::Tangent tau(0.1, 0.0, 0.0, 0.0, 0.0, 0.05);
  std::printf("|x.plus(tau).minus(x) - tau| = %.1e\n", (x.plus(tau).minus(x) - tau).norm());

  // Three laps of a 10 m square, 1 m a step; odometry reads each turn 3 degrees too large.
  const auto isometry = [](const posefuse::Pose4Dof& p) {
    return Eigen::Isometry3d(Eigen::Translation3d(p.p) * Eigen::AngleAxisd(p.yaw, Eigen::Vector3d::UnitZ()));
  };
  posefuse::PoseGraph4Dof graph;  // node 0 fixed
  posefuse::Trajectory truth, odometry, optimised;
  posefuse::Pose4Dof t, o;        // the true and the odometry pose
  posefuse::Edge4Dof odo, loop;   // identity information (order x, y, z, yaw)
  odo.dp = Eigen::Vector3d::UnitX();
  for (int k = 0; k <= 120; ++k) {
    if (k > 0) {  // 1 m ahead, then turn at the corners
      const double turn = k % 10 == 0 ? std::numbers::pi / 2 : 0.0;
      t.p += isometry(t).linear() * Eigen::Vector3d::UnitX();
      o.p += isometry(o).linear() * Eigen::Vector3d::UnitX();
      t.yaw += turn;
      odo.dyaw = turn > 0 ? turn + 3 * std::numbers::pi / 180 : 0.0;
      o.yaw += odo.dyaw;
    }
    graph.add_node(k, o, /*fixed=*/k == 0);
    truth.push_back(k, isometry(t));
    odometry.push_back(k, isometry(o));
    odo.from = k - 1;
    odo.to = loop.to = k;
    if (k > 0) graph.add_edge(odo);
    if (k > 0 && k % 40 == 0) graph.add_edge(loop);  // back at node 0: a loop closure
  }
  const posefuse::PoseGraphSummary s = graph.optimize();
  for (int k = 0; k <= 120; ++k) optimised.push_back(k, isometry(graph.pose(k)));

  const auto ape = [&](const posefuse::Trajectory& est) {  // evo_ape -a: SE(3)-aligned, translation
    using posefuse::PoseRelation, posefuse::Alignment;
    return posefuse::ape(truth, est, PoseRelation::kTranslation, Alignment::kSE3).stats.rmse;
  };
  std::printf("chi2 %.1f -> %.3g in %d iterations; APE (SE(3)-aligned) %.3f m -> %.3f m\n", s.initial_cost,
              s.final_cost, s.iterations, ape(odometry), ape(optimised));
}

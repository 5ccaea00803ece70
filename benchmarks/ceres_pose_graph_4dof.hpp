#pragma once
// The Ceres side of the 4-DoF pose-graph comparisons (bench_graph and
// memory_peak): the same residual as posefuse's edge error, written for
// Ceres's automatic differentiation, and the solver settings of every
// comparison. Compiled only when Ceres is found (POSEFUSE_HAVE_CERES).

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Cholesky>
#include <ceres/ceres.h>

#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/lie/rotation.hpp>

namespace posefuse::bench {

/// Angle wrapped to [-π, π) for Ceres's Jets (Ceres's pose_graph_2d
/// normalize_angle idea, written here).
template <class T>
T wrap(const T& a) {
  const T two_pi(2.0 * std::numbers::pi);
  return a - two_pi * ceres::floor((a + T(std::numbers::pi)) / two_pi);
}

/// The standard 4-DoF residual (VINS-Mono's four-DoF error with g2o's
/// measurement-frame translation error), whitened by the information's
/// upper Cholesky factor.
struct FourDofError {
  Eigen::Matrix3d Qi_t;
  Eigen::Vector3d dp;
  double dyaw;
  Eigen::Matrix4d sqrt_info;

  template <class T>
  bool operator()(const T* xi, const T* xj, T* residual) const {
    const T d0 = xj[0] - xi[0], d1 = xj[1] - xi[1], d2 = xj[2] - xi[2];
    const T ci = ceres::cos(xi[3]), si = ceres::sin(xi[3]);
    // w = Rz(yaw_i)^T d
    const T w0 = ci * d0 + si * d1, w1 = -si * d0 + ci * d1, w2 = d2;
    T u[3];
    for (int r = 0; r < 3; ++r) u[r] = T(Qi_t(r, 0)) * w0 + T(Qi_t(r, 1)) * w1 + T(Qi_t(r, 2)) * w2 - T(dp(r));
    const double cm = std::cos(dyaw), sm = std::sin(dyaw);
    T e[4];
    e[0] = cm * u[0] + sm * u[1];
    e[1] = -sm * u[0] + cm * u[1];
    e[2] = u[2];
    e[3] = wrap(xj[3] - xi[3] - T(dyaw));
    for (int r = 0; r < 4; ++r) {
      residual[r] = T(0);
      for (int c = r; c < 4; ++c) residual[r] += T(sqrt_info(r, c)) * e[c];
    }
    return true;
  }
};

/// What the Ceres rows report of a solve.
struct CeresRun {
  double chi2;     ///< g2o's chi² (twice Ceres's cost)
  int iterations;  ///< LM iterations (Ceres counts iteration 0)
};

/// The Ceres settings of every comparison: sparse normal Cholesky, one
/// thread, LM with function tolerance 1e-10, at most 100 iterations.
inline CeresRun solve_with_ceres(ceres::Problem& problem) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.max_num_iterations = 100;
  o.function_tolerance = 1e-10;
  o.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(o, &problem, &summary);
  return {2.0 * summary.final_cost, static_cast<int>(summary.iterations.size()) - 1};
}

/// Builds and solves the 4-DoF problem of `edges` (node ids 0..n-1 index
/// `poses` and `x`) from the [x y z yaw] blocks `x` (left at the solution);
/// roll and pitch come from `poses`, node 0 is held fixed.
inline CeresRun solve_4dof_with_ceres(const std::vector<Edge4Dof>& edges, const std::vector<Pose4Dof>& poses,
                                      std::vector<std::array<double, 4>>& x) {
  ceres::Problem problem;
  for (const Edge4Dof& e : edges) {
    const Pose4Dof& a = poses[std::size_t(e.from)];
    const FourDofError f{rotation_from_euler_zyx(EulerZYX<double>{a.roll, a.pitch, 0.0}).transpose(), e.dp, e.dyaw,
                         e.information.llt().matrixU()};
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<FourDofError, 4, 4, 4>(new FourDofError(f)), nullptr,
                             x[std::size_t(e.from)].data(), x[std::size_t(e.to)].data());
  }
  problem.SetParameterBlockConstant(x[0].data());
  return solve_with_ceres(problem);
}

/// [x y z yaw] blocks of poses.
inline std::vector<std::array<double, 4>> ceres_blocks_4dof(const std::vector<Pose4Dof>& poses) {
  std::vector<std::array<double, 4>> x(poses.size());
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = {poses[k].p.x(), poses[k].p.y(), poses[k].p.z(), poses[k].yaw};
  return x;
}

}  // namespace posefuse::bench

// 4-DoF pose graph: Jacobians against central differences, exact recovery,
// yaw wrap-around, robust losses, hand-checked optimum, input validation.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <posefuse/eval/alignment.hpp>
#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/testing/conformance.hpp>

using namespace posefuse;

namespace {

using Vec8 = Eigen::Matrix<double, 8, 1>;

/// The edge error as a function of the stacked [p_i; ψ_i; p_j; ψ_j].
struct ErrorOf {
  Eigen::Matrix3d Qi_t;
  Eigen::Vector3d dp;
  double dyaw;
  Eigen::Vector4d operator()(const Vec8& x) const {
    return edge_error_4dof(x.head<3>(), x(3), Qi_t, x.segment<3>(4), x(7), dp, dyaw);
  }
};

Eigen::Matrix<double, 4, 8> analytic(const ErrorOf& f, const Vec8& x, bool flip = false) {
  Eigen::Matrix4d Ji, Jj;
  (void)edge_error_4dof(x.head<3>(), x(3), f.Qi_t, x.segment<3>(4), x(7), f.dp, f.dyaw, &Ji, &Jj);
  Eigen::Matrix<double, 4, 8> J;
  J << Ji, Jj;
  if (flip) J(1, 3) = -J(1, 3);
  return J;
}

/// The pose of j in i's frame and the relative yaw, from two true poses.
Edge4Dof exact_edge(const Pose4Dof& a, const Pose4Dof& b, std::int64_t i, std::int64_t j) {
  Edge4Dof e;
  e.from = i;
  e.to = j;
  const Eigen::Matrix3d Ri = rotation_from_euler_zyx(EulerZYX<double>{a.roll, a.pitch, a.yaw});
  e.dp = Ri.transpose() * (b.p - a.p);
  e.dyaw = wrap_angle(b.yaw - a.yaw);
  return e;
}

/// A random 3-D drive with roll/pitch, loops every 10 nodes back 7 nodes.
struct TrueGraph {
  std::vector<Pose4Dof> truth;
  std::vector<Edge4Dof> edges;
};

TrueGraph make_true_graph(int n, unsigned seed, double yaw0 = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  TrueGraph g;
  Pose4Dof x;
  x.yaw = yaw0;
  for (int k = 0; k < n; ++k) {
    g.truth.push_back(x);
    Pose4Dof next = x;
    const double turn = 0.3 * n01(rng);
    next.yaw = wrap_angle(x.yaw + turn);
    const double roll = 0.05 * n01(rng);
    const double pitch = 0.05 * n01(rng);
    next.roll = roll;
    next.pitch = pitch;
    const double step = 1.0 + 0.2 * n01(rng);
    const double climb = 0.1 * n01(rng);
    next.p = x.p + Eigen::Vector3d(step * std::cos(x.yaw), step * std::sin(x.yaw), climb);
    x = next;
  }
  for (int k = 0; k + 1 < n; ++k) g.edges.push_back(exact_edge(g.truth[k], g.truth[k + 1], k, k + 1));
  for (int k = 10; k < n; k += 10) g.edges.push_back(exact_edge(g.truth[k - 7], g.truth[k], k - 7, k));
  return g;
}

/// The graph built from the true edges, started from a perturbed guess.
PoseGraph4Dof perturbed(const TrueGraph& g, unsigned seed, double sigma_p, double sigma_yaw) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  PoseGraph4Dof graph;
  for (std::size_t k = 0; k < g.truth.size(); ++k) {
    Pose4Dof x = g.truth[k];
    if (k > 0) {
      const double dx = n01(rng);
      const double dy = n01(rng);
      const double dz = n01(rng);
      const double dpsi = n01(rng);
      x.p += sigma_p * Eigen::Vector3d(dx, dy, dz);
      x.yaw = wrap_angle(x.yaw + sigma_yaw * dpsi);
    }
    graph.add_node(static_cast<std::int64_t>(k), x, k == 0);
  }
  for (const Edge4Dof& e : g.edges) graph.add_edge(e);
  return graph;
}

double max_pose_error(const PoseGraph4Dof& graph, const std::vector<Pose4Dof>& truth) {
  double m = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const Pose4Dof& x = graph.poses()[k];
    m = std::max(m, (x.p - truth[k].p).lpNorm<Eigen::Infinity>());
    m = std::max(m, std::abs(angle_diff(x.yaw, truth[k].yaw)));
  }
  return m;
}

/// No early stop: run until no step lowers the cost (or a rounding-level step was taken).
PoseGraphOptions tight() {
  PoseGraphOptions o;
  o.function_tolerance = 0.0;
  o.gradient_tolerance = 0.0;
  o.parameter_tolerance = 0.0;
  return o;
}

}  // namespace

TEST_CASE("PoseGraph4Dof: edge Jacobians match central differences", "[graph][jacobian]") {
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Vec8 x;
    for (int r = 0; r < 8; ++r) x(r) = 2.0 * n01(rng);
    x(3) = wrap_angle(x(3));
    x(7) = wrap_angle(x(7));
    const double roll = 0.3 * n01(rng);
    const double pitch = 0.3 * n01(rng);
    ErrorOf f{rotation_from_euler_zyx(EulerZYX<double>{roll, pitch, 0.0}).transpose(), Eigen::Vector3d::Zero(), 0.0};
    for (int r = 0; r < 3; ++r) f.dp(r) = n01(rng);
    f.dyaw = n01(rng);
    // Keep away from the yaw-error wrap point, where e_ψ jumps by 2π.
    if (std::abs(wrap_angle(x(7) - x(3) - f.dyaw)) > 3.0) continue;
    const testing::CheckResult r = testing::check_jacobian("edge_error_4dof", f, x, analytic(f, x), 1e-6);
    INFO(r);
    CHECK(r.ok);
  }
}

TEST_CASE("PoseGraph4Dof: a flipped Jacobian entry fails the conformance check", "[graph][jacobian]") {
  const ErrorOf f{rotation_from_euler_zyx(EulerZYX<double>{0.1, -0.2, 0.0}).transpose(),
                  Eigen::Vector3d(1.0, 0.5, -0.2), 0.4};
  Vec8 x;
  x << 0.3, -1.0, 0.2, 0.7, 2.0, 1.0, -0.5, 1.2;
  CHECK(testing::check_jacobian("ok", f, x, analytic(f, x), 1e-6).ok);
  CHECK_FALSE(testing::check_jacobian("flipped", f, x, analytic(f, x, true), 1e-6).ok);
}

TEST_CASE("PoseGraph4Dof: a noise-free graph is recovered to 1e-9", "[graph][optimize]") {
  const TrueGraph g = make_true_graph(200, 3);
  SECTION("Levenberg-Marquardt from a perturbed start") {
    PoseGraph4Dof graph = perturbed(g, 11, 0.3, 0.05);
    const PoseGraphSummary s = graph.optimize(tight());
    INFO("iterations " << s.iterations << " termination " << to_string(s.termination) << " cost "
                       << s.final_cost);
    CHECK(s.initial_cost > 1.0);
    CHECK(s.final_cost < 1e-18);
    CHECK(max_pose_error(graph, g.truth) < 1e-9);
  }
  SECTION("Gauss-Newton after the rotation-first initialisation") {
    PoseGraph4Dof graph = perturbed(g, 12, 5.0, 1.0);
    graph.initialize_rotation_first();
    PoseGraphOptions o = tight();
    o.levenberg_marquardt = false;
    const PoseGraphSummary s = graph.optimize(o);
    INFO("iterations " << s.iterations << " termination " << to_string(s.termination));
    CHECK(max_pose_error(graph, g.truth) < 1e-9);
  }
}

TEST_CASE("PoseGraph4Dof: yaw wraps around at +-pi", "[graph][optimize]") {
  // Headings around ±π: every relative yaw crosses the wrap point.
  const TrueGraph g = make_true_graph(60, 5, std::numbers::pi - 0.01);
  bool crosses = false;
  for (std::size_t k = 1; k < g.truth.size(); ++k)
    if (std::abs(g.truth[k].yaw - g.truth[k - 1].yaw) > std::numbers::pi) crosses = true;
  REQUIRE(crosses);
  PoseGraph4Dof graph = perturbed(g, 9, 0.2, 0.2);
  const PoseGraphSummary s = graph.optimize(tight());
  INFO("termination " << to_string(s.termination));
  CHECK(max_pose_error(graph, g.truth) < 1e-9);
  for (const Pose4Dof& x : graph.poses()) {
    CHECK(x.yaw >= -std::numbers::pi);
    CHECK(x.yaw < std::numbers::pi);
  }
}

TEST_CASE("PoseGraph4Dof: a wrong loop edge is down-weighted by Huber and Cauchy", "[graph][robust]") {
  TrueGraph g = make_true_graph(120, 21);
  // Noisy odometry-like measurements so that the solution is not exact.
  std::mt19937 rng(4);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (Edge4Dof& e : g.edges) {
    const double a = n01(rng);
    const double b = n01(rng);
    const double c = n01(rng);
    const double d = n01(rng);
    e.dp += 0.01 * Eigen::Vector3d(a, b, c);
    e.dyaw += 0.002 * d;
    e.information.diagonal() << 1e4, 1e4, 1e4, 2.5e5;
  }
  PoseGraph4Dof clean = perturbed(g, 1, 0.0, 0.0);
  (void)clean.optimize();

  Edge4Dof wrong = exact_edge(g.truth[15], g.truth[100], 15, 100);
  wrong.dp += Eigen::Vector3d(8.0, -6.0, 1.0);  // a false loop closure
  wrong.dyaw += 1.0;
  wrong.information = g.edges.front().information;
  const auto solve_with = [&](RobustLoss loss) {
    PoseGraph4Dof graph = perturbed(g, 1, 0.0, 0.0);
    Edge4Dof w = wrong;
    w.loss = {loss, 1.0};
    graph.add_edge(w);
    (void)graph.optimize();
    double m = 0.0;
    for (std::size_t k = 0; k < graph.poses().size(); ++k)
      m = std::max(m, (graph.poses()[k].p - clean.poses()[k].p).norm());
    return m;
  };
  const double plain = solve_with(RobustLoss::kNone);
  const double huber = solve_with(RobustLoss::kHuber);
  const double cauchy = solve_with(RobustLoss::kCauchy);
  INFO("max position deviation from the outlier-free solution: none " << plain << " m, huber "
                                                                      << huber << " m, cauchy " << cauchy << " m");
  CHECK(plain > 10.0);           // the outlier drags the least-squares solution by metres
  CHECK(huber < 0.25 * plain);  // Huber bounds its pull (linear growth): at least 4x less
  CHECK(cauchy < 0.005);        // Cauchy (redescending) almost ignores it: within 5 mm
}

TEST_CASE("PoseGraph4Dof: planar two-edge case matches the hand-computed optimum", "[graph][optimize]") {
  // Node 0 fixed at the origin; two parallel measurements of node 1 at x = 1
  // (information 1) and x = 3 (information 3). Weighted mean 2.5; cost
  // 1 * 1.5^2 + 3 * 0.5^2 = 3.
  PoseGraph4Dof graph;
  graph.add_node(0, {});
  graph.add_node(1, Pose4Dof{Eigen::Vector3d(7.0, -2.0, 0.0), 0.5, 0.0, 0.0});
  Edge4Dof a;
  a.from = 0;
  a.to = 1;
  a.dp = Eigen::Vector3d(1.0, 0.0, 0.0);
  Edge4Dof b = a;
  b.dp.x() = 3.0;
  b.information *= 3.0;
  graph.add_edge(a);
  graph.add_edge(b);
  const PoseGraphOptions o = tight();
  const PoseGraphSummary s = graph.optimize(o);
  INFO("iterations " << s.iterations << " termination " << to_string(s.termination));
  CHECK(graph.pose(1).p.x() == Approx(2.5).margin(1e-12));
  CHECK(graph.pose(1).p.y() == Approx(0.0).margin(1e-12));
  CHECK(graph.pose(1).yaw == Approx(0.0).margin(1e-12));
  CHECK(s.final_cost == Approx(3.0).epsilon(1e-12));
  CHECK(graph.pose(0).p.norm() == 0.0);  // the first node is held fixed by default
}

TEST_CASE("PoseGraph4Dof: bad graphs are refused with a clear message", "[graph][validation]") {
  PoseGraph4Dof graph;
  graph.add_node(1, {});
  graph.add_node(2, {});
  graph.add_node(3, {});
  CHECK_THROWS_WITH(graph.add_node(2, {}), Catch::Contains("duplicate node id 2"));
  Edge4Dof e;
  e.from = 1;
  e.to = 9;
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("node 9 does not exist"));
  e.to = 2;
  e.information(0, 0) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("not finite"));
  e.information = Eigen::Matrix4d::Identity();
  e.information(2, 2) = -1.0;
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("positive semi-definite"));
  e.information = Eigen::Matrix4d::Identity();
  e.information(0, 1) = 0.5;  // not symmetric
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("positive semi-definite"));
  e.information = Eigen::Matrix4d::Identity();
  e.dp.x() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("measurement is not finite"));
  e.dp.x() = 1.0;
  e.to = 1;
  CHECK_THROWS_WITH(graph.add_edge(e), Catch::Contains("same node"));
  e.to = 2;
  graph.add_edge(e);  // node 3 is left unlinked
  CHECK_THROWS_WITH(graph.optimize(), Catch::Contains("disconnected") && Catch::Contains("ids 3"));
  CHECK_THROWS_WITH(graph.initialize_rotation_first(), Catch::Contains("disconnected"));
  graph.set_fixed(1);
  graph.set_fixed(3);  // a separately anchored part is well posed
  CHECK_NOTHROW(graph.optimize());
  CHECK_THROWS_WITH(graph.set_fixed(42), Catch::Contains("node 42 does not exist"));
}

TEST_CASE("align_posyaw: recovers a known 4-DoF (position + yaw) transform exactly", "[graph][eval][alignment]") {
  std::mt19937 rng(17);
  std::normal_distribution<double> n01(0.0, 1.0);
  Trajectory ref;
  for (int k = 0; k < 50; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double x = 10.0 * n01(rng);
    const double y = 10.0 * n01(rng);
    const double z = n01(rng);
    T.translation() = Eigen::Vector3d(x, y, z);
    T.linear() = rotation_from_euler_zyx(EulerZYX<double>{0.1 * n01(rng), 0.0, 0.0});
    ref.push_back(double(k), T);
  }
  for (const double psi : {0.7, -3.1, 3.14159}) {
    Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
    G.linear() = Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    G.translation() = Eigen::Vector3d(5.0, -2.0, 0.5);
    Trajectory est = ref;
    for (Eigen::Isometry3d& T : est.poses) T = G.inverse() * T;
    const AlignedTrajectory a = align_posyaw(est, ref);
    CHECK((a.transform.rotation - G.linear()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((a.transform.translation - G.translation()).cwiseAbs().maxCoeff() < 1e-12);
    for (std::size_t k = 0; k < ref.size(); ++k)
      CHECK((a.trajectory.poses[k].matrix() - ref.poses[k].matrix()).cwiseAbs().maxCoeff() < 1e-11);
  }
  // Only yaw: a roll between the sets is not absorbed (SE(3) alignment would).
  Trajectory rolled = ref;
  for (Eigen::Isometry3d& T : rolled.poses) T = Eigen::Isometry3d(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())) * T;
  CHECK(align_posyaw(rolled, ref).transform.rotation.isApprox(Eigen::Matrix3d::Identity(), 1e-2));
  Trajectory still;
  still.push_back(0.0, Eigen::Isometry3d::Identity());
  still.push_back(1.0, Eigen::Isometry3d::Identity());
  CHECK_THROWS_WITH(align_posyaw(still, still), Catch::Contains("no horizontal spread"));
}

namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

/// The planar edge error as a function of [x_i, y_i, ψ_i, x_j, y_j, ψ_j].
struct PlanarErrorOf {
  Eigen::Vector2d dp;
  double dyaw;
  Eigen::Vector3d operator()(const Vec6& x) const {
    return edge_error_planar(x.head<2>(), x(2), x.segment<2>(3), x(5), dp, dyaw);
  }
};

Eigen::Matrix<double, 3, 6> analytic_planar(const PlanarErrorOf& f, const Vec6& x, bool flip = false) {
  Eigen::Matrix3d Ji, Jj;
  (void)edge_error_planar(x.head<2>(), x(2), x.segment<2>(3), x(5), f.dp, f.dyaw, &Ji, &Jj);
  Eigen::Matrix<double, 3, 6> J;
  J << Ji, Jj;
  if (flip) J(0, 2) = -J(0, 2);
  return J;
}

}  // namespace

TEST_CASE("edge_error_planar: Jacobians match central differences and equal the 4-DoF ones", "[graph][jacobian]") {
  std::mt19937 rng(17);
  std::normal_distribution<double> n01(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 50; ++trial) {
    Vec6 x;
    for (int r = 0; r < 6; ++r) x(r) = 2.0 * n01(rng);
    x(2) = wrap_angle(x(2));
    x(5) = wrap_angle(x(5));
    const PlanarErrorOf f{Eigen::Vector2d(n01(rng), n01(rng)), n01(rng)};
    if (std::abs(wrap_angle(x(5) - x(2) - f.dyaw)) > 3.0) continue;
    const testing::CheckResult r = testing::check_jacobian("edge_error_planar", f, x, analytic_planar(f, x), 1e-6);
    INFO(r);
    CHECK(r.ok);
    // The 4-DoF error at z = 0 without roll or pitch, rows and columns (x, y, yaw).
    Eigen::Matrix3d Pi, Pj;
    const Eigen::Vector3d e3 = edge_error_planar(x.head<2>(), x(2), x.segment<2>(3), x(5), f.dp, f.dyaw, &Pi, &Pj);
    Eigen::Matrix4d Ji, Jj;
    const Eigen::Vector4d e4 = edge_error_4dof(Eigen::Vector3d(x(0), x(1), 0.0), x(2), Eigen::Matrix3d::Identity(),
                                               Eigen::Vector3d(x(3), x(4), 0.0), x(5),
                                               Eigen::Vector3d(f.dp.x(), f.dp.y(), 0.0), f.dyaw, &Ji, &Jj);
    const int map[3] = {0, 1, 3};
    for (int a = 0; a < 3; ++a) {
      CHECK(e3(a) == Approx(e4(map[a])).margin(1e-12));
      for (int b = 0; b < 3; ++b) {
        CHECK(Pi(a, b) == Approx(Ji(map[a], map[b])).margin(1e-12));
        CHECK(Pj(a, b) == Approx(Jj(map[a], map[b])).margin(1e-12));
      }
    }
    CHECK(e4(2) == 0.0);
    ++checked;
  }
  CHECK(checked > 40);
  const PlanarErrorOf f{Eigen::Vector2d(1.0, -0.5), 0.4};
  Vec6 x;
  x << 0.3, -1.0, 0.7, 2.0, 1.0, 1.2;
  CHECK_FALSE(testing::check_jacobian("flipped", f, x, analytic_planar(f, x, true), 1e-6).ok);
}

TEST_CASE("PoseGraph4Dof: the planar path equals the 4-DoF path on a planar graph", "[graph][optimize][planar]") {
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  // A planar drive: 300 poses on laps of a circle, odometry and loop edges
  // with full (correlated) 3x3 information, a Cauchy loss on the loops.
  const int n = 300;
  std::vector<Pose4Dof> truth(n);
  for (int k = 0; k < n; ++k) {
    const double s = 2.0 * std::numbers::pi * (k % 50) / 50.0;
    truth[std::size_t(k)].p = Eigen::Vector3d(8.0 * std::cos(s), 8.0 * std::sin(s), 0.0);
    truth[std::size_t(k)].yaw = wrap_angle(s + std::numbers::pi / 2);
  }
  const auto make = [&](std::int64_t i, std::int64_t j, double sp, double sy, bool robust) {
    Edge4Dof e = exact_edge(truth[std::size_t(i)], truth[std::size_t(j)], i, j);
    e.dp += Eigen::Vector3d(sp * n01(rng), sp * n01(rng), 0.0);
    e.dyaw = wrap_angle(e.dyaw + sy * n01(rng));
    Eigen::Matrix3d A;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) A(r, c) = 0.3 * n01(rng);
    Eigen::Matrix3d I3 = (A * A.transpose() + Eigen::Matrix3d::Identity());
    I3.topLeftCorner<2, 2>() /= sp * sp;
    I3.col(2).head<2>() /= sp * sy;
    I3.row(2).head<2>() /= sp * sy;
    I3(2, 2) /= sy * sy;
    e.information.setZero();
    const int map[3] = {0, 1, 3};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) e.information(map[r], map[c]) = I3(r, c);
    e.information(2, 2) = 1.0;
    if (robust) e.loss = RobustKernel{RobustLoss::kCauchy, 2.0};
    return e;
  };
  std::vector<Edge4Dof> edges;
  for (int k = 0; k + 1 < n; ++k) edges.push_back(make(k, k + 1, 0.05, 0.01, false));
  for (int k = 50; k < n; k += 3) edges.push_back(make(k - 50, k, 0.1, 0.02, true));
  PoseGraph4Dof a;
  Pose4Dof start = truth[0];
  for (int k = 0; k < n; ++k) {
    if (k > 0) {  // chained odometry, the drifting start
      const Edge4Dof& e = edges[std::size_t(k - 1)];
      const Pose4Dof& prev = a.poses().back();
      start.p = prev.p + Eigen::Vector3d(std::cos(prev.yaw) * e.dp.x() - std::sin(prev.yaw) * e.dp.y(),
                                         std::sin(prev.yaw) * e.dp.x() + std::cos(prev.yaw) * e.dp.y(), 0.0);
      start.yaw = wrap_angle(prev.yaw + e.dyaw);
    }
    a.add_node(k, start, k == 0);
  }
  for (const Edge4Dof& e : edges) a.add_edge(e);
  REQUIRE(a.is_planar());
  const PoseGraph4Dof start_graph = a;
  PoseGraph4Dof b = a;
  PoseGraphOptions planar, general;
  general.planar_fast_path = false;
  const PoseGraphSummary sa = a.optimize(planar);
  const PoseGraphSummary sb = b.optimize(general);
  CHECK(sa.planar);
  CHECK_FALSE(sb.planar);
  INFO("planar " << sa.final_cost << " in " << sa.iterations << ", 4-DoF " << sb.final_cost << " in "
                 << sb.iterations);
  CHECK(sa.initial_cost == Approx(sb.initial_cost).epsilon(1e-12));
  CHECK(sa.final_cost == Approx(sb.final_cost).epsilon(1e-12));
  CHECK(sa.iterations == sb.iterations);
  CHECK(sa.termination == sb.termination);
  CHECK(sa.final_cost < 0.5 * sa.initial_cost);  // noise-level chi2 (~257) from a drifting start (~860)
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const Pose4Dof& pa = a.pose(k);
    const Pose4Dof& pb = b.pose(k);
    worst = std::max({worst, (pa.p - pb.p).norm(), std::abs(wrap_angle(pa.yaw - pb.yaw))});
    CHECK(pa.p.z() == 0.0);
  }
  CHECK(worst < 1e-10);
  // Solving again after the buffers were released gives the same answer.
  a.release_workspace();
  PoseGraph4Dof a2 = start_graph;
  const PoseGraphSummary sa2 = a2.optimize(planar);
  CHECK(sa2.final_cost == sa.final_cost);
  CHECK(sa2.iterations == sa.iterations);
  // A z offset, roll or a z-coupled information makes the graph non-planar.
  PoseGraph4Dof c = a;
  Pose4Dof p = c.pose(5);
  p.p.z() = 1e-3;
  c.set_pose(5, p);
  CHECK_FALSE(c.is_planar());
  CHECK_FALSE(c.optimize().planar);
  PoseGraph4Dof d;
  d.add_node(0, Pose4Dof{});
  d.add_node(1, Pose4Dof{});
  Edge4Dof e;
  e.to = 1;
  e.information(0, 2) = e.information(2, 0) = 0.1;
  d.add_edge(e);
  CHECK_FALSE(d.is_planar());
}

namespace {

/// H = sum J^T w Omega J and b = sum J^T w Omega e assembled densely, edge
/// by edge, from edge_error_4dof's Jacobians (checked against central
/// differences above), in the block order of `ids`; planar: the blocks are
/// [x, y, yaw] (rows and columns 0, 1, 3 of the 4-DoF ones).
std::pair<Eigen::MatrixXd, Eigen::VectorXd> dense_normal_equations(const PoseGraph4Dof& g,
                                                                   const std::vector<Edge4Dof>& edges,
                                                                   const std::vector<std::int64_t>& ids,
                                                                   bool planar) {
  const int B = planar ? 3 : 4;
  const int map[4] = {0, 1, planar ? 3 : 2, 3};
  const auto column = [&](std::int64_t id) {
    const auto it = std::find(ids.begin(), ids.end(), id);
    return it == ids.end() ? -1 : int(it - ids.begin());
  };
  const auto pose = [&](std::int64_t id) {
    const auto it = std::find(g.ids().begin(), g.ids().end(), id);
    return g.poses()[std::size_t(it - g.ids().begin())];
  };
  const int n = int(ids.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(B * n, B * n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(B * n);
  for (const Edge4Dof& e : edges) {
    const Pose4Dof xi = pose(e.from), xj = pose(e.to);
    Eigen::Matrix4d Ji, Jj;
    const Eigen::Vector4d r = edge_error_4dof(xi.p, xi.yaw, roll_pitch_rotation(xi).transpose(), xj.p, xj.yaw,
                                              e.dp, e.dyaw, &Ji, &Jj);
    const Eigen::Matrix4d W = e.loss.weight(r.dot(e.information * r)) * e.information;
    const int ci = column(e.from), cj = column(e.to);
    const Eigen::Matrix4d* J[2] = {&Ji, &Jj};
    const int c[2] = {ci, cj};
    for (int s = 0; s < 2; ++s) {
      if (c[s] < 0) continue;
      const Eigen::Vector4d bs = J[s]->transpose() * W * r;
      for (int u = 0; u < B; ++u) b(B * c[s] + u) += bs(map[u]);
      for (int t = 0; t < 2; ++t) {
        if (c[t] < 0) continue;
        const Eigen::Matrix4d Hst = J[s]->transpose() * W * *J[t];
        for (int u = 0; u < B; ++u)
          for (int v = 0; v < B; ++v) H(B * c[s] + u, B * c[t] + v) += Hst(map[u], map[v]);
      }
    }
  }
  return {H, b};
}

double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("PoseGraph4Dof: the assembled normal equations equal J^T W J from the checked Jacobians",
          "[graph][jacobian][assembly]") {
  // optimize() assembles H and b from the Jacobians' structure (J_i = -J_j +
  // g e_yaw^T, one triple product per edge), not from the Jacobians
  // themselves: compare with the dense sum over edges of J^T w Omega J, at a
  // perturbed state with roll/pitch, correlated information and robust
  // losses whose weights are below 1. A wrong sign or term in the assembly
  // fails here.
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  TrueGraph t = make_true_graph(40, 4);
  for (std::size_t k = 0; k < t.edges.size(); ++k) {
    Edge4Dof& e = t.edges[k];
    Eigen::Matrix4d A;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) A(r, c) = n01(rng);
    e.information = A * A.transpose() + 0.1 * Eigen::Matrix4d::Identity();
    e.dp += 0.2 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    if (k % 3 == 1) e.loss = RobustKernel{RobustLoss::kCauchy, 0.5};
    if (k % 3 == 2) e.loss = RobustKernel{RobustLoss::kHuber, 0.5};
  }
  PoseGraph4Dof g = perturbed(t, 9, 0.3, 0.2);
  const NormalEquations ne = g.normal_equations();
  REQUIRE(ne.block_size == 4);
  REQUIRE(ne.ids.size() == 39);  // node 0 is fixed
  const auto [H, b] = dense_normal_equations(g, t.edges, ne.ids, false);
  INFO("H: " << relative_difference(ne.H, H) << ", b: " << relative_difference(ne.b, b));
  CHECK(relative_difference(ne.H, H) < 1e-12);
  CHECK(relative_difference(ne.b, b) < 1e-12);
  // Some weights really are below 1, so the loss enters.
  int down_weighted = 0;
  for (const Edge4Dof& e : t.edges) {
    const auto pose = [&](std::int64_t id) { return g.poses()[std::size_t(id)]; };
    const Eigen::Vector4d r = edge_error_4dof(pose(e.from).p, pose(e.from).yaw,
                                              roll_pitch_rotation(pose(e.from)).transpose(), pose(e.to).p,
                                              pose(e.to).yaw, e.dp, e.dyaw);
    if (e.loss.weight(r.dot(e.information * r)) < 0.9) ++down_weighted;
  }
  CHECK(down_weighted > 5);
  CHECK_THROWS_AS(g.normal_equations(true), invalid_argument);  // roll/pitch: not planar
}

TEST_CASE("PoseGraph4Dof: the planar path's normal equations equal J^T W J on [x, y, yaw]",
          "[graph][jacobian][assembly][planar]") {
  std::mt19937 rng(12);
  std::normal_distribution<double> n01(0.0, 1.0);
  PoseGraph4Dof g;
  std::vector<Edge4Dof> edges;
  const int n = 25;
  for (int k = 0; k < n; ++k) {
    Pose4Dof x;
    x.p = Eigen::Vector3d(3.0 * n01(rng), 3.0 * n01(rng), 0.0);
    x.yaw = wrap_angle(2.0 * n01(rng));
    g.add_node(k, x, k == 0);
  }
  const auto add = [&](std::int64_t i, std::int64_t j, int k) {
    Edge4Dof e;
    e.from = i;
    e.to = j;
    e.dp = Eigen::Vector3d(n01(rng), n01(rng), 0.0);
    e.dyaw = wrap_angle(n01(rng));
    Eigen::Matrix3d A;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) A(r, c) = n01(rng);
    const Eigen::Matrix3d I3 = A * A.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    e.information.setZero();
    const int map[3] = {0, 1, 3};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) e.information(map[r], map[c]) = I3(r, c);
    e.information(2, 2) = 1.0;
    if (k % 2 == 1) e.loss = RobustKernel{RobustLoss::kCauchy, 1.0};
    g.add_edge(e);
    edges.push_back(e);
  };
  int k = 0;
  for (int i = 0; i + 1 < n; ++i) add(i, i + 1, k++);
  for (int i = 5; i < n; i += 4) add(i - 5, i, k++);
  REQUIRE(g.is_planar());
  const NormalEquations ne = g.normal_equations(true);
  REQUIRE(ne.block_size == 3);
  const auto [H, b] = dense_normal_equations(g, edges, ne.ids, true);
  INFO("H: " << relative_difference(ne.H, H) << ", b: " << relative_difference(ne.b, b));
  CHECK(relative_difference(ne.H, H) < 1e-12);
  CHECK(relative_difference(ne.b, b) < 1e-12);
  // The 4-DoF system of the same graph holds the planar one (z decoupled).
  const NormalEquations full = g.normal_equations();
  REQUIRE(full.ids == ne.ids);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const int map[3] = {0, 1, 3};
      CHECK(full.H(map[r], map[c]) == Approx(ne.H(r, c)).epsilon(1e-12));
    }
}

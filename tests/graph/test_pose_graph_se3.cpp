// SE(3) pose graph: Jacobians against central differences (and a flipped
// entry that must fail), exact recovery, a hand-checked optimum, robust
// losses against a false loop, the chordal start under large rotation
// noise, the assembled normal equations, input validation.

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <posefuse/graph/pose_graph_se3.hpp>
#include <posefuse/sim/pose_graph_se3.hpp>
#include <posefuse/testing/conformance.hpp>

using namespace posefuse;

namespace {

using Vec12 = Eigen::Matrix<double, 12, 1>;

/// The edge error as a function of the increments [δ_i; δ_j] at (X_i, X_j).
struct ErrorOf {
  SE3d xi, xj, z;
  Vector6d operator()(const Vec12& d) const {
    return edge_error_se3(pose_graph_plus(xi, d.head<6>()), pose_graph_plus(xj, d.tail<6>()), z);
  }
};

Eigen::Matrix<double, 6, 12> analytic(const ErrorOf& f, bool flip = false) {
  Matrix6d Ji, Jj;
  (void)edge_error_se3(f.xi, f.xj, f.z, &Ji, &Jj);
  Eigen::Matrix<double, 6, 12> J;
  J << Ji, Jj;
  if (flip) J(1, 3) = -J(1, 3);  // d t_E,y / d phi_i,x: non-zero at a generic point
  return J;
}

SE3d random_pose(std::mt19937& rng, double angle, double dist) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d axis(u(rng), u(rng), u(rng));
  axis.normalize();
  const double a = angle * u(rng);
  return SE3d(dist * Eigen::Vector3d(u(rng), u(rng), u(rng)), SO3d::exp(a * axis));
}

double max_pose_error(const std::vector<SE3d>& a, const std::vector<SE3d>& b) {
  double m = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    m = std::max(m, (a[k].translation() - b[k].translation()).norm());
    m = std::max(m, (a[k].so3().inverse() * b[k].so3()).log().norm());
  }
  return m;
}

/// Exact edges of a small problem (sequential + loops), no noise.
sim::PoseGraphProblemSE3 exact_problem(int nodes, int lap) {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = nodes;
  c.lap = lap;
  c.seed = 7;
  sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  for (EdgeSE3& e : pr.edges) {
    e.measurement = pr.truth[std::size_t(e.from)].inverse() * pr.truth[std::size_t(e.to)];
  }
  return pr;
}

}  // namespace

TEST_CASE("PoseGraphSE3: edge Jacobians match central differences", "[graph][se3][jacobian]") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    // Rotation errors up to ~170 degrees, the w >= 0 sign included.
    const ErrorOf f{random_pose(rng, 3.0, 5.0), random_pose(rng, 3.0, 5.0), random_pose(rng, 1.5, 3.0)};
    const testing::CheckResult r = testing::check_jacobian("edge_error_se3", f, Vec12::Zero().eval(), analytic(f), 1e-6);
    INFO(r.message);
    CHECK(r.ok);
  }
}

TEST_CASE("PoseGraphSE3: a flipped Jacobian entry fails the conformance check", "[graph][se3][jacobian]") {
  std::mt19937 rng(5);
  const ErrorOf f{random_pose(rng, 1.0, 2.0), random_pose(rng, 1.0, 2.0), random_pose(rng, 0.5, 1.0)};
  CHECK(testing::check_jacobian("ok", f, Vec12::Zero().eval(), analytic(f), 1e-6).ok);
  CHECK_FALSE(testing::check_jacobian("flipped", f, Vec12::Zero().eval(), analytic(f, true), 1e-6).ok);
}

TEST_CASE("PoseGraphSE3: the error is g2o's [t; q_xyz] of Z^-1 Xi^-1 Xj", "[graph][se3]") {
  // X_i = identity, X_j a rotation of 0.5 rad about z and a translation: the
  // error of an identity measurement is X_j itself, q = (cos .25, 0, 0, sin .25).
  const SE3d xj(Eigen::Vector3d(1.0, 2.0, 3.0), SO3d::exp(Eigen::Vector3d(0.0, 0.0, 0.5)));
  const Vector6d e = edge_error_se3(SE3d(), xj, SE3d());
  CHECK(e(0) == Approx(1.0));
  CHECK(e(1) == Approx(2.0));
  CHECK(e(2) == Approx(3.0));
  CHECK(std::abs(e(3)) < 1e-15);
  CHECK(std::abs(e(4)) < 1e-15);
  CHECK(e(5) == Approx(std::sin(0.25)).epsilon(1e-14));
  // A rotation error beyond pi is taken with w >= 0: q of 1.5 pi about z is
  // -(cos .75 pi, 0, 0, sin .75 pi) -> v_z = -sin(0.75 pi).
  const SE3d xk(Eigen::Vector3d::Zero(), SO3d(Eigen::Quaterniond(std::cos(0.75 * M_PI), 0, 0, std::sin(0.75 * M_PI))));
  CHECK(edge_error_se3(SE3d(), xk, SE3d())(5) == Approx(-std::sin(0.75 * M_PI)));
}

TEST_CASE("PoseGraphSE3: two measurements of one pose meet at the hand-computed optimum", "[graph][se3][optimize]") {
  // Node 0 fixed at the identity; two edges 0 -> 1 measure (Rz(0.2), (1,0,0))
  // and (Rz(-0.2), (3,0,0)) with unit information. |t_E| = |t - t_Z| and the
  // rotation terms are sin^2((theta -+ 0.2)/2): the optimum is t = (2,0,0),
  // theta = 0, chi^2 = 1 + 1 + 2 sin^2(0.1).
  PoseGraphSE3 g;
  g.add_node(0, SE3d(), true);
  g.add_node(1, SE3d(Eigen::Vector3d(0.5, 0.3, -0.2), SO3d::exp(Eigen::Vector3d(0.1, -0.2, 0.3))));
  EdgeSE3 a;
  a.from = 0;
  a.to = 1;
  a.measurement = SE3d(Eigen::Vector3d(1, 0, 0), SO3d::exp(Eigen::Vector3d(0, 0, 0.2)));
  EdgeSE3 b = a;
  b.measurement = SE3d(Eigen::Vector3d(3, 0, 0), SO3d::exp(Eigen::Vector3d(0, 0, -0.2)));
  g.add_edge(a);
  g.add_edge(b);
  PoseGraphOptions o;
  o.function_tolerance = 0.0;  // run to the rounding floor
  const PoseGraphSummary s = g.optimize(o);
  CHECK(s.final_cost == Approx(2.0 + 2.0 * std::sin(0.1) * std::sin(0.1)).epsilon(1e-12));
  CHECK((g.pose(1).translation() - Eigen::Vector3d(2, 0, 0)).norm() < 1e-8);
  CHECK(g.pose(1).so3().log().norm() < 1e-8);
  CHECK(g.cost() == Approx(s.final_cost).epsilon(1e-14));
}

TEST_CASE("PoseGraphSE3: a noise-free graph is recovered to 1e-9", "[graph][se3][optimize]") {
  const sim::PoseGraphProblemSE3 pr = exact_problem(300, 50);
  std::mt19937 rng(11);
  PoseGraphSE3 g;
  for (std::size_t k = 0; k < pr.truth.size(); ++k)
    g.add_node(std::int64_t(k), k == 0 ? pr.truth[0] : pose_graph_plus(pr.truth[k], [&] {
      Vector6d d;
      std::normal_distribution<double> n(0.0, 1.0);
      for (int a = 0; a < 6; ++a) d(a) = (a < 3 ? 0.5 : 0.1) * n(rng);
      return d;
    }()), k == 0);
  for (const EdgeSE3& e : pr.edges) g.add_edge(e);
  for (const bool lm : {true, false}) {
    PoseGraphSE3 h = g;
    PoseGraphOptions o;
    o.levenberg_marquardt = lm;
    const PoseGraphSummary s = h.optimize(o);
    INFO("levenberg_marquardt " << lm << " termination " << to_string(s.termination));
    CHECK(s.final_cost < 1e-16);
    CHECK(max_pose_error(h.poses(), pr.truth) < 1e-9);
  }
}

TEST_CASE("PoseGraphSE3: fixed nodes stay where they are", "[graph][se3][optimize]") {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 120;
  c.lap = 40;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  PoseGraphSE3 g = sim::to_pose_graph_se3(pr);
  g.set_fixed(60);
  const SE3d held = g.pose(60);
  const double before = g.cost();
  const PoseGraphSummary s = g.optimize();
  CHECK(s.final_cost < before);
  CHECK(g.pose(60).translation() == held.translation());
  CHECK(g.pose(60).so3().quaternion().coeffs() == held.so3().quaternion().coeffs());
  CHECK(g.pose(0).translation() == pr.initial[0].translation());
}

TEST_CASE("PoseGraphSE3: a false loop edge is down-weighted by Huber and Cauchy", "[graph][se3][robust]") {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 200;
  c.lap = 50;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  const auto solve = [&](RobustLoss type) {
    PoseGraphSE3 g = sim::to_pose_graph_se3(pr, RobustKernel{type, 1.0});
    EdgeSE3 bad;  // claims node 170 sits on node 30 (they are ~10 m apart)
    bad.from = 30;
    bad.to = 170;
    bad.information = pr.edges.back().information;
    bad.loss = RobustKernel{type, 1.0};
    g.add_edge(bad);
    (void)g.optimize();
    return max_pose_error(g.poses(), pr.truth);
  };
  PoseGraphSE3 clean = sim::to_pose_graph_se3(pr);
  (void)clean.optimize();
  const double ref = max_pose_error(clean.poses(), pr.truth);
  const double none = solve(RobustLoss::kNone);
  const double huber = solve(RobustLoss::kHuber);
  const double cauchy = solve(RobustLoss::kCauchy);
  INFO("clean " << ref << " none " << none << " huber " << huber << " cauchy " << cauchy);
  CHECK(ref < 0.2);
  CHECK(none > 1.0);
  CHECK(huber < 0.5 * none);
  CHECK(cauchy < 2.0 * ref);
}

TEST_CASE("PoseGraphSE3: the chordal start recovers a noise-free graph from any rotations", "[graph][se3][chordal]") {
  const sim::PoseGraphProblemSE3 pr = exact_problem(300, 50);
  std::mt19937 rng(13);
  PoseGraphSE3 g;
  for (std::size_t k = 0; k < pr.truth.size(); ++k)
    g.add_node(std::int64_t(k), k == 0 ? pr.truth[0] : random_pose(rng, 3.1, 30.0), k == 0);
  for (const EdgeSE3& e : pr.edges) g.add_edge(e);
  g.initialize_chordal();
  CHECK(max_pose_error(g.poses(), pr.truth) < 1e-9);
}

TEST_CASE("PoseGraphSE3: under large rotation noise the chordal start reaches the optimum", "[graph][se3][chordal]") {
  // Odometry with 6 degrees of rotation noise per axis (30x the simulator's)
  // drifts far from the loops; the chordal start, which does not read the
  // chained poses, lands near the optimum, and LM from it reaches the
  // optimum found from the truth.
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 300;
  c.lap = 50;
  c.loop_every = 2;
  c.sigma_odo_r = 6.0 * M_PI / 180.0;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  PoseGraphOptions o;
  o.function_tolerance = 0.0;  // both to the rounding floor, so that their poses can be compared
  PoseGraphSE3 from_truth = sim::to_pose_graph_se3(pr);
  for (std::size_t k = 0; k < pr.truth.size(); ++k) from_truth.set_pose(std::int64_t(k), pr.truth[k]);
  const double best = from_truth.optimize(o).final_cost;
  PoseGraphSE3 chordal = sim::to_pose_graph_se3(pr);
  const double odometry_cost = chordal.cost();
  chordal.initialize_chordal();
  const double start_cost = chordal.cost();
  const double chordal_cost = chordal.optimize(o).final_cost;
  INFO("odometry start " << odometry_cost << " chordal start " << start_cost << " optimum " << best
                         << " from chordal " << chordal_cost);
  CHECK(start_cost < 0.01 * odometry_cost);
  CHECK(start_cost < 20.0 * best);
  CHECK(chordal_cost == Approx(best).epsilon(1e-8));
  CHECK(max_pose_error(chordal.poses(), from_truth.poses()) < 1e-6);
}

TEST_CASE("PoseGraphSE3: the assembled normal equations equal J^T W J from the checked Jacobians",
          "[graph][se3][jacobian][assembly]") {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 12;
  c.lap = 6;
  c.loop_every = 1;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  PoseGraphSE3 g = sim::to_pose_graph_se3(pr, RobustKernel{RobustLoss::kCauchy, 0.5});
  const NormalEquationsSE3 ne = g.normal_equations();
  const int n = int(ne.ids.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6 * n, 6 * n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(6 * n);
  const auto col = [&](std::int64_t id) {
    for (int k = 0; k < n; ++k)
      if (ne.ids[std::size_t(k)] == id) return k;
    return -1;
  };
  for (const EdgeSE3& e : g.edges()) {
    Matrix6d Ji, Jj;
    const Vector6d r = edge_error_se3(g.pose(e.from), g.pose(e.to), e.measurement, &Ji, &Jj);
    const double w = e.loss.weight(r.dot(e.information * r));
    const int ci = col(e.from), cj = col(e.to);
    const Matrix6d* J[2] = {&Ji, &Jj};
    const int c2[2] = {ci, cj};
    for (int p = 0; p < 2; ++p) {
      if (c2[p] < 0) continue;
      b.segment<6>(6 * c2[p]) += w * J[p]->transpose() * e.information * r;
      for (int q = 0; q < 2; ++q)
        if (c2[q] >= 0)
          H.block<6, 6>(6 * c2[p], 6 * c2[q]) += w * J[p]->transpose() * e.information * *J[q];
    }
  }
  CHECK((ne.H - H).cwiseAbs().maxCoeff() < 1e-9 * (1.0 + H.cwiseAbs().maxCoeff()));
  CHECK((ne.b - b).cwiseAbs().maxCoeff() < 1e-9 * (1.0 + b.cwiseAbs().maxCoeff()));
}

TEST_CASE("PoseGraphSE3: bad graphs are refused with a clear message", "[graph][se3][validation]") {
  PoseGraphSE3 g;
  CHECK_THROWS_WITH(g.validate(), "pose graph: no nodes");
  g.add_node(1, SE3d());
  CHECK_THROWS_WITH(g.add_node(1, SE3d()), "pose graph: duplicate node id 1");
  CHECK_THROWS_WITH(g.add_node(2, SE3d(Eigen::Vector3d(NAN, 0, 0), SO3d())),
                    "pose graph: node 2 has a non-finite pose");
  g.add_node(2, SE3d());
  g.add_node(3, SE3d());
  EdgeSE3 e;
  e.from = 1;
  e.to = 9;
  CHECK_THROWS_WITH(g.add_edge(e), "pose graph: edge 0 (1 -> 9): node 9 does not exist");
  e.to = 1;
  CHECK_THROWS_WITH(g.add_edge(e), "pose graph: edge 0 (1 -> 1): both ends are the same node");
  e.to = 2;
  e.information(0, 1) = 0.5;  // not symmetric
  CHECK_THROWS_WITH(g.add_edge(e),
                    "pose graph: edge 0 (1 -> 2): the information matrix is not symmetric positive semi-definite");
  e.information = -Matrix6d::Identity();
  CHECK_THROWS_WITH(g.add_edge(e),
                    "pose graph: edge 0 (1 -> 2): the information matrix is not symmetric positive semi-definite");
  e.information = Matrix6d::Identity();
  e.information(3, 3) = INFINITY;
  CHECK_THROWS_WITH(g.add_edge(e), "pose graph: edge 0 (1 -> 2): the information matrix is not finite");
  e.information = Matrix6d::Identity();
  e.loss = RobustKernel{RobustLoss::kHuber, 0.0};
  CHECK_THROWS_WITH(g.add_edge(e), "pose graph: edge 0 (1 -> 2): the robust-loss scale must be finite and > 0");
  e.loss = {};
  g.add_edge(e);
  CHECK_THROWS_WITH(g.validate(),
                    "pose graph is disconnected: 1 node(s) are not linked by any edge path to a fixed node (ids 3); "
                    "add edges or fix a node in each part");
  CHECK_THROWS_WITH(g.optimize(), Catch::Contains("disconnected"));
  CHECK_THROWS_WITH(g.initialize_chordal(), Catch::Contains("disconnected"));
  CHECK_THROWS_WITH(g.set_fixed(7), "pose graph: node 7 does not exist");
}

TEST_CASE("PoseGraphSE3: a workspace used by another graph gives the same result to the last bit",
          "[graph][se3][workspace]") {
  sim::PoseGraphProblemSE3Config c;
  c.nodes = 150;
  c.lap = 50;
  const sim::PoseGraphProblemSE3 pr = sim::make_pose_graph_problem_se3(c);
  c.nodes = 220;
  c.seed = 9;
  PoseGraphSE3Workspace used;
  PoseGraphSE3 other = sim::to_pose_graph_se3(sim::make_pose_graph_problem_se3(c));
  other.initialize_chordal(used);
  (void)other.optimize({}, used);
  CHECK(used.capacity_bytes() > 0);
  PoseGraphSE3 a = sim::to_pose_graph_se3(pr);
  PoseGraphSE3 b = a;
  a.initialize_chordal();
  b.initialize_chordal(used);
  const PoseGraphSummary sa = a.optimize();
  const PoseGraphSummary sb = b.optimize({}, used);
  CHECK(sa.final_cost == sb.final_cost);
  CHECK(sa.iterations == sb.iterations);
  for (std::size_t k = 0; k < a.num_nodes(); ++k) {
    CHECK(a.poses()[k].translation() == b.poses()[k].translation());
    CHECK(a.poses()[k].so3().quaternion().coeffs() == b.poses()[k].so3().quaternion().coeffs());
  }
  CHECK(a.workspace_bytes() > 0);
  a.release_workspace();
  CHECK(a.workspace_bytes() == 0);
  used.release();
  CHECK(used.capacity_bytes() == 0);
}

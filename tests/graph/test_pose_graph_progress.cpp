// PoseGraphOptions::progress: called once per iteration with the iteration,
// the cost, the step and the damping, and only observing (the same
// iterations and bit-identical poses with and without it).

#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/graph/pose_graph_options.hpp>
#include <posefuse/sim/pose_graph_4dof.hpp>

namespace {

using posefuse::PoseGraph4Dof;
using posefuse::PoseGraphIteration;
using posefuse::PoseGraphOptions;
using posefuse::PoseGraphSummary;

PoseGraph4Dof problem(bool planar) {
  posefuse::sim::PoseGraphProblemConfig c;
  c.nodes = 400;
  c.planar = planar;
  c.seed = 7;
  return posefuse::sim::to_pose_graph(posefuse::sim::make_pose_graph_problem(c));
}

bool same_bits(const PoseGraph4Dof& a, const PoseGraph4Dof& b) {
  if (a.num_nodes() != b.num_nodes()) return false;
  for (std::size_t k = 0; k < a.num_nodes(); ++k) {
    const auto& x = a.poses()[k];
    const auto& y = b.poses()[k];
    const double u[6] = {x.p.x(), x.p.y(), x.p.z(), x.yaw, x.roll, x.pitch};
    const double v[6] = {y.p.x(), y.p.y(), y.p.z(), y.yaw, y.roll, y.pitch};
    if (std::memcmp(u, v, sizeof u) != 0) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("PoseGraphOptions::progress is told every iteration and changes nothing", "[graph][progress]") {
  const bool planar = GENERATE(true, false);
  const bool lm = GENERATE(true, false);
  INFO("planar " << planar << ", levenberg_marquardt " << lm);
  PoseGraph4Dof quiet = problem(planar);
  PoseGraph4Dof told = problem(planar);
  PoseGraphOptions o;
  o.levenberg_marquardt = lm;
  const PoseGraphSummary a = quiet.optimize(o);

  std::vector<PoseGraphIteration> seen;
  o.progress = [&seen](const PoseGraphIteration& it) { seen.push_back(it); };
  const PoseGraphSummary b = told.optimize(o);

  CHECK(same_bits(quiet, told));
  CHECK(a.iterations == b.iterations);
  CHECK(a.accepted == b.accepted);
  CHECK(a.final_cost == b.final_cost);
  CHECK(a.termination == b.termination);

  REQUIRE(b.iterations > 1);
  REQUIRE(seen.size() == std::size_t(b.iterations));
  int accepted = 0;
  for (std::size_t k = 0; k < seen.size(); ++k) {
    CHECK(seen[k].iteration == int(k) + 1);
    CHECK(seen[k].step_norm > 0.0);
    CHECK((seen[k].lambda > 0.0) == lm);
    if (k > 0) CHECK(seen[k].cost <= seen[k - 1].cost);
    accepted += seen[k].accepted ? 1 : 0;
  }
  CHECK(accepted == b.accepted);
  CHECK(seen.front().cost < b.initial_cost);
  CHECK(seen.back().cost == b.final_cost);
}

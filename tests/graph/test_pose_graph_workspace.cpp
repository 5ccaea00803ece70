// The pose graph's solver buffers: each graph owns its own (no state shared
// between graphs), they hold no result (interleaved solves, a caller's
// workspace, a released one: all equal a graph solved alone, to the last
// bit), and they are freed with the graph or by release_workspace().

#include <catch2/catch.hpp>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/sim/pose_graph_4dof.hpp>

using namespace posefuse;

namespace {

/// A seeded problem of the simulator: 4-DoF (hills, roll and pitch) or planar.
PoseGraph4Dof make_graph(int nodes, std::uint32_t seed, bool planar, bool cauchy_loops) {
  sim::PoseGraphProblemConfig c;
  c.nodes = nodes;
  c.seed = seed;
  c.planar = planar;
  return sim::to_pose_graph(sim::make_pose_graph_problem(c),
                            cauchy_loops ? RobustKernel{RobustLoss::kCauchy, 1.0} : RobustKernel{});
}

/// A graph's poses and the summary of the solve that left them.
struct Solved {
  std::vector<Pose4Dof> poses;
  PoseGraphSummary summary;
};

/// Every pose and summary field but the time equal, bit for bit.
void require_same(const PoseGraph4Dof& g, const PoseGraphSummary& s, const Solved& expected) {
  CHECK(s.initial_cost == expected.summary.initial_cost);
  CHECK(s.final_cost == expected.summary.final_cost);
  CHECK(s.iterations == expected.summary.iterations);
  CHECK(s.accepted == expected.summary.accepted);
  CHECK(s.termination == expected.summary.termination);
  CHECK(s.planar == expected.summary.planar);
  REQUIRE(g.num_nodes() == expected.poses.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < g.num_nodes(); ++k) {
    const Pose4Dof& p = g.poses()[k];
    const Pose4Dof& q = expected.poses[k];
    if (p.p != q.p || p.yaw != q.yaw) ++differing;
  }
  CHECK(differing == 0);
}

/// A few LM iterations per call, so that a solve is spread over many calls.
PoseGraphOptions few_iterations() {
  PoseGraphOptions o;
  o.max_iterations = 2;
  return o;
}

}  // namespace

TEST_CASE("PoseGraph4Dof workspace: interleaved solves of two graphs equal each solved alone",
          "[graph][workspace]") {
  // Different sizes and paths (4-DoF with robust loops, planar after the
  // rotation-first start), so that a buffer left by one graph would be the
  // wrong size or pattern for the other.
  const PoseGraph4Dof a0 = make_graph(300, 3, false, true);
  const PoseGraph4Dof b0 = make_graph(520, 8, true, false);
  REQUIRE_FALSE(a0.is_planar());
  REQUIRE(b0.is_planar());
  constexpr int kCalls = 4;

  // Alone: each graph solved by itself, kCalls short solves in a row.
  std::vector<Solved> a_alone, b_alone;
  {
    PoseGraph4Dof a = a0, b = b0;
    for (int k = 0; k < kCalls; ++k) {
      const PoseGraphSummary s = a.optimize(few_iterations());
      a_alone.push_back({a.poses(), s});
    }
    b.initialize_rotation_first();
    for (int k = 0; k < kCalls; ++k) {
      const PoseGraphSummary s = b.optimize(few_iterations());
      b_alone.push_back({b.poses(), s});
    }
  }
  // The solves do progress, on both paths.
  REQUIRE(a_alone.back().summary.final_cost < 0.5 * a_alone.front().summary.initial_cost);
  REQUIRE(b_alone.back().summary.final_cost < b_alone.front().summary.initial_cost);
  REQUIRE(b_alone.back().summary.planar);

  SECTION("each graph with its own workspace") {
    PoseGraph4Dof a = a0, b = b0;
    b.initialize_rotation_first();
    for (int k = 0; k < kCalls; ++k) {
      const PoseGraphSummary sa = a.optimize(few_iterations());
      const PoseGraphSummary sb = b.optimize(few_iterations());
      INFO("call " << k);
      require_same(a, sa, a_alone[std::size_t(k)]);
      require_same(b, sb, b_alone[std::size_t(k)]);
    }
  }
  SECTION("both graphs through one caller-held workspace") {
    PoseGraphWorkspace shared;
    PoseGraph4Dof a = a0, b = b0;
    b.initialize_rotation_first(shared);
    for (int k = 0; k < kCalls; ++k) {
      const PoseGraphSummary sa = a.optimize(few_iterations(), shared);
      const PoseGraphSummary sb = b.optimize(few_iterations(), shared);
      INFO("call " << k);
      require_same(a, sa, a_alone[std::size_t(k)]);
      require_same(b, sb, b_alone[std::size_t(k)]);
    }
    CHECK(shared.capacity_bytes() > 0);
    CHECK(a.workspace_bytes() == 0);  // the graphs' own buffers were never used
    CHECK(b.workspace_bytes() == 0);
  }
}

TEST_CASE("PoseGraph4Dof workspace: owned by the graph, released on request", "[graph][workspace]") {
  const PoseGraph4Dof start = make_graph(400, 5, false, false);
  PoseGraph4Dof a = start;
  PoseGraph4Dof b = start;
  CHECK(a.workspace_bytes() == 0);  // nothing before the first solve
  const PoseGraphSummary sa = a.optimize();
  const std::size_t held = a.workspace_bytes();
  CHECK(held > 100'000);            // the factor of a 400-node graph and its companions
  CHECK(b.workspace_bytes() == 0);  // b shares nothing with a
  CHECK(PoseGraph4Dof(a).workspace_bytes() == 0);  // a copy starts empty

  // A second solve of the same graph reuses the buffers: no growth.
  PoseGraph4Dof again = start;
  again.optimize();
  const std::size_t after_first = again.workspace_bytes();
  again.set_pose(again.ids().back(), start.poses().back());
  again.optimize();
  CHECK(again.workspace_bytes() == after_first);

  a.release_workspace();
  CHECK(a.workspace_bytes() == 0);
  // Released buffers hold no result: b, solved after, equals a.
  const PoseGraphSummary sb = b.optimize();
  require_same(b, sb, Solved{a.poses(), sa});

  // Moving a graph moves its buffers.
  const std::size_t b_held = b.workspace_bytes();
  PoseGraph4Dof moved = std::move(b);
  CHECK(moved.workspace_bytes() == b_held);

  PoseGraphWorkspace w;
  CHECK(w.capacity_bytes() == 0);
  PoseGraph4Dof c = start;
  c.optimize({}, w);
  CHECK(w.capacity_bytes() > 100'000);
  CHECK(PoseGraphWorkspace(w).capacity_bytes() == 0);  // copies are empty: scratch, not state
  w.release();
  CHECK(w.capacity_bytes() == 0);
}

// The allocator's own count of bytes in use, where it is glibc's (not under
// a sanitizer, whose allocator glibc does not see).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define POSEFUSE_TEST_SANITIZED_HEAP 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define POSEFUSE_TEST_SANITIZED_HEAP 1
#endif
#endif

#if defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33) && !defined(POSEFUSE_TEST_SANITIZED_HEAP)
TEST_CASE("PoseGraph4Dof workspace: destroying a graph gives its buffers back", "[graph][workspace]") {
  const auto in_use = [] {
    const struct mallinfo2 m = mallinfo2();
    return m.uordblks + m.hblkhd;  // heap chunks in use + mmapped blocks
  };
  const PoseGraph4Dof start = make_graph(600, 9, false, false);
  PoseGraph4Dof first = start;  // the same solve once, so that one-off allocations are done
  first.optimize();
  first.release_workspace();
  std::size_t before = 0, during = 0, after = 0, held = 0;
  {
    before = in_use();
    PoseGraph4Dof g = start;
    g.optimize();
    held = g.workspace_bytes();
    during = in_use();
  }
  after = in_use();
  INFO("in use before " << before << " B, with the solved graph " << during << " B, after " << after
                        << " B; its workspace " << held << " B");
  REQUIRE(held > 100'000);
  CHECK(during >= before + held);  // the allocator does see the buffers
  // ... and gets them back with the graph. Small freed blocks that glibc
  // keeps in its per-thread cache still count as in use, hence a margin of
  // 5 % of the workspace (buffers kept past the graph would be all of it).
  CHECK(after < before + held / 20);
}
#endif

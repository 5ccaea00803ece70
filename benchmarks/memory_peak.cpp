// memory_peak: peak memory of one workload, run once per process.
//
//   memory_peak graph_posefuse [N]   build PoseGraph4Dof + optimize() on the
//                                    simulated 4-DoF problem of N nodes
//                                    (default 100 000; seed 42, the problem
//                                    of bench_graph's BM_PoseGraph4Dof rows,
//                                    from the chained odometry)
//   memory_peak graph_ceres [N]      build the ceres::Problem + Solve on the
//                                    same problem, from the same start, with
//                                    bench_graph's settings (only when Ceres
//                                    is found)
//   memory_peak preintegration [S]   pre-integrate a 200 Hz IMU log of S
//                                    seconds (default 600: 10 minutes,
//                                    120 001 samples, sim/imu.hpp with noise)
//                                    into one Preintegration
//
// Two measures, both taken around the workload only (the generated problem
// or IMU log is made first and is part of the baseline):
//  * heap: every malloc, calloc, realloc, memalign / posix_memalign /
//    aligned_alloc and free of the process (operator new, Eigen, Ceres,
//    CHOLMOD and BLAS all allocate through them) is counted by
//    malloc_usable_size; the figure is the peak of the live heap bytes
//    during the workload minus the live bytes before it. This is exact for
//    the heap and ignores what the allocator keeps cached or unmapped.
//  * RSS: getrusage's ru_maxrss (peak resident set, KiB) after the workload
//    minus ru_maxrss before it: what the kernel saw, including pages the
//    allocator did not return, stacks, and (for Ceres) its libraries' touched
//    pages. Coarser (page granularity, high-water mark of the whole process).
//
// One line of output: workload, peak heap bytes, RSS delta KiB, and the
// result (χ² and iterations, or the number of samples) to check that the
// workload did what it says. Run each case in its own process, e.g.
//
//   for c in graph_posefuse graph_ceres preintegration; do OMP_THREAD_LIMIT=1 ./memory_peak $c; done
//
// glibc only (the __libc_* entry points and malloc_usable_size).

#include <malloc.h>
#include <sys/resource.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <posefuse/graph/pose_graph_4dof.hpp>
#include <posefuse/inertial/preintegrate.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/sim/pose_graph_4dof.hpp>

#ifdef POSEFUSE_HAVE_CERES
#include "ceres_pose_graph_4dof.hpp"
#endif

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);
}

namespace {

std::atomic<long long> g_live{0};
std::atomic<long long> g_peak{0};

void count_in(void* p) {
  if (p == nullptr) return;
  const long long now = g_live.fetch_add(static_cast<long long>(malloc_usable_size(p))) +
                        static_cast<long long>(malloc_usable_size(p));
  long long peak = g_peak.load();
  while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {
  }
}
void count_out(void* p) {
  if (p != nullptr) g_live.fetch_sub(static_cast<long long>(malloc_usable_size(p)));
}

}  // namespace

// The process's allocator entry points, counted (see the file comment).
extern "C" {
void* malloc(std::size_t n) {
  void* p = __libc_malloc(n);
  count_in(p);
  return p;
}
void free(void* p) {
  count_out(p);
  __libc_free(p);
}
void* calloc(std::size_t n, std::size_t size) {
  void* p = __libc_calloc(n, size);
  count_in(p);
  return p;
}
void* realloc(void* old, std::size_t n) {
  count_out(old);
  void* p = __libc_realloc(old, n);
  if (p != nullptr) count_in(p);
  else if (old != nullptr && n != 0) count_in(old);  // failed: the old block stays
  return p;
}
void* memalign(std::size_t alignment, std::size_t n) {
  void* p = __libc_memalign(alignment, n);
  count_in(p);
  return p;
}
void* aligned_alloc(std::size_t alignment, std::size_t n) { return memalign(alignment, n); }
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  void* p = memalign(alignment, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void* valloc(std::size_t n) { return memalign(4096, n); }
}

namespace {

using namespace posefuse;

long max_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

/// Measures `work` (see the file comment) and prints one line.
template <class Work>
int measure(const std::string& name, Work&& work) {
  const long rss0 = max_rss_kib();
  const long long live0 = g_live.load();
  g_peak.store(live0);
  const std::string result = work();
  const long long peak = g_peak.load() - live0;
  const long rss = max_rss_kib() - rss0;
  std::printf("%s: peak heap %.1f MiB (%lld bytes), max RSS +%.1f MiB, %s\n", name.c_str(),
              double(peak) / (1024.0 * 1024.0), peak, double(rss) / 1024.0, result.c_str());
  return 0;
}

sim::PoseGraphProblem graph_problem(int nodes) {
  sim::PoseGraphProblemConfig c;
  c.nodes = nodes;
  c.seed = 42;
  return sim::make_pose_graph_problem(c);
}

std::string chi2_line(double chi2, int iterations) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "chi2 %.10g, %d iterations", chi2, iterations);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string what = argc > 1 ? argv[1] : "";
  const double arg = argc > 2 ? std::atof(argv[2]) : 0.0;
  if (what == "graph_posefuse") {
    const int n = arg > 0 ? int(arg) : 100000;
    const sim::PoseGraphProblem pr = graph_problem(n);
    return measure("graph_posefuse " + std::to_string(n), [&] {
      PoseGraph4Dof g = sim::to_pose_graph(pr);
      const PoseGraphSummary s = g.optimize();
      return chi2_line(s.final_cost, s.iterations);
    });
  }
  if (what == "graph_ceres") {
#ifdef POSEFUSE_HAVE_CERES
    const int n = arg > 0 ? int(arg) : 100000;
    const sim::PoseGraphProblem pr = graph_problem(n);
    return measure("graph_ceres " + std::to_string(n), [&] {
      std::vector<std::array<double, 4>> x = bench::ceres_blocks_4dof(pr.initial);
      const bench::CeresRun run = bench::solve_4dof_with_ceres(pr.edges, pr.initial, x);
      return chi2_line(run.chi2, run.iterations);
    });
#else
    std::fprintf(stderr, "memory_peak: built without Ceres\n");
    return 2;
#endif
  }
  if (what == "preintegration") {
    const double seconds = arg > 0 ? arg : 600.0;
    sim::ImuSimConfig c;
    c.rate_hz = 200.0;
    c.noise = ImuNoise{};  // the default densities
    const sim::ImuSequence log = sim::simulate_imu(c, seconds);
    const std::int64_t t0 = log.samples.front().t_ns, t1 = log.samples.back().t_ns;
    return measure("preintegration " + std::to_string(log.samples.size()) + " samples", [&] {
      Preintegration p(c.noise);
      const ImuStatus st = preintegrate(log.samples, t0, t1, p);
      char buf[96];
      std::snprintf(buf, sizeof buf, "status %s, %.3f s integrated", to_string(st), p.dt_s());
      return std::string(buf);
    });
  }
  std::fprintf(stderr, "usage: memory_peak graph_posefuse [N] | graph_ceres [N] | preintegration [seconds]\n");
  return 2;
}

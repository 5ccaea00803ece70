#pragma once
/// @file
/// Seed 000's benchmark inputs, shared by bench_filters and
/// bench_opencv_kalman so that both time the same frames: 1024 planar
/// displacements u_k = (1 + n, 0.2 n) and positions z_k = sum(u) + (n, n),
/// n ~ N(0, 0.3²), from std::mt19937 seeded with 3.
#include <Eigen/Core>
#include <cstddef>
#include <random>
#include <vector>

namespace posefuse_bench {

/// Number of seed-000 frames (a power of two: the benchmarks cycle by mask).
inline constexpr std::size_t kSeed000Frames = 1024;

/// Controls u and measurements z of seed 000's filter, one per frame.
struct PlanarFrames {
  std::vector<Eigen::Vector2d> u, z;
};

/// The frames, generated once.
inline const PlanarFrames& seed000_frames() {
  static const PlanarFrames f = []() __attribute__((noinline)) {
    PlanarFrames out;
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 0.3);
    Eigen::Vector2d p(0, 0);
    for (std::size_t k = 0; k < kSeed000Frames; ++k) {
      const double sx = n(rng);
      const double sy = n(rng);
      const Eigen::Vector2d step(1.0 + sx, 0.2 * sy);
      p += step;
      out.u.push_back(step);
      const double zx = n(rng);
      const double zy = n(rng);
      out.z.push_back(p + Eigen::Vector2d(zx, zy));
    }
    return out;
  }();
  return f;
}

}  // namespace posefuse_bench

#pragma once
/// @file
/// The scene of the feature-track simulator (sim/feature_tracks.hpp; not
/// API): its landmarks, on the room walls around the path and free at
/// stated depths in front of the camera.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/sim/detail/rng.hpp>
#include <posefuse/vio/camera.hpp>

namespace posefuse::sim::detail {

/// The axis-aligned room: the bounding box of the camera positions grown by
/// `margin` on every side.
struct Room {
  Eigen::Vector3d lo, hi;
  [[nodiscard]] bool contains(const Eigen::Vector3d& p, double inset) const {
    return (p.array() > lo.array() + inset).all() && (p.array() < hi.array() - inset).all();
  }
};

[[nodiscard]] inline Room room_around(const std::vector<Eigen::Isometry3d>& T_W_C, double margin) {
  Room r{T_W_C.front().translation(), T_W_C.front().translation()};
  for (const Eigen::Isometry3d& T : T_W_C) {
    r.lo = r.lo.cwiseMin(T.translation());
    r.hi = r.hi.cwiseMax(T.translation());
  }
  r.lo.array() -= margin;
  r.hi.array() += margin;
  return r;
}

/// Landmarks uniformly on the six faces of the room, `density` per m²
/// (each face gets round(area * density)).
inline void add_wall_landmarks(const Room& room, double density, SeededRng& rng,
                               std::vector<Eigen::Vector3d>& out) {
  const Eigen::Vector3d size = room.hi - room.lo;
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const auto n = std::size_t(std::llround(size(a) * size(b) * density));
    for (const double side : {room.lo(axis), room.hi(axis)}) {
      for (std::size_t i = 0; i < n; ++i) {
        Eigen::Vector3d p;
        p(axis) = side;
        p(a) = rng.uniform(room.lo(a), room.hi(a));
        p(b) = rng.uniform(room.lo(b), room.hi(b));
        out.push_back(p);
      }
    }
  }
}

/// `count` free points: each on the ray of a uniformly random pixel of a
/// uniformly random frame, at a depth (camera z) uniform in
/// [depth_min, depth_max], kept when inside the room (0.1 m from its walls);
/// up to 20 draws per point, so fewer than `count` when the room is small.
inline void add_free_landmarks(const std::vector<Eigen::Isometry3d>& T_W_C, const PinholeRadtan& cam,
                               const Room& room, std::size_t count, double depth_min, double depth_max,
                               SeededRng& rng, std::vector<Eigen::Vector3d>& out) {
  for (std::size_t i = 0; i < count; ++i) {
    for (int attempt = 0; attempt < 20; ++attempt) {
      const Eigen::Isometry3d& T = T_W_C[rng.below(T_W_C.size())];
      const Eigen::Vector2d uv(rng.uniform(-0.5, cam.width - 0.5), rng.uniform(-0.5, cam.height - 0.5));
      const double depth = rng.uniform(depth_min, depth_max);
      const Eigen::Vector2d xy = cam.undistort(uv);
      if (!xy.allFinite()) continue;
      const Eigen::Vector3d p = T * Eigen::Vector3d(xy.x() * depth, xy.y() * depth, depth);
      if (!room.contains(p, 0.1)) continue;
      out.push_back(p);
      break;
    }
  }
}

/// A grid over the image that answers "is there a feature closer than d?"
/// (cells of size d, so only the 3x3 neighbourhood is searched).
class PixelGrid {
 public:
  PixelGrid(int width, int height, double d)
      : d_(d), nx_(d > 0 ? std::max(1, int(std::ceil((width + 1) / d))) : 1),
        ny_(d > 0 ? std::max(1, int(std::ceil((height + 1) / d))) : 1), cells_(std::size_t(nx_ * ny_)) {}
  void clear() {
    for (auto& c : cells_) c.clear();
  }
  void add(const Eigen::Vector2d& uv) { cells_[index(cell(uv.x(), nx_), cell(uv.y(), ny_))].push_back(uv); }
  [[nodiscard]] bool free_at(const Eigen::Vector2d& uv) const {
    if (d_ <= 0) return true;
    const int cx = cell(uv.x(), nx_), cy = cell(uv.y(), ny_);
    for (int y = std::max(0, cy - 1); y <= std::min(ny_ - 1, cy + 1); ++y)
      for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x)
        for (const Eigen::Vector2d& q : cells_[index(x, y)])
          if ((q - uv).squaredNorm() < d_ * d_) return false;
    return true;
  }

 private:
  [[nodiscard]] int cell(double c, int n) const {
    if (d_ <= 0) return 0;
    return std::clamp(int(std::floor((c + 0.5) / d_)), 0, n - 1);
  }
  [[nodiscard]] std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(nx_) + std::size_t(x); }
  double d_;
  int nx_, ny_;
  std::vector<std::vector<Eigen::Vector2d>> cells_;
};

}  // namespace posefuse::sim::detail

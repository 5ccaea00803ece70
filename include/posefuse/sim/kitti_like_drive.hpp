#pragma once
/// @file
/// A documented synthetic stand-in for KITTI odometry sequence 06: a
/// ground-truth drive and a SLAM-like estimate of it with drift and noise.
///
/// **Ground truth.** A stadium-shaped loop on the road plane — two straights
/// of `straight_m` joined by half circles of `radius_m` — driven once at
/// constant speed `speed_mps`, sampled at `rate_hz`, closing on itself. KITTI
/// 06 is an urban loop of about 1.2 km in 1101 frames at 10 Hz; the defaults
/// reproduce that length and rate. Poses are in KITTI's camera convention
/// (x right, y down, z forward), so the road plane is x-z and heading is a
/// rotation about y. The road rises and falls by `height_m` (a slow sine in y).
///
/// **Estimate.** The truth perturbed by the two kinds of error a visual SLAM
/// trajectory has:
/// * *drift*: a heading error that follows a random walk
///   (`heading_drift_rad_per_sqrt_m` per sqrt(metre) travelled) and a
///   constant scale error `scale_error`, integrated along the path, so
///   position error grows smoothly with distance;
/// * *jitter*: independent zero-mean Gaussian noise of `jitter_m` (m) on each
///   axis of every frame's position (feature-matching noise).
/// Everything comes from one `std::mt19937_64` seeded with `seed`, so a seed
/// gives the same data on every machine whose standard library implements
/// the distributions alike (the test suite checks properties, not digits).

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>
#include <random>

namespace posefuse::sim {

/// Parameters of the synthetic drive (see the file comment).
struct KittiLikeDriveConfig {
  double straight_m = 450.0;   ///< length of each straight (m)
  double radius_m = 45.0;      ///< radius of the two half circles (m)
  double speed_mps = 11.0;     ///< constant speed (m/s)
  double rate_hz = 10.0;       ///< frame rate (Hz)
  double height_m = 1.0;       ///< amplitude of the road's rise and fall (m)
  double heading_drift_rad_per_sqrt_m = 2.5e-4;  ///< random-walk heading drift
  double scale_error = 0.004;  ///< relative scale error of the estimate
  double jitter_m = 0.35;      ///< white position noise per axis (m)
  std::uint64_t seed = 6;      ///< random seed
};

/// A ground-truth trajectory and a drifting, noisy estimate of it, same stamps.
struct SyntheticDrive {
  Trajectory groundtruth;
  Trajectory estimate;
};

/// Generates the drive described in the file comment.
/// @throws posefuse::invalid_argument for non-positive lengths, speed or rate,
///         or negative noise
[[nodiscard]] inline SyntheticDrive make_kitti_like_drive(const KittiLikeDriveConfig& c = {}) {
  if (!(c.straight_m > 0 && c.radius_m > 0 && c.speed_mps > 0 && c.rate_hz > 0))
    throw invalid_argument("make_kitti_like_drive: lengths, speed and rate must be > 0");
  if (!(c.height_m >= 0 && c.heading_drift_rad_per_sqrt_m >= 0 && c.jitter_m >= 0))
    throw invalid_argument("make_kitti_like_drive: noise levels must be >= 0");
  constexpr double pi = std::numbers::pi;
  const double perimeter = 2 * c.straight_m + 2 * pi * c.radius_m;
  const double step = c.speed_mps / c.rate_hz;
  const auto frames = static_cast<std::size_t>(std::floor(perimeter / step)) + 1;

  // Arc length s -> (x, z, heading) on the stadium; heading 0 looks along +z.
  auto on_loop = [&](double s) {
    s = std::fmod(s, perimeter);
    const double L = c.straight_m;
    const double r = c.radius_m;
    if (s < L) return Eigen::Vector3d(0, s, 0);
    s -= L;
    if (s < pi * r) {
      const double a = s / r;  // turning right around (r, L)
      return Eigen::Vector3d(r - r * std::cos(a), L + r * std::sin(a), a);
    }
    s -= pi * r;
    if (s < L) return Eigen::Vector3d(2 * r, L - s, pi);
    s -= L;
    const double a = s / r;  // around (r, 0)
    return Eigen::Vector3d(r + r * std::cos(a), -r * std::sin(a), pi + a);
  };
  auto pose = [&](double x, double y, double z, double heading) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    // Camera looks along +z; a right turn (clockwise seen from above, y down)
    // is a positive rotation about y.
    T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    return T;
  };

  std::mt19937_64 rng(c.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  SyntheticDrive out;
  double drift_heading = 0;
  Eigen::Vector2d est_xz(0, 0);
  Eigen::Vector3d prev = on_loop(0);
  for (std::size_t k = 0; k < frames; ++k) {
    const double t = static_cast<double>(k) / c.rate_hz;
    const double s = static_cast<double>(k) * step;
    const Eigen::Vector3d g = on_loop(s);
    const double y = c.height_m * std::sin(2 * pi * s / perimeter * 3);
    out.groundtruth.push_back(t, pose(g.x(), y, g.y(), g.z()));

    if (k > 0) {
      // Integrate the true displacement through the drifting heading and scale.
      const Eigen::Vector2d d(g.x() - prev.x(), g.y() - prev.y());
      drift_heading += c.heading_drift_rad_per_sqrt_m * std::sqrt(d.norm()) * normal(rng);
      const Eigen::Rotation2Dd Rd(-drift_heading);
      est_xz += (1.0 + c.scale_error) * (Rd * d);
    }
    prev = g;
    const double jx = c.jitter_m * normal(rng);
    const double jz = c.jitter_m * normal(rng);
    out.estimate.push_back(
        t, pose(est_xz.x() + jx, y, est_xz.y() + jz, wrap_angle(g.z() + drift_heading)));
  }
  return out;
}

}  // namespace posefuse::sim

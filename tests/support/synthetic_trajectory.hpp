#pragma once
// Documented synthetic trajectories for io/ and eval/ tests (no real data).
//
// make_vehicle_trajectory: a car-like drive in KITTI's camera convention
// (x right, y down, z forward): speed 8-12 m/s, yaw rate a smooth random
// walk, small pitch/roll wobble, 10 Hz stamps starting at t0. Deterministic
// for a given seed (std::mt19937_64, explicit distributions), so test values
// are reproducible across runs (not across standard libraries).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <random>

#include <posefuse/core/trajectory.hpp>

namespace posefuse::test {

/// A uniformly random rotation (normalised Gaussian quaternion).
inline Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// A random pose: uniform rotation, translation N(0, sigma_t^2) per axis.
inline Eigen::Isometry3d random_pose(std::mt19937_64& rng, double sigma_t = 10.0) {
  std::normal_distribution<double> n(0.0, sigma_t);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = random_rotation(rng);
  T.translation() = Eigen::Vector3d(n(rng), n(rng), n(rng));
  return T;
}

/// Car-like trajectory T_world_cam with n poses at 10 Hz (see file comment).
inline Trajectory make_vehicle_trajectory(std::size_t n, unsigned seed, double t0 = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> speed(8.0, 12.0);
  std::normal_distribution<double> yaw_acc(0.0, 0.05);
  std::normal_distribution<double> wobble(0.0, 0.002);
  const double dt = 0.1;
  Trajectory traj;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0.0, yaw_rate = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    // Yaw turns about the camera's down axis (y); pitch about x, roll about z.
    T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(wobble(rng), Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(wobble(rng), Eigen::Vector3d::UnitZ()))
                     .toRotationMatrix();
    T.translation() = p;
    traj.push_back(t0 + dt * static_cast<double>(k), T);
    const double v = speed(rng);
    p += dt * v * Eigen::Vector3d(std::sin(yaw), 0.0, std::cos(yaw));
    yaw_rate = 0.9 * yaw_rate + yaw_acc(rng);
    yaw += dt * yaw_rate;
  }
  return traj;
}

/// Adds independent noise to every pose: translation N(0, sigma_t^2) per
/// axis, rotation by a random axis-angle with N(0, sigma_r^2) angle.
inline Trajectory perturb(const Trajectory& traj, double sigma_t, double sigma_r, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nt(0.0, sigma_t), nr(0.0, sigma_r), n(0.0, 1.0);
  Trajectory out = traj;
  for (Eigen::Isometry3d& T : out.poses) {
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    T.linear() = T.linear() * Eigen::AngleAxisd(nr(rng), axis).toRotationMatrix();
    T.translation() += Eigen::Vector3d(nt(rng), nt(rng), nt(rng));
  }
  return out;
}

}  // namespace posefuse::test

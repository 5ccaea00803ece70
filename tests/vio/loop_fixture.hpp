#pragma once
// A loop-closure scene for the vio tests: a body flying a circle (radius
// 3 m, 20 s a lap) looking outward at 3000 landmarks on a cylinder wall
// (radius 7 m), ids = landmark index (they recur on every lap), and
// keyframe records made from the truth with an injected 4-DoF drift (yaw
// and translation growing linearly in time), as the odometry would hand
// them on: pose, extrinsic, normalised observations (noise 0.5 px at 460 px
// focal) and world points in the drifted frame (noise 1 cm).
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/vio/keyframe_record.hpp>
#include <posefuse/vio/loop_closure.hpp>

namespace posefuse::test {

struct LoopScene {
  static constexpr double kRadius = 3.0, kWall = 7.0, kLapS = 20.0;
  std::vector<Eigen::Vector3d> landmarks;
  SE3d T_b_c;

  LoopScene() {
    std::mt19937_64 g(11);
    std::uniform_real_distribution<double> a(0, 2 * std::numbers::pi), h(-1.0, 3.0);
    for (int i = 0; i < 3000; ++i) {
      const double t = a(g);
      landmarks.emplace_back(kWall * std::cos(t), kWall * std::sin(t), h(g));
    }
    Eigen::Matrix3d R_bc;  // camera z = body x (outward), camera x = -body y, camera y = -body z
    R_bc << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    T_b_c = SE3d(Eigen::Vector3d(0.05, 0, 0), SO3d(R_bc));
  }

  // True body pose at time t (s): on the circle, facing outward, a small roll.
  static SE3d truth(double t) {
    const double th = 2 * std::numbers::pi * t / kLapS;
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(th, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.05 * std::sin(th), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    return SE3d(Eigen::Vector3d(kRadius * std::cos(th), kRadius * std::sin(th), 1.0), SO3d(R));
  }

  // A 4-DoF drift (yaw rate rad/s, translation rate m/s) from time t0, on top of an offset.
  struct Drift {
    double yaw0 = 0, yaw_rate = 0;
    Eigen::Vector3d t0 = Eigen::Vector3d::Zero(), rate = Eigen::Vector3d::Zero();
    double start_s = 0;
    [[nodiscard]] DriftCorrection at(double t) const {
      return DriftCorrection{yaw0 + yaw_rate * (t - start_s), t0 + rate * (t - start_s)};
    }
  };

  // The keyframe record the odometry would give at time t with drift d.
  [[nodiscard]] KeyframeRecord record(double t, const Drift& d, std::uint64_t seed) const {
    return record_seen_from(t, d, seed, truth(t));
  }

  // As record(), but the features are what a camera at body pose `view`
  // (true frame) would see: with view != truth(t), a consistent but false
  // view of another place (perceptual aliasing).
  [[nodiscard]] KeyframeRecord record_seen_from(double t, const Drift& d, std::uint64_t seed, const SE3d& view) const {
    std::mt19937_64 g(seed);
    std::normal_distribution<double> px(0.0, 0.5 / 460.0), pt(0.0, 0.01);
    const SE3d T_w_b = truth(t);
    const SE3d T_w_c = view * T_b_c;
    const SE3d T_c_w = T_w_c.inverse();
    const DriftCorrection D = d.at(t);
    KeyframeRecord r;
    r.t_ns = std::int64_t(std::llround(t * 1e9));
    r.T_w_b = D.apply(T_w_b);
    r.T_b_c = T_b_c;
    for (std::size_t i = 0; i < landmarks.size(); ++i) {
      const Eigen::Vector3d p = T_c_w.act(landmarks[i]);
      if (p.z() < 0.5 || std::abs(p.x() / p.z()) > 0.75 || std::abs(p.y() / p.z()) > 0.5) continue;
      KeyframeFeature f;
      f.id = i;
      f.m = Eigen::Vector2d(p.x() / p.z() + px(g), p.y() / p.z() + px(g));
      f.has_point = true;
      f.p_w = D.rotation() * landmarks[i] + D.t + Eigen::Vector3d(pt(g), pt(g), pt(g));
      r.features.push_back(f);
    }
    return r;
  }
};

// Keyframe stamps every 0.25 s in [t0, t1).
inline std::vector<double> keyframe_times(double t0, double t1) {
  std::vector<double> t;
  for (int k = 0; t0 + 0.25 * k < t1 - 1e-9; ++k) t.push_back(t0 + 0.25 * k);
  return t;
}

// Position + yaw aligned APE (RMSE, m) of poses against the truth at their stamps.
inline double ape_posyaw(const std::vector<double>& t, const std::vector<SE3d>& poses) {
  Trajectory ref, est;
  for (std::size_t k = 0; k < t.size(); ++k) {
    ref.push_back(t[k], LoopScene::truth(t[k]).isometry());
    est.push_back(t[k], poses[k].isometry());
  }
  return ape(ref, est, PoseRelation::kTranslation, Alignment::kPosYaw).stats.rmse;
}

// Largest position error (m) against the truth, without alignment.
inline double max_error(const std::vector<double>& t, const std::vector<SE3d>& poses) {
  double e = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    e = std::max(e, (poses[k].translation() - LoopScene::truth(t[k]).translation()).norm());
  return e;
}

inline std::int64_t ns(double t) { return std::int64_t(std::llround(t * 1e9)); }

}  // namespace posefuse::test

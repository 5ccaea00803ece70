#pragma once
/// @file
/// The state of a visual-inertial sliding window: keyframes \f$ [p, v, q, b_a, b_g] \f$
/// with the IMU factor from the previous keyframe, features with an inverse
/// depth anchored at their first observation in the window, the camera-IMU
/// extrinsic, and the marginalisation prior with the points it was
/// linearised at. Plus the two geometric helpers every stage needs:
/// triangulation of a feature and re-anchoring of its inverse depth.
///
/// **Prior.** A MarginalizationPrior (graph/marginalization.hpp) over a list
/// of blocks (keyframes by id, the extrinsic), each with its reference value
/// \f$ \bar x \f$ (the estimate when the prior was formed); its residual at
/// the estimate x is \f$ r_0 + J\,(x \ominus \bar x) \f$, stacked over the
/// blocks. A keyframe or extrinsic in the prior also keeps its first
/// estimate (`fej`): the point at which every factor's Jacobian with respect
/// to it is evaluated when first-estimate Jacobians are on (see
/// vio/window_problem.hpp).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include <posefuse/graph/marginalization.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/vio/reprojection_factor.hpp>

namespace posefuse {

/// One keyframe of the window.
struct VioFrame {
  std::int64_t t_ns = 0;             ///< image stamp (ns)
  std::uint64_t id = 0;              ///< unique, increasing frame id
  ImuState x;                        ///< current estimate
  std::optional<ImuState> fej;       ///< first estimate, set once the frame enters the prior
  Preintegration pre;                ///< IMU from the previous keyframe to this one (empty for the first)
  std::optional<ImuFactor> imu;      ///< factor built from `pre` (absent for the first frame)
  bool stationary = false;           ///< at rest: a zero-velocity factor (vio/window_problem.hpp) holds v
  /// The pose part \f$ (p, R) \f$ of a state.
  [[nodiscard]] static RigidPose pose(const ImuState& s) { return RigidPose{s.p, s.R}; }
};

/// One observation of a feature: the frame and its undistorted normalised coordinates.
struct VioObservation {
  std::uint64_t frame_id = 0;  ///< VioFrame::id
  Eigen::Vector2d m;           ///< (x/z, y/z) in that camera
};

/// A feature of the window: observations in frame order, the first is the anchor.
struct VioLandmark {
  std::vector<VioObservation> obs;  ///< obs[0] = anchor
  double inv_depth = 0.0;           ///< λ in the anchor camera (1/m)
  bool initialised = false;         ///< λ set by triangulation (and part of the solve)
};

/// One block of the marginalisation prior.
struct VioPriorBlock {
  bool extrinsic = false;    ///< the extrinsic block (6) rather than a keyframe (15)
  std::uint64_t frame_id = 0;  ///< the keyframe (when !extrinsic)
  ImuState frame_ref;        ///< reference value of a keyframe block
  RigidPose extrinsic_ref;   ///< reference value of the extrinsic block
  /// Tangent dimension.
  [[nodiscard]] int dim() const noexcept { return extrinsic ? 6 : 15; }
};

/// The marginalisation prior: residual \f$ r_0 + J\,(x \ominus \bar x) \f$ over the blocks.
struct VioPrior {
  MarginalizationPrior linear;        ///< r0, J (columns: blocks stacked in order)
  std::vector<VioPriorBlock> blocks;  ///< the variables, in the column order of J
};

/// The whole window (see the file comment).
struct VioWindow {
  std::vector<VioFrame> frames;                    ///< keyframes, oldest first
  std::map<std::uint64_t, VioLandmark> landmarks;  ///< by feature id (ordered: deterministic)
  RigidPose T_bc;                                  ///< camera → body extrinsic
  std::optional<RigidPose> T_bc_fej;               ///< its first estimate once in the prior
  bool estimate_extrinsic = false;                 ///< the extrinsic is a variable of the solve
  std::optional<VioPrior> prior;                   ///< marginalisation prior
  Eigen::Vector3d gravity_w{0.0, 0.0, -9.81};      ///< gravity in the world frame (m/s²)
  Eigen::Vector2d sqrt_info{460.0, 460.0};         ///< \f$ (f_u/\sigma, f_v/\sigma) \f$ of the residuals

  /// Slot (index in `frames`) of a frame id, -1 when not in the window.
  [[nodiscard]] int slot_of(std::uint64_t frame_id) const noexcept {
    for (std::size_t k = 0; k < frames.size(); ++k)
      if (frames[k].id == frame_id) return int(k);
    return -1;
  }
  /// Dimension of the camera-side system: 15 per keyframe (+ 6 for the extrinsic).
  [[nodiscard]] int dimension() const noexcept {
    return 15 * int(frames.size()) + (estimate_extrinsic ? 6 : 0);
  }
};

/// The world point of a feature from its anchor and inverse depth.
[[nodiscard]] inline Eigen::Vector3d landmark_world_point(const VioWindow& w, const VioLandmark& l) {
  const VioFrame& a = w.frames[std::size_t(w.slot_of(l.obs.front().frame_id))];
  const Eigen::Vector3d m(l.obs.front().m.x(), l.obs.front().m.y(), 1.0);
  return VioFrame::pose(a.x).act(w.T_bc.act(m / l.inv_depth));
}

/// The depth of a world point along the optical axis of a frame's camera.
[[nodiscard]] inline double camera_depth(const VioWindow& w, const VioFrame& f, const Eigen::Vector3d& P_w) {
  const Eigen::Vector3d P_b = f.x.R.inverse().act(P_w - f.x.p);
  return w.T_bc.R.inverse().act(P_b - w.T_bc.p).z();
}

/// Linear (DLT) triangulation of a feature from every observation whose
/// frame is in the window: the smallest eigenvector of the 4x4 normal matrix
/// \f$ \sum_k (m_k \times [R_k^\top \mid -R_k^\top t_k])^\top(\cdots) \f$ of the camera poses
/// \f$ (R_k, t_k) \f$ (camera → world).
/// @return the inverse depth in the anchor camera, or nullopt when the
///         point is at infinity, not in front of every camera, closer than
///         `min_depth` or farther than `max_depth` from the anchor, or when
///         the rays' largest angle is below `min_angle_rad`
[[nodiscard]] inline std::optional<double> triangulate_inverse_depth(const VioWindow& w, const VioLandmark& l,
                                                                     double min_depth, double max_depth,
                                                                     double min_angle_rad) {
  if (l.obs.size() < 2) return std::nullopt;
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector3d first_ray = Eigen::Vector3d::Zero();
  double max_angle = 0.0;
  int used = 0;
  for (const VioObservation& o : l.obs) {
    const int s = w.slot_of(o.frame_id);
    if (s < 0) continue;
    const VioFrame& f = w.frames[std::size_t(s)];
    const SO3d R_wc = f.x.R.compose(w.T_bc.R);
    const Eigen::Vector3d t_wc = f.x.R.act(w.T_bc.p) + f.x.p;
    const Eigen::Matrix3d RT = R_wc.matrix().transpose();
    Eigen::Matrix<double, 3, 4> P;
    P << RT, -RT * t_wc;
    const Eigen::Vector3d m(o.m.x(), o.m.y(), 1.0);
    const Eigen::Matrix<double, 3, 4> C = SO3d::hat(m) * P;
    A.noalias() += C.transpose() * C;
    const Eigen::Vector3d ray = R_wc.act(m.normalized());
    if (used == 0) first_ray = ray;
    else max_angle = std::max(max_angle, std::acos(std::clamp(first_ray.dot(ray), -1.0, 1.0)));
    ++used;
  }
  if (used < 2 || max_angle < min_angle_rad) return std::nullopt;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> es(A);
  const Eigen::Vector4d X = es.eigenvectors().col(0);
  if (!(std::abs(X(3)) > 1e-12)) return std::nullopt;
  const Eigen::Vector3d P_w = X.head<3>() / X(3);
  for (const VioObservation& o : l.obs) {
    const int s = w.slot_of(o.frame_id);
    if (s >= 0 && !(camera_depth(w, w.frames[std::size_t(s)], P_w) > min_depth)) return std::nullopt;
  }
  const double d = camera_depth(w, w.frames[std::size_t(w.slot_of(l.obs.front().frame_id))], P_w);
  if (!(d > min_depth && d < max_depth)) return std::nullopt;
  return 1.0 / d;
}

/// Drops the anchor observation of a feature and expresses its inverse
/// depth in the next observation's camera (the point in the world stays).
/// @return false when fewer than two observations remain or the point is
///         not in front of the new anchor (the feature is then uninitialised)
inline bool reanchor_landmark(const VioWindow& w, VioLandmark& l) {
  const bool had_depth = l.initialised && l.obs.size() >= 2;
  const Eigen::Vector3d P_w = had_depth ? landmark_world_point(w, l) : Eigen::Vector3d::Zero();
  l.obs.erase(l.obs.begin());
  if (!had_depth || l.obs.size() < 2) {
    l.initialised = false;
    return false;
  }
  const int s = w.slot_of(l.obs.front().frame_id);
  const double d = s < 0 ? -1.0 : camera_depth(w, w.frames[std::size_t(s)], P_w);
  if (!(d > 1e-3)) {
    l.initialised = false;
    return false;
  }
  l.inv_depth = 1.0 / d;
  return true;
}

}  // namespace posefuse

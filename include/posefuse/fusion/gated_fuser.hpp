#pragma once
/// @file
/// A sound replacement for seed 001's threshold fuser (eq 14-15): fuses
/// odometry and SLAM poses on the plane with their covariances, gates SLAM
/// with Mahalanobis tests, averages angles on the circle, and **re-anchors**
/// SLAM when it re-initialises in a new map frame instead of discarding it.
///
/// Every step is a step of the library's one estimation core, an
/// Ekf (filters/ekf.hpp) over PlanarPose with three models:
///
/// **State.** \f$x = [x, y, \theta]\f$ of the body in the world (=
/// odometry) frame with a 3x3 covariance P (the Ekf's belief), and
/// \f$T_{wm}\f$, the pose of the current SLAM map frame in the world,
/// estimated once per map (below).
///
/// **Odometry (prediction)**, Se2Odometry (models/se2_odometry.hpp). Only
/// increments are used: \f$\delta = O_{k-1}^{-1} \oplus O_k\f$,
/// \f$x \leftarrow x \oplus \delta\f$, \f$P \leftarrow F P F^T + J_\delta
/// Q_\delta J_\delta^T\f$ with body-frame noise \f$Q_\delta =
/// \mathrm{diag}(k_{xy}^2 s, k_{xy}^2 s, k_{\theta s}^2 s + k_{\theta\theta}^2
/// |\Delta\theta|)\f$ (s = distance). The fused pose is therefore odometry
/// *rebased onto the fused estimate* after every update — the same as
/// resetting dead reckoning to it — so odometry drift does not keep
/// accumulating into it.
///
/// **SLAM (update)**, PlanarPoseFix (models/planar_pose_fix.hpp). The SLAM
/// pose is transformed into the world, \f$z_w = T_{wm} \oplus z\f$, and fused
/// as a direct pose measurement, \f$H = I\f$, \f$S = P + R\f$,
/// \f$K = P S^{-1}\f$, \f$x \leftarrow x \boxplus K(z_w \boxminus x)\f$,
/// Joseph form — the heading residual wrapped: angle-aware averaging.
///
/// **Gates** on \f$r = z_w \boxminus x\f$, \f$S = P + R\f$, passed to the
/// Ekf update as a gate functor. kSeparate: position
/// \f$r_{xy}^T S_{xy}^{-1} r_{xy} \le \chi^2_2\f$ *and* heading
/// \f$r_\theta^2 / S_{\theta\theta} \le \chi^2_1\f$ — a large position
/// disagreement is rejected even when the headings agree, unlike seed eq 14.
/// kMahalanobis: \f$r^T S^{-1} r \le \chi^2_3\f$. kBoth: all three. A
/// rejection is FilterStatus::kGated with FuserStatus::rejected_by naming the
/// gate (the first that failed, in the order position, heading, joint).
///
/// **Heading (update)**, HeadingFix (models/heading_fix.hpp), e.g. a compass
/// aligned to the world: \f$r = \mathrm{wrap}(\psi - \theta)\f$, NIS gate
/// \f$r^2 / S \le\f$ gate_theta_chi2.
///
/// **Re-anchoring.** At the first SLAM pose and at every `new_map_frame`
/// (seed: ORB-SLAM re-initialised), the fuser pairs the following SLAM poses
/// \f$z_i\f$ with its own odometry-propagated poses \f$x_i\f$, over at least
/// `anchor_samples` poses and `anchor_min_travel_m` of travel: yaw = circular
/// mean of \f$\theta_{x,i} - \theta_{z,i}\f$, translation = mean of
/// \f$p_{x,i} - R(\mathrm{yaw})\,p_{z,i}\f$. When every pair then agrees at
/// the robot, \f$x_i \approx T_{wm} \oplus z_i\f$ within tolerance (a frozen
/// SLAM on a moving robot, or a jumping one, does not), the estimate becomes
/// \f$T_{wm}\f$ and fusion resumes. After `reanchor_after_rejects`
/// consecutive rejections the fuser assumes an unannounced map change and
/// re-anchors the same way. The map frame is then held fixed: whatever error
/// the pose had when it was anchored (drift while SLAM was unavailable) is
/// not observable from SLAM and stays; anchor_covariance() reports it, and
/// covariance() is relative to the anchored map. (An EKF that keeps
/// \f$T_{wm}\f$ in its state was tried first: re-linearising at a lever arm of
/// metres let it drift along that unobservable direction — the classic
/// EKF-SLAM inconsistency — and it did worse on the corridor.)

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/fusion/fuse_poses.hpp>
#include <posefuse/fusion/fuser_status.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/se2_odometry.hpp>

namespace posefuse {

/// Parameters of GatedFuser. Sigmas are 1-σ; gates are χ² quantiles.
template <std::floating_point T = double>
struct GatedFuserParams {
  T odom_xy_sigma_per_sqrt_m = T(0.02);        ///< position noise per √m travelled (m/√m)
  T odom_theta_sigma_per_sqrt_m = T(0.005);    ///< heading noise per √m travelled (rad/√m)
  T odom_theta_sigma_per_sqrt_rad = T(0.03);   ///< heading noise per √rad turned (rad/√rad)
  T slam_xy_sigma_m = T(0.05);                 ///< SLAM position noise (m)
  T slam_theta_sigma_rad = T(0.02);            ///< SLAM heading noise (rad)
  GateMode gate = GateMode::kSeparate;         ///< which gates apply
  T gate_xy_chi2 = T(13.8155);                 ///< χ²₂ at 0.999
  T gate_theta_chi2 = T(10.8276);              ///< χ²₁ at 0.999 (also for update_heading)
  T gate_joint_chi2 = T(16.2662);              ///< χ²₃ at 0.999
  int anchor_samples = 8;                      ///< min SLAM poses per anchor estimate (1..32)
  T anchor_min_travel_m = T(0.5);              ///< odometry travel the anchor window must span (m)
  T anchor_tol_xy_m = T(0.1);                  ///< max offset spread accepted (m)
  T anchor_tol_theta_rad = T(0.05);            ///< max offset spread accepted (rad)
  int reanchor_after_rejects = 15;             ///< consecutive rejections → re-anchor (≥ 1)
};

/// One synchronous step for GatedFuser used as a pipeline stage.
template <std::floating_point T = double>
struct GatedFuserInput {
  PlanarPose<T> odom;            ///< odometry pose (its own frame; increments are used)
  bool has_slam = false;         ///< whether `slam` holds a SLAM pose at the same instant
  PlanarPose<T> slam;            ///< SLAM body pose in its current map frame
  bool slam_new_map_frame = false;  ///< SLAM re-initialised: `slam` is in a new map frame
};

/// Result of one GatedFuser stage step.
template <std::floating_point T = double>
struct GatedFuserOutput {
  PlanarPose<T> pose;                         ///< fused pose in the world frame
  Eigen::Matrix<T, 3, 3> cov;                 ///< its covariance
  FilterStatus odom_status = FilterStatus::kApplied;  ///< what the prediction did
  /// What happened to the SLAM pose; empty when the input had none or the
  /// prediction was not applied (the SLAM pose is then not used).
  std::optional<FuserStatus> slam_status;
};

/// Covariance-weighted, gated, re-anchoring fusion of odometry and SLAM on
/// the plane (see the file comment for the equations), built on
/// Ekf<Se2Odometry<T>>. Fixed-size, no heap.
template <std::floating_point T = double>
class GatedFuser {
 public:
  using Scalar = T;
  using Pose = PlanarPose<T>;
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  using Mat3 = Eigen::Matrix<T, 3, 3>;
  using Input = GatedFuserInput<T>;
  using Output = GatedFuserOutput<T>;
  using Filter = Ekf<Se2Odometry<T>>;  ///< the estimation core
  static constexpr int kMaxAnchorSamples = 32;

  /// @throws posefuse::invalid_argument for a negative or non-finite sigma, a
  ///         non-positive gate or tolerance, or anchor_samples /
  ///         reanchor_after_rejects out of range
  explicit GatedFuser(const GatedFuserParams<T>& p = {})
      : p_(validated(p)),
        ekf_(Se2Odometry<T>(Se2OdometryNoise<T>{p.odom_xy_sigma_per_sqrt_m,
                                                p.odom_theta_sigma_per_sqrt_m,
                                                p.odom_theta_sigma_per_sqrt_rad})),
        slam_(PlanarPoseFix<T>::from_sigmas(p.slam_xy_sigma_m, p.slam_theta_sigma_rad)) {
    reset(Pose{}, Mat3::Identity() * T(1e-6));
  }

  /// Restarts at `start` (world frame) with covariance `cov`; forgets the
  /// odometry reference, any SLAM anchor, the distance travelled and the
  /// anchor count.
  /// @throws posefuse::invalid_argument if start is not finite or cov is not a
  ///         finite symmetric PSD matrix (the fuser is then unchanged)
  void reset(const Pose& start, const Mat3& cov) {
    ekf_.reset(start, cov);
    a_ = Pose{};
    a_g_ = as_se2(a_);
    Pa_.setZero();
    have_odom_ = false;
    anchor_ = AnchorState::kNone;
    n_cand_ = 0;
    rejects_ = 0;
    travelled_ = 0;
    anchors_ = 0;
  }

  /// Applies the odometry increment since the previous call (the first call
  /// only stores the reference) as an Ekf prediction with Se2Odometry.
  /// @param[in] odom odometry pose in the odometry frame (m, rad)
  /// @return kApplied, or kNonFinite (state untouched)
  [[nodiscard]] FilterStatus predict(const Pose& odom) noexcept {
    if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta))
      return FilterStatus::kNonFinite;
    if (!have_odom_) {
      odom_ = odom;
      odom_g_ = as_se2(odom);
      have_odom_ = true;
      return FilterStatus::kApplied;
    }
    const SE2<T> g = as_se2(odom);
    const SE2<T> d = odom_g_.between(g);  // δ = O_{k-1}^-1 O_k
    const FilterStatus s = ekf_.predict(d, T(0));
    if (s != FilterStatus::kApplied) return s;
    odom_ = odom;
    odom_g_ = g;
    travelled_ += std::hypot(d.x(), d.y());
    return s;
  }

  /// Fuses a SLAM pose taken at the time of the last predict().
  /// @param[in] z             body pose in the SLAM map frame (m, rad)
  /// @param[in] new_map_frame true when SLAM re-initialised (z is the first
  ///                          pose of a new map frame)
  /// @return kFused; a rejection (step kGated, rejected_by the gate);
  ///         kAnchoring / kAnchored (step kNotInitialised: the pose went to the
  ///         anchor estimate); kNonFinite or kSingularInnovation
  [[nodiscard]] FuserStatus update_slam(const Pose& z, bool new_map_frame) noexcept {
    if (!std::isfinite(z.x) || !std::isfinite(z.y) || !std::isfinite(z.theta))
      return FuserStatus::kNonFinite;
    if (new_map_frame || anchor_ == AnchorState::kNone) start_anchoring();
    if (anchor_ == AnchorState::kCollecting) return collect(z);
    // The SLAM pose in the world, T_wm (+) z: the heading as a wrapped sum,
    // so no trigonometry of z is needed.
    const typename SE2<T>::Point pw = a_g_.act(z.position());
    const Pose zw{pw.x(), pw.y(), wrap_angle(a_.theta + z.theta)};
    FuserGate failed = FuserGate::kNone;
    const auto gates = [this, &failed](const Vec3& r, const Mat3& S, T nis) {
      failed = which_gate_fails(r, S, nis);
      return failed == FuserGate::kNone;
    };
    // R is isotropic in x, y: the same in the map and the world frame.
    const auto res = ekf_.update_with(slam_, zw, gates);
    if (res.status == FilterStatus::kGated) {
      if (++rejects_ >= p_.reanchor_after_rejects) start_anchoring();
      return {FilterStatus::kGated, AnchorEvent::kNone, failed};
    }
    if (res.status == FilterStatus::kApplied) rejects_ = 0;
    return res.status;
  }

  /// Fuses an absolute heading (e.g. a compass aligned to the world frame)
  /// as an Ekf update with HeadingFix, gated by \f$r^2/S \le\f$ gate_theta_chi2.
  /// @param[in] yaw   heading in the world frame (rad)
  /// @param[in] sigma its 1-σ noise (rad, > 0)
  /// @return kFused, kRejectedHeading, kNonFinite (yaw or sigma not finite),
  ///         {kInvalidInput} (sigma <= 0) or kSingularInnovation
  [[nodiscard]] FuserStatus update_heading(T yaw, T sigma) noexcept {
    if (!std::isfinite(yaw) || !std::isfinite(sigma)) return FuserStatus::kNonFinite;
    if (!(sigma > T(0))) return FilterStatus::kInvalidInput;
    const auto res = ekf_.update_with(HeadingFix<T>(sigma), SO2<T>(yaw), p_.gate_theta_chi2);
    if (res.status == FilterStatus::kGated) return FuserStatus::kRejectedHeading;
    return res.status;
  }

  /// Stage form: predict with `in.odom`, then fuse `in.slam` if present.
  [[nodiscard]] Output operator()(const Input& in) noexcept {
    Output out;
    out.odom_status = predict(in.odom);
    if (in.has_slam && out.odom_status == FilterStatus::kApplied)
      out.slam_status = update_slam(in.slam, in.slam_new_map_frame);
    out.pose = pose();
    out.cov = covariance();
    return out;
  }

  /// Fused body pose in the world frame.
  [[nodiscard]] const Pose& pose() const noexcept { return ekf_.state(); }
  /// Its covariance, relative to the anchored SLAM map once one is anchored.
  [[nodiscard]] const Mat3& covariance() const noexcept { return ekf_.covariance(); }
  /// Covariance of the pose when the current map was anchored (the part of
  /// the error that SLAM cannot remove); zero before the first anchor.
  [[nodiscard]] const Mat3& anchor_covariance() const noexcept { return Pa_; }
  /// True when a SLAM map frame is anchored (SLAM poses are being fused).
  [[nodiscard]] bool anchored() const noexcept { return anchor_ == AnchorState::kAnchored; }
  /// \f$T_{wm}\f$: the current SLAM map frame in the world (valid when anchored()).
  [[nodiscard]] const Pose& map_in_world() const noexcept { return a_; }
  /// \f$T_{wo} = x \oplus O_k^{-1}\f$: maps the odometry frame onto the fused
  /// estimate (rebasing); `as_se2(odometry_correction()) * as_se2(odom)` is
  /// the fused pose at the last predict().
  [[nodiscard]] Pose odometry_correction() const noexcept {
    return as_planar_pose(as_se2(pose()) * odom_g_.inverse());
  }
  /// Odometry distance travelled since construction or reset() (m).
  [[nodiscard]] T travelled() const noexcept { return travelled_; }
  /// Number of anchors estimated so far (first frame, re-inits, unannounced changes).
  [[nodiscard]] int anchor_count() const noexcept { return anchors_; }
  /// The underlying filter (read-only).
  [[nodiscard]] const Filter& filter() const noexcept { return ekf_; }

 private:
  enum class AnchorState { kNone, kCollecting, kAnchored };
  struct Candidate {
    Pose x;  // fused (odometry-propagated) pose when the SLAM pose arrived
    Pose z;  // the SLAM pose, map frame
    T s;     // odometry distance travelled by then (m)
  };

  static const GatedFuserParams<T>& validated(const GatedFuserParams<T>& p) {
    const T s[] = {p.odom_xy_sigma_per_sqrt_m, p.odom_theta_sigma_per_sqrt_m,
                   p.odom_theta_sigma_per_sqrt_rad, p.anchor_min_travel_m};
    for (T v : s)
      if (!std::isfinite(v) || v < 0)
        throw invalid_argument("GatedFuser: odometry sigmas and anchor_min_travel_m must be >= 0");
    const T q[] = {p.slam_xy_sigma_m, p.slam_theta_sigma_rad, p.gate_xy_chi2, p.gate_theta_chi2,
                   p.gate_joint_chi2, p.anchor_tol_xy_m, p.anchor_tol_theta_rad};
    for (T v : q)
      if (!std::isfinite(v) || !(v > 0))
        throw invalid_argument("GatedFuser: SLAM sigmas, gates and anchor tolerances must be > 0");
    if (p.anchor_samples < 1 || p.anchor_samples > kMaxAnchorSamples)
      throw invalid_argument("GatedFuser: anchor_samples must lie in [1, 32]");
    if (p.reanchor_after_rejects < 1)
      throw invalid_argument("GatedFuser: reanchor_after_rejects must be >= 1");
    return p;
  }

  void start_anchoring() noexcept {
    anchor_ = AnchorState::kCollecting;
    n_cand_ = 0;
    rejects_ = 0;
  }

  /// The first of the configured gates that r fails (kNone: accepted).
  FuserGate which_gate_fails(const Vec3& r, const Mat3& S, T nis) const noexcept {
    if (p_.gate != GateMode::kMahalanobis) {
      // r_xy^T S_xy^-1 r_xy in closed form (S_xy = S's top-left 2x2 block,
      // positive definite because the Ekf accepted S): adj(S_xy) / det.
      const T det = S(0, 0) * S(1, 1) - S(0, 1) * S(1, 0);
      const T dxy = (S(1, 1) * r(0) * r(0) - (S(0, 1) + S(1, 0)) * r(0) * r(1) +
                     S(0, 0) * r(1) * r(1)) / det;
      if (!(det > T(0)) || !(dxy <= p_.gate_xy_chi2)) return FuserGate::kPosition;
      if (!(r(2) * r(2) <= p_.gate_theta_chi2 * S(2, 2))) return FuserGate::kHeading;
    }
    if (p_.gate != GateMode::kSeparate && !(nis <= p_.gate_joint_chi2)) return FuserGate::kJoint;
    return FuserGate::kNone;
  }

  FuserStatus collect(const Pose& z) noexcept {
    if (n_cand_ == kMaxAnchorSamples) {  // drop the oldest
      for (int i = 1; i < n_cand_; ++i) cand_[std::size_t(i - 1)] = cand_[std::size_t(i)];
      --n_cand_;
    }
    cand_[std::size_t(n_cand_++)] = {pose(), z, travelled_};
    if (n_cand_ < p_.anchor_samples) return FuserStatus::kAnchoring;
    // The window: the newest anchor_samples pairs, widened until it spans
    // anchor_min_travel_m of odometry (unless the buffer is full).
    const T s_new = cand_[std::size_t(n_cand_ - 1)].s;
    int first = n_cand_ - p_.anchor_samples;
    while (first > 0 && s_new - cand_[std::size_t(first)].s < p_.anchor_min_travel_m) --first;
    if (s_new - cand_[std::size_t(first)].s < p_.anchor_min_travel_m && n_cand_ < kMaxAnchorSamples)
      return FuserStatus::kAnchoring;
    const int N = n_cand_ - first;
    // Yaw from the headings (so a short window suffices), then translation.
    T ss = 0, sc = 0;
    for (int i = first; i < n_cand_; ++i) {
      const Candidate& c = cand_[std::size_t(i)];
      ss += std::sin(c.x.theta - c.z.theta);
      sc += std::cos(c.x.theta - c.z.theta);
    }
    const T yaw = std::atan2(ss, sc);
    const SO2<T> rot(yaw);
    Pose mean{0, 0, wrap_angle(yaw)};
    for (int i = first; i < n_cand_; ++i) {
      const Candidate& c = cand_[std::size_t(i)];
      const typename SO2<T>::Point r = rot.act(c.z.position());
      mean.x += (c.x.x - r.x()) / T(N);
      mean.y += (c.x.y - r.y()) / T(N);
    }
    // Consistency, checked at the robot (free of the lever arm to the map
    // origin): every pair must satisfy x_i ~ mean (+) z_i.
    const SE2<T> T_wm = as_se2(mean);
    for (int i = first; i < n_cand_; ++i) {
      const Candidate& c = cand_[std::size_t(i)];
      const Vec3 e = c.x.minus(as_planar_pose(T_wm * as_se2(c.z)));
      if (std::hypot(e(0), e(1)) > p_.anchor_tol_xy_m || std::abs(e(2)) > p_.anchor_tol_theta_rad)
        return FuserStatus::kAnchoring;  // inconsistent (frozen, jumping): keep collecting
    }
    a_ = mean;
    a_g_ = T_wm;
    Pa_ = covariance();
    anchor_ = AnchorState::kAnchored;
    ++anchors_;
    return FuserStatus::kAnchored;
  }

  GatedFuserParams<T> p_;
  Filter ekf_;
  PlanarPoseFix<T> slam_;
  Pose a_{}, odom_{};
  // as_se2(a_) and as_se2(odom_), kept with them (their sine and cosine
  // computed once per change, not once per use).
  SE2<T> a_g_{}, odom_g_{};
  Mat3 Pa_ = Mat3::Zero();
  bool have_odom_ = false;
  AnchorState anchor_ = AnchorState::kNone;
  std::array<Candidate, kMaxAnchorSamples> cand_{};
  T travelled_ = 0;
  int n_cand_ = 0, rejects_ = 0, anchors_ = 0;
};

}  // namespace posefuse

#pragma once
/// @file
/// A sound replacement for seed 001's threshold fuser (eq 14-15): fuses
/// odometry and SLAM poses on the plane with their covariances, gates SLAM
/// with Mahalanobis tests, averages angles on the circle, and **re-anchors**
/// SLAM when it re-initialises in a new map frame instead of discarding it.
///
/// **State.** \f$x = [x, y, \theta]\f$ of the body in the world (=
/// odometry) frame with a 3x3 covariance P, and \f$T_{wm}\f$, the pose of the
/// current SLAM map frame in the world, estimated once per map (below).
///
/// **Odometry (prediction).** Only increments are used:
/// \f$\delta = O_{k-1}^{-1} \oplus O_k\f$, \f$x \leftarrow x \oplus \delta\f$,
/// \f$P \leftarrow J_x P J_x^T + J_\delta Q_\delta J_\delta^T\f$ with body-frame
/// noise \f$Q_\delta = \mathrm{diag}(k_{xy}^2 s, k_{xy}^2 s, k_{\theta s}^2 s +
/// k_{\theta\theta}^2 |\Delta\theta|)\f$ (s = distance). The fused pose is
/// therefore odometry *rebased onto the fused estimate* after every update —
/// the same as resetting dead reckoning to it — so odometry drift does not
/// keep accumulating into it.
///
/// **SLAM (update).** The SLAM pose is transformed into the world,
/// \f$z_w = T_{wm} \oplus z\f$, and fused by information weighting
/// (fuse_poses: \f$K = P(P+R)^{-1}\f$, \f$x \leftarrow x \boxplus K(z_w \boxminus
/// x)\f$, Joseph form), the heading residual wrapped — angle-aware averaging.
///
/// **Gates** on \f$r = z_w \boxminus x\f$, \f$S = P + R\f$. kSeparate: position
/// \f$r_{xy}^T S_{xy}^{-1} r_{xy} \le \chi^2_2\f$ *and* heading
/// \f$r_\theta^2 / S_{\theta\theta} \le \chi^2_1\f$ — a large position
/// disagreement is rejected even when the headings agree, unlike seed eq 14.
/// kMahalanobis: \f$r^T S^{-1} r \le \chi^2_3\f$. kBoth: all three.
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

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <limits>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// SE(2) composition \f$a \oplus b\f$ (b expressed in a's frame).
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> se2_compose(const PlanarPose<T>& a, const PlanarPose<T>& b) {
  const T c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrap_angle(a.theta + b.theta)};
}

/// SE(2) inverse \f$a^{-1}\f$.
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> se2_inverse(const PlanarPose<T>& a) {
  const T c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, wrap_angle(-a.theta)};
}

/// A planar pose with its covariance (x, y, theta; m², m·rad, rad²).
template <std::floating_point T = double>
struct PlanarPoseWithCov {
  PlanarPose<T> pose;                                       ///< x, y (m), theta (rad)
  Eigen::Matrix<T, 3, 3> cov = Eigen::Matrix<T, 3, 3>::Zero();  ///< covariance
};

/// Information-weighted fusion of two estimates of one planar pose, angle-aware:
/// \f$ K = P_a (P_a + P_b)^{-1},\; x = a \boxplus K (b \boxminus a),\;
/// P = (I-K) P_a (I-K)^\top + K P_b K^\top = (P_a^{-1} + P_b^{-1})^{-1} \f$,
/// with the heading residual wrapped, so 179° and -179° with equal weights
/// fuse to 180°, not 0° (cf. seed eq 15-a).
/// @param[in] a, Pa first estimate and its covariance
/// @param[in] b, Pb second estimate and its covariance
/// @return the fused pose and covariance; NaN when Pa + Pb is not positive definite
template <std::floating_point T>
[[nodiscard]] inline PlanarPoseWithCov<T> fuse_poses(const PlanarPose<T>& a,
                                                     const Eigen::Matrix<T, 3, 3>& Pa,
                                                     const PlanarPose<T>& b,
                                                     const Eigen::Matrix<T, 3, 3>& Pb) {
  using Mat3 = Eigen::Matrix<T, 3, 3>;
  const Eigen::LDLT<Mat3> ldlt(Pa + Pb);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive() || !(ldlt.vectorD().array() > 0).all())
    return {{std::numeric_limits<T>::quiet_NaN(), std::numeric_limits<T>::quiet_NaN(),
             std::numeric_limits<T>::quiet_NaN()},
            Mat3::Constant(std::numeric_limits<T>::quiet_NaN())};
  const Mat3 K = ldlt.solve(Pa).transpose();  // Pa (Pa + Pb)^-1
  const Mat3 IK = Mat3::Identity() - K;
  return {a.plus(K * b.minus(a)), IK * Pa * IK.transpose() + K * Pb * K.transpose()};
}

/// How GatedFuser tests a SLAM pose against its prediction.
enum class GateMode { kSeparate, kMahalanobis, kBoth };

/// What happened to one sample given to GatedFuser.
enum class FuserStatus {
  kPredicted,          ///< odometry increment applied
  kFused,              ///< measurement passed the gates and was fused
  kRejectedPosition,   ///< position gate failed
  kRejectedHeading,    ///< heading gate failed
  kRejectedJoint,      ///< 3-dof Mahalanobis gate failed
  kAnchoring,          ///< collecting SLAM poses to estimate the map frame
  kAnchored,           ///< map frame estimated from the collected poses
  kNonFinite,          ///< NaN/Inf input; state untouched
  kSingularInnovation  ///< innovation covariance not positive definite; state untouched
};

/// True for the rejected-by-gate statuses.
[[nodiscard]] constexpr bool is_rejection(FuserStatus s) noexcept {
  return s == FuserStatus::kRejectedPosition || s == FuserStatus::kRejectedHeading ||
         s == FuserStatus::kRejectedJoint;
}

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
  FuserStatus slam_status = FuserStatus::kPredicted;  ///< what happened to the SLAM pose
};

/// Covariance-weighted, gated, re-anchoring fusion of odometry and SLAM on
/// the plane (see the file comment for the equations). Fixed-size, no heap.
template <std::floating_point T = double>
class GatedFuser {
 public:
  using Scalar = T;
  using Pose = PlanarPose<T>;
  using Vec3 = Eigen::Matrix<T, 3, 1>;
  using Mat3 = Eigen::Matrix<T, 3, 3>;
  using Input = GatedFuserInput<T>;
  using Output = GatedFuserOutput<T>;
  static constexpr int kMaxAnchorSamples = 32;

  /// @throws posefuse::invalid_argument for a negative or non-finite sigma, a
  ///         non-positive gate or tolerance, or anchor_samples /
  ///         reanchor_after_rejects out of range
  explicit GatedFuser(const GatedFuserParams<T>& p = {}) : p_(p) {
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
    const T sxy = p.slam_xy_sigma_m, sth = p.slam_theta_sigma_rad;
    R_ = Vec3(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
    reset(Pose{}, Mat3::Identity() * T(1e-6));
  }

  /// Restarts at `start` (world frame) with covariance `cov`; forgets the
  /// odometry reference, any SLAM anchor, the distance travelled and the
  /// anchor count.
  void reset(const Pose& start, const Mat3& cov) noexcept {
    x_ = start;
    a_ = Pose{};
    P_ = cov;
    Pa_.setZero();
    have_odom_ = false;
    anchor_ = AnchorState::kNone;
    n_cand_ = 0;
    rejects_ = 0;
    travelled_ = 0;
    anchors_ = 0;
  }

  /// Applies the odometry increment since the previous call (the first call
  /// only stores the reference).
  /// @param[in] odom odometry pose in the odometry frame (m, rad)
  /// @return kPredicted, or kNonFinite (state untouched)
  [[nodiscard]] FuserStatus predict(const Pose& odom) noexcept {
    if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta))
      return FuserStatus::kNonFinite;
    if (!have_odom_) {
      odom_ = odom;
      have_odom_ = true;
      return FuserStatus::kPredicted;
    }
    const Pose d = se2_compose(se2_inverse(odom_), odom);
    odom_ = odom;
    const T ds = std::hypot(d.x, d.y), dth = std::abs(d.theta);
    const T c = std::cos(x_.theta), s = std::sin(x_.theta);
    Mat3 Jx = Mat3::Identity();
    Jx(0, 2) = -s * d.x - c * d.y;
    Jx(1, 2) = c * d.x - s * d.y;
    Mat3 Jd = Mat3::Identity();
    Jd.template topLeftCorner<2, 2>() << c, -s, s, c;
    const T kxy = p_.odom_xy_sigma_per_sqrt_m, kts = p_.odom_theta_sigma_per_sqrt_m,
            ktt = p_.odom_theta_sigma_per_sqrt_rad;
    const Vec3 q(kxy * kxy * ds, kxy * kxy * ds, kts * kts * ds + ktt * ktt * dth);
    x_ = se2_compose(x_, d);
    travelled_ += ds;
    P_ = Jx * P_ * Jx.transpose() + Jd * q.asDiagonal() * Jd.transpose();
    return FuserStatus::kPredicted;
  }

  /// Fuses a SLAM pose taken at the time of the last predict().
  /// @param[in] z             body pose in the SLAM map frame (m, rad)
  /// @param[in] new_map_frame true when SLAM re-initialised (z is the first
  ///                          pose of a new map frame)
  /// @return kFused, a rejection, kAnchoring / kAnchored, kNonFinite or
  ///         kSingularInnovation
  [[nodiscard]] FuserStatus update_slam(const Pose& z, bool new_map_frame) noexcept {
    if (!std::isfinite(z.x) || !std::isfinite(z.y) || !std::isfinite(z.theta))
      return FuserStatus::kNonFinite;
    if (new_map_frame || anchor_ == AnchorState::kNone) start_anchoring();
    if (anchor_ == AnchorState::kCollecting) return collect(z);
    const Pose zw = se2_compose(a_, z);  // SLAM pose in the world
    const Vec3 r = zw.minus(x_);
    const Mat3 S = P_ + R_;  // R is isotropic in x, y: the same in any frame
    const Eigen::LDLT<Mat3> ldlt(S);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return FuserStatus::kSingularInnovation;
    const FuserStatus g = gate(r, S, ldlt);
    if (g != FuserStatus::kFused) {
      if (++rejects_ >= p_.reanchor_after_rejects) start_anchoring();
      return g;
    }
    rejects_ = 0;
    const Mat3 K = ldlt.solve(P_).transpose();  // P (P + R)^-1
    const Mat3 IK = Mat3::Identity() - K;
    x_ = x_.plus(K * r);
    P_ = IK * P_ * IK.transpose() + K * R_ * K.transpose();
    return FuserStatus::kFused;
  }

  /// Fuses an absolute heading (e.g. a compass aligned to the world frame),
  /// gated by \f$r^2/S \le\f$ gate_theta_chi2.
  /// @param[in] yaw   heading in the world frame (rad)
  /// @param[in] sigma its 1-σ noise (rad, > 0)
  [[nodiscard]] FuserStatus update_heading(T yaw, T sigma) noexcept {
    if (!std::isfinite(yaw) || !std::isfinite(sigma) || !(sigma > 0)) return FuserStatus::kNonFinite;
    const T r = angle_diff(yaw, x_.theta), S = P_(2, 2) + sigma * sigma;
    if (!(S > 0)) return FuserStatus::kSingularInnovation;
    if (r * r > p_.gate_theta_chi2 * S) return FuserStatus::kRejectedHeading;
    const Vec3 K = P_.col(2) / S;
    Mat3 IKH = Mat3::Identity();
    IKH.col(2) -= K;
    x_ = x_.plus(K * r);
    P_ = IKH * P_ * IKH.transpose() + (sigma * sigma) * K * K.transpose();
    return FuserStatus::kFused;
  }

  /// Stage form: predict with `in.odom`, then fuse `in.slam` if present.
  [[nodiscard]] Output operator()(const Input& in) noexcept {
    Output out;
    out.slam_status = predict(in.odom);
    if (in.has_slam && out.slam_status == FuserStatus::kPredicted)
      out.slam_status = update_slam(in.slam, in.slam_new_map_frame);
    out.pose = x_;
    out.cov = P_;
    return out;
  }

  /// Fused body pose in the world frame.
  [[nodiscard]] const Pose& pose() const noexcept { return x_; }
  /// Its covariance, relative to the anchored SLAM map once one is anchored.
  [[nodiscard]] const Mat3& covariance() const noexcept { return P_; }
  /// Covariance of the pose when the current map was anchored (the part of
  /// the error that SLAM cannot remove); zero before the first anchor.
  [[nodiscard]] const Mat3& anchor_covariance() const noexcept { return Pa_; }
  /// True when a SLAM map frame is anchored (SLAM poses are being fused).
  [[nodiscard]] bool anchored() const noexcept { return anchor_ == AnchorState::kAnchored; }
  /// \f$T_{wm}\f$: the current SLAM map frame in the world (valid when anchored()).
  [[nodiscard]] const Pose& map_in_world() const noexcept { return a_; }
  /// \f$T_{wo} = x \oplus O_k^{-1}\f$: maps the odometry frame onto the fused
  /// estimate (rebasing); `se2_compose(odometry_correction(), odom)` is the
  /// fused pose at the last predict().
  [[nodiscard]] Pose odometry_correction() const noexcept {
    return se2_compose(x_, se2_inverse(odom_));
  }
  /// Odometry distance travelled since construction or reset() (m).
  [[nodiscard]] T travelled() const noexcept { return travelled_; }
  /// Number of anchors estimated so far (first frame, re-inits, unannounced changes).
  [[nodiscard]] int anchor_count() const noexcept { return anchors_; }

 private:
  enum class AnchorState { kNone, kCollecting, kAnchored };
  struct Candidate {
    Pose x;  // fused (odometry-propagated) pose when the SLAM pose arrived
    Pose z;  // the SLAM pose, map frame
    T s;     // odometry distance travelled by then (m)
  };

  void start_anchoring() noexcept {
    anchor_ = AnchorState::kCollecting;
    n_cand_ = 0;
    rejects_ = 0;
  }

  FuserStatus gate(const Vec3& r, const Mat3& S, const Eigen::LDLT<Mat3>& ldlt) const noexcept {
    if (p_.gate != GateMode::kMahalanobis) {
      const Eigen::Matrix<T, 2, 1> rxy = r.template head<2>();
      const T dxy = rxy.dot(S.template topLeftCorner<2, 2>().ldlt().solve(rxy));
      if (!(dxy <= p_.gate_xy_chi2)) return FuserStatus::kRejectedPosition;
      if (!(r(2) * r(2) <= p_.gate_theta_chi2 * S(2, 2))) return FuserStatus::kRejectedHeading;
    }
    if (p_.gate != GateMode::kSeparate && !(r.dot(ldlt.solve(r)) <= p_.gate_joint_chi2))
      return FuserStatus::kRejectedJoint;
    return FuserStatus::kFused;
  }

  FuserStatus collect(const Pose& z) noexcept {
    if (n_cand_ == kMaxAnchorSamples) {  // drop the oldest
      for (int i = 1; i < n_cand_; ++i) cand_[std::size_t(i - 1)] = cand_[std::size_t(i)];
      --n_cand_;
    }
    cand_[std::size_t(n_cand_++)] = {x_, z, travelled_};
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
    const Pose rot{0, 0, std::atan2(ss, sc)};
    Pose mean = rot;
    for (int i = first; i < n_cand_; ++i) {
      const Candidate& c = cand_[std::size_t(i)];
      const Pose r = se2_compose(rot, c.z);
      mean.x += (c.x.x - r.x) / T(N);
      mean.y += (c.x.y - r.y) / T(N);
    }
    // Consistency, checked at the robot (free of the lever arm to the map
    // origin): every pair must satisfy x_i ~ mean (+) z_i.
    for (int i = first; i < n_cand_; ++i) {
      const Candidate& c = cand_[std::size_t(i)];
      const Vec3 e = c.x.minus(se2_compose(mean, c.z));
      if (std::hypot(e(0), e(1)) > p_.anchor_tol_xy_m || std::abs(e(2)) > p_.anchor_tol_theta_rad)
        return FuserStatus::kAnchoring;  // inconsistent (frozen, jumping): keep collecting
    }
    a_ = mean;
    Pa_ = P_;
    anchor_ = AnchorState::kAnchored;
    ++anchors_;
    return FuserStatus::kAnchored;
  }

  GatedFuserParams<T> p_;
  Pose x_{}, a_{}, odom_{};
  Mat3 P_ = Mat3::Identity(), Pa_ = Mat3::Zero(), R_ = Mat3::Identity();
  bool have_odom_ = false;
  AnchorState anchor_ = AnchorState::kNone;
  std::array<Candidate, kMaxAnchorSamples> cand_{};
  T travelled_ = 0;
  int n_cand_ = 0, rejects_ = 0, anchors_ = 0;
};

static_assert(Stage<GatedFuser<double>>);
static_assert(Stage<GatedFuser<float>>);

}  // namespace posefuse

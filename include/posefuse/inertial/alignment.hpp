#pragma once
/// @file
/// Visual-inertial alignment (VINS-Mono's initialisation: Qin, Li, Shen,
/// "VINS-Mono", IEEE T-RO 2018, §V-B; the formulas are the paper's, written
/// here from them): from N keyframes' up-to-scale camera poses (vision-only
/// SfM), the camera–IMU extrinsic and the IMU pre-integrations between
/// consecutive keyframes, estimate the gyroscope bias, the metric scale,
/// gravity and every keyframe's velocity, then rotate everything into a world
/// frame whose z axis is up (gravity along −z).
///
/// **Frames.** c0 is the first camera's frame (the SfM frame);
/// \f$ T_{c0,c_k} = (R_{c0,c_k}, \bar p_k) \f$ with \f$ \bar p_k \f$ up to scale
/// s (metric \f$ = s\,\bar p_k \f$); the extrinsic \f$ T_{b,c} = (R_{bc}, p_{bc}) \f$
/// is the camera's pose in the body (IMU) frame, so
/// \f$ R_k := R_{c0,b_k} = R_{c0,c_k} R_{bc}^\top \f$ and the body position
/// \f$ p_k = s\bar p_k - R_k p_{bc} \f$. g is the gravity **acceleration** in
/// c0 (pointing down, |g| ≈ 9.81 m/s²), as in inertial/preintegration.hpp.
///
/// **1. Gyroscope bias** (VINS-Mono eq 18-19, with Log instead of the
/// quaternion's vector part): for each pair k, k+1 the first-order corrected
/// pre-integrated rotation must equal the vision one,
/// \f$ \Delta R_k\,\mathrm{Exp}(J^k_{\phi b_g}\delta b_g) = R_k^\top R_{k+1} \f$, so
/// \f$ \delta b_g = \arg\min \sum_k |J^k_{\phi b_g}\delta b_g - \mathrm{Log}(\Delta R_k^\top R_k^\top R_{k+1})|^2 \f$
/// (3x3 normal equations). Every pre-integration is then re-integrated about
/// \f$ b_g = \bar b_g + \delta b_g \f$.
///
/// **2. Velocity, gravity, scale** (VINS-Mono eq 20-22, velocities kept in c0
/// rather than in each body frame): unknowns \f$ [v_0 .. v_{N-1}, g, s] \f$
/// (3N + 4); each pair gives six linear equations from
/// \f$ p_{k+1} = p_k + v_k\Delta t + \tfrac12 g\Delta t^2 + R_k\Delta p_k \f$ and
/// \f$ v_{k+1} = v_k + g\Delta t + R_k\Delta v_k \f$:
/// \f[ v_k\Delta t + \tfrac12 g\Delta t^2 - s(\bar p_{k+1} - \bar p_k) = (R_k - R_{k+1})p_{bc} - R_k\Delta p_k, \quad
///     v_{k+1} - v_k - g\Delta t = R_k\Delta v_k, \f]
/// solved by column-pivoting Householder QR after scaling every column to unit norm.
///
/// **3. Gravity refinement** (VINS-Mono §V-B.3): |g| is fixed to G; g is
/// replaced by \f$ G\hat g + B w \f$ with B a 2-column orthonormal basis of the
/// tangent plane at \f$ \hat g \f$, the system re-solved for \f$ [v, w, s] \f$ and
/// \f$ \hat g \f$ renormalised; four iterations.
///
/// **4. World frame**: \f$ R_{w,c0} \f$ is the smallest rotation that takes
/// \f$ \hat g \f$ to −z, followed by the rotation about z that zeroes the first
/// body's yaw (yaw is unobservable). Positions are put relative to the first body.
///
/// **Failure statuses** — never a silent wrong answer:
/// * kInsufficientExcitation: the scale is observable only through
///   acceleration. Criterion (as VINS-Mono): the standard deviation over the
///   pairs of the mean specific force \f$ R_k\Delta v_k / \Delta t_k \f$ (in c0)
///   must be at least `min_accel_std` (default 0.25 m/s²);
/// * kSolveFailed: the linear system is rank deficient (QR rank < 3N + 4) or
///   the result is not finite;
/// * kNonPositiveScale: s ≤ 0 (before or after refinement);
/// * kGravityNorm: |g| of step 2 differs from G by more than
///   `max_gravity_norm_error` (default 1.0 m/s², as VINS-Mono).
///
/// The keyframe count N (≥ 4) is a run-time size: one compiled function
/// serves every window length; an overload takes N as a template parameter
/// and returns fixed-size arrays. The accelerometer bias is not estimated
/// (as in VINS-Mono's initialisation).

#include <Eigen/Core>
#include <Eigen/QR>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>

#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// Outcome of a visual-inertial alignment.
enum class VisualInertialAlignmentStatus {
  kOk,                       ///< every output is valid
  kInsufficientExcitation,   ///< accelerations too uniform for the scale (file comment)
  kSolveFailed,              ///< rank-deficient system or non-finite result
  kNonPositiveScale,         ///< the scale came out ≤ 0
  kGravityNorm,              ///< |g| far from the configured norm
};

/// Human-readable name of a VisualInertialAlignmentStatus.
[[nodiscard]] constexpr const char* to_string(VisualInertialAlignmentStatus s) noexcept {
  switch (s) {
    case VisualInertialAlignmentStatus::kOk: return "ok";
    case VisualInertialAlignmentStatus::kInsufficientExcitation: return "insufficient excitation";
    case VisualInertialAlignmentStatus::kSolveFailed: return "solve failed";
    case VisualInertialAlignmentStatus::kNonPositiveScale: return "non-positive scale";
    case VisualInertialAlignmentStatus::kGravityNorm: return "gravity norm off";
  }
  return "unknown";
}

/// Configuration of align_visual_inertial.
struct VisualInertialAlignmentOptions {
  double gravity_norm = 9.81;           ///< G (m/s²)
  double min_accel_std = 0.25;          ///< excitation threshold (m/s²)
  double max_gravity_norm_error = 1.0;  ///< allowed ||g| - G| before refinement (m/s²)
  int refinement_iterations = 4;        ///< gravity refinement iterations
};

/// What a visual-inertial alignment finds besides its per-keyframe arrays
/// (valid only when status is kOk; diagnostics are filled as far as the
/// computation went). Not to be confused with posefuse::AlignmentResult
/// (eval/alignment.hpp), the similarity that aligns an estimated trajectory
/// to a reference.
struct VisualInertialAlignmentSummary {
  /// outcome
  VisualInertialAlignmentStatus status = VisualInertialAlignmentStatus::kSolveFailed;
  double scale = 0;                    ///< s: metric = s × SfM units
  Eigen::Vector3d gravity_c0 = Eigen::Vector3d::Zero();  ///< g in c0, refined (m/s²)
  double gravity_norm_unrefined = 0;   ///< |g| of step 2 (m/s²)
  double accel_std = 0;                ///< the excitation measure (m/s²)
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   ///< estimated b_g (rad/s)
  SO3d R_w_c0;                         ///< world (z up) from c0
};

/// The result of aligning a run-time number of keyframes.
struct VisualInertialAlignmentResult : VisualInertialAlignmentSummary {
  std::vector<Eigen::Vector3d> velocity_c0;              ///< v_k in c0 (m/s), one per keyframe when kOk
  std::vector<SE3d> T_w_b;             ///< body poses in the world frame (metric), one per keyframe when kOk
  std::vector<Eigen::Vector3d> velocity_w;               ///< v_k in the world frame (m/s), one per keyframe when kOk
};

/// The result of aligning N keyframes: VisualInertialAlignmentResult with
/// fixed-size arrays.
template <int N>
struct VisualInertialAlignment : VisualInertialAlignmentSummary {
  std::array<Eigen::Vector3d, N> velocity_c0{};          ///< v_k in c0 (m/s)
  std::array<SE3d, N> T_w_b{};         ///< body poses in the world frame (metric)
  std::array<Eigen::Vector3d, N> velocity_w{};           ///< v_k in the world frame (m/s)
};

namespace detail {

/// x = argmin |M x - rhs| by column-pivoting Householder QR after scaling
/// every column of M to unit norm; false when M is rank deficient or x is
/// not finite.
template <class Lazy = void>
[[nodiscard]] bool scaled_qr_solve(const dependent_t<Eigen::MatrixXd, Lazy>& M, const Eigen::VectorXd& rhs,
                                   Eigen::VectorXd& x) {
  using Mat = dependent_t<Eigen::MatrixXd, Lazy>;
  Eigen::VectorXd scale(M.cols());
  for (Eigen::Index c = 0; c < M.cols(); ++c) {
    const double n = M.col(c).norm();
    scale(c) = n > 0 ? 1.0 / n : 1.0;
  }
  const Mat Ms = M * scale.asDiagonal();
  const Eigen::ColPivHouseholderQR<Mat> qr(Ms);
  if (qr.rank() < M.cols()) return false;
  x = scale.asDiagonal() * qr.solve(rhs);
  return bool(x.allFinite());
}

}  // namespace detail

/// Visual-inertial alignment of `T_c0_c.size()` keyframes, at least 4 (see
/// the file comment). The linear systems are sized at run time (6 (N − 1)
/// rows, 3 N + 4 columns), so one compiled function serves every window length.
/// @param[in] T_c0_c up-to-scale camera poses \f$ T_{c0,c_k} \f$ (first one ≈ identity)
/// @param[in] T_b_c camera–IMU extrinsic (camera pose in the body frame, metric)
/// @param[in,out] pre the N − 1 pre-integrations between consecutive keyframes;
///                re-integrated about the estimated gyroscope bias
/// @param[in] options gravity norm, thresholds
/// @throws posefuse::invalid_argument when fewer than 4 keyframes are given,
///         `pre` does not hold N − 1 pre-integrations, or a pre-integration has no step
template <class Lazy = void>
[[nodiscard]] VisualInertialAlignmentResult align_visual_inertial(std::span<const SE3d> T_c0_c, const SE3d& T_b_c,
                                                                  std::span<Preintegration> pre,
                                                                  const VisualInertialAlignmentOptions& options = {}) {
  // 6 (N − 1) equations in 3 N + 4 unknowns: at N = 3, 12 equations in 13
  // unknowns, a system with a null space whatever the motion.
  const int N = int(T_c0_c.size());
  if (N < 4)
    throw invalid_argument("align_visual_inertial: " + std::to_string(N) +
                           " keyframes; at least 4 are needed (with 3, its 12 equations cannot determine "
                           "the 13 unknowns: 3 velocities, gravity, scale)");
  if (pre.size() + 1 != T_c0_c.size())
    throw invalid_argument("align_visual_inertial: " + std::to_string(N) + " keyframes need " +
                           std::to_string(N - 1) + " pre-integrations, got " + std::to_string(pre.size()));
  using M3 = Eigen::Matrix3d;
  using MatX = detail::dependent_t<Eigen::MatrixXd, Lazy>;
  const int U = 3 * N + 4;  // unknowns [v_0..v_{N-1}, g, s]
  const int Rows = 6 * (N - 1);
  VisualInertialAlignmentResult out;
  for (const Preintegration& p : pre)
    if (!(p.dt_s() > 0)) throw invalid_argument("align_visual_inertial: a pre-integration has no step");
  const SO3d R_bc = T_b_c.so3();
  const Eigen::Vector3d p_bc = T_b_c.translation();
  std::vector<SO3d> R(T_c0_c.size());  // R_{c0, b_k}
  for (int k = 0; k < N; ++k) R[k] = T_c0_c[k].so3().compose(R_bc.inverse());

  // 1. Gyroscope bias.
  M3 H = M3::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int k = 0; k + 1 < N; ++k) {
    const M3 J = pre[k].bias_jacobian().template block<3, 3>(3, 3);
    const Eigen::Vector3d r = pre[k].delta().R.inverse().compose(R[k].between(R[k + 1])).log();
    H.noalias() += J.transpose() * J;
    b.noalias() += J.transpose() * r;
  }
  const Eigen::Vector3d dbg = H.ldlt().solve(b);
  if (!dbg.allFinite()) return out;
  out.gyro_bias = pre[0].bias().gyro + dbg;
  for (Preintegration& p : pre) p.reintegrate(ImuBias{p.bias().accel, out.gyro_bias});

  // Excitation: spread of the mean specific force per pair, in c0.
  {
    std::vector<Eigen::Vector3d> a(std::size_t(N - 1));
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k = 0; k + 1 < N; ++k) {
      a[k] = R[k].act(pre[k].delta().v) / pre[k].dt_s();
      mean += a[k];
    }
    mean /= double(N - 1);
    double var = 0;
    for (const Eigen::Vector3d& x : a) var += (x - mean).squaredNorm();
    out.accel_std = std::sqrt(var / double(N - 1));
    if (!(out.accel_std >= options.min_accel_std)) {
      out.status = VisualInertialAlignmentStatus::kInsufficientExcitation;
      return out;
    }
  }

  // 2. The linear system A x = y.
  MatX A = MatX::Zero(Rows, U);
  Eigen::VectorXd y(Rows);
  for (int k = 0; k + 1 < N; ++k) {
    const double T = pre[k].dt_s();
    const ImuDelta d = pre[k].delta();
    const int r = 6 * k;
    A.template block<3, 3>(r, 3 * k) = M3::Identity() * T;
    A.template block<3, 3>(r, 3 * N) = M3::Identity() * (0.5 * T * T);
    A.template block<3, 1>(r, 3 * N + 3) = -(T_c0_c[k + 1].translation() - T_c0_c[k].translation());
    y.template segment<3>(r) = R[k].act(p_bc) - R[k + 1].act(p_bc) - R[k].act(d.p);
    A.template block<3, 3>(r + 3, 3 * k) = -M3::Identity();
    A.template block<3, 3>(r + 3, 3 * k + 3) = M3::Identity();
    A.template block<3, 3>(r + 3, 3 * N) = -M3::Identity() * T;
    y.template segment<3>(r + 3) = R[k].act(d.v);
  }
  Eigen::VectorXd x(U);
  if (!detail::scaled_qr_solve<Lazy>(A, y, x)) return out;
  const double s0 = x(3 * N + 3);
  Eigen::Vector3d g = x.template segment<3>(3 * N);
  out.gravity_norm_unrefined = g.norm();
  out.scale = s0;
  if (!(s0 > 0)) {
    out.status = VisualInertialAlignmentStatus::kNonPositiveScale;
    return out;
  }
  if (!(std::abs(g.norm() - options.gravity_norm) <= options.max_gravity_norm_error)) {
    out.status = VisualInertialAlignmentStatus::kGravityNorm;
    return out;
  }

  // 3. Gravity refinement on the sphere: unknowns [v, w (2), s].
  const int U2 = 3 * N + 3;
  Eigen::Vector3d g_hat = g.normalized();
  Eigen::VectorXd x2(U2);
  MatX A2(Rows, U2);
  for (int it = 0; it < options.refinement_iterations; ++it) {
    const Eigen::Vector3d t = std::abs(g_hat.x()) < 0.9 ? Eigen::Vector3d::UnitX()
                                                         : Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d b1 = (t - g_hat * g_hat.dot(t)).normalized();
    const Eigen::Vector3d b2 = g_hat.cross(b1);
    Eigen::Matrix<double, 3, 2> B;
    B << b1, b2;
    A2.leftCols(3 * N) = A.leftCols(3 * N);
    A2.middleCols(3 * N, 2) = A.middleCols(3 * N, 3) * B;
    A2.col(3 * N + 2) = A.col(3 * N + 3);
    const Eigen::VectorXd y2 = y - A.middleCols(3 * N, 3) * (options.gravity_norm * g_hat);
    if (!detail::scaled_qr_solve<Lazy>(A2, y2, x2)) return out;
    g_hat = (options.gravity_norm * g_hat + B * x2.template segment<2>(3 * N)).normalized();
  }
  const double s = options.refinement_iterations > 0 ? x2(3 * N + 2) : s0;
  out.scale = s;
  out.gravity_c0 = options.gravity_norm * g_hat;
  if (!(s > 0)) {
    out.status = VisualInertialAlignmentStatus::kNonPositiveScale;
    return out;
  }
  out.velocity_c0.resize(std::size_t(N));
  for (int k = 0; k < N; ++k)
    out.velocity_c0[k] = options.refinement_iterations > 0 ? Eigen::Vector3d(x2.template segment<3>(3 * k))
                                                           : Eigen::Vector3d(x.template segment<3>(3 * k));

  // 4. World frame: gravity along -z, first body's yaw zero.
  const Eigen::Quaterniond q_tilt =
      Eigen::Quaterniond::FromTwoVectors(g_hat, Eigen::Vector3d(0, 0, -1));
  const SO3d R_tilt(q_tilt);
  const M3 Rb0 = (R_tilt.compose(R[0])).matrix();
  const double yaw = std::atan2(Rb0(1, 0), Rb0(0, 0));
  out.R_w_c0 = SO3d::exp(Eigen::Vector3d(0, 0, -yaw)).compose(R_tilt);
  const Eigen::Vector3d p0 = s * T_c0_c[0].translation() - R[0].act(p_bc);
  out.T_w_b.resize(std::size_t(N));
  out.velocity_w.resize(std::size_t(N));
  for (int k = 0; k < N; ++k) {
    const Eigen::Vector3d pk = s * T_c0_c[k].translation() - R[k].act(p_bc);
    out.T_w_b[k] = SE3d(out.R_w_c0.act(pk - p0), out.R_w_c0.compose(R[k]));
    out.velocity_w[k] = out.R_w_c0.act(out.velocity_c0[k]);
  }
  out.status = VisualInertialAlignmentStatus::kOk;
  return out;
}

/// Visual-inertial alignment of N keyframes (see the file comment): the
/// run-time overload above, with the keyframe count checked at compile time
/// and the result in fixed-size arrays.
/// @param[in] T_c0_c up-to-scale camera poses \f$ T_{c0,c_k} \f$ (first one ≈ identity)
/// @param[in] T_b_c camera–IMU extrinsic (camera pose in the body frame, metric)
/// @param[in,out] pre the N − 1 pre-integrations between consecutive keyframes;
///                re-integrated about the estimated gyroscope bias
/// @param[in] options gravity norm, thresholds
/// @throws posefuse::invalid_argument when a pre-integration has no step
template <int N>
[[nodiscard]] VisualInertialAlignment<N> align_visual_inertial(
    const std::array<SE3d, N>& T_c0_c, const SE3d& T_b_c, std::span<Preintegration, N - 1> pre,
    const VisualInertialAlignmentOptions& options = {}) {
  static_assert(N >= 4, "align_visual_inertial needs at least 4 keyframes: with 3, its 12 equations "
                        "cannot determine the 13 unknowns (3 velocities, gravity, scale)");
  const VisualInertialAlignmentResult r =
      align_visual_inertial(std::span<const SE3d>(T_c0_c), T_b_c, std::span<Preintegration>(pre), options);
  VisualInertialAlignment<N> out;
  static_cast<VisualInertialAlignmentSummary&>(out) = r;
  for (std::size_t k = 0; k < r.velocity_c0.size() && k < std::size_t(N); ++k) out.velocity_c0[k] = r.velocity_c0[k];
  for (std::size_t k = 0; k < r.T_w_b.size() && k < std::size_t(N); ++k) {
    out.T_w_b[k] = r.T_w_b[k];
    out.velocity_w[k] = r.velocity_w[k];
  }
  return out;
}

}  // namespace posefuse

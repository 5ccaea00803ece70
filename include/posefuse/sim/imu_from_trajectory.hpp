#pragma once
/// @file
/// An IMU synthesised from a sampled motion: a C2 spline fitted to
/// time-stamped poses, the accelerometer and gyroscope readings of that
/// spline, then white noise and bias random walks of given densities — so
/// that the IMU agrees with the poses exactly up to the noise it is given.
///
/// **Spline** (world frame w, z up, gravity \f$ g_w = (0, 0, -g) \f$). Knots
/// are uniform, \f$ \tau_s = t_0 + s\,h \f$ for s = 0..S, with S segments over
/// the poses' span \f$ [t_0, t_{N-1}] \f$ (h is `knot_spacing_s` rounded so
/// that S h is the span; by default the mean pose spacing, S = N - 1). On
/// segment s, with \f$ u = (t - \tau_s)/h \f$ and the four control points
/// s..s+3 (S + 3 in all):
///
/// * position, a uniform cubic B-spline per axis,
///   \f$ p(t) = \sum_{j=0}^{3} B_j(u)\,c_{s+j} \f$;
/// * attitude, a cumulative cubic B-spline on SO(3) (Kim, Kim, Shin,
///   "A general construction scheme for unit quaternion curves", SIGGRAPH
///   1995; Lovegrove, Patron-Perez, Sibley, "Spline Fusion", BMVC 2013;
///   Mueggler, Gallego, Rebecq, Scaramuzza, "Continuous-time visual-inertial
///   odometry for event cameras", T-RO 2018),
///   \f$ R(t) = Q_s \prod_{j=1}^{3} \mathrm{Exp}(\tilde B_j(u)\,d_j) \f$,
///   \f$ d_j = \mathrm{Log}(Q_{s+j-1}^\top Q_{s+j}) \f$, with
///   \f$ \tilde B_j = \sum_{l \ge j} B_l \f$. The body angular rate follows
///   Sommer, Usenko, Schubert, Demmel, Cremers, "Efficient derivative
///   computation for cumulative B-splines on Lie groups", CVPR 2020:
///   \f$ \omega \leftarrow \mathrm{Exp}(\tilde B_j d_j)^\top\omega + \dot{\tilde B}_j d_j \f$
///   for j = 1..3 from \f$ \omega = 0 \f$.
///
/// Both are C2 in time. The control points minimise
/// \f[ \sum_k \|p(t_k) - p_k\|^2 + \lambda \sum_j \|c_{j-1} - 2c_j + c_{j+1}\|^2 \f]
/// (linear least squares) and
/// \f[ \sum_k \|\mathrm{Log}(R_k^\top R(t_k))\|^2 + \lambda \sum_j
///     \|\mathrm{Log}(Q_j^\top Q_{j+1}) - \mathrm{Log}(Q_{j-1}^\top Q_j)\|^2 \f]
/// (Gauss-Newton, from the poses' attitude at each control point's knot,
/// central-difference Jacobians), both with banded normal equations. λ
/// (`smoothing`, dimensionless, in m² per m² and rad² per rad²) is at least
/// 1e-6, which fixes the two end control points an interpolating fit leaves
/// free (a natural-spline-like end) and changes the fit by far less than a
/// micrometre; a larger λ, or knots sparser than the poses, smooths poses that
/// carry measurement jitter — a spline through jittery positions has an
/// acceleration of about jitter / h², which an accelerometer would not see.
///
/// **Readings** at sample k, \f$ t_k = t_0 + k\,\delta t \f$ (integer ns,
/// \f$ \delta t \f$ = 1/rate rounded to ns, while \f$ t_k \le t_{N-1} \f$):
/// \f[ \tilde\omega_k = \omega(t_k) + b_{g,k} + \frac{\sigma_g}{\sqrt{\delta t}} n, \qquad
///     \tilde a_k = R(t_k)^\top(\ddot p(t_k) - g_w) + b_{a,k} + \frac{\sigma_a}{\sqrt{\delta t}} n, \f]
/// \f[ b_{k+1} = b_k + \sigma_b \sqrt{\delta t}\, n, \f]
/// the model of sim/imu.hpp, with n standard normal draws from one
/// sim::detail::SeededRng seeded with `seed` (the same numbers under every
/// standard library), drawn in a fixed order: accelerometer x y z,
/// gyroscope x y z, accelerometer bias x y z, gyroscope bias x y z.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/lazy.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/inertial/imu_types.hpp>
#include <posefuse/lie/so3.hpp>
#include <posefuse/sim/detail/rng.hpp>
#include <posefuse/sim/imu.hpp>

namespace posefuse::sim {

/// One input pose: the body's position and attitude in the world at a stamp.
struct StampedPose {
  std::int64_t t_ns{0};                                        ///< stamp (ns)
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();               ///< position (m, world)
  Eigen::Quaterniond q_w_b = Eigen::Quaterniond::Identity();   ///< attitude body → world, unit norm
};

/// Parameters of the synthesised IMU (see the file comment).
struct ImuFromTrajectoryConfig {
  double rate_hz = 200.0;            ///< sample rate (Hz), > 0
  double gravity_mps2 = 9.81;        ///< g (m/s²), finite and >= 0
  ImuNoise noise{0, 0, 0, 0};        ///< densities (0 = noise-free)
  ImuBias initial_bias;              ///< \f$ b_0 \f$
  std::uint64_t seed = 1;            ///< random seed
  /// Knot spacing h (s): 0 for the mean pose spacing (a fit through the
  /// poses); larger smooths. Rounded so that a whole number of segments spans
  /// the poses.
  double knot_spacing_s = 0.0;
  /// λ of the file comment (dimensionless, finite, >= 0; below 1e-6 counts as 1e-6).
  double smoothing = 0.0;
};

/// Largest quaternion norm error accepted (| |q| - 1 |).
inline constexpr double kPoseQuaternionNormTolerance = 1e-6;

namespace detail {

/// Banded symmetric positive-definite system: lower band of half-width w
/// stored row by row (a(i, i - k) at band[i * (w + 1) + k]).
struct BandSystem {
  std::size_t n = 0, w = 0;
  std::vector<double> band, rhs;
  BandSystem(std::size_t n_, std::size_t w_) : n(n_), w(w_), band(n_ * (w_ + 1), 0.0), rhs(n_, 0.0) {}
  double& at(std::size_t i, std::size_t j) { return band[i * (w + 1) + (i - j)]; }  // i >= j, i - j <= w
  /// Solves in place (Cholesky); returns false when not positive definite.
  bool solve() {
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j0 = i > w ? i - w : 0;
      for (std::size_t j = j0; j <= i; ++j) {
        double s = at(i, j);
        const std::size_t k0 = std::max(j0, j > w ? j - w : std::size_t{0});
        for (std::size_t k = k0; k < j; ++k) s -= at(i, k) * at(j, k);
        if (j == i) {
          if (!(s > 0.0)) return false;
          at(i, i) = std::sqrt(s);
        } else {
          at(i, j) = s / at(j, j);
        }
      }
    }
    for (std::size_t i = 0; i < n; ++i) {  // L y = b
      double s = rhs[i];
      for (std::size_t k = i > w ? i - w : 0; k < i; ++k) s -= at(i, k) * rhs[k];
      rhs[i] = s / at(i, i);
    }
    for (std::size_t i = n; i-- > 0;) {  // L^T x = y
      double s = rhs[i];
      for (std::size_t k = i + 1; k < std::min(n, i + w + 1); ++k) s -= at(k, i) * rhs[k];
      rhs[i] = s / at(i, i);
    }
    return true;
  }
};

/// The cubic B-spline basis at u (values, first and second derivatives in u).
inline void bspline_basis(double u, double B[4], double dB[4], double ddB[4]) {
  const double v = 1.0 - u, u2 = u * u, u3 = u2 * u;
  B[0] = v * v * v / 6.0;
  B[1] = (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0;
  B[2] = (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0;
  B[3] = u3 / 6.0;
  dB[0] = -v * v / 2.0;
  dB[1] = (3.0 * u2 - 4.0 * u) / 2.0;
  dB[2] = (-3.0 * u2 + 2.0 * u + 1.0) / 2.0;
  dB[3] = u2 / 2.0;
  ddB[0] = v;
  ddB[1] = 3.0 * u - 2.0;
  ddB[2] = 1.0 - 3.0 * u;
  ddB[3] = u;
}

}  // namespace detail

/// The fitted spline of the file comment: position, velocity, acceleration,
/// attitude and body angular rate at any time of the poses' span. Time t is
/// seconds since the first pose's stamp. `Lazy` defers the Eigen code to the
/// files that use it (core/lazy.hpp); use it as `PoseSpline`.
template <class Lazy = void>
class BasicPoseSpline {
  using Vec3 = posefuse::detail::dependent_t<Eigen::Vector3d, Lazy>;
  using Rot = posefuse::detail::dependent_t<SO3d, Lazy>;
  using Jac = posefuse::detail::dependent_t<Eigen::Matrix<double, 3, 12>, Lazy>;

 public:
  /// Fits the spline to `poses` (see the file comment).
  /// @throws posefuse::invalid_argument for fewer than 4 poses, stamps that do
  ///         not increase, a non-finite position or quaternion coefficient, a
  ///         quaternion off unit norm by more than kPoseQuaternionNormTolerance,
  ///         or a bad knot spacing or smoothing
  BasicPoseSpline(std::span<const StampedPose> poses, double knot_spacing_s = 0.0, double smoothing = 0.0) {
    validate(poses, knot_spacing_s, smoothing);
    t0_ns_ = poses.front().t_ns;
    span_s_ = double(poses.back().t_ns - t0_ns_) * 1e-9;
    const std::size_t n = poses.size();
    const double h_wanted = knot_spacing_s > 0 ? knot_spacing_s : span_s_ / double(n - 1);
    segments_ = std::size_t(std::max(1.0, std::round(span_s_ / h_wanted)));
    if (double(segments_) > 1e7)
      throw invalid_argument("PoseSpline: knot spacing " + std::to_string(knot_spacing_s) +
                             " s gives more than 1e7 segments");
    h_ = span_s_ / double(segments_);
    lambda_ = std::max(smoothing, 1e-6);
    std::vector<double> t(n);
    for (std::size_t k = 0; k < n; ++k) t[k] = double(poses[k].t_ns - t0_ns_) * 1e-9;
    fit_position(poses, t);
    fit_attitude(poses, t);
  }

  /// Span of the poses, t in [0, span_s()] (s).
  [[nodiscard]] double span_s() const noexcept { return span_s_; }
  /// Stamp of t = 0 (ns): the first pose's.
  [[nodiscard]] std::int64_t t0_ns() const noexcept { return t0_ns_; }
  /// Knot spacing h (s).
  [[nodiscard]] double knot_spacing_s() const noexcept { return h_; }
  /// Number of control points (segments + 3).
  [[nodiscard]] std::size_t control_points() const noexcept { return c_.size(); }

  /// \f$ p(t) \f$ (m, world).
  [[nodiscard]] Vec3 position(double t_s) const { return pos(t_s, 0); }
  /// \f$ \dot p(t) \f$ (m/s, world).
  [[nodiscard]] Vec3 velocity(double t_s) const { return pos(t_s, 1); }
  /// \f$ \ddot p(t) \f$ (m/s², world).
  [[nodiscard]] Vec3 acceleration(double t_s) const { return pos(t_s, 2); }
  /// \f$ R(t) \f$, body → world.
  [[nodiscard]] Rot rotation(double t_s) const {
    Vec3 w;
    return rot(t_s, w);
  }
  /// \f$ R(t) \f$, and the body angular rate in `omega_body` (one evaluation for both).
  [[nodiscard]] Rot rotation(double t_s, Vec3& omega_body) const { return rot(t_s, omega_body); }
  /// Body angular rate \f$ \omega(t) \f$ (rad/s, body: \f$ R^\top\dot R = [\omega]_\times \f$).
  [[nodiscard]] Vec3 angular_velocity_body(double t_s) const {
    Vec3 w;
    (void)rot(t_s, w);
    return w;
  }
  /// Specific force \f$ R^\top(\ddot p - g_w) \f$ (m/s², body), \f$ g_w = (0, 0, -g) \f$.
  [[nodiscard]] Vec3 specific_force_body(double t_s, double gravity_mps2) const {
    return rotation(t_s).inverse().act(acceleration(t_s) + Vec3(0, 0, gravity_mps2));
  }

 private:
  static void validate(std::span<const StampedPose> poses, double knot_spacing_s, double smoothing) {
    if (poses.size() < 4)
      throw invalid_argument("PoseSpline: needs at least 4 poses, got " + std::to_string(poses.size()));
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const StampedPose& p = poses[k];
      const std::string at = " (pose " + std::to_string(k) + ", t_ns " + std::to_string(p.t_ns) + ")";
      if (k > 0 && !(p.t_ns > poses[k - 1].t_ns))
        throw invalid_argument("PoseSpline: stamps must increase strictly" + at);
      if (!p.p_w.allFinite()) throw invalid_argument("PoseSpline: non-finite position" + at);
      if (!p.q_w_b.coeffs().allFinite()) throw invalid_argument("PoseSpline: non-finite quaternion" + at);
      const double nq = p.q_w_b.norm();
      if (!(std::abs(nq - 1.0) <= kPoseQuaternionNormTolerance))
        throw invalid_argument("PoseSpline: quaternion of norm " + std::to_string(nq) +
                               " is not unit (tolerance 1e-6)" + at);
    }
    if (!(std::isfinite(knot_spacing_s) && knot_spacing_s >= 0))
      throw invalid_argument("PoseSpline: knot spacing must be finite and >= 0 s");
    if (!(std::isfinite(smoothing) && smoothing >= 0))
      throw invalid_argument("PoseSpline: smoothing must be finite and >= 0");
  }

  // Segment and local coordinate of t (clamped to the span).
  void locate(double t_s, std::size_t& s, double& u) const {
    const double x = std::clamp(t_s, 0.0, span_s_) / h_;
    s = std::min(segments_ - 1, std::size_t(std::max(0.0, std::floor(x))));
    u = x - double(s);
  }

  Vec3 pos(double t_s, int order) const {
    std::size_t s;
    double u, B[3][4];
    locate(t_s, s, u);
    detail::bspline_basis(u, B[0], B[1], B[2]);
    const double scale = order == 0 ? 1.0 : order == 1 ? 1.0 / h_ : 1.0 / (h_ * h_);
    Vec3 p = Vec3::Zero();
    for (int j = 0; j < 4; ++j) p += B[order][j] * c_[s + std::size_t(j)];
    return p * scale;
  }

  // R(t) from control rotations q[s..s+3] at local coordinate u; w gets the body rate.
  Rot rot_of(const Rot* q, double u, Vec3& w) const {
    double B[4], dB[4], ddB[4];
    detail::bspline_basis(u, B, dB, ddB);
    Rot R = q[0];
    w.setZero();
    double sum = 0, dsum = 0, cum[4] = {1, 0, 0, 0}, dcum[4] = {0, 0, 0, 0};
    for (int j = 3; j >= 1; --j) {  // cumulative basis from the top
      sum += B[j];
      dsum += dB[j];
      cum[j] = sum;
      dcum[j] = dsum / h_;
    }
    for (int j = 1; j <= 3; ++j) {
      const Vec3 d = q[j - 1].between(q[j]).log();
      const Rot A = Rot::exp(cum[j] * d);
      w = A.inverse().act(w) + dcum[j] * d;
      R = R * A;
    }
    return R;
  }

  Rot rot(double t_s, Vec3& w) const {
    std::size_t s;
    double u;
    locate(t_s, s, u);
    return rot_of(&q_[s], u, w);
  }

  void fit_position(std::span<const StampedPose> poses, const std::vector<double>& t) {
    const std::size_t m = segments_ + 3;
    const Vec3 origin = poses.front().p_w;  // fitted relative to the first position: less rounding
    detail::BandSystem sys(m, 3);
    std::vector<Vec3> rhs(m, Vec3::Zero());
    for (std::size_t k = 0; k < poses.size(); ++k) {
      std::size_t s;
      double u, B[4], dB[4], ddB[4];
      locate(t[k], s, u);
      detail::bspline_basis(u, B, dB, ddB);
      for (std::size_t a = 0; a < 4; ++a) {
        rhs[s + a] += B[a] * (poses[k].p_w - origin);
        for (std::size_t b = 0; b <= a; ++b) sys.at(s + a, s + b) += B[a] * B[b];
      }
    }
    const double D[3] = {1.0, -2.0, 1.0};
    for (std::size_t j = 0; j + 2 < m; ++j)
      for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t b = 0; b <= a; ++b) sys.at(j + a, j + b) += lambda_ * D[a] * D[b];
    c_.assign(m, origin);
    for (int axis = 0; axis < 3; ++axis) {
      detail::BandSystem one = sys;
      for (std::size_t j = 0; j < m; ++j) one.rhs[j] = rhs[j](axis);
      if (!one.solve()) throw invalid_argument("PoseSpline: the position fit is singular");
      for (std::size_t j = 0; j < m; ++j) c_[j](axis) += one.rhs[j];
    }
  }

  // The poses' attitude at t (slerp between the bracketing poses, clamped to the span).
  static Rot attitude_at(std::span<const StampedPose> poses, const std::vector<double>& t, double x) {
    if (x <= t.front()) return Rot(poses.front().q_w_b);
    if (x >= t.back()) return Rot(poses.back().q_w_b);
    const std::size_t k = std::size_t(std::upper_bound(t.begin(), t.end(), x) - t.begin());  // t[k-1] <= x < t[k]
    const Rot a(poses[k - 1].q_w_b), b(poses[k].q_w_b);
    return a * Rot::exp(((x - t[k - 1]) / (t[k] - t[k - 1])) * a.between(b).log());
  }

  void fit_attitude(std::span<const StampedPose> poses, const std::vector<double>& t) {
    const std::size_t m = segments_ + 3;
    q_.clear();
    for (std::size_t j = 0; j < m; ++j) q_.push_back(attitude_at(poses, t, (double(j) - 1.0) * h_));
    std::vector<Rot> meas;
    for (const StampedPose& p : poses) meas.push_back(Rot(p.q_w_b));
    const double sl = std::sqrt(lambda_), eps = 1e-6;
    for (int iter = 0; iter < 30; ++iter) {
      detail::BandSystem sys(3 * m, 11);
      // Adds J^T J and -J^T r for a residual of the 3 * nc parameters from control `first`.
      auto accumulate = [&](std::size_t first, int nc, const Vec3& r, const Jac& J) {
        for (int a = 0; a < 3 * nc; ++a) {
          const std::size_t ia = 3 * first + std::size_t(a);
          sys.rhs[ia] -= J.col(a).dot(r);
          for (int b = 0; b <= a; ++b) sys.at(ia, 3 * first + std::size_t(b)) += J.col(a).dot(J.col(b));
        }
      };
      for (std::size_t k = 0; k < poses.size(); ++k) {
        std::size_t s;
        double u;
        locate(t[k], s, u);
        Rot q[4] = {q_[s], q_[s + 1], q_[s + 2], q_[s + 3]};
        Vec3 w;
        const auto res = [&]() { return meas[k].between(rot_of(q, u, w)).log(); };
        const Vec3 r = res();
        Jac J;
        for (int a = 0; a < 12; ++a) {
          const Rot keep = q[a / 3];
          Vec3 d = Vec3::Zero();
          d(a % 3) = eps;
          q[a / 3] = keep.plus(d);
          const Vec3 rp = res();
          q[a / 3] = keep.plus(-d);
          const Vec3 rm = res();
          q[a / 3] = keep;
          J.col(a) = (rp - rm) / (2 * eps);
        }
        accumulate(s, 4, r, J);
      }
      for (std::size_t j = 0; j + 2 < m; ++j) {
        Rot q[3] = {q_[j], q_[j + 1], q_[j + 2]};
        const auto res = [&]() {
          return Vec3(sl * (q[1].between(q[2]).log() - q[0].between(q[1]).log()));
        };
        const Vec3 r = res();
        Jac J = Jac::Zero();
        for (int a = 0; a < 9; ++a) {
          const Rot keep = q[a / 3];
          Vec3 d = Vec3::Zero();
          d(a % 3) = eps;
          q[a / 3] = keep.plus(d);
          const Vec3 rp = res();
          q[a / 3] = keep.plus(-d);
          const Vec3 rm = res();
          q[a / 3] = keep;
          J.col(a) = (rp - rm) / (2 * eps);
        }
        accumulate(j, 3, r, J);
      }
      if (!sys.solve()) throw invalid_argument("PoseSpline: the attitude fit is singular");
      double step = 0;
      for (std::size_t j = 0; j < m; ++j) {
        const Vec3 d(sys.rhs[3 * j], sys.rhs[3 * j + 1], sys.rhs[3 * j + 2]);
        q_[j] = q_[j].plus(d);
        step = std::max(step, d.cwiseAbs().maxCoeff());
      }
      if (step < 1e-11) break;
    }
  }

  std::int64_t t0_ns_ = 0;
  double span_s_ = 0, h_ = 1, lambda_ = 1e-6;
  std::size_t segments_ = 1;
  std::vector<Vec3> c_;  // position control points
  std::vector<Rot> q_;   // attitude control points
};

/// The spline of the file comment.
using PoseSpline = BasicPoseSpline<>;

/// Synthesises an IMU from time-stamped poses (see the file comment): samples
/// from the first pose's stamp to the last, and the spline's state at each.
/// @param[in] poses  at least 4, stamps strictly increasing, unit quaternions
/// @param[in] config rate, gravity, noise, initial bias, seed, fit
/// @return the readings and the true state (position, velocity, attitude, bias) at each
/// @throws posefuse::invalid_argument for bad poses (PoseSpline), a rate not
///         in (0, 1e6] Hz, a bad gravity or bad noise densities
template <class Lazy = void>
[[nodiscard]] ImuSequence imu_from_trajectory(std::span<const StampedPose> poses,
                                              const ImuFromTrajectoryConfig& config = {}) {
  using Vec3 = posefuse::detail::dependent_t<Eigen::Vector3d, Lazy>;
  if (!(config.rate_hz > 0 && config.rate_hz <= 1e6))
    throw invalid_argument("imu_from_trajectory: rate must be in (0, 1e6] Hz, got " +
                           std::to_string(config.rate_hz));
  if (!(std::isfinite(config.gravity_mps2) && config.gravity_mps2 >= 0))
    throw invalid_argument("imu_from_trajectory: gravity must be finite and >= 0");
  config.noise.validate();
  if (!(config.initial_bias.accel.allFinite() && config.initial_bias.gyro.allFinite()))
    throw invalid_argument("imu_from_trajectory: the initial bias must be finite");
  const BasicPoseSpline<Lazy> spline(poses, config.knot_spacing_s, config.smoothing);
  const std::int64_t step_ns = std::max<std::int64_t>(1, std::llround(1e9 / config.rate_hz));
  const std::int64_t span_ns = poses.back().t_ns - poses.front().t_ns;
  const std::size_t n = std::size_t(span_ns / step_ns) + 1;
  const double dt = double(step_ns) * 1e-9;
  const double sa = config.noise.accel_noise_density / std::sqrt(dt);
  const double sg = config.noise.gyro_noise_density / std::sqrt(dt);
  const double sba = config.noise.accel_random_walk * std::sqrt(dt);
  const double sbg = config.noise.gyro_random_walk * std::sqrt(dt);
  detail::SeededRng rng(config.seed);
  ImuSequence out;
  out.samples.reserve(n);
  out.truth.reserve(n);
  ImuBias b = config.initial_bias;
  for (std::size_t k = 0; k < n; ++k) {
    const std::int64_t dk_ns = std::int64_t(k) * step_ns;
    const double t = double(dk_ns) * 1e-9;
    ImuSample s;
    s.t_ns = spline.t0_ns() + dk_ns;
    Vec3 omega;
    const auto R = spline.rotation(t, omega);
    s.accel_mps2 = R.inverse().act(spline.acceleration(t) + Vec3(0, 0, config.gravity_mps2)) + b.accel;
    s.gyro_radps = omega + b.gyro;
    for (int i = 0; i < 3; ++i) s.accel_mps2(i) += sa * rng.normal();
    for (int i = 0; i < 3; ++i) s.gyro_radps(i) += sg * rng.normal();
    out.samples.push_back(s);
    out.truth.push_back(ImuTruth{s.t_ns, spline.position(t), spline.velocity(t), R, b});
    Vec3 dba, dbg;
    for (int i = 0; i < 3; ++i) dba(i) = sba * rng.normal();
    for (int i = 0; i < 3; ++i) dbg(i) = sbg * rng.normal();
    b.accel += dba;
    b.gyro += dbg;
  }
  return out;
}

}  // namespace posefuse::sim

#pragma once
/// @file
/// A seeded IMU simulator: a smooth 6-DoF trajectory with analytic
/// derivatives, the exact accelerometer and gyroscope readings it produces,
/// then white noise and bias random walks of given densities.
///
/// **Trajectory** (world frame w, z up, gravity \f$ g_w = (0, 0, -g) \f$):
/// position \f$ p(t)_i = A_i \sin(\omega_i t + \psi_i) \f$ (plus a constant
/// offset) and attitude \f$ R(t) = \mathrm{Exp}(\phi(t)) \f$ with
/// \f$ \phi(t)_i = \alpha_i \sin(\varpi_i t + \chi_i) \f$ (|φ| stays below π).
/// Derivatives are analytic: \f$ v = \dot p \f$, \f$ a_w = \ddot p \f$, and the
/// body angular rate is \f$ \omega_b = J_r(\phi)\,\dot\phi \f$ (right
/// Jacobian of SO(3), lie/so3.hpp: \f$ R^\top\dot R = [J_r(\phi)\dot\phi]_\times \f$).
///
/// **Readings** at sample k (stamp \f$ t_k = t_0 + k\,\delta t \f$, integer ns):
/// \f[ \tilde\omega_k = \omega_b(t_k) + b_{g,k} + \frac{\sigma_g}{\sqrt{\delta t}} n, \qquad
///     \tilde a_k = R(t_k)^\top(a_w(t_k) - g_w) + b_{a,k} + \frac{\sigma_a}{\sqrt{\delta t}} n, \f]
/// \f[ b_{k+1} = b_k + \sigma_b \sqrt{\delta t}\, n, \f]
/// with n standard normal draws from one `std::mt19937_64` seeded with
/// `seed`, drawn in a fixed order (accelerometer x y z, gyroscope x y z,
/// accelerometer bias x y z, gyroscope bias x y z), one statement each.

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/inertial/preintegration.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse::sim {

/// Parameters of the simulated motion and sensor (see the file comment).
struct ImuSimConfig {
  Eigen::Vector3d position_amplitude_m{2.0, 1.5, 0.5};     ///< \f$ A \f$ (m)
  Eigen::Vector3d position_rate_radps{0.9, 1.3, 1.7};      ///< \f$ \omega \f$ (rad/s)
  Eigen::Vector3d position_phase_rad{0.3, 1.1, 2.0};       ///< \f$ \psi \f$ (rad)
  Eigen::Vector3d position_offset_m{1.0, -2.0, 1.5};       ///< constant offset (m)
  Eigen::Vector3d attitude_amplitude_rad{0.4, 0.3, 1.2};   ///< \f$ \alpha \f$ (rad)
  Eigen::Vector3d attitude_rate_radps{1.1, 0.7, 0.5};      ///< \f$ \varpi \f$ (rad/s)
  Eigen::Vector3d attitude_phase_rad{0.2, 0.9, 0.4};       ///< \f$ \chi \f$ (rad)
  double gravity_mps2 = 9.81;                              ///< g (m/s²)
  double rate_hz = 200.0;                                  ///< sample rate (Hz)
  std::int64_t start_t_ns = 1'000'000'000;                 ///< first stamp (ns)
  ImuNoise noise{0, 0, 0, 0};                              ///< densities (0 = noise-free)
  ImuBias initial_bias;                                    ///< \f$ b_0 \f$
  std::uint64_t seed = 1;                                  ///< random seed
};

/// The true state of the body at one stamp.
struct ImuTruth {
  std::int64_t t_ns{0};        ///< stamp (ns)
  Eigen::Vector3d p_w;         ///< position (m, world)
  Eigen::Vector3d v_w;         ///< velocity (m/s, world)
  SO3d R_w_b;                  ///< attitude, body → world
  ImuBias bias;                ///< biases at this sample
};

/// The analytic trajectory of the file comment.
class ImuTrajectory {
 public:
  explicit ImuTrajectory(const ImuSimConfig& c) : c_(c) {}
  /// \f$ p(t) \f$ (m).
  [[nodiscard]] Eigen::Vector3d position(double t_s) const {
    return c_.position_offset_m +
           c_.position_amplitude_m.cwiseProduct(arg_p(t_s).array().sin().matrix());
  }
  /// \f$ \dot p(t) \f$ (m/s).
  [[nodiscard]] Eigen::Vector3d velocity(double t_s) const {
    return c_.position_amplitude_m.cwiseProduct(c_.position_rate_radps)
        .cwiseProduct(arg_p(t_s).array().cos().matrix());
  }
  /// \f$ \ddot p(t) \f$ (m/s²).
  [[nodiscard]] Eigen::Vector3d acceleration(double t_s) const {
    return -c_.position_amplitude_m.cwiseProduct(c_.position_rate_radps.cwiseAbs2())
                .cwiseProduct(arg_p(t_s).array().sin().matrix());
  }
  /// \f$ R(t) = \mathrm{Exp}(\phi(t)) \f$.
  [[nodiscard]] SO3d rotation(double t_s) const { return SO3d::exp(phi(t_s)); }
  /// \f$ \omega_b(t) = J_r(\phi)\dot\phi \f$ (rad/s, body).
  [[nodiscard]] Eigen::Vector3d angular_velocity_body(double t_s) const {
    const Eigen::Vector3d phi_dot = c_.attitude_amplitude_rad.cwiseProduct(c_.attitude_rate_radps)
                                        .cwiseProduct(arg_r(t_s).array().cos().matrix());
    return SO3d::right_jacobian(phi(t_s)) * phi_dot;
  }
  /// Specific force \f$ R^\top(a_w - g_w) \f$ (m/s², body).
  [[nodiscard]] Eigen::Vector3d specific_force_body(double t_s) const {
    const Eigen::Vector3d g_w(0, 0, -c_.gravity_mps2);
    return rotation(t_s).inverse().act(acceleration(t_s) - g_w);
  }

 private:
  [[nodiscard]] Eigen::Vector3d arg_p(double t) const {
    return c_.position_rate_radps * t + c_.position_phase_rad;
  }
  [[nodiscard]] Eigen::Vector3d arg_r(double t) const {
    return c_.attitude_rate_radps * t + c_.attitude_phase_rad;
  }
  [[nodiscard]] Eigen::Vector3d phi(double t) const {
    return c_.attitude_amplitude_rad.cwiseProduct(arg_r(t).array().sin().matrix());
  }
  ImuSimConfig c_;
};

/// Samples and the truth at every sample.
struct ImuSequence {
  std::vector<ImuSample> samples;  ///< readings
  std::vector<ImuTruth> truth;     ///< truth at the same stamps
};

/// Simulates `duration_s` of readings (see the file comment). Time t in the
/// trajectory is seconds since `start_t_ns`.
/// @throws posefuse::invalid_argument for a non-positive rate or duration or bad noise
[[nodiscard]] inline ImuSequence simulate_imu(const ImuSimConfig& c, double duration_s) {
  if (!(c.rate_hz > 0 && duration_s > 0))
    throw invalid_argument("simulate_imu: rate and duration must be positive");
  c.noise.validate();
  const ImuTrajectory traj(c);
  const std::int64_t step_ns = std::llround(1e9 / c.rate_hz);
  const double dt = double(step_ns) * 1e-9;
  const auto n = std::size_t(std::floor(duration_s / dt)) + 1;
  std::mt19937_64 rng(c.seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  ImuSequence out;
  out.samples.reserve(n);
  out.truth.reserve(n);
  ImuBias b = c.initial_bias;
  const double sa = c.noise.accel_noise_density / std::sqrt(dt);
  const double sg = c.noise.gyro_noise_density / std::sqrt(dt);
  const double sba = c.noise.accel_random_walk * std::sqrt(dt);
  const double sbg = c.noise.gyro_random_walk * std::sqrt(dt);
  for (std::size_t k = 0; k < n; ++k) {
    const std::int64_t t_ns = c.start_t_ns + std::int64_t(k) * step_ns;
    const double t = double(std::int64_t(k) * step_ns) * 1e-9;
    ImuSample s;
    s.t_ns = t_ns;
    s.accel_mps2 = traj.specific_force_body(t) + b.accel;
    s.gyro_radps = traj.angular_velocity_body(t) + b.gyro;
    for (int i = 0; i < 3; ++i) s.accel_mps2(i) += sa * nd(rng);
    for (int i = 0; i < 3; ++i) s.gyro_radps(i) += sg * nd(rng);
    out.samples.push_back(s);
    out.truth.push_back(ImuTruth{t_ns, traj.position(t), traj.velocity(t), traj.rotation(t), b});
    for (int i = 0; i < 3; ++i) b.accel(i) += sba * nd(rng);
    for (int i = 0; i < 3; ++i) b.gyro(i) += sbg * nd(rng);
  }
  return out;
}

/// The true pre-integrated measurement between two truth states (the
/// inverse of the file comment of inertial/preintegration.hpp):
/// \f$ \Delta R = R_i^\top R_j \f$, \f$ \Delta v = R_i^\top(v_j - v_i - g_w\Delta t) \f$,
/// \f$ \Delta p = R_i^\top(p_j - p_i - v_i\Delta t - \tfrac12 g_w\Delta t^2) \f$.
[[nodiscard]] inline ImuDelta true_delta(const ImuTruth& i, const ImuTruth& j, double gravity_mps2) {
  const double T = seconds_between(j.t_ns, i.t_ns);
  const Eigen::Vector3d g_w(0, 0, -gravity_mps2);
  const SO3d Ri_inv = i.R_w_b.inverse();
  return ImuDelta{Ri_inv.act(j.p_w - i.p_w - i.v_w * T - 0.5 * g_w * T * T), i.R_w_b.between(j.R_w_b),
                  Ri_inv.act(j.v_w - i.v_w - g_w * T)};
}

}  // namespace posefuse::sim

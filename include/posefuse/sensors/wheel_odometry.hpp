#pragma once
/// @file
/// Four-wheel encoders -> differential drive -> body motion (seed 001 eq 8-9).
///
/// Units are explicit: encoders count `ticks_per_rev` ticks per wheel
/// revolution, so a tick increment \f$ \Delta E \f$ turns the wheel by
/// \f$ 2\pi \Delta E / N \f$ rad and moves its contact point by
/// \f$ m_{tick} \Delta E \f$ metres with \f$ m_{tick} = 2\pi r / N \f$.
/// Eq 9 prints \f$ v = r(\Delta E_R + \Delta E_L)/2 \f$ and calls r the wheel
/// *diameter*; with increments in radians r must be the **radius** (a wheel
/// turning by an angle a moves its contact point by r a). Only the radius
/// form is implemented.
/// Body frame REP-103 (x forward, y left); a positive turn is counter-clockwise.
///
/// The chain's input is the library's raw WheelSample (core/samples.hpp):
/// cumulative counts stamped `t_ns`; step lengths `dt_s` are computed from
/// stamp differences with seconds_between (core/time.hpp), which cannot
/// overflow.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>
#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/sensors/sample_status.hpp>
#include <string>

namespace posefuse {

/// Per-wheel increment `now - before` (ticks), each saturated to the int64
/// range instead of overflowing (saturating_difference, core/samples.hpp).
/// @param[in] now, before cumulative counts (ticks)
/// @return the four increments (ticks)
[[nodiscard]] constexpr WheelTicks tick_increment(const WheelTicks& now, const WheelTicks& before) noexcept {
  return {saturating_difference(now.fl, before.fl), saturating_difference(now.fr, before.fr),
          saturating_difference(now.bl, before.bl), saturating_difference(now.br, before.br)};
}

/// Geometry of a differential-drive robot.
struct DiffDriveParams {
  double ticks_per_rev{0};   ///< encoder ticks per wheel revolution N (> 0)
  double wheel_radius_m{0};  ///< wheel radius r, m (> 0; the seed's "diameter" is a typo)
  double track_width_m{0};   ///< distance d between left and right wheels, m (> 0)

  /// @throws posefuse::invalid_argument if any field is not finite and positive
  void validate() const {
    auto check = [](double v, const char* name) {
      if (!(std::isfinite(v) && v > 0.0))
        throw invalid_argument(std::string("posefuse: DiffDriveParams.") + name +
                               " must be finite and > 0, got " + std::to_string(v));
    };
    check(ticks_per_rev, "ticks_per_rev");
    check(wheel_radius_m, "wheel_radius_m");
    check(track_width_m, "track_width_m");
  }
  /// Distance a wheel rolls per tick, \f$ 2\pi r / N \f$, m.
  [[nodiscard]] double metres_per_tick() const noexcept {
    return 2.0 * std::numbers::pi * wheel_radius_m / ticks_per_rev;
  }
};

/// Encoder noise per wheel and per step, in ticks.
/// Per-side increment variance (ticks²), two wheels averaged (eq 8):
/// \f$ \sigma_{side}^2 = \sigma_q^2 / 2 + (k\,\Delta E_{side})^2 \f$ — the
/// quantisation of the two wheels is independent, slip is taken as common
/// to both wheels of a side (conservative). Quantisation is treated as
/// independent per step, which over-estimates its (bounded) growth.
struct WheelNoiseParams {
  double tick_sigma{0.28867513459481287};  ///< \f$ \sigma_q \f$, ticks per increment (default 1/sqrt(12))
  double slip_fraction{0.0};                ///< k, std of slip as a fraction of the increment

  /// @throws posefuse::invalid_argument if a field is negative or not finite
  void validate() const {
    if (!(std::isfinite(tick_sigma) && tick_sigma >= 0.0) ||
        !(std::isfinite(slip_fraction) && slip_fraction >= 0.0))
      throw invalid_argument("posefuse: WheelNoiseParams fields must be finite and >= 0");
  }
};

/// Left and right encoder values of the equivalent two-wheel robot, ticks.
template <std::floating_point T = double>
struct SideTicks {
  T left{0};   ///< \f$ E_L \f$
  T right{0};  ///< \f$ E_R \f$
};

/// Seed 001 eq 8: \f$ E_L = (E_{FL} + E_{BL})/2 \f$, \f$ E_R = (E_{FR} + E_{BR})/2 \f$.
/// Works on cumulative counts or on increments (eq 8 is linear).
/// @param[in] t four wheel counts, ticks
/// @return left/right averages, ticks
template <std::floating_point T = double>
[[nodiscard]] constexpr SideTicks<T> average_sides(const WheelTicks& t) noexcept {
  return {(T(t.fl) + T(t.bl)) / T(2), (T(t.fr) + T(t.br)) / T(2)};
}

/// Displacement of the body over one step.
template <std::floating_point T = double>
struct BodyDisplacement {
  T ds_m{0};        ///< arc length travelled by the body origin, m
  T dtheta_rad{0};  ///< heading change, rad (counter-clockwise positive)
};

/// Velocity of the body.
template <std::floating_point T = double>
struct BodyVelocity {
  T v_mps{0};    ///< forward speed, m/s
  T w_radps{0};  ///< yaw rate, rad/s (counter-clockwise positive)
};

/// Seed 001 eq 9 per step (times \f$ \Delta t \f$), with explicit units:
/// \f$ \Delta s = m_{tick}(\Delta E_R + \Delta E_L)/2 \f$,
/// \f$ \Delta\theta = m_{tick}(\Delta E_R - \Delta E_L)/d \f$.
/// @param[in] delta side increments \f$ \Delta E_L, \Delta E_R \f$, ticks
/// @param[in] p geometry (assumed validated)
template <std::floating_point T>
[[nodiscard]] inline BodyDisplacement<T> body_displacement(const SideTicks<T>& delta,
                                                           const DiffDriveParams& p) noexcept {
  const T m = T(p.metres_per_tick());
  return {m * (delta.right + delta.left) / T(2), m * (delta.right - delta.left) / T(p.track_width_m)};
}

/// Seed 001 eq 9: \f$ v = m_{tick}(\Delta E_R + \Delta E_L)/(2\Delta t) \f$,
/// \f$ w = m_{tick}(\Delta E_R - \Delta E_L)/(d\,\Delta t) \f$.
/// @param[in] delta side increments over the step, ticks
/// @param[in] dt_s step, s
/// @param[in] p geometry (assumed validated)
/// @throws posefuse::invalid_argument if dt_s is not finite and positive
template <std::floating_point T>
[[nodiscard]] inline BodyVelocity<T> body_velocity(const SideTicks<T>& delta, T dt_s,
                                                   const DiffDriveParams& p) {
  if (!(std::isfinite(dt_s) && dt_s > T(0)))
    throw invalid_argument("posefuse: body_velocity needs dt_s > 0");
  const BodyDisplacement<T> d = body_displacement(delta, p);
  return {d.ds_m / dt_s, d.dtheta_rad / dt_s};
}

/// Covariance of \f$ (\Delta s, \Delta\theta) \f$ (m², m·rad, rad²) for one step:
/// \f$ J\,\mathrm{diag}(\sigma_R^2, \sigma_L^2)\,J^\top \f$ with
/// \f$ J = m_{tick} \begin{pmatrix} 1/2 & 1/2 \\ 1/d & -1/d \end{pmatrix} \f$
/// and the per-side variances of WheelNoiseParams.
/// @param[in] delta side increments over the step, ticks
/// @param[in] p geometry (assumed validated)
/// @param[in] noise encoder noise (assumed validated)
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 2, 2> body_displacement_covariance(
    const SideTicks<T>& delta, const DiffDriveParams& p, const WheelNoiseParams& noise) noexcept {
  const T q2 = T(noise.tick_sigma * noise.tick_sigma) / T(2);
  const T k = T(noise.slip_fraction);
  const T var_r = q2 + (k * delta.right) * (k * delta.right);
  const T var_l = q2 + (k * delta.left) * (k * delta.left);
  const T m = T(p.metres_per_tick());
  const T d = T(p.track_width_m);
  Eigen::Matrix<T, 2, 2> C;
  C(0, 0) = m * m * (var_r + var_l) / T(4);
  C(0, 1) = m * m * (var_r - var_l) / (T(2) * d);
  C(1, 0) = C(0, 1);
  C(1, 1) = m * m * (var_r + var_l) / (d * d);
  return C;
}

/// Body motion over one step: output of the wheel-odometry stages, input of dead reckoning.
struct BodyMotion {
  double dt_s{0};        ///< step \f$ \Delta t \f$, s (0 for the first sample)
  double ds_m{0};        ///< arc length \f$ v \Delta t \f$, m
  double dtheta_rad{0};  ///< heading change \f$ w \Delta t \f$, rad
  double v_mps{0};       ///< eq 9-a, m/s (0 when dt_s is 0)
  double w_radps{0};     ///< eq 9-b, rad/s (0 when dt_s is 0)
  std::int64_t t_ns{0};  ///< stamp of the end of the step (ns)
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();  ///< covariance of (ds_m, dtheta_rad)
  SampleStatus status{SampleStatus::kOk};          ///< kFirst for the first sample
};

/// Left/right encoder values stamped with their time.
struct StampedSideTicks {
  std::int64_t t_ns{0};         ///< stamp (ns)
  SideTicks<double> ticks;      ///< cumulative E_L, E_R, ticks
};

/// Odometry-chain stage 1 (eq 8): four wheels -> two sides. Stateless.
struct FourWheelAverage {
  using Input = WheelSample;
  using Output = StampedSideTicks;
  /// @return the stamp and average_sides(in.ticks)
  [[nodiscard]] StampedSideTicks operator()(const WheelSample& in) const noexcept {
    return {in.t_ns, average_sides<double>(in.ticks)};
  }
};

/// Odometry-chain stage 2 (eq 9): successive side counts -> body motion with
/// covariance, \f$ \Delta t \f$ = seconds_between(t_ns, previous t_ns). The
/// first sample yields a zero motion with dt_s = 0 and status kFirst.
class DiffDriveOdometry {
 public:
  using Input = StampedSideTicks;
  using Output = BodyMotion;

  /// @throws posefuse::invalid_argument if params or noise is invalid
  explicit DiffDriveOdometry(const DiffDriveParams& params, const WheelNoiseParams& noise = {})
      : params_(params), noise_(noise) {
    params_.validate();
    noise_.validate();
  }

  /// @param[in] in cumulative side counts at time in.t_ns
  /// @return motion since the previous sample
  /// @throws posefuse::invalid_argument if a count is not finite, or the stamp
  ///         is not greater than the previous one (state untouched)
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] BodyMotion operator()(const StampedSideTicks& in) {
    if (!std::isfinite(in.ticks.left) || !std::isfinite(in.ticks.right))
      throw invalid_argument("posefuse: DiffDriveOdometry got a non-finite count");
    BodyMotion out;
    out.t_ns = in.t_ns;
    if (!has_prev_) {
      prev_ = in;
      has_prev_ = true;
      out.status = SampleStatus::kFirst;
      return out;
    }
    if (!(in.t_ns > prev_.t_ns))
      throw invalid_argument("posefuse: DiffDriveOdometry time stamps must increase strictly (got " +
                             std::to_string(in.t_ns) + " ns after " + std::to_string(prev_.t_ns) +
                             " ns)");
    const SideTicks<double> delta{in.ticks.left - prev_.ticks.left, in.ticks.right - prev_.ticks.right};
    const BodyDisplacement<double> d = body_displacement(delta, params_);
    out.dt_s = seconds_between(in.t_ns, prev_.t_ns);
    out.ds_m = d.ds_m;
    out.dtheta_rad = d.dtheta_rad;
    out.v_mps = d.ds_m / out.dt_s;
    out.w_radps = d.dtheta_rad / out.dt_s;
    out.cov = body_displacement_covariance(delta, params_, noise_);
    prev_ = in;
    return out;
  }

  /// Forgets the previous sample; the next one is treated as the first.
  void reset() noexcept { has_prev_ = false; }
  /// Geometry in use.
  [[nodiscard]] const DiffDriveParams& params() const noexcept { return params_; }
  /// Encoder noise in use.
  [[nodiscard]] const WheelNoiseParams& noise() const noexcept { return noise_; }

 private:
  DiffDriveParams params_;
  WheelNoiseParams noise_;
  StampedSideTicks prev_{};
  bool has_prev_{false};
};

/// Eq 8 and 9 in one stage: four cumulative wheel counts -> body motion.
/// Input WheelSample, Output BodyMotion (the first sample yields a zero
/// motion with dt_s = 0 and status kFirst).
class WheelOdometry {
 public:
  using Input = WheelSample;
  using Output = BodyMotion;

  /// @throws posefuse::invalid_argument if params or noise is invalid
  explicit WheelOdometry(const DiffDriveParams& params, const WheelNoiseParams& noise = {})
      : diff_(params, noise) {}

  /// @throws posefuse::invalid_argument on a non-increasing time stamp
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] BodyMotion operator()(const WheelSample& in) { return diff_(average_(in)); }

  /// Forgets the previous sample.
  void reset() noexcept { diff_.reset(); }
  /// Geometry in use.
  [[nodiscard]] const DiffDriveParams& params() const noexcept { return diff_.params(); }
  /// Encoder noise in use.
  [[nodiscard]] const WheelNoiseParams& noise() const noexcept { return diff_.noise(); }

 private:
  FourWheelAverage average_;
  DiffDriveOdometry diff_;
};

}  // namespace posefuse

#pragma once
/// @file
/// Complementary filter for angles (seed 001 eq 3-4): the gyro's integrated
/// rate through a high-pass, an absolute angle (accelerometer tilt) through
/// a low-pass,
/// \f[ \rho_i = \alpha(\rho_{i-1} + \omega\,\Delta t) + (1 - \alpha)\,\rho_a . \f]
/// The step \f$ \Delta t = t_i - t_{i-1} \f$ comes from the sample time stamps.
/// The filter is generic over N independent angle channels (N = 2: roll and
/// pitch as in the seed).
///
/// The blend is the sound form: it equals eq 3-4 as printed while the
/// prediction and the absolute angle are less than 180° apart, and blends
/// along the short arc across ±180°, where the printed arithmetic goes the
/// long way round (α = 0.98, prediction 179°, absolute angle -179°: 179.04°
/// here, 171.84° as printed). There is no option for the printed form.
/// Which rates drive each channel is the caller's choice; the attitude chain
/// (sensors/pipelines.hpp) offers the seed's gyro_x, gyro_y as printed
/// (GyroToTiltRate::kSeed) and, by default, the Euler kinematics.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <string>

namespace posefuse {

/// Outcome of ComplementaryFilter::update.
enum class ComplementaryStatus : std::uint8_t {
  kInitialised,  ///< first sample: the estimate was set to the absolute angles
  kUpdated,      ///< eq 3-4 applied
  kNonFinite,    ///< a rate or angle was not finite; estimate and time untouched
};

/// Filter constant for a time constant tau and a nominal step:
/// \f$ \alpha = \tau / (\tau + \Delta t) \f$ (the crossover frequency is
/// \f$ 1 / (2 \pi \tau) \f$).
/// @param[in] tau_s time constant, s (> 0)
/// @param[in] dt_s nominal sample period, s (> 0)
/// @throws posefuse::invalid_argument if either is not finite and positive
template <std::floating_point T>
[[nodiscard]] inline T complementary_alpha(T tau_s, T dt_s) {
  if (!(std::isfinite(tau_s) && tau_s > T(0)) || !(std::isfinite(dt_s) && dt_s > T(0)))
    throw invalid_argument("posefuse: complementary_alpha needs tau_s > 0 and dt_s > 0");
  return tau_s / (tau_s + dt_s);
}

/// Complementary filter over N angle channels (seed 001 eq 3-4).
/// @tparam T scalar type
/// @tparam N number of angles (2 for roll and pitch)
template <std::floating_point T = double, int N = 2>
class ComplementaryFilter {
 public:
  using Scalar = T;
  static constexpr int Dim = N;
  /// N angles (rad) or N angular rates (rad/s).
  using Vector = Eigen::Matrix<T, N, 1>;

  /// One step of eq 3-4, without state:
  /// \f$ p = \theta_{i-1} + \omega \Delta t \f$,
  /// \f$ \theta_i = \mathrm{wrap}(p + (1 - \alpha)\,\mathrm{wrap}(\theta_a - p)) \f$,
  /// which equals \f$ \alpha p + (1 - \alpha)\theta_a \f$ (eq 3-4 as printed)
  /// whenever \f$ |\theta_a - p| < \pi \f$, and blends along the short arc
  /// across ±180°.
  /// @param[in] prev previous estimate \f$ \theta_{i-1} \f$, rad
  /// @param[in] rate angular rates (gyro_x, gyro_y in eq 3-4), rad/s
  /// @param[in] dt_s step, s
  /// @param[in] absolute absolute angles \f$ \theta_a \f$ (eq 1-2), rad
  /// @param[in] alpha filter constant in [0, 1]
  [[nodiscard]] static Vector blend(const Vector& prev, const Vector& rate, T dt_s,
                                    const Vector& absolute, T alpha) noexcept {
    Vector out;
    for (int k = 0; k < N; ++k) {
      const T p = prev(k) + rate(k) * dt_s;
      out(k) = wrap_angle(p + (T(1) - alpha) * angle_diff(absolute(k), p));
    }
    return out;
  }

  /// @param[in] alpha filter constant \f$ \alpha \in [0, 1] \f$ (1: gyro only, 0: accelerometer only)
  /// @throws posefuse::invalid_argument if alpha is outside [0, 1] or not finite
  explicit ComplementaryFilter(T alpha) : alpha_(alpha) {
    if (!(alpha >= T(0) && alpha <= T(1)))
      throw invalid_argument("posefuse: ComplementaryFilter alpha must lie in [0, 1], got " +
                             std::to_string(double(alpha)));
  }

  /// Feeds one sample. The first sample sets the estimate to `absolute`;
  /// later ones apply eq 3-4 with \f$ \Delta t = t_s - t_{prev} \f$.
  /// @param[in] t_s time stamp of the sample, s
  /// @param[in] rate angular rates, rad/s
  /// @param[in] absolute absolute angles (e.g. accelerometer tilt), rad
  /// @return kInitialised, kUpdated, or kNonFinite (nothing changed)
  /// @throws posefuse::invalid_argument if t_s is not finite or not greater than
  ///         the previous accepted time stamp
  [[nodiscard]] ComplementaryStatus update(T t_s, const Vector& rate, const Vector& absolute) {
    if (!std::isfinite(t_s))
      throw invalid_argument("posefuse: ComplementaryFilter time stamp is not finite");
    if (initialised_ && !(t_s > t_prev_s_))
      throw invalid_argument("posefuse: ComplementaryFilter time stamps must increase strictly (got " +
                             std::to_string(double(t_s)) + " after " +
                             std::to_string(double(t_prev_s_)) + ")");
    if (!absolute.allFinite() || (initialised_ && !rate.allFinite()))
      return ComplementaryStatus::kNonFinite;
    if (!initialised_) {
      for (int k = 0; k < N; ++k) x_(k) = wrap_angle(absolute(k));
      t_prev_s_ = t_s;
      initialised_ = true;
      return ComplementaryStatus::kInitialised;
    }
    x_ = blend(x_, rate, t_s - t_prev_s_, absolute, alpha_);
    t_prev_s_ = t_s;
    return ComplementaryStatus::kUpdated;
  }

  /// Current estimate (rad, wrapped to [-pi, pi)); zero before the first sample.
  [[nodiscard]] const Vector& estimate() const noexcept { return x_; }
  /// True once a sample has been accepted.
  [[nodiscard]] bool initialised() const noexcept { return initialised_; }
  /// Time stamp of the last accepted sample, s.
  [[nodiscard]] T last_time_s() const noexcept { return t_prev_s_; }
  /// The filter constant.
  [[nodiscard]] T alpha() const noexcept { return alpha_; }
  /// Forgets the estimate; the next sample initialises again.
  void reset() noexcept {
    x_.setZero();
    t_prev_s_ = T(0);
    initialised_ = false;
  }

 private:
  T alpha_;
  Vector x_ = Vector::Zero();
  T t_prev_s_{0};
  bool initialised_{false};
};

}  // namespace posefuse

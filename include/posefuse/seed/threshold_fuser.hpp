#pragma once
/// @file
/// Seed 001's threshold fuser, eq 14-15, reproduced exactly as printed —
/// including its two flaws, which the tests demonstrate:
///
/// 1. **Multiplied RMS terms.** \f$O_{diff}\f$ is the *product* of the
///    position RMS and the angle RMS, so a large position disagreement passes
///    the gate whenever the angles happen to agree (e.g. a SLAM pose frozen
///    while the robot drives straight), and vice versa.
/// 2. **Plain angle arithmetic.** Angle differences in eq 14 and the average
///    in eq 15 are taken on the raw numbers: averaging 179° and -179° gives
///    0° instead of 180°, and the same pair counts as a 358° disagreement.
///
/// Units: positions in metres, angles in radians, so the threshold is in
/// m·rad. The fuser is stateless: eq 15 never feeds \f$O_r\f$ back into the
/// robot odometry \f$O_m\f$, so \f$O_m\f$ keeps its own drift.
///
/// A reproduction, in posefuse::seed apart from the recommended API: do not
/// use it to navigate. The sound fuser is posefuse::GatedFuser
/// (fusion/gated_fuser.hpp): covariance-weighted, with separate position and
/// heading gates and angles averaged on the circle.

#include <cmath>
#include <concepts>

#include <posefuse/core/error.hpp>
#include <posefuse/core/pipeline.hpp>

namespace posefuse::seed {

/// Seed 001's odometry vector \f$O = [x, y, \rho, \phi, \theta]\f$: position
/// (m) in the odometry/world frame and roll, pitch, yaw (rad, ZYX). z is
/// dropped as in the seed (encoders cannot observe it).
template <std::floating_point T = double>
struct SeedOdometry {
  using Scalar = T;
  T x{0};      ///< position x (m)
  T y{0};      ///< position y (m)
  T roll{0};   ///< \f$\rho\f$ (rad)
  T pitch{0};  ///< \f$\phi\f$ (rad)
  T yaw{0};    ///< \f$\theta\f$ (rad)
};

/// Seed 001 eq 14, as printed:
/// \f[ O_{diff} = \frac{1}{3}\sqrt{\frac{(x_m-x_v)^2 + (y_m-y_v)^2}{2}}\;
///     \sqrt{\frac{(\rho_m-\rho_v)^2 + (\phi_m-\phi_v)^2 + (\theta_m-\theta_v)^2}{3}} \f]
/// Angle differences are raw (not wrapped), as printed.
/// @param[in] m robot odometry \f$O_m\f$ (encoders + IMU)
/// @param[in] v visual odometry \f$O_v\f$ (SLAM)
/// @return \f$O_{diff}\f$ in m·rad
template <std::floating_point T>
[[nodiscard]] inline T seed_o_diff(const SeedOdometry<T>& m, const SeedOdometry<T>& v) noexcept {
  const T dx = m.x - v.x, dy = m.y - v.y;
  const T dr = m.roll - v.roll, dp = m.pitch - v.pitch, dt = m.yaw - v.yaw;
  return std::sqrt((dx * dx + dy * dy) / T(2)) * std::sqrt((dr * dr + dp * dp + dt * dt) / T(3)) /
         T(3);
}

/// Seed 001 eq 15-a, as printed: the element-wise average \f$(O_m + O_v)/2\f$,
/// angles included (no wrapping — averaging 179° and -179° gives 0°).
template <std::floating_point T>
[[nodiscard]] inline SeedOdometry<T> seed_average(const SeedOdometry<T>& m,
                                                  const SeedOdometry<T>& v) noexcept {
  return {(m.x + v.x) / T(2), (m.y + v.y) / T(2), (m.roll + v.roll) / T(2),
          (m.pitch + v.pitch) / T(2), (m.yaw + v.yaw) / T(2)};
}

/// Input of ThresholdFuser: both odometries at the same instant.
template <std::floating_point T = double>
struct ThresholdFuserInput {
  SeedOdometry<T> robot;   ///< \f$O_m\f$: encoder position, IMU attitude
  SeedOdometry<T> visual;  ///< \f$O_v\f$: SLAM pose, same frame as \f$O_m\f$
};

/// Output of ThresholdFuser.
template <std::floating_point T = double>
struct ThresholdFuserOutput {
  SeedOdometry<T> pose;       ///< \f$O_r\f$
  T o_diff{0};                ///< \f$O_{diff}\f$ (m·rad), eq 14
  bool averaged{false};       ///< true: eq 15-a (average); false: eq 15-b (\f$O_r = O_m\f$)
  bool reinitialise{false};   ///< seed: "ORB-SLAM is re-initialised from O_m" (= !averaged)
};

/// Seed 001 eq 14-15 as a pipeline stage:
/// \f$O_r = (O_m + O_v)/2\f$ if \f$O_{diff} \le\f$ threshold, else \f$O_r = O_m\f$
/// and a signal to re-initialise SLAM from \f$O_m\f$.
/// Use it only when SLAM has a pose; without one the seed's result is \f$O_m\f$.
template <std::floating_point T = double>
class ThresholdFuser {
 public:
  using Scalar = T;
  using Input = ThresholdFuserInput<T>;
  using Output = ThresholdFuserOutput<T>;

  /// @param[in] threshold eq 15 threshold on \f$O_{diff}\f$ (m·rad)
  /// @throws posefuse::invalid_argument unless threshold is finite and > 0
  explicit ThresholdFuser(T threshold) : threshold_(threshold) {
    if (!std::isfinite(threshold) || !(threshold > T(0)))
      throw invalid_argument("ThresholdFuser: threshold must be finite and positive");
  }

  /// Applies eq 14-15. A NaN \f$O_{diff}\f$ fails the comparison and falls
  /// back to \f$O_m\f$ (eq 15-b).
  [[nodiscard]] Output operator()(const Input& in) const noexcept {
    Output out;
    out.o_diff = seed_o_diff(in.robot, in.visual);
    out.averaged = out.o_diff <= threshold_;
    out.reinitialise = !out.averaged;
    out.pose = out.averaged ? seed_average(in.robot, in.visual) : in.robot;
    return out;
  }

  /// The eq 15 threshold (m·rad).
  [[nodiscard]] T threshold() const noexcept { return threshold_; }

 private:
  T threshold_;
};

}  // namespace posefuse::seed

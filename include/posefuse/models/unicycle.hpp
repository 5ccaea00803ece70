#pragma once
/// @file
/// Unicycle (differential-drive) motion on the plane, seed 001 eq 10, with
/// analytic Jacobians, and a posefuse::MotionModel built on it.
///
/// The step is written in the displacements \f$ \Delta s = v\Delta t \f$ and
/// \f$ \Delta\theta = w\Delta t \f$. Two integrators:
///  * Integration::kEuler — eq 10 as printed:
///    \f$ x' = x + \Delta s\cos\theta,\; y' = y + \Delta s\sin\theta,\;
///        \theta' = \theta + \Delta\theta \f$.
///  * Integration::kExactArc — the exact solution for constant v, w over the
///    step (a circular arc), in chord form, smooth through \f$ \Delta\theta = 0 \f$:
///    \f$ x' = x + \Delta s\,\mathrm{sinc}(\Delta\theta/2)\cos(\theta + \Delta\theta/2) \f$,
///    \f$ y' = y + \Delta s\,\mathrm{sinc}(\Delta\theta/2)\sin(\theta + \Delta\theta/2) \f$,
///    \f$ \theta' = \theta + \Delta\theta \f$.
/// kExactArc is the default wherever a default exists (Unicycle::method,
/// and in sensors/ DeadReckoning and make_odometry_pipeline); kEuler
/// reproduces the seed and is selected explicitly.
/// World frame x, y (m), heading counter-clockwise from x (rad), REP-103.

#include <Eigen/Core>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/concepts.hpp>
#include <posefuse/models/planar_pose.hpp>

namespace posefuse {

/// How a unicycle step is integrated.
enum class Integration : std::uint8_t {
  kEuler,     ///< seed 001 eq 10 as printed (first order; drifts on curves)
  kExactArc,  ///< exact for constant v and w over the step; the default
};

namespace detail {
/// Below this |a|, sinc_and_derivative() sums its series: the first omitted
/// terms, \f$ a^{10}/11! \f$ and \f$ 12 a^{10}/13! \f$ relative, stay below a
/// quarter of the type's epsilon (0.125 for float and double; 0.0625 for
/// the 64-bit mantissa of long double).
template <std::floating_point T>
inline constexpr T kSincSeriesLimit = std::numeric_limits<T>::digits <= 53 ? T(0.125) : T(0.0625);

/// \f$ \mathrm{sinc}(a) = \sin a / a \f$ and its derivative
/// \f$ (a\cos a - \sin a) / a^2 \f$: Taylor series (five terms each, Horner
/// in \f$ a^2 \f$) below kSincSeriesLimit, so an ordinary per-step heading
/// change costs no sine or cosine and the derivative no cancellation; the
/// closed forms above it.
template <std::floating_point T>
inline void sinc_and_derivative(T a, T& s, T& ds) noexcept {
  const T a2 = a * a;
  if (std::abs(a) < kSincSeriesLimit<T>) {
    // sinc = sum (-1)^n a^2n / (2n+1)!, sinc' = a sum_{n>=1} (-1)^n 2n a^(2n-2) / (2n+1)!
    s = T(1) + a2 * (T(-1) / T(6) + a2 * (T(1) / T(120) + a2 * (T(-1) / T(5040) + a2 * (T(1) / T(362880)))));
    ds = a * (T(-1) / T(3) +
              a2 * (T(1) / T(30) + a2 * (T(-1) / T(840) + a2 * (T(1) / T(45360) + a2 * (T(-1) / T(3991680))))));
  } else {
    s = std::sin(a) / a;
    ds = (a * std::cos(a) - std::sin(a)) / a2;
  }
}
}  // namespace detail

/// One unicycle step (seed 001 eq 10, or the exact arc).
/// @param[in] x pose before the step (m, m, rad)
/// @param[in] ds_m arc length \f$ v\Delta t \f$, m
/// @param[in] dtheta_rad heading change \f$ w\Delta t \f$, rad
/// @param[in] method kEuler (eq 10) or kExactArc
/// @param[out] J_x if not null, \f$ \partial x' / \partial x \f$ (3x3)
/// @param[out] J_u if not null, \f$ \partial x' / \partial(\Delta s, \Delta\theta) \f$ (3x2)
/// @return pose after the step, heading wrapped to [-pi, pi)
template <std::floating_point T>
[[nodiscard]] inline PlanarPose<T> unicycle_step(const PlanarPose<T>& x, T ds_m, T dtheta_rad,
                                                 Integration method,
                                                 std::type_identity_t<Eigen::Matrix<T, 3, 3>>* J_x = nullptr,
                                                 std::type_identity_t<Eigen::Matrix<T, 3, 2>>* J_u = nullptr) noexcept {
  PlanarPose<T> out;
  out.theta = wrap_angle(x.theta + dtheta_rad);
  if (method == Integration::kEuler) {
    const T c = std::cos(x.theta), s = std::sin(x.theta);
    out.x = x.x + ds_m * c;  // eq 10-b
    out.y = x.y + ds_m * s;  // eq 10-c
    if (J_x) *J_x << T(1), T(0), -ds_m * s, T(0), T(1), ds_m * c, T(0), T(0), T(1);
    if (J_u) *J_u << c, T(0), s, T(0), T(0), T(1);
    return out;
  }
  T k, dk;
  detail::sinc_and_derivative(dtheta_rad / T(2), k, dk);
  const T mid = x.theta + dtheta_rad / T(2);
  const T c = std::cos(mid), s = std::sin(mid);
  out.x = x.x + ds_m * k * c;
  out.y = x.y + ds_m * k * s;
  if (J_x) *J_x << T(1), T(0), -ds_m * k * s, T(0), T(1), ds_m * k * c, T(0), T(0), T(1);
  if (J_u)
    *J_u << k * c, ds_m * (dk * c - k * s) / T(2),  //
        k * s, ds_m * (dk * s + k * c) / T(2),      //
        T(0), T(1);
  return out;
}

/// First-order covariance propagation through a step,
/// \f$ P' = J_x P J_x^\top + J_u \Sigma_u J_u^\top \f$, symmetrised.
/// @param[in] P pose covariance before the step
/// @param[in] J_x, J_u Jacobians from unicycle_step
/// @param[in] Sigma_u covariance of \f$ (\Delta s, \Delta\theta) \f$
template <std::floating_point T>
[[nodiscard]] inline Eigen::Matrix<T, 3, 3> propagate_pose_covariance(
    const Eigen::Matrix<T, 3, 3>& P, const Eigen::Matrix<T, 3, 3>& J_x,
    const Eigen::Matrix<T, 3, 2>& J_u, const Eigen::Matrix<T, 2, 2>& Sigma_u) noexcept {
  const Eigen::Matrix<T, 3, 3> Pn = J_x * P * J_x.transpose() + J_u * Sigma_u * J_u.transpose();
  return T(0.5) * (Pn + Pn.transpose());
}

/// Unicycle motion model driven by body velocities (a posefuse::MotionModel).
/// State PlanarPose<T> (m, m, rad); Control (v m/s, w rad/s);
/// \f$ f(x, u, \Delta t) \f$ = unicycle_step(x, v Δt, w Δt, method).
template <std::floating_point T = double>
struct Unicycle {
  using Scalar = T;
  using State = PlanarPose<T>;
  using Control = Eigen::Matrix<T, 2, 1>;  ///< (v m/s, w rad/s)

  Integration method{Integration::kExactArc};  ///< exact arc, or kEuler: eq 10 as printed
  /// Covariance of the control (v, w) over a step: (m/s)², (rad/s)².
  Eigen::Matrix<T, 2, 2> control_cov = Eigen::Matrix<T, 2, 2>::Zero();

  /// \f$ f(x, u, \Delta t) \f$.
  [[nodiscard]] State predict(const State& x, const Control& u, T dt_s) const noexcept {
    return unicycle_step(x, u(0) * dt_s, u(1) * dt_s, method);
  }
  /// \f$ J_{f,x} \f$.
  [[nodiscard]] Eigen::Matrix<T, 3, 3> jacobian(const State& x, const Control& u, T dt_s) const noexcept {
    Eigen::Matrix<T, 3, 3> J;
    (void)unicycle_step(x, u(0) * dt_s, u(1) * dt_s, method, &J);
    return J;
  }
  /// Process noise \f$ J_u (\Delta t^2 \Sigma_{vw}) J_u^\top \f$ (J_u w.r.t. (Δs, Δθ)).
  [[nodiscard]] Eigen::Matrix<T, 3, 3> noise(const State& x, const Control& u, T dt_s) const noexcept {
    Eigen::Matrix<T, 3, 2> Ju;
    (void)unicycle_step(x, u(0) * dt_s, u(1) * dt_s, method, nullptr, &Ju);
    return noise_of(Ju, dt_s);
  }

  /// predict(), jacobian() and noise() from one integration of the step
  /// (see HasLinearize): the same values bit for bit, the arc computed once
  /// instead of three times.
  struct Linearization {
    State state;                      ///< \f$ f(x, u, \Delta t) \f$
    Eigen::Matrix<T, 3, 3> jacobian;  ///< \f$ J_{f,x} = [1, 0, a; 0, 1, b; 0, 0, 1] \f$
    Eigen::Matrix<T, 3, 3> noise;     ///< process noise, as noise()
    /// \f$ J_{f,x} P J_{f,x}^\top \f$ from the two non-trivial entries a, b
    /// of the Jacobian, in closed form: with \f$ p_i \f$ row i of P, rows 0
    /// and 1 become \f$ p_0 + a p_2,\ p_1 + b p_2 \f$ and then the same on
    /// columns; one triangle is computed (eight multiply-adds) and mirrored
    /// (see HasLinearizePropagate). P must be symmetric, as every covariance
    /// is; only its lower triangle is read.
    [[nodiscard]] Eigen::Matrix<T, 3, 3> propagate(const Eigen::Matrix<T, 3, 3>& P) const noexcept {
      const T a = jacobian(0, 2), b = jacobian(1, 2);
      Eigen::Matrix<T, 3, 3> out;
      out(2, 2) = P(2, 2);
      out(2, 0) = P(2, 0) + a * P(2, 2);
      out(2, 1) = P(2, 1) + b * P(2, 2);
      out(0, 0) = (P(0, 0) + a * P(2, 0)) + a * out(2, 0);
      out(1, 0) = (P(1, 0) + b * P(2, 0)) + a * out(2, 1);
      out(1, 1) = (P(1, 1) + b * P(2, 1)) + b * out(2, 1);
      out(0, 1) = out(1, 0);
      out(0, 2) = out(2, 0);
      out(1, 2) = out(2, 1);
      return out;
    }
  };
  /// The step, its Jacobian and its noise at once.
  [[nodiscard]] Linearization linearize(const State& x, const Control& u, T dt_s) const noexcept {
    Linearization out;
    Eigen::Matrix<T, 3, 2> Ju;
    out.state = unicycle_step(x, u(0) * dt_s, u(1) * dt_s, method, &out.jacobian, &Ju);
    out.noise = noise_of(Ju, dt_s);
    return out;
  }

 private:
  /// \f$ J_u (\Delta t^2 \Sigma) J_u^\top \f$, \f$ \Sigma \f$ = control_cov made
  /// symmetric, in closed form from \f$ J_u \f$'s structure (row 2 is (0, 1)):
  /// one triangle (six entries) computed and mirrored, so the result is
  /// exactly symmetric.
  [[nodiscard]] Eigen::Matrix<T, 3, 3> noise_of(const Eigen::Matrix<T, 3, 2>& Ju, T dt_s) const noexcept {
    const T d2 = dt_s * dt_s;
    const T s00 = d2 * control_cov(0, 0), s11 = d2 * control_cov(1, 1);
    const T s01 = d2 * (T(0.5) * (control_cov(0, 1) + control_cov(1, 0)));
    const T a0 = Ju(0, 0), b0 = Ju(0, 1), a1 = Ju(1, 0), b1 = Ju(1, 1);
    // Rows 0 and 1 of J_u S: (a s00 + b s01, a s01 + b s11); row 2 is (s01, s11).
    const T g00 = a0 * s00 + b0 * s01, g01 = a0 * s01 + b0 * s11;
    const T g10 = a1 * s00 + b1 * s01, g11 = a1 * s01 + b1 * s11;
    Eigen::Matrix<T, 3, 3> Q;
    Q(0, 0) = g00 * a0 + g01 * b0;
    Q(1, 0) = Q(0, 1) = g10 * a0 + g11 * b0;
    Q(1, 1) = g10 * a1 + g11 * b1;
    Q(2, 0) = Q(0, 2) = s01 * a0 + s11 * b0;
    Q(2, 1) = Q(1, 2) = s01 * a1 + s11 * b1;
    Q(2, 2) = s11;
    return Q;
  }
};

}  // namespace posefuse

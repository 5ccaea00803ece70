#pragma once
/// @file
/// Interpolation between two timed samples: vectors (linear), planar poses
/// (linear position, heading along the shorter arc) and SE(3) poses (linear
/// translation, rotation by spherical linear interpolation), and the
/// interpolated pose of a Trajectory or PlanarTrajectory at a given time.
///
/// With the fraction \f$ f = (t - t_a) / (t_b - t_a) \f$ of a time t between
/// two samples at \f$ t_a < t_b \f$:
/// * vector: \f$ a + f (b - a) \f$;
/// * planar pose: \f$ (x, y) \f$ as a vector and
///   \f$ \theta = \mathrm{wrap}(\theta_a + f\,\mathrm{wrap}(\theta_b - \theta_a)) \f$
///   (angle_interpolate, core/angles.hpp), so 179° → -179° passes through 180°;
/// * SE(3) pose: \f$ t = t_a + f (t_b - t_a) \f$ and
///   \f$ q = \mathrm{slerp}(q_a, q_b, f) \f$ along the shorter arc, i.e.
///   \f$ R = R_a \,\mathrm{Exp}(f \,\mathrm{Log}(R_a^\top R_b)) \f$ (Shoemake,
///   "Animating rotation with quaternion curves", SIGGRAPH 1985). This is
///   interpolation of rotation and translation separately, as evo and the
///   TUM benchmark tools do, not along the SE(3) geodesic.
///
/// The pure kernels take f as given (f outside [0, 1] extrapolates) and are
/// noexcept: a NaN input gives NaN output. The time-based functions check
/// their input and throw posefuse::invalid_argument on a NaN time or samples
/// out of time order.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <optional>
#include <string>

#include <posefuse/core/angles.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/trajectory.hpp>

namespace posefuse {

/// The fraction \f$ f = (t - t_a) / (t_b - t_a) \f$ of t between two stamps.
/// @param[in] t_a_s, t_b_s the two stamps (s), \f$ t_a < t_b \f$
/// @param[in] t_s the time (s); outside [t_a, t_b] the result is outside [0, 1]
/// @return f
/// @throws posefuse::invalid_argument if a time is not finite or t_b <= t_a
template <std::floating_point T>
[[nodiscard]] T time_fraction(T t_a_s, T t_b_s, T t_s) {
  if (!std::isfinite(t_a_s) || !std::isfinite(t_b_s) || !std::isfinite(t_s))
    throw invalid_argument("time_fraction: times must be finite");
  if (!(t_b_s > t_a_s))
    throw invalid_argument("time_fraction: the second stamp (" + std::to_string(double(t_b_s)) +
                           " s) must be later than the first (" + std::to_string(double(t_a_s)) +
                           " s)");
  return (t_s - t_a_s) / (t_b_s - t_a_s);
}

/// Linear interpolation of two fixed-size vectors, \f$ a + f (b - a) \f$,
/// element by element.
/// @param[in] a value at f = 0
/// @param[in] b value at f = 1
/// @param[in] f fraction
/// @return the interpolated vector
template <class Derived>
[[nodiscard]] typename Derived::PlainObject lerp(const Eigen::MatrixBase<Derived>& a,
                                                 const Eigen::MatrixBase<Derived>& b,
                                                 typename Derived::Scalar f) noexcept {
  typename Derived::PlainObject out;
  for (Eigen::Index i = 0; i < a.size(); ++i) out(i) = a(i) + f * (b(i) - a(i));
  return out;
}

/// Interpolates a planar pose (x, y, θ): position linearly, heading along the
/// shorter arc (see the file comment). The heading of the result is wrapped
/// to [-π, π).
/// @param[in] a (x m, y m, θ rad) at f = 0
/// @param[in] b (x m, y m, θ rad) at f = 1
/// @param[in] f fraction
/// @return (x m, y m, θ rad)
template <std::floating_point T>
[[nodiscard]] Eigen::Matrix<T, 3, 1> interpolate_planar_pose(const Eigen::Matrix<T, 3, 1>& a,
                                                             const Eigen::Matrix<T, 3, 1>& b,
                                                             T f) noexcept {
  return {a(0) + f * (b(0) - a(0)), a(1) + f * (b(1) - a(1)), angle_interpolate(a(2), b(2), f)};
}

/// Interpolates an SE(3) pose: translation linearly, rotation by slerp along
/// the shorter arc (see the file comment).
/// @param[in] a pose at f = 0 (its linear part a rotation)
/// @param[in] b pose at f = 1 (its linear part a rotation)
/// @param[in] f fraction
/// @return the interpolated pose
template <std::floating_point T>
[[nodiscard]] Eigen::Transform<T, 3, Eigen::Isometry> interpolate_pose(
    const Eigen::Transform<T, 3, Eigen::Isometry>& a, const Eigen::Transform<T, 3, Eigen::Isometry>& b,
    T f) noexcept {
  const Eigen::Quaternion<T> qa(a.linear()), qb(b.linear());
  Eigen::Transform<T, 3, Eigen::Isometry> out = Eigen::Transform<T, 3, Eigen::Isometry>::Identity();
  out.linear() = qa.slerp(f, qb).normalized().toRotationMatrix();
  out.translation() = lerp(a.translation().eval(), b.translation().eval(), f);
  return out;
}

namespace detail {

/// Index k with t_s[k-1] < t <= t_s[k] (or 0 when t equals the first stamp),
/// for stamps in time order and t within [front, back].
template <class Lazy = void>
std::size_t bracket(const std::vector<double>& t_s, double t) {
  return std::size_t(std::lower_bound(t_s.begin(), t_s.end(), t) - t_s.begin());
}

/// interpolate_at() on a planar trajectory already checked with
/// validate_time_order() (no checks; used by loops over many times).
template <class Lazy = void>
std::optional<Eigen::Vector3d> interpolate_in_order(const PlanarTrajectory& traj, double t_s) {
  if (traj.empty() || !(t_s >= traj.t_s.front() && t_s <= traj.t_s.back())) return std::nullopt;
  const std::size_t k = bracket(traj.t_s, t_s);
  if (k == 0) return traj.poses[0];
  const double f = (t_s - traj.t_s[k - 1]) / (traj.t_s[k] - traj.t_s[k - 1]);
  return interpolate_planar_pose(traj.poses[k - 1], traj.poses[k], f);
}

/// Throws unless a Trajectory has matching counts, finite entries and
/// non-decreasing stamps.
template <class Lazy = void>
void require_time_order(const Trajectory& traj, const char* what) {
  if (traj.t_s.size() != traj.poses.size())
    throw invalid_argument(std::string(what) + ": trajectory has mismatched stamp and pose counts");
  for (std::size_t k = 0; k < traj.size(); ++k) {
    if (!std::isfinite(traj.t_s[k]) || !traj.poses[k].matrix().allFinite())
      throw invalid_argument(std::string(what) + ": trajectory entry " + std::to_string(k) +
                             " is not finite");
    if (k > 0 && traj.t_s[k] < traj.t_s[k - 1])
      throw invalid_argument(std::string(what) + ": trajectory stamps are not in time order at index " +
                             std::to_string(k));
  }
}

}  // namespace detail

/// The planar trajectory's pose at time `t_s`, interpolated between the two
/// poses around it (interpolate_planar_pose); a pose at exactly `t_s` is
/// returned as stored. The whole trajectory is checked first (O(n), then an
/// O(log n) search); to look up many times, check once and use the metrics of
/// eval/planar_metrics.hpp, which do.
/// @param[in] traj poses in time order (stamps non-decreasing)
/// @param[in] t_s time (s)
/// @return the pose (x m, y m, θ rad); nullopt when `traj` is empty or `t_s`
///         lies outside [t_s.front(), t_s.back()]
/// @throws posefuse::invalid_argument if `t_s` is not finite, or `traj` has
///         mismatched counts, a non-finite entry or decreasing stamps
///         (PlanarTrajectory::validate_time_order)
template <class Lazy = void>
[[nodiscard]] std::optional<Eigen::Vector3d> interpolate_at(const PlanarTrajectory& traj,
                                                          double t_s) {
  if (!std::isfinite(t_s)) throw invalid_argument("interpolate_at: the time is not finite");
  traj.validate_time_order();
  return detail::interpolate_in_order(traj, t_s);
}

/// The trajectory's pose at time `t_s`, interpolated between the two poses
/// around it (interpolate_pose: linear translation, slerp rotation); a pose
/// at exactly `t_s` is returned as stored. The whole trajectory is checked
/// first (O(n), then an O(log n) search).
/// @param[in] traj poses in time order (stamps non-decreasing)
/// @param[in] t_s time (s)
/// @return \f$ T_{world,body}(t) \f$; nullopt when `traj` is empty or `t_s`
///         lies outside [t_s.front(), t_s.back()]
/// @throws posefuse::invalid_argument if `t_s` is not finite, or `traj` has
///         mismatched counts, a non-finite entry or decreasing stamps
template <class Lazy = void>
[[nodiscard]] std::optional<Eigen::Isometry3d> interpolate_at(const Trajectory& traj,
                                                            double t_s) {
  if (!std::isfinite(t_s)) throw invalid_argument("interpolate_at: the time is not finite");
  detail::require_time_order(traj, "interpolate_at");
  if (traj.empty() || t_s < traj.t_s.front() || t_s > traj.t_s.back()) return std::nullopt;
  const std::size_t k = detail::bracket(traj.t_s, t_s);
  if (k == 0) return traj.poses[0];
  const double f = (t_s - traj.t_s[k - 1]) / (traj.t_s[k] - traj.t_s[k - 1]);
  return interpolate_pose(traj.poses[k - 1], traj.poses[k], f);
}

}  // namespace posefuse

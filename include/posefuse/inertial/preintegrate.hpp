#pragma once
/// @file
/// Pre-integration over a recorded, time-ordered sample range between two
/// arbitrary stamps (keyframes that fall between IMU samples): the boundary
/// samples are linearly interpolated. The Preintegration class itself is in
/// inertial/preintegration.hpp, which includes this header.

#include <cstddef>
#include <cstdint>
#include <span>

#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/inertial/imu_types.hpp>
#include <posefuse/inertial/preintegration.hpp>

namespace posefuse {

/// The sample at `t_ns` linearly interpolated between `a` and `b` (readings
/// only; the magnetometer is interpolated too).
/// @pre a.t_ns < b.t_ns and a.t_ns <= t_ns <= b.t_ns
[[nodiscard]] inline ImuSample interpolate_imu(const ImuSample& a, const ImuSample& b,
                                               std::int64_t t_ns) noexcept {
  const double s = seconds_between(t_ns, a.t_ns) / seconds_between(b.t_ns, a.t_ns);
  ImuSample out;
  out.t_ns = t_ns;
  out.accel_mps2 = a.accel_mps2 + s * (b.accel_mps2 - a.accel_mps2);
  out.gyro_radps = a.gyro_radps + s * (b.gyro_radps - a.gyro_radps);
  out.mag_uT = a.mag_uT + s * (b.mag_uT - a.mag_uT);
  return out;
}

/// Pre-integrates a time-ordered sample stream between two arbitrary stamps:
/// the boundary samples at `t0_ns` and `t1_ns` are linearly interpolated
/// from the samples around them (used as they are when a stamp matches).
/// @param[in] samples time-ordered samples covering [t0_ns, t1_ns]
/// @param[in] t0_ns, t1_ns the keyframe stamps, t0_ns < t1_ns
/// @param[out] out a fresh Preintegration (its noise, bias and options are kept)
/// @return kApplied, kOutOfRange when the samples do not cover the interval
///         (or t1_ns <= t0_ns), or the first non-applied status of a sample
///         inside it (out is then partial: do not use it)
template <class Lazy = void>
[[nodiscard]] ImuStatus preintegrate(std::span<const ImuSample> samples, std::int64_t t0_ns,
                                     std::int64_t t1_ns, Preintegration& out) {
  out = Preintegration(out.noise(), out.bias(), out.options());
  if (!(t0_ns < t1_ns) || samples.empty() || samples.front().t_ns > t0_ns ||
      samples.back().t_ns < t1_ns)
    return ImuStatus::kOutOfRange;
  // First sample with t > t0 (binary search; the stream must be ordered, which add() checks).
  std::size_t lo = 0, hi = samples.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (samples[mid].t_ns <= t0_ns) lo = mid + 1; else hi = mid;
  }
  const std::size_t k0 = lo;  // samples[k0 - 1].t_ns <= t0 < samples[k0].t_ns
  const ImuSample& before = samples[k0 - 1];
  const ImuSample first =
      before.t_ns == t0_ns ? before : interpolate_imu(before, samples[k0], t0_ns);
  ImuStatus st = out.add(first);
  if (st != ImuStatus::kStarted) return st;
  for (std::size_t k = k0; k < samples.size(); ++k) {
    const ImuSample& s = samples[k];
    if (s.t_ns >= t1_ns) {
      const ImuSample last = s.t_ns == t1_ns ? s : interpolate_imu(samples[k - 1], s, t1_ns);
      st = out.add(last);
      return st;
    }
    st = out.add(s);
    if (st != ImuStatus::kApplied) return st;
  }
  return ImuStatus::kOutOfRange;  // unreachable: samples.back().t_ns >= t1_ns
}

}  // namespace posefuse

#pragma once
/// @file
/// Gaps in an IMU stream: a missing stretch of samples that an estimator
/// would otherwise integrate over as if it had been measured. The limit is
/// the caller's to state (e.g. 4 sample periods: 20 ms for EuRoC's 200 Hz
/// IMU, whose V1_01_easy intervals are 5 ms ± 0.2 µs); nothing here guesses
/// it from the data.
///
/// * find_imu_gaps lists every interval longer than the limit (a report);
/// * read_euroc_imu_checked reads a EuRoC IMU csv as read_euroc_imu
///   (io/euroc.hpp) and refuses the first such interval as an io_error
///   naming the line of the sample after the gap and the line before it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/euroc.hpp>

namespace posefuse {

/// One interval between consecutive IMU samples longer than the limit.
struct ImuGap {
  std::size_t index = 0;       ///< the sample after the gap (samples[index - 1] is before it)
  std::int64_t t_before_ns = 0;  ///< stamp of the sample before the gap (ns)
  std::int64_t t_after_ns = 0;   ///< stamp of the sample after the gap (ns)
  /// Length of the interval (ns).
  [[nodiscard]] std::int64_t length_ns() const noexcept { return t_after_ns - t_before_ns; }
};

/// Every interval between consecutive samples longer than `max_interval_ns`.
/// @param[in] samples IMU samples in time order
/// @param[in] max_interval_ns the longest interval accepted (ns, > 0)
/// @throws posefuse::invalid_argument for a non-positive limit or stamps
///         that do not increase
template <class Lazy = void>
[[nodiscard]] std::vector<ImuGap> find_imu_gaps(const std::vector<ImuSample>& samples,
                                                std::int64_t max_interval_ns) {
  if (max_interval_ns <= 0) throw invalid_argument("find_imu_gaps: the limit must be > 0 ns");
  std::vector<ImuGap> gaps;
  for (std::size_t k = 1; k < samples.size(); ++k) {
    const std::int64_t a = samples[k - 1].t_ns, b = samples[k].t_ns;
    if (!(b > a))
      throw invalid_argument("find_imu_gaps: stamps do not increase at sample " + std::to_string(k));
    if (b - a > max_interval_ns) gaps.push_back(ImuGap{k, a, b});
  }
  return gaps;
}

/// Reads a EuRoC IMU csv (read_euroc_imu's format and checks) and refuses
/// an interval between consecutive samples longer than `max_interval_ns`.
/// @param[in] file the csv
/// @param[in] max_interval_ns the longest interval accepted (ns, > 0)
/// @return the samples
/// @throws posefuse::io_error (file:line) as read_euroc_imu, and for a gap:
///         `file:N: gap of X ms after line M (limit Y ms)`
/// @throws posefuse::invalid_argument for a non-positive limit
template <class Lazy = void>
[[nodiscard]] std::vector<ImuSample> read_euroc_imu_checked(const std::filesystem::path& file,
                                                            std::int64_t max_interval_ns) {
  if (max_interval_ns <= 0)
    throw invalid_argument("read_euroc_imu_checked: the gap limit must be > 0 ns");
  detail::LineReader reader(file);
  std::vector<ImuSample> out;
  std::vector<double> v;
  std::string line;
  std::size_t previous_line = 0;
  const auto ms = [](std::int64_t ns) { return detail::traj_io::format_number(double(ns) * 1e-6); };
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    ImuSample s;
    detail::euroc_io::parse_line(line, 7, "t[ns], wx, wy, wz [rad/s], ax, ay, az [m/s^2]", file, n,
                                 s.t_ns, v);
    if (!out.empty()) {
      detail::euroc_io::check_order(s.t_ns, out.back().t_ns, previous_line, file, n);
      const std::int64_t dt = s.t_ns - out.back().t_ns;
      if (dt > max_interval_ns)
        throw io_error(file, n,
                       "gap of " + ms(dt) + " ms after line " + std::to_string(previous_line) +
                           " (the limit is " + ms(max_interval_ns) + " ms)");
    }
    s.gyro_radps = Eigen::Vector3d(v[0], v[1], v[2]);
    s.accel_mps2 = Eigen::Vector3d(v[3], v[4], v[5]);
    out.push_back(s);
    previous_line = n;
  }
  if (out.empty()) throw io_error(file, "no IMU samples (the file has no data lines)");
  return out;
}

}  // namespace posefuse

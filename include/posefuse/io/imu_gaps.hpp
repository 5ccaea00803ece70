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
/// @param[in] options the reader's bounds on the readings
/// @throws posefuse::invalid_argument for a non-positive limit or bad bounds
template <class Lazy = void>
[[nodiscard]] std::vector<ImuSample> read_euroc_imu_checked(const std::filesystem::path& file,
                                                            std::int64_t max_interval_ns,
                                                            const ImuReadOptions& options = {}) {
  if (max_interval_ns <= 0)
    throw invalid_argument("read_euroc_imu_checked: the gap limit must be > 0 ns");
  std::vector<ImuSample> samples = read_euroc_imu(file, options);  // every check of the reader
  const std::vector<ImuGap> gaps = find_imu_gaps(samples, max_interval_ns);
  if (gaps.empty()) return samples;
  // Only on failure: a second pass finds the lines of the samples around the
  // first gap (data lines are the lines that are neither blank nor comments).
  const std::size_t after = gaps.front().index;
  detail::LineReader reader(file);
  std::string line;
  std::size_t data_lines = 0, line_before = 0, line_after = 0;
  while (line_after == 0 && reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    if (data_lines == after - 1) line_before = reader.line_no();
    if (data_lines == after) line_after = reader.line_no();
    ++data_lines;
  }
  const auto ms = [](std::int64_t ns) { return detail::message_number(double(ns) * 1e-6); };
  throw io_error(file, line_after,
                 "gap of " + ms(gaps.front().length_ns()) + " ms after line " + std::to_string(line_before) +
                     " (the limit is " + ms(max_interval_ns) + " ms)");
}

}  // namespace posefuse

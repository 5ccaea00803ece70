#pragma once
/// @file
/// EuRoC MAV csv files (Burri et al., "The EuRoC micro aerial vehicle
/// datasets", IJRR 2016): the IMU file `imu0/data.csv` and the state ground
/// truth `state_groundtruth_estimate0/data.csv`.
///
/// **IMU** — one sample a line, comma-separated:
/// `#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y,w_RS_S_z,a_RS_S_x [m s^-2],a_RS_S_y,a_RS_S_z`,
/// i.e. the stamp (integer ns), the angular rate and the specific force in
/// the sensor frame S.
///
/// **Ground truth** — `#timestamp, p_RS_R_x [m], p_RS_R_y, p_RS_R_z,
/// q_RS_w [], q_RS_x, q_RS_y, q_RS_z` (8 columns: the pose of the sensor frame
/// S in the reference frame R, quaternion scalar **first**), optionally
/// followed by `v_RS_R_x [m s^-1], v_RS_R_y, v_RS_R_z, b_w_RS_S_x [rad s^-1],
/// b_w_RS_S_y, b_w_RS_S_z, b_a_RS_S_x [m s^-2], b_a_RS_S_y, b_a_RS_S_z`
/// (17 columns: velocity in R, gyroscope bias, then accelerometer bias, in S).
/// Every data line must have the column count of the first.
///
/// **Strictness** (both readers). Lines starting with '#' and blank lines are
/// skipped; line numbers in errors are the file's physical, 1-based lines
/// (posefuse::io_error, `file:line: reason`). Fields are separated by commas
/// (spaces around them are allowed). A stamp must be a decimal integer that
/// fits int64; every other field a finite number. IMU readings and the
/// ground truth's biases must lie within physical bounds: an angular rate
/// within kMaxAbsAngularRate (50 rad/s) and a specific force within
/// kMaxAbsSpecificForce (500 m/s²) per axis, bounds the IMU reader can
/// widen (ImuReadOptions) for a sensor of a wider range; positions within
/// kMaxAbsPosition (1e100 m), as for every trajectory reader. Stamps must increase
/// strictly: a repeated or earlier stamp is an error naming both lines
/// (the ground-truth reader can keep the first or last of repeated stamps
/// instead, see ReadOptions::duplicates). A
/// quaternion must be within `quaternion_norm_tolerance` of unit norm (it is
/// then normalised). A file without data lines is an error.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <charconv>
#include <cstdio>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/message_number.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/read_options.hpp>

namespace posefuse {

/// A EuRoC state ground truth: stamps, poses \f$ T_{R,S} \f$, and — when the
/// file has 17 columns — velocity and biases.
struct EurocGroundTruth {
  std::vector<std::int64_t> t_ns;  ///< stamps (ns), strictly increasing
  /// Poses \f$ T_{R,S} \f$ (rotation S → R, translation = S origin in R, m);
  /// `trajectory.t_s[k] = seconds_from_ns(t_ns[k])`.
  Trajectory trajectory;
  /// Velocity of S in R (m/s), when present.
  std::optional<std::vector<Eigen::Vector3d>> velocity;
  /// Gyroscope bias (rad/s, frame S), when present.
  std::optional<std::vector<Eigen::Vector3d>> gyro_bias;
  /// Accelerometer bias (m/s², frame S), when present.
  std::optional<std::vector<Eigen::Vector3d>> accel_bias;

  /// Number of states.
  [[nodiscard]] std::size_t size() const noexcept { return t_ns.size(); }
  /// True when velocity and biases were read (17-column file).
  [[nodiscard]] bool has_velocity_and_biases() const noexcept { return velocity.has_value(); }
};

/// Default largest magnitude (rad/s) of an angular rate (a gyroscope
/// reading or bias axis) in a EuRoC file: about 2 900 deg/s, beyond the
/// range of the gyroscopes of visual-inertial rigs (MEMS parts saturate at
/// 2 000 deg/s, 35 rad/s; EuRoC's ADIS16448 at 1 000 deg/s). A reading
/// beyond it is corrupt or saturated; ImuReadOptions raises it for a sensor
/// of a wider range.
inline constexpr double kMaxAbsAngularRate = 50.0;

/// Default largest magnitude (m/s²) of a specific force (an accelerometer
/// reading or bias axis) in a EuRoC file: about 51 g, beyond the range of
/// the accelerometers of visual-inertial rigs (16 g; EuRoC's ADIS16448
/// 18 g). ImuReadOptions raises it for a sensor of a wider range.
inline constexpr double kMaxAbsSpecificForce = 500.0;

/// The largest bounds ImuReadOptions accepts: beyond them the products of
/// pre-integration overflow.
inline constexpr double kMaxAbsAngularRateLimit = 1e4;
inline constexpr double kMaxAbsSpecificForceLimit = 1e7;

/// Bounds of the EuRoC IMU reader (read_euroc_imu).
struct ImuReadOptions {
  double max_abs_angular_rate = kMaxAbsAngularRate;      ///< per axis (rad/s), in (0, 1e4]
  double max_abs_specific_force = kMaxAbsSpecificForce;  ///< per axis (m/s²), in (0, 1e7]
};

namespace detail::euroc_io {

/// Refuses a vector of `what` (unit `unit`) with an axis beyond `bound`
/// (file:line).
template <class Lazy = void>
void check_bound(const Eigen::Vector3d& v, double bound, const char* what, const char* unit,
                 const std::filesystem::path& file, std::size_t line) {
  const double m = v.cwiseAbs().maxCoeff();
  if (m <= bound) return;
  throw io_error(file, line,
                 std::string(what) + " of magnitude " + posefuse::detail::message_number(m) + " " + unit +
                     " is beyond the physical bound " + posefuse::detail::message_number(bound) + " " + unit);
}

/// Refuses an angular rate and a specific force beyond `bounds` (file:line).
template <class Lazy = void>
void check_imu_bounds(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, const char* gyro_what,
                      const char* accel_what, const std::filesystem::path& file, std::size_t line,
                      const ImuReadOptions& bounds = {}) {
  check_bound(gyro, bounds.max_abs_angular_rate, gyro_what, "rad/s", file, line);
  check_bound(accel, bounds.max_abs_specific_force, accel_what, "m/s^2", file, line);
}

/// Tokenises and parses one data line: the stamp and the remaining numbers.
template <class Lazy = void>
void parse_line(std::string_view line, std::size_t expected, std::string_view layout,
                const std::filesystem::path& file, std::size_t line_no, std::int64_t& t_ns,
                std::vector<double>& values) {
  const std::vector<std::string_view> f = split_csv(line);
  if (f.size() != expected)
    throw io_error(file, line_no,
                   "expected " + std::to_string(expected) + " comma-separated fields (" +
                       std::string(layout) + "), found " + std::to_string(f.size()));
  t_ns = parse_stamp(f[0], file, line_no);
  values.resize(expected - 1);
  for (std::size_t c = 1; c < expected; ++c)
    values[c - 1] = traj_io::parse_number(f[c], file, line_no, c + 1);
}

/// Throws when `t_ns` does not follow `previous` strictly (IMU samples:
/// no duplicate policy).
template <class Lazy = void>
void check_order(std::int64_t t_ns, std::int64_t previous, std::size_t previous_line,
                 const std::filesystem::path& file, std::size_t line_no) {
  if (t_ns > previous) return;
  traj_io::throw_stamp_out_of_order(t_ns, previous, previous_line, file, line_no,
                                    /*offer_policies=*/false);
}

}  // namespace detail::euroc_io

/// Reads a EuRoC IMU csv (see the file comment). The magnetometer field of
/// each ImuSample is zero.
/// @param[in] file path of `imu0/data.csv` (or any file of that layout)
/// @param[in] options the largest angular rate and specific force accepted
///                    (physically impossible readings are refused at their line)
/// @return the samples in file order, stamps strictly increasing
/// @throws posefuse::io_error (file:line) when the file cannot be opened or
///         read, a line has not 7 fields, a stamp is not an int64 integer, a
///         number is unparsable or not finite, an angular rate or a specific
///         force beyond `options`' bounds, a stamp repeats or goes back, a
///         line is longer than kMaxLineBytes; (file only) when it has no data line
/// @throws posefuse::invalid_argument for a bound not in (0, kMaxAbs...Limit]
template <class Lazy = void>
[[nodiscard]] std::vector<ImuSample> read_euroc_imu(const std::filesystem::path& file,
                                                    const ImuReadOptions& options = {}) {
  if (!(options.max_abs_angular_rate > 0 && options.max_abs_angular_rate <= kMaxAbsAngularRateLimit))
    throw invalid_argument("read_euroc_imu: max_abs_angular_rate must be in (0, 1e4] rad/s");
  if (!(options.max_abs_specific_force > 0 && options.max_abs_specific_force <= kMaxAbsSpecificForceLimit))
    throw invalid_argument("read_euroc_imu: max_abs_specific_force must be in (0, 1e7] m/s^2");
  detail::LineReader reader(file);
  std::vector<ImuSample> out;
  std::vector<double> v;
  std::string line;
  std::size_t previous_line = 0;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    ImuSample s;
    detail::euroc_io::parse_line(line, 7, "t[ns], wx, wy, wz [rad/s], ax, ay, az [m/s^2]", file, n,
                                 s.t_ns, v);
    if (!out.empty()) detail::euroc_io::check_order(s.t_ns, out.back().t_ns, previous_line, file, n);
    s.gyro_radps = Eigen::Vector3d(v[0], v[1], v[2]);
    s.accel_mps2 = Eigen::Vector3d(v[3], v[4], v[5]);
    detail::euroc_io::check_imu_bounds(s.gyro_radps, s.accel_mps2, "angular rate", "specific force",
                                       file, n, options);
    out.push_back(s);
    previous_line = n;
  }
  if (out.empty()) throw io_error(file, "no IMU samples (the file has no data lines)");
  return out;
}

/// Reads a EuRoC state ground truth csv with 8 columns (pose) or 17 (pose,
/// velocity, gyroscope bias, accelerometer bias); see the file comment.
/// @param[in] file path of `state_groundtruth_estimate0/data.csv` (or any file of that layout)
/// @param[in] options quaternion norm tolerance; repeated stamps follow
///            `options.duplicates` (the default refuses them)
/// @param[out] report optional: states dropped for a repeated stamp
/// @return stamps, poses and, for 17 columns, velocity and biases
/// @throws posefuse::io_error (file:line) when the file cannot be opened or
///         read, the first data line has neither 8 nor 17 fields or a later
///         one differs from it, a stamp is not an int64 integer, a number is
///         unparsable or not finite, a position is beyond kMaxAbsPosition, a
///         bias beyond kMaxAbsAngularRate / kMaxAbsSpecificForce, a
///         quaternion is zero or not unit within tolerance, a stamp repeats or goes back, a line is too long;
///         (file only) when it has no data line
template <class Lazy = void>
[[nodiscard]] EurocGroundTruth read_euroc_groundtruth(const std::filesystem::path& file,
                                                      const ReadOptions& options = {},
                                                      ReadReport* report = nullptr) {
  detail::LineReader reader(file);
  EurocGroundTruth gt;
  std::vector<double> v;
  std::string line;
  std::size_t columns = 0, previous_line = 0;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    if (columns == 0) {
      columns = detail::split_csv(line).size();
      if (columns != 8 && columns != 17)
        throw io_error(file, n,
                       "expected 8 fields (t[ns], p xyz, q wxyz) or 17 (+ v xyz, b_gyro xyz, "
                       "b_accel xyz), found " +
                           std::to_string(columns));
      if (columns == 17) {
        gt.velocity.emplace();
        gt.gyro_bias.emplace();
        gt.accel_bias.emplace();
      }
    }
    std::int64_t t_ns = 0;
    detail::euroc_io::parse_line(line, columns,
                                 columns == 8 ? "t[ns], p xyz, q wxyz (as the first data line)"
                                              : "t[ns], p xyz, q wxyz, v xyz, b_gyro xyz, "
                                                "b_accel xyz (as the first data line)",
                                 file, n, t_ns, v);
    const Eigen::Quaterniond q = detail::traj_io::checked_quaternion(
        Eigen::Quaterniond(v[3], v[4], v[5], v[6]), options.quaternion_norm_tolerance, file, n);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = q.toRotationMatrix();
    T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    detail::traj_io::check_position(T.translation(), file, n);
    if (columns == 17)
      detail::euroc_io::check_imu_bounds(Eigen::Vector3d(v[10], v[11], v[12]),
                                         Eigen::Vector3d(v[13], v[14], v[15]), "gyroscope bias",
                                         "accelerometer bias", file, n);
    const detail::traj_io::StampAction action =
        gt.t_ns.empty() ? detail::traj_io::StampAction::kAppend
                        : detail::traj_io::next_stamp_action(t_ns, gt.t_ns.back(), previous_line,
                                                             options.duplicates, report, file, n);
    previous_line = n;
    if (action == detail::traj_io::StampAction::kSkip) continue;
    if (action == detail::traj_io::StampAction::kReplaceLast) {
      gt.trajectory.poses.back() = T;
      if (columns == 17) {
        gt.velocity->back() = Eigen::Vector3d(v[7], v[8], v[9]);
        gt.gyro_bias->back() = Eigen::Vector3d(v[10], v[11], v[12]);
        gt.accel_bias->back() = Eigen::Vector3d(v[13], v[14], v[15]);
      }
      continue;
    }
    gt.t_ns.push_back(t_ns);
    gt.trajectory.push_back(seconds_from_ns(t_ns), T);
    if (columns == 17) {
      gt.velocity->emplace_back(v[7], v[8], v[9]);
      gt.gyro_bias->emplace_back(v[10], v[11], v[12]);
      gt.accel_bias->emplace_back(v[13], v[14], v[15]);
    }
  }
  if (gt.t_ns.empty()) throw io_error(file, "no ground-truth states (the file has no data lines)");
  return gt;
}

}  // namespace posefuse

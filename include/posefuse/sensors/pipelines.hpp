#pragma once
/// @file
/// The two ready-made compile-time sensor chains of seed 001 (Fig. 2, Fig. 5):
///
///  * attitude: ImuSample -> AccelerometerTiltStage (eq 1-2, REP-103 form)
///    -> ComplementaryTiltStage (eq 3-4) -> CompassStage (eq 5-7, corrected)
///    -> Attitude;
///  * odometry: WheelSample -> FourWheelAverage (eq 8)
///    -> DiffDriveOdometry (eq 9) -> DeadReckoning (eq 10) -> PlanarPoseEstimate.
///
/// The defaults are the sound variants: the gyro rates reach roll and pitch
/// through the ZYX Euler kinematics (GyroToTiltRate::kEulerKinematics) and
/// dead reckoning integrates the exact arc (Integration::kExactArc). The
/// seed's printed forms are options, selected explicitly to reproduce its
/// figures: GyroToTiltRate::kSeed (eq 3-4 as printed: the body rates taken
/// for roll and pitch rates, which lags while turning on a tilt) and
/// Integration::kEuler (eq 10 as printed, first order).
///
/// Both start from the library's raw samples (core/samples.hpp, stamped
/// `t_ns`) and compute every step length from stamp differences with
/// seconds_between (core/time.hpp), so they run on stamps anywhere in the
/// int64 range.
///
/// Both are posefuse::Pipeline types (core/pipeline.hpp): every call is
/// inlined, no allocation, no virtual dispatch; stages are reachable with
/// `pipeline.stage<I>()` (e.g. `stage<2>().reset(pose, cov)` to re-anchor
/// dead reckoning).

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <limits>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/filters/complementary.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/sensors/accelerometer_tilt.hpp>
#include <posefuse/sensors/compass.hpp>
#include <posefuse/sensors/dead_reckoning.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <posefuse/sensors/sample_status.hpp>
#include <posefuse/sensors/wheel_odometry.hpp>

namespace posefuse {

/// Which angular rates drive the roll/pitch prediction of the complementary filter.
enum class GyroToTiltRate : std::uint8_t {
  /// Seed 001 eq 3-4 as printed (a reproduction; select it explicitly):
  /// roll rate = gyro_x, pitch rate = gyro_y. Right only for small tilt:
  /// turning at a tilt, the yaw rate leaks into roll and pitch.
  kSeed,
  /// ZYX Euler kinematics, the default:
  /// \f$ \dot r = \omega_x + \tan p(\sin r\,\omega_y + \cos r\,\omega_z) \f$,
  /// \f$ \dot p = \cos r\,\omega_y - \sin r\,\omega_z \f$ (exact at any tilt below 90° pitch).
  kEulerKinematics,
};

/// Attitude-chain stage 2: complementary filter on roll and pitch (seed 001
/// eq 3-4) with \f$ \Delta t \f$ from the sample stamps: the filter runs on
/// the time since the stage's first sample, seconds_between(t_ns, first
/// t_ns), so its steps are stamp differences in seconds. Input and Output
/// TiltedImu; the output's tilt is the filtered estimate. The first sample
/// initialises from the accelerometer (status kFirst); a sample whose tilt is
/// not usable (status kNonFinite or a non-finite gyro) leaves the filter
/// untouched and is passed on with the held estimate and status kNonFinite.
class ComplementaryTiltStage {
 public:
  using Input = TiltedImu;
  using Output = TiltedImu;

  /// @param[in] alpha filter constant in [0, 1] (seed: gyro weight)
  /// @param[in] mapping how gyro rates become roll/pitch rates (kSeed: eq 3-4 as printed)
  /// @throws posefuse::invalid_argument if alpha is outside [0, 1]
  explicit ComplementaryTiltStage(double alpha,
                                  GyroToTiltRate mapping = GyroToTiltRate::kEulerKinematics)
      : filter_(alpha), mapping_(mapping) {}

  /// @throws posefuse::invalid_argument if the stamp is not later than the
  ///         previous accepted one
  template <class Lazy = void>  // compiled only where called (compile cost)
  [[nodiscard]] TiltedImu operator()(const TiltedImu& in) {
    if (!filter_.initialised()) t0_ns_ = in.imu.t_ns;
    TiltedImu out = in;
    const Eigen::Vector2d absolute(in.tilt.roll, in.tilt.pitch);
    const Eigen::Vector3d& g = in.imu.gyro_radps;
    const Eigen::Vector2d& x = filter_.estimate();
    Eigen::Vector2d rate(g.x(), g.y());
    if (mapping_ == GyroToTiltRate::kEulerKinematics) {
      const double sr = std::sin(x(0)), cr = std::cos(x(0)), tp = std::tan(x(1));
      rate << g.x() + tp * (sr * g.y() + cr * g.z()), cr * g.y() - sr * g.z();
    }
    const Eigen::Vector2d bad = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    const ComplementaryStatus st =
        filter_.update(seconds_between(in.imu.t_ns, t0_ns_), rate,
                       in.status == SampleStatus::kNonFinite ? bad : absolute);
    out.tilt = {filter_.estimate()(0), filter_.estimate()(1)};
    out.status = st == ComplementaryStatus::kNonFinite  ? SampleStatus::kNonFinite
                 : st == ComplementaryStatus::kInitialised ? SampleStatus::kFirst
                                                          : SampleStatus::kOk;
    return out;
  }

  /// The underlying filter (estimate, alpha; its time is seconds since first_stamp_ns()).
  [[nodiscard]] const ComplementaryFilter<double, 2>& filter() const noexcept { return filter_; }
  /// Stamp of the sample that initialised the filter (ns; meaningful once it is initialised).
  [[nodiscard]] std::int64_t first_stamp_ns() const noexcept { return t0_ns_; }
  /// Forgets the estimate; the next sample initialises again.
  void reset() noexcept { filter_.reset(); }

 private:
  ComplementaryFilter<double, 2> filter_;
  GyroToTiltRate mapping_;
  std::int64_t t0_ns_{0};
};

/// Configuration of the attitude chain.
struct AttitudeConfig {
  double alpha{0.98};  ///< complementary filter constant, [0, 1]
  /// Euler kinematics by default; kSeed reproduces eq 3-4 as printed.
  GyroToTiltRate gyro_mapping{GyroToTiltRate::kEulerKinematics};
  MagnetometerCalibration calibration{};  ///< hard/soft iron (identity by default)
  double declination_rad{0.0};            ///< added to the magnetic yaw, rad
};

/// ImuSample -> Attitude (seed 001 eq 1-7).
using AttitudePipeline = Pipeline<AccelerometerTiltStage, ComplementaryTiltStage, CompassStage>;

/// Builds the attitude chain.
/// @throws posefuse::invalid_argument if alpha is outside [0, 1] or the
///         calibration/declination is not finite
[[nodiscard]] inline AttitudePipeline make_attitude_pipeline(const AttitudeConfig& config = {}) {
  return AttitudePipeline(AccelerometerTiltStage{},
                          ComplementaryTiltStage(config.alpha, config.gyro_mapping),
                          CompassStage(config.calibration, config.declination_rad));
}

/// WheelSample -> PlanarPoseEstimate (seed 001 eq 8-10).
using OdometryPipeline = Pipeline<FourWheelAverage, DiffDriveOdometry, DeadReckoning>;

/// Builds the odometry chain; `stage<2>()` is the DeadReckoning (for reset()).
/// @param[in] params robot geometry
/// @param[in] noise per-wheel encoder noise
/// @param[in] method kExactArc (default) or kEuler (eq 10 as printed)
/// @param[in] start initial pose, world frame
/// @param[in] cov0 initial pose covariance (3x3; a template only so that
///            including this header does not compile DeadReckoning's check)
/// @throws posefuse::invalid_argument for invalid params, noise, start or cov0
template <class Cov = Eigen::Matrix3d>
[[nodiscard]] OdometryPipeline make_odometry_pipeline(
    const DiffDriveParams& params, const WheelNoiseParams& noise = {},
    Integration method = Integration::kExactArc, const PlanarPose<double>& start = {},
    const Cov& cov0 = Cov::Zero()) {
  return OdometryPipeline(FourWheelAverage{}, DiffDriveOdometry(params, noise),
                          DeadReckoning(method, start, cov0));
}

}  // namespace posefuse

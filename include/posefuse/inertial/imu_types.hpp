#pragma once
/// @file
/// The value types of IMU pre-integration (inertial/preintegration.hpp):
/// the continuous-time noise figures, the accelerometer and gyroscope biases,
/// the outcome of adding one sample, and the pre-integrated measurement
/// \f$ (\Delta p, \Delta R, \Delta v) \f$ as a manifold. The samples themselves
/// are posefuse::ImuSample (core/samples.hpp).

#include <Eigen/Core>
#include <cmath>
#include <string>

#include <posefuse/core/error.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse {

/// Continuous-time IMU noise figures (the four numbers of a Kalibr / EuRoC
/// `imu.yaml`).
struct ImuNoise {
  double gyro_noise_density = 1.6968e-4;   ///< \f$ \sigma_g \f$ (rad/s/√Hz)
  double accel_noise_density = 2.0e-3;     ///< \f$ \sigma_a \f$ (m/s²/√Hz)
  double gyro_random_walk = 1.9393e-5;     ///< \f$ \sigma_{b_g} \f$ (rad/s²/√Hz)
  double accel_random_walk = 3.0e-3;       ///< \f$ \sigma_{b_a} \f$ (m/s³/√Hz)

  /// Checks every figure is finite and non-negative.
  /// @throws posefuse::invalid_argument naming the first bad figure
  void validate() const {
    const double v[4] = {gyro_noise_density, accel_noise_density, gyro_random_walk,
                         accel_random_walk};
    const char* names[4] = {"gyro_noise_density", "accel_noise_density", "gyro_random_walk",
                            "accel_random_walk"};
    for (int i = 0; i < 4; ++i)
      if (!(std::isfinite(v[i]) && v[i] >= 0.0))
        throw invalid_argument(std::string("ImuNoise: ") + names[i] +
                               " must be finite and >= 0, got " + std::to_string(v[i]));
  }
};

/// Accelerometer and gyroscope biases in the body frame.
struct ImuBias {
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< \f$ b_a \f$ (m/s²)
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   ///< \f$ b_g \f$ (rad/s)
  /// As one vector \f$ [b_a, b_g] \f$.
  [[nodiscard]] Eigen::Matrix<double, 6, 1> vector() const {
    Eigen::Matrix<double, 6, 1> b;
    b << accel, gyro;
    return b;
  }
  /// From one vector \f$ [b_a, b_g] \f$.
  [[nodiscard]] static ImuBias from_vector(const Eigen::Matrix<double, 6, 1>& b) {
    return ImuBias{b.head<3>(), b.tail<3>()};
  }
};

/// Outcome of adding one IMU sample. A sample older than the last one, with
/// the same stamp, after a gap above the limit or with a non-finite reading
/// is reported and not integrated; the state is then untouched.
enum class ImuStatus {
  kApplied,        ///< integrated
  kStarted,        ///< the first sample: it starts the interval, nothing to integrate yet
  kOutOfOrder,     ///< stamp before the last sample's: not integrated
  kRepeated,       ///< stamp equal to the last sample's: not integrated
  kGap,            ///< time since the last sample above max_gap_ns: not integrated
  kNonFinite,      ///< a reading is NaN or infinite: not integrated
  kOutOfRange,     ///< (preintegrate) the samples do not cover the requested interval
};

/// Human-readable name of an ImuStatus.
[[nodiscard]] constexpr const char* to_string(ImuStatus s) noexcept {
  switch (s) {
    case ImuStatus::kApplied: return "applied";
    case ImuStatus::kStarted: return "started";
    case ImuStatus::kOutOfOrder: return "out of order";
    case ImuStatus::kRepeated: return "repeated stamp";
    case ImuStatus::kGap: return "gap above the limit";
    case ImuStatus::kNonFinite: return "non-finite reading";
    case ImuStatus::kOutOfRange: return "samples do not cover the interval";
  }
  return "unknown";
}

/// The pre-integrated measurement \f$ (\Delta p, \Delta R, \Delta v) \f$, a
/// posefuse::Manifold of dimension 9 with tangent \f$ [\delta p, \delta\phi, \delta v] \f$
/// (\f$ \Delta R \oplus \delta\phi = \Delta R\,\mathrm{Exp}(\delta\phi) \f$; p and v Euclidean).
struct ImuDelta {
  using Scalar = double;             ///< scalar type
  static constexpr int Dim = 9;      ///< tangent dimension
  using Tangent = Eigen::Matrix<double, 9, 1>;  ///< [δp, δφ, δv]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< \f$ \Delta p_{ij} \f$ (m, frame i)
  SO3d R;                                       ///< \f$ \Delta R_{ij} = R_i^\top R_j \f$
  Eigen::Vector3d v = Eigen::Vector3d::Zero();  ///< \f$ \Delta v_{ij} \f$ (m/s, frame i)

  /// \f$ x \oplus d \f$.
  [[nodiscard]] ImuDelta plus(const Tangent& d) const {
    return ImuDelta{p + d.segment<3>(0), R.plus(d.segment<3>(3)), v + d.segment<3>(6)};
  }
  /// \f$ y \ominus x \f$ (this = y).
  [[nodiscard]] Tangent minus(const ImuDelta& x) const {
    Tangent d;
    d << p - x.p, R.minus(x.R), v - x.v;
    return d;
  }
};

}  // namespace posefuse

// Per-sample cost of the seed-001 sensor layer: complementary filter, compass
// (corrected vs printed eq 5-7), one odometry step (Euler vs exact arc, with
// and without covariance), and the attitude / odometry pipelines against the
// same stages called by hand (the pipeline should add nothing).
//
// Build in Release: cmake --preset release && cmake --build --target bench_sensors
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <posefuse/lie/rotation.hpp>
#include <posefuse/filters/complementary.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/seed/tilt_compensated_heading.hpp>
#include <posefuse/sensors/compass.hpp>
#include <posefuse/sensors/dead_reckoning.hpp>
#include <posefuse/sensors/pipelines.hpp>
#include <posefuse/sensors/wheel_odometry.hpp>
#include <random>

namespace {

constexpr std::size_t kN = 1024;  // inputs cycled through, built outside the timed loop

std::array<posefuse::ImuSample, kN> make_imu() {
  std::array<posefuse::ImuSample, kN> out;
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.05);
  const Eigen::Vector3d field(30.0, 0.0, -40.0);
  for (std::size_t k = 0; k < kN; ++k) {
    const double t = 0.01 * double(k);
    const Eigen::Matrix3d R = posefuse::rotation_from_euler_zyx(
        posefuse::EulerZYX<double>{0.1 * std::sin(t), 0.05 * std::cos(t), 0.3 * t});
    out[k].accel_mps2 = R.transpose() * Eigen::Vector3d(0, 0, 9.81) + Eigen::Vector3d(n(rng), n(rng), n(rng));
    out[k].gyro_radps = Eigen::Vector3d(n(rng), n(rng), 0.3 + n(rng));
    out[k].mag_uT = R.transpose() * field + Eigen::Vector3d(n(rng), n(rng), n(rng));
  }
  return out;
}

template <class T>
void BM_ComplementaryFilter_Update(benchmark::State& state) {
  using F = posefuse::ComplementaryFilter<T, 2>;
  const auto imu = make_imu();
  std::array<typename F::Vector, kN> rate, tilt;
  for (std::size_t k = 0; k < kN; ++k) {
    rate[k] = imu[k].gyro_radps.template head<2>().template cast<T>();
    const auto t = posefuse::accelerometer_tilt_rep103(imu[k].accel_mps2);
    tilt[k] << T(t.roll), T(t.pitch);
  }
  F f(T(0.98));
  std::size_t k = 0;
  double t = 0.0;
  for (auto _ : state) {
    t += 0.01;
    benchmark::DoNotOptimize(f.update(T(t), rate[k], tilt[k]));
    benchmark::DoNotOptimize(f.estimate().data());
    if (++k == kN) {  // float stamps run out of resolution: restart every kN samples
      k = 0;
      t = 0.0;
      f.reset();
    }
  }
}
BENCHMARK_TEMPLATE(BM_ComplementaryFilter_Update, float);
BENCHMARK_TEMPLATE(BM_ComplementaryFilter_Update, double);

template <class T, bool kSeed>
void compass_bench(benchmark::State& state) {
  const auto imu = make_imu();
  std::array<Eigen::Matrix<T, 3, 1>, kN> mag;
  std::array<posefuse::Tilt<T>, kN> tilt;
  for (std::size_t k = 0; k < kN; ++k) {
    mag[k] = imu[k].mag_uT.template cast<T>();
    tilt[k] = posefuse::accelerometer_tilt_rep103(Eigen::Matrix<T, 3, 1>(imu[k].accel_mps2.template cast<T>()));
  }
  std::size_t k = 0;
  for (auto _ : state) {
    if constexpr (kSeed) {
      benchmark::DoNotOptimize(posefuse::seed::tilt_compensated_heading_seed(mag[k], tilt[k].roll, tilt[k].pitch));
    } else {
      benchmark::DoNotOptimize(posefuse::tilt_compensated_heading(mag[k], tilt[k].roll, tilt[k].pitch));
    }
    k = (k + 1) % kN;
  }
}
template <class T>
void BM_Compass_HeadingCorrect(benchmark::State& state) {
  compass_bench<T, false>(state);
}
template <class T>
void BM_Compass_HeadingSeed(benchmark::State& state) {
  compass_bench<T, true>(state);
}
BENCHMARK_TEMPLATE(BM_Compass_HeadingCorrect, float);
BENCHMARK_TEMPLATE(BM_Compass_HeadingCorrect, double);
BENCHMARK_TEMPLATE(BM_Compass_HeadingSeed, float);
BENCHMARK_TEMPLATE(BM_Compass_HeadingSeed, double);

void BM_MagnetometerCalibration_Apply(benchmark::State& state) {
  const auto imu = make_imu();
  posefuse::MagnetometerCalibration cal;
  cal.hard_iron << 3, -2, 5;
  cal.soft_iron << 1.1, 0.05, 0, 0.05, 0.95, 0.02, 0, 0.02, 1.0;
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(cal.apply(imu[k].mag_uT).eval());
    k = (k + 1) % kN;
  }
}
BENCHMARK(BM_MagnetometerCalibration_Apply);

std::array<Eigen::Vector2d, kN> make_motion() {
  std::array<Eigen::Vector2d, kN> u;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ds(0.0, 0.02), dth(-0.05, 0.05);
  for (auto& x : u) x << ds(rng), dth(rng);
  return u;
}

/// One pose step without covariance (state.range(0): 0 Euler, 1 exact arc).
template <class T>
void BM_Unicycle_Step(benchmark::State& state) {
  const auto u = make_motion();
  const auto method = state.range(0) == 0 ? posefuse::Integration::kEuler : posefuse::Integration::kExactArc;
  posefuse::PlanarPose<T> x;
  std::size_t k = 0;
  for (auto _ : state) {
    x = posefuse::unicycle_step(x, T(u[k](0)), T(u[k](1)), method);
    benchmark::DoNotOptimize(x);
    k = (k + 1) % kN;
  }
  state.SetLabel(state.range(0) == 0 ? "euler" : "exact_arc");
}
BENCHMARK_TEMPLATE(BM_Unicycle_Step, float)->Arg(0)->Arg(1);
BENCHMARK_TEMPLATE(BM_Unicycle_Step, double)->Arg(0)->Arg(1);

/// One dead-reckoning step with covariance propagation (0 Euler, 1 exact arc).
void BM_DeadReckoning_StepWithCovariance(benchmark::State& state) {
  const auto u = make_motion();
  const auto method = state.range(0) == 0 ? posefuse::Integration::kEuler : posefuse::Integration::kExactArc;
  posefuse::DeadReckoning dr(method);
  Eigen::Matrix2d C;
  C << 1e-6, 1e-8, 1e-8, 1e-5;
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(dr.step(u[k](0), u[k](1), C));
    benchmark::DoNotOptimize(dr.covariance().data());
    k = (k + 1) % kN;
  }
  state.SetLabel(state.range(0) == 0 ? "euler" : "exact_arc");
}
BENCHMARK(BM_DeadReckoning_StepWithCovariance)->Arg(0)->Arg(1);

void BM_AttitudePipeline_Run(benchmark::State& state) {
  auto imu = make_imu();
  // eq 3-4 as printed (kSeed), as the corridor program runs it; the default is the Euler kinematics.
  posefuse::AttitudePipeline att =
      posefuse::make_attitude_pipeline(posefuse::AttitudeConfig{0.98, posefuse::GyroToTiltRate::kSeed});
  std::size_t k = 0;
  std::int64_t t_ns = 0;
  for (auto _ : state) {
    imu[k].t_ns = (t_ns += 10'000'000);  // 100 Hz
    benchmark::DoNotOptimize(att(imu[k]));
    k = (k + 1) % kN;
  }
}
BENCHMARK(BM_AttitudePipeline_Run);

void BM_AttitudeStages_ByHand(benchmark::State& state) {
  auto imu = make_imu();
  posefuse::AccelerometerTiltStage s1;
  posefuse::ComplementaryTiltStage s2(0.98, posefuse::GyroToTiltRate::kSeed);
  posefuse::CompassStage s3;
  std::size_t k = 0;
  std::int64_t t_ns = 0;
  for (auto _ : state) {
    imu[k].t_ns = (t_ns += 10'000'000);  // 100 Hz
    benchmark::DoNotOptimize(s3(s2(s1(imu[k]))));
    k = (k + 1) % kN;
  }
}
BENCHMARK(BM_AttitudeStages_ByHand);

constexpr posefuse::DiffDriveParams kParams{1000.0, 0.05, 0.40};

/// The next encoder sample of a gently curving drive at 50 Hz (the same input
/// for the pipeline and the hand-called stages).
void advance_wheels(posefuse::WheelSample& in, std::int64_t k) {
  in.t_ns += 20'000'000;
  in.ticks.fl += 100 + (k & 7);
  in.ticks.bl += 101;
  in.ticks.fr += 120 - (k & 3);
  in.ticks.br += 119;
}

void BM_OdometryPipeline_Run(benchmark::State& state) {
  posefuse::OdometryPipeline odo = posefuse::make_odometry_pipeline(kParams, {0.3, 0.01});
  posefuse::WheelSample in{};
  std::int64_t k = 0;
  for (auto _ : state) {
    advance_wheels(in, k++);
    benchmark::DoNotOptimize(odo(in));
  }
}
BENCHMARK(BM_OdometryPipeline_Run);

void BM_OdometryStages_ByHand(benchmark::State& state) {
  posefuse::FourWheelAverage s1;
  posefuse::DiffDriveOdometry s2(kParams, {0.3, 0.01});
  posefuse::DeadReckoning s3;
  posefuse::WheelSample in{};
  std::int64_t k = 0;
  for (auto _ : state) {
    advance_wheels(in, k++);
    benchmark::DoNotOptimize(s3(s2(s1(in))));
  }
}
BENCHMARK(BM_OdometryStages_ByHand);

}  // namespace

#pragma once
/// @file
/// Umbrella header for the estimation core. It includes exactly:
///  * core/    — angles, chi-square, concepts, errors and statuses, Gaussian,
///               interpolation, pipelines, plane, samples, stream merge, time,
///               trajectories
///  * lie/     — lie.hpp (SO2, SE2, SO3, SE3)
///  * models/  — every motion and measurement model
///  * filters/ — the EKF, the complementary filter, the RTS smoother
///  * sensors/ — tilt, compass, wheel odometry, dead reckoning, magnetometer
///               calibration and the sensor pipelines
///  * fusion/  — the gated fuser, fuse_poses and the fuser statuses
///  * eval/    — alignment, metrics, planar metrics, statistics
///
/// It leaves out, on purpose:
///  * inertial/, graph/ and vio/ (pre-integration, pose graphs, the
///    visual-inertial estimator): heavy to compile and needed by few
///    translation units, so include them one by one;
///  * io/ (the file readers and writers: trajectory formats, association,
///    the robot log, EuRoC, KITTI, g2o, cameras): they bring file streams
///    and parsers that estimation code does not need, so include the one
///    you use (<posefuse/io/formats.hpp> reads and writes every trajectory
///    format);
///  * the rest of eval/ (consistency, RPE pairs): include the one you use;
///  * testing/ (the conformance harness and test references), sim/ (the
///    simulators) and seed/ (the source documents' formulas as printed, kept
///    apart from the recommended API).
/// Single headers keep compile times down; tests/compile_cost holds this one
/// to 3x a bare Eigen include.

#include <posefuse/core/angles.hpp>
#include <posefuse/core/chi_square.hpp>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/core/plane.hpp>
#include <posefuse/core/samples.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/core/stream_merge.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/core/trajectory.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/eval/planar_metrics.hpp>
#include <posefuse/eval/statistics.hpp>
#include <posefuse/filters/complementary.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/noise_tuning.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/fusion/fuse_poses.hpp>
#include <posefuse/fusion/fuser_status.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/lie/lie.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/ctrv.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/sensors/accelerometer_tilt.hpp>
#include <posefuse/sensors/compass.hpp>
#include <posefuse/sensors/dead_reckoning.hpp>
#include <posefuse/sensors/magnetometer_calibration.hpp>
#include <posefuse/sensors/pipelines.hpp>
#include <posefuse/sensors/wheel_odometry.hpp>

#pragma once
/// @file
/// Umbrella header: the whole public API of posefuse. Include single headers
/// (`<posefuse/filters/ekf.hpp>`, ...) to keep compile times down. The
/// conformance harness (`<posefuse/testing/conformance.hpp>`) is for tests and
/// is not included here.

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
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/fusion/fuse_poses.hpp>
#include <posefuse/fusion/fuser_status.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/seed/threshold_fuser.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/io/robot_log.hpp>
#include <posefuse/lie/lie.hpp>
#include <posefuse/models/constant_velocity.hpp>
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

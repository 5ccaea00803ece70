// Positive and negative compile-time checks of the concepts. Compiling this
// file is the test.
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/fusion/gated_fuser.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/lie/so3.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/seed/threshold_fuser.hpp>
#include <posefuse/sensors/pipelines.hpp>

namespace {
using namespace posefuse;

// Manifolds.
static_assert(Manifold<Eigen::Vector2d>);
static_assert(Manifold<Eigen::Matrix<float, 7, 1>>);
static_assert(!Manifold<Eigen::VectorXd>);  // size must be known at compile time
static_assert(!Manifold<Eigen::Matrix2d>);  // not a column vector
static_assert(!Manifold<int>);
static_assert(State<PlanarPose<double>>);
static_assert(DimOf<PlanarPose<float>> == 3);

// Models.
static_assert(MotionModel<PlanarDisplacement<double>>);
static_assert(MotionModel<ConstantVelocity2<float>>);
static_assert(!MotionModel<PositionFix<2>>);
static_assert(MeasurementModel<PositionFix<2>>);
static_assert(!MeasurementModel<ConstantVelocity2<double>>);
static_assert(MeasurementModelFor<PositionFix<4>, Eigen::Vector4d>);
static_assert(!MeasurementModelFor<PositionFix<4>, Eigen::Vector2d>);
static_assert(has_identity_jacobian_v<PlanarDisplacement<double>>);
static_assert(!has_identity_jacobian_v<ConstantVelocity2<double>>);

struct MissingNoise {
  using State = Eigen::Vector2d;
  using Control = Eigen::Vector2d;
  State predict(const State& x, const Control& u, double) const { return x + u; }
  Eigen::Matrix2d jacobian(const State&, const Control&, double) const {
    return Eigen::Matrix2d::Identity();
  }
};
static_assert(!MotionModel<MissingNoise>);

struct WrongJacobianSize {
  using State = Eigen::Vector4d;
  using Measurement = Eigen::Vector2d;
  Measurement predict(const State& x) const { return x.head<2>(); }
  Eigen::Matrix<double, 4, 2> jacobian(const State&) const { return {}; }
  Eigen::Matrix2d noise() const { return Eigen::Matrix2d::Identity(); }
};
static_assert(!MeasurementModel<WrongJacobianSize>);

struct MixedScalars {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Vector2f;
  Measurement predict(const State& x) const { return x.cast<float>(); }
  Eigen::Matrix2d jacobian(const State&) const { return Eigen::Matrix2d::Identity(); }
  Eigen::Matrix2f noise() const { return Eigen::Matrix2f::Identity(); }
};
static_assert(!MeasurementModel<MixedScalars>);

// Noise may depend on the state: noise(const State&) instead of noise().
struct StateDependentNoise {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  Measurement predict(const State& x) const { return x; }
  Eigen::Matrix2d jacobian(const State&) const { return Eigen::Matrix2d::Identity(); }
  Eigen::Matrix2d noise(const State& x) const { return Eigen::Matrix2d::Identity() * x.norm(); }
};
static_assert(MeasurementModel<StateDependentNoise>);
static_assert(has_state_dependent_noise_v<StateDependentNoise>);
static_assert(!has_state_dependent_noise_v<PositionFix<2>>);

struct NoNoise {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  Measurement predict(const State& x) const { return x; }
  Eigen::Matrix2d jacobian(const State&) const { return Eigen::Matrix2d::Identity(); }
};
static_assert(!MeasurementModel<NoNoise>);

struct NoiseOfWrongArgument {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Vector2d;
  Measurement predict(const State& x) const { return x; }
  Eigen::Matrix2d jacobian(const State&) const { return Eigen::Matrix2d::Identity(); }
  Eigen::Matrix2d noise(const PlanarPose<double>&) const { return Eigen::Matrix2d::Identity(); }
};
static_assert(!MeasurementModel<NoiseOfWrongArgument>);

// The planar models of the fusion layer.
static_assert(MotionModel<Se2Odometry<double>>);
static_assert(MotionModel<Se2Odometry<float>>);
static_assert(MeasurementModelFor<PlanarPoseFix<double>, PlanarPose<double>>);
static_assert(MeasurementModelFor<HeadingFix<float>, PlanarPose<float>>);
static_assert(has_identity_jacobian_v<PlanarPoseFix<double>>);
static_assert(is_time_invariant_v<HeadingFix<double>>);

// Gates: a number, or a functor of (r, S) or (r, S, nis) returning bool.
using Innov3 = Eigen::Vector3d;
using InnovCov3 = Eigen::Matrix3d;
static_assert(InnovationGate<double, PlanarPoseFix<double>>);
static_assert(InnovationGate<bool (*)(const Innov3&, const InnovCov3&), PlanarPoseFix<double>>);
static_assert(
    InnovationGate<bool (*)(const Innov3&, const InnovCov3&, double), PlanarPoseFix<double>>);
static_assert(!InnovationGate<bool (*)(const Eigen::Vector2d&), PlanarPoseFix<double>>);
static_assert(!InnovationGate<const char*, PlanarPoseFix<double>>);
static_assert(!InnovationGate<bool, PlanarPoseFix<double>>);  // not a threshold

// Filters are fixed-size all the way down.
using Seed000 = Ekf<PlanarDisplacement<double>, PositionFix<2>>;
static_assert(Seed000::Dim == 2);
static_assert(std::is_same_v<Seed000::Covariance, Eigen::Matrix2d>);

// Every model, Lie type, fuser and pipeline of the library satisfies its
// concept (checked here rather than in the headers, so that including a
// header does not instantiate the float variants: compile cost, docs/design.md).
// posefuse/fusion/gated_fuser.hpp
static_assert(Stage<GatedFuser<double>>);
static_assert(Stage<GatedFuser<float>>);
// posefuse/seed/threshold_fuser.hpp
static_assert(Stage<seed::ThresholdFuser<double>>);
static_assert(Stage<seed::ThresholdFuser<float>>);
// posefuse/lie/se2.hpp
static_assert(Manifold<SE2<double>>);
static_assert(Manifold<SE2<float>>);
// posefuse/lie/se3.hpp
static_assert(Manifold<SE3<double>>);
static_assert(Manifold<SE3<float>>);
// posefuse/lie/so2.hpp
static_assert(Manifold<SO2<double>>);
static_assert(Manifold<SO2<float>>);
// posefuse/lie/so3.hpp
static_assert(Manifold<SO3<double>>);
static_assert(Manifold<SO3<float>>);
// posefuse/models/constant_velocity.hpp
static_assert(MotionModel<ConstantVelocity2<double>>);
static_assert(MotionModel<ConstantVelocity2<float>>);
// posefuse/models/heading_fix.hpp
static_assert(MeasurementModel<HeadingFix<double>>);
static_assert(MeasurementModel<HeadingFix<float>>);
// posefuse/models/planar_displacement.hpp
static_assert(MotionModel<PlanarDisplacement<double>>);
static_assert(MotionModel<PlanarDisplacement<float>>);
// posefuse/models/planar_pose.hpp
static_assert(State<PlanarPose<double>>);
static_assert(State<PlanarPose<float>>);
// posefuse/models/planar_pose_fix.hpp
static_assert(MeasurementModel<PlanarPoseFix<double>>);
static_assert(MeasurementModel<PlanarPoseFix<float>>);
// posefuse/models/position.hpp
static_assert(MeasurementModel<PositionFix<2>>);
static_assert(MeasurementModel<PositionFix<4, 2, float>>);
// posefuse/models/se2_odometry.hpp
static_assert(MotionModel<Se2Odometry<double>>);
static_assert(MotionModel<Se2Odometry<float>>);
// posefuse/models/unicycle.hpp
static_assert(check_motion_model<Unicycle<double>>());
static_assert(MotionModel<Unicycle<float>>);
// posefuse/sensors/pipelines.hpp
static_assert(Stage<AttitudePipeline>);
static_assert(Stage<OdometryPipeline>);
}  // namespace

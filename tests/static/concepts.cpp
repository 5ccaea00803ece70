// Positive and negative compile-time checks of the concepts. Compiling this
// file is the test.
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/position.hpp>

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

// Filters are fixed-size all the way down.
using Seed000 = Ekf<PlanarDisplacement<double>, PositionFix<2>>;
static_assert(Seed000::Dim == 2);
static_assert(std::is_same_v<Seed000::Covariance, Eigen::Matrix2d>);
}  // namespace

// Tests for testing/conformance.hpp, the harness itself: correct Jacobians
// pass, corrupted ones (one sign flipped, two columns swapped, scaled by 1.01)
// fail with a message naming the entry; numeric_jacobian is exact on linear
// maps; broken manifolds, covariances, models and Lie groups are caught.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/core/angles.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/lie/so3.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/testing/conformance.hpp>
#include <string>
#include <type_traits>

namespace pt = posefuse::testing;
using Catch::Contains;

namespace {

// f(x) = [sin(x0) x1, exp(x2), x0 x1 x2] and its Jacobian.
template <class T>
Eigen::Matrix<T, 3, 1> f3(const Eigen::Matrix<T, 3, 1>& x) {
  return {std::sin(x(0)) * x(1), std::exp(x(2)), x(0) * x(1) * x(2)};
}
template <class T>
Eigen::Matrix<T, 3, 3> J3(const Eigen::Matrix<T, 3, 1>& x) {
  Eigen::Matrix<T, 3, 3> J;
  J << std::cos(x(0)) * x(1), std::sin(x(0)), 0,  //
      0, 0, std::exp(x(2)),                       //
      x(1) * x(2), x(0) * x(2), x(0) * x(1);
  return J;
}
template <class T>
double jac_tol() {
  // Central differences with h = eps^(1/3): ~1e-10 in double, ~3e-5 in float here.
  return std::is_same_v<T, float> ? 1e-3 : 1e-8;
}

// A one-angle "manifold" whose minus forgets to wrap: check_manifold must catch it.
struct UnwrappedAngle {
  using Scalar = double;
  static constexpr int Dim = 1;
  double a{0};
  UnwrappedAngle plus(const Eigen::Matrix<double, 1, 1>& d) const {
    return {posefuse::wrap_angle(a + d(0))};
  }
  Eigen::Matrix<double, 1, 1> minus(const UnwrappedAngle& o) const {
    return Eigen::Matrix<double, 1, 1>(a - o.a);
  }
};

// A motion model whose Jacobian has one entry's sign flipped.
struct FlippedCv {
  using State = Eigen::Vector4d;
  using Control = posefuse::NoControl;
  posefuse::ConstantVelocity2<double> m{0.5};
  State predict(const State& x, const Control& u, double dt) const { return m.predict(x, u, dt); }
  Eigen::Matrix4d jacobian(const State& x, const Control& u, double dt) const {
    Eigen::Matrix4d J = m.jacobian(x, u, dt);
    J(0, 2) = -J(0, 2);
    return J;
  }
  Eigen::Matrix4d noise(const State& x, const Control& u, double dt) const {
    return m.noise(x, u, dt);
  }
};

// Range to the origin with state-dependent noise, R(x) = (0.01 |x|)^2.
struct Range {
  using State = Eigen::Vector2d;
  using Measurement = Eigen::Matrix<double, 1, 1>;
  bool wrong_sign = false;
  Measurement predict(const State& x) const { return Measurement(x.norm()); }
  Eigen::Matrix<double, 1, 2> jacobian(const State& x) const {
    Eigen::Matrix<double, 1, 2> J = x.transpose() / x.norm();
    if (wrong_sign) J(0, 1) = -J(0, 1);
    return J;
  }
  Eigen::Matrix<double, 1, 1> noise(const State& x) const {
    return Eigen::Matrix<double, 1, 1>(1e-4 * x.squaredNorm());
  }
};

// Heading of a planar pose as an SO2 measurement (its minus wraps).
struct Heading {
  using State = posefuse::PlanarPose<double>;
  using Measurement = posefuse::SO2<double>;
  Measurement predict(const State& x) const { return Measurement(x.theta); }
  Eigen::Matrix<double, 1, 3> jacobian(const State&) const { return {0, 0, 1}; }
  Eigen::Matrix<double, 1, 1> noise() const { return Eigen::Matrix<double, 1, 1>(0.01); }
};

// Lie groups with one corrupted Jacobian each.
template <std::floating_point T>
struct SE2WrongCompose : posefuse::SE2<T> {
  using Base = posefuse::SE2<T>;
  using Base::Base;
  SE2WrongCompose(const Base& g) : Base(g) {}  // NOLINT: implicit, like the group it wraps
  Base compose(const Base& b, typename Base::Jacobian* J_c_a = nullptr,
               typename Base::Jacobian* J_c_b = nullptr) const {
    const Base c = Base::compose(b, J_c_a, J_c_b);
    if (J_c_a) (*J_c_a)(0, 2) = -(*J_c_a)(0, 2);
    return c;
  }
};
template <std::floating_point T>
struct SE3WrongQ : posefuse::SE3<T> {
  using Base = posefuse::SE3<T>;
  using Base::Base;
  SE3WrongQ(const Base& g) : Base(g) {}  // NOLINT
  // Uses Q(rho, phi) (the left Jacobian's block) where J_r needs Q(-rho, -phi).
  static Base exp(const typename Base::Tangent& tau, typename Base::Jacobian* J = nullptr) {
    const Base g = Base::exp(tau, J);
    if (J)
      J->template topRightCorner<3, 3>() = Base::left_jacobian(tau).template topRightCorner<3, 3>();
    return g;
  }
};
template <std::floating_point T>
struct SO3WrongLog : posefuse::SO3<T> {
  using Base = posefuse::SO3<T>;
  using Base::Base;
  SO3WrongLog(const Base& g) : Base(g) {}  // NOLINT
  // Returns J_r instead of J_r^-1.
  typename Base::Tangent log(typename Base::Jacobian* J = nullptr) const {
    const typename Base::Tangent t = Base::log();
    if (J) *J = Base::right_jacobian(t);
    return t;
  }
};

}  // namespace

namespace posefuse::testing {
template <std::floating_point T>
struct LieGroupTraits<SE2WrongCompose<T>> : LieGroupTraits<SE2<T>> {};
template <std::floating_point T>
struct LieGroupTraits<SE3WrongQ<T>> : LieGroupTraits<SE3<T>> {};
template <std::floating_point T>
struct LieGroupTraits<SO3WrongLog<T>> : LieGroupTraits<SO3<T>> {};
}  // namespace posefuse::testing

TEMPLATE_TEST_CASE("Conformance: a correct Jacobian passes", "[testing][conformance]", float,
                   double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  const V x(T(0.3), T(-1.2), T(0.5));
  const pt::CheckResult r = pt::check_jacobian(
      "f3", [](const V& v) { return f3(v); }, x, J3(x), jac_tol<T>());
  INFO(r.message);
  CHECK(r);
  CHECK(r.ok);
  CHECK(r.max_error < jac_tol<T>());
  CHECK(r.max_error > 0);  // a finite-difference check, not an identity
  CHECK_THAT(r.message, Contains("f3: ok"));
}

TEMPLATE_TEST_CASE("Conformance: corrupted Jacobians fail and name the entry",
                   "[testing][conformance]", float, double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  using M = Eigen::Matrix<T, 3, 3>;
  const V x(T(0.3), T(-1.2), T(0.5));
  const M J = J3(x);
  const auto f = [](const V& v) { return f3(v); };

  // Every non-zero entry, flipped on its own, fails and is named.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (J(i, j) == T(0)) continue;
      M bad = J;
      bad(i, j) = -bad(i, j);
      const pt::CheckResult r = pt::check_jacobian("f3", f, x, bad, jac_tol<T>());
      INFO(r.message);
      CHECK_FALSE(r);
      CHECK_THAT(r.message,
                 Contains("entry (" + std::to_string(i) + ", " + std::to_string(j) + ")"));
      CHECK_THAT(r.message, Contains("analytic") && Contains("numeric") && Contains("f3"));
    }
  }
  // Two columns swapped: the worst entry lies in one of them.
  {
    M bad = J;
    bad.col(0).swap(bad.col(2));
    const pt::CheckResult r = pt::check_jacobian("f3", f, x, bad, jac_tol<T>());
    INFO(r.message);
    CHECK_FALSE(r);
    CHECK_THAT(r.message, Contains(", 0):") || Contains(", 2):"));
  }
  // Scaled by 1.01: the largest entry, exp(0.5) at (1, 2), has the largest error.
  {
    const M bad = J * T(1.01);
    const pt::CheckResult r = pt::check_jacobian("f3", f, x, bad, jac_tol<T>());
    INFO(r.message);
    CHECK_FALSE(r);
    CHECK_THAT(r.message, Contains("entry (1, 2)"));
    CHECK(r.max_error == Approx(0.01 * std::exp(0.5) / (1 + std::exp(0.5))).epsilon(0.02));
  }
  // A non-finite analytic entry fails.
  {
    M bad = J;
    bad(2, 1) = std::numeric_limits<T>::quiet_NaN();
    const pt::CheckResult r = pt::check_jacobian("f3", f, x, bad, jac_tol<T>());
    CHECK_FALSE(r);
    CHECK_THAT(r.message, Contains("entry (2, 1)"));
  }
}

TEMPLATE_TEST_CASE("Conformance: numeric_jacobian of a linear map is exact to rounding",
                   "[testing][conformance]", float, double) {
  using T = TestType;
  Eigen::Matrix<T, 3, 4> A;
  A << 1, -2, 3, 0, 4, 5, -6, 7, 0, 1, 1, -9;
  const Eigen::Matrix<T, 4, 1> x(3, -1, 2, 5);
  const auto f = [&](const Eigen::Matrix<T, 4, 1>& v) -> Eigen::Matrix<T, 3, 1> { return A * v; };
  // With a power-of-two step and integer data every operation is exact.
  const Eigen::Matrix<T, 3, 4> J_exact = pt::numeric_jacobian(f, x, T(0.5));
  CHECK(J_exact == A);
  // With the default step the error is rounding of |f(x)| divided by the step.
  const T h = pt::default_step<T>();
  const Eigen::Matrix<T, 3, 4> J = pt::numeric_jacobian(f, x);
  const T bound =
      T(8) * std::numeric_limits<T>::epsilon() * (A.cwiseAbs() * x.cwiseAbs()).maxCoeff() / h;
  INFO("max error " << (J - A).cwiseAbs().maxCoeff() << ", bound " << bound);
  CHECK((J - A).cwiseAbs().maxCoeff() <= bound);
}

TEST_CASE("Conformance: numeric_jacobian differences through plus / minus",
          "[testing][conformance]") {
  // The identity map of a pose with heading next to pi: x (+) h e_theta wraps
  // to -pi, and minus unwraps it, so the Jacobian is still I.
  const posefuse::PlanarPose<double> x{1.0, 2.0, std::numbers::pi - 1e-9};
  const Eigen::Matrix3d J =
      pt::numeric_jacobian([](const posefuse::PlanarPose<double>& p) { return p; }, x);
  CHECK((J - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
  // SO2 -> point: d(R p)/d theta = R [1]x p.
  const posefuse::SO2<double> R(3.0);
  const Eigen::Vector2d p(1.0, -2.0);
  Eigen::Vector2d Jq;
  (void)R.act(p, &Jq);
  const auto r = pt::check_jacobian(
      "SO2 act", [&](const posefuse::SO2<double>& g) { return g.act(p); }, R, Jq, 1e-8);
  INFO(r.message);
  CHECK(r);
}

TEST_CASE("Conformance: check_manifold passes wrapping states and catches a missing wrap",
          "[testing][conformance]") {
  const posefuse::PlanarPose<double> x{1.0, 2.0, 3.1};
  const auto ok = pt::check_manifold(x, Eigen::Vector3d(0.1, -0.2, 0.2), 1e-14);
  INFO(ok.message);
  CHECK(ok);
  const auto bad = pt::check_manifold(UnwrappedAngle{3.1}, Eigen::Matrix<double, 1, 1>(0.2), 1e-9);
  INFO(bad.message);
  CHECK_FALSE(bad);
  CHECK_THAT(bad.message, Contains("(x + d) - x == d"));
  // Inside (-pi, pi) without crossing, the same type passes: the check is about the wrap.
  CHECK(pt::check_manifold(UnwrappedAngle{0.1}, Eigen::Matrix<double, 1, 1>(0.2), 1e-15));
}

TEST_CASE("Conformance: check_covariance", "[testing][conformance]") {
  CHECK(pt::check_covariance("P", Eigen::Vector3d(1, 2, 0).asDiagonal().toDenseMatrix(), 1e-12));
  Eigen::Matrix2d P;
  P << 1, 0.1, 0, 1;
  auto r = pt::check_covariance("P", P, 1e-12);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("P symmetric: error"));
  P << 1, 2, 2, 1;  // eigenvalues 3, -1
  r = pt::check_covariance("P", P, 1e-12);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("positive semi-definite"));
  P(0, 0) = std::numeric_limits<double>::infinity();
  r = pt::check_covariance("P", P, 1e-12);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("finite"));
}

TEST_CASE("Conformance: check_motion_model catches a flipped Jacobian entry",
          "[testing][conformance]") {
  const Eigen::Vector4d x(1, -2, 0.3, 0.7);
  const posefuse::ConstantVelocity2<double> good(0.5);
  CHECK(pt::check_motion_model(good, x, {}, 0.4, 1e-8));
  const auto r = pt::check_motion_model(FlippedCv{}, x, {}, 0.4, 1e-8);
  INFO(r.message);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("jacobian (J_f_x): entry (0, 2)"));
}

TEST_CASE("Conformance: check_measurement_model takes noise() or noise(x)",
          "[testing][conformance]") {
  const Eigen::Vector2d x(3, -4);
  auto r = pt::check_measurement_model(Range{}, x, 1e-8);
  INFO(r.message);
  CHECK(r);
  CHECK_THAT(r.message, Contains("all 3 checks passed"));
  r = pt::check_measurement_model(Range{true}, x, 1e-8);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("jacobian (J_h_x): entry (0, 1)"));
  // An SO2 measurement near pi: the numeric Jacobian differences through SO2's minus.
  const posefuse::PlanarPose<double> p{0.0, 0.0, std::numbers::pi - 1e-9};
  r = pt::check_measurement_model(Heading{}, p, 1e-8);
  INFO(r.message);
  CHECK(r);
}

TEST_CASE("Conformance: check_lie_group catches corrupted group Jacobians",
          "[testing][conformance]") {
  auto r = pt::check_lie_group<SE2WrongCompose<double>>(1u, 8, 1e-9);
  INFO(r.message);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("compose J_c_a: entry (0, 2)"));
  CHECK_THAT(r.message, !Contains("compose J_c_b"));
  r = pt::check_lie_group<SE3WrongQ<double>>(2u, 8, 1e-9);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("exp J_g_tau: entry ("));
  r = pt::check_lie_group<SO3WrongLog<double>>(3u, 8, 1e-9);
  CHECK_FALSE(r);
  CHECK_THAT(r.message, Contains("log J_tau_g"));
  // The unmodified groups pass with the same seeds and tolerance.
  CHECK(pt::check_lie_group<posefuse::SE2<double>>(1u, 8, 1e-9));
  CHECK(pt::check_lie_group<posefuse::SE3<double>>(2u, 8, 1e-9));
  CHECK(pt::check_lie_group<posefuse::SO3<double>>(3u, 8, 1e-9));
}

TEST_CASE("Conformance: combine and all_ok", "[testing][conformance]") {
  std::vector<pt::CheckResult> v(3);
  v[1].max_error = 0.5;
  CHECK(pt::all_ok(v));
  CHECK(pt::combine("x", v).message == "x: all 3 checks passed (max error 0.5)");
  v[2].ok = false;
  v[2].message = "bad thing";
  CHECK_FALSE(pt::all_ok(v));
  const pt::CheckResult c = pt::combine("x", v);
  CHECK_FALSE(c);
  CHECK_THAT(c.message, Contains("1 of 3 checks failed") && Contains("bad thing"));
}

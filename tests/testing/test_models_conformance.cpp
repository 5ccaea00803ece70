// The conformance harness run on every model of include/posefuse/models/
// (ConstantVelocity2, PlanarDisplacement, PositionFix, Unicycle, HeadingFix,
// PlanarPoseFix, Se2Odometry):
// analytic Jacobians against central differences through the states' plus /
// minus, noise finite / symmetric / PSD, at random states (fixed seeds), for
// straight-line and turning inputs; unicycle_step's J_x and J_u out-parameters
// for both integrations, including dtheta ~ 0 and large dtheta. Each test also
// checks that the harness would notice: flipping the sign of any one
// non-zero Jacobian entry (through a wrapper model, not the shared header)
// makes some check fail.
//
// Sensors (include/posefuse/sensors/) expose no Jacobian of their own:
// DeadReckoning propagates its covariance with unicycle_step's J_x and J_u,
// which are checked here.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/models/unicycle.hpp>
#include <posefuse/testing/conformance.hpp>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace pt = posefuse::testing;
using posefuse::Integration;
using posefuse::PlanarPose;

namespace {

// Tolerance of the Jacobian checks for states and inputs of order 1-10:
// central differences in double are good to ~1e-9 here, in float to ~3e-4.
template <class T>
double tol() {
  return std::is_same_v<T, float> ? 3e-3 : 1e-8;
}

/// A motion model whose Jacobian entry (i, j) has its sign flipped.
template <class M>
struct FlipMotion {
  using State = typename M::State;
  using Control = typename M::Control;
  using T = posefuse::ScalarOf<State>;
  M m;
  int i, j;
  State predict(const State& x, const Control& u, T dt) const { return m.predict(x, u, dt); }
  posefuse::CovarianceOf<State> jacobian(const State& x, const Control& u, T dt) const {
    posefuse::CovarianceOf<State> J = m.jacobian(x, u, dt);
    J(i, j) = -J(i, j);
    return J;
  }
  posefuse::CovarianceOf<State> noise(const State& x, const Control& u, T dt) const {
    return m.noise(x, u, dt);
  }
};

/// A motion model with linearize() (posefuse::HasLinearize) whose
/// linearize().jacobian entry (i, j) alone has its sign flipped: jacobian()
/// stays right, so only the check of the one-call form can notice.
template <class M>
struct FlipLinearize {
  using State = typename M::State;
  using Control = typename M::Control;
  using T = posefuse::ScalarOf<State>;
  M m;
  int i, j;
  State predict(const State& x, const Control& u, T dt) const { return m.predict(x, u, dt); }
  posefuse::CovarianceOf<State> jacobian(const State& x, const Control& u, T dt) const {
    return m.jacobian(x, u, dt);
  }
  posefuse::CovarianceOf<State> noise(const State& x, const Control& u, T dt) const {
    return m.noise(x, u, dt);
  }
  auto linearize(const State& x, const Control& u, T dt) const {
    auto lin = m.linearize(x, u, dt);
    lin.jacobian(i, j) = -lin.jacobian(i, j);
    return lin;
  }
};

/// A measurement model whose Jacobian entry (i, j) has its sign flipped.
template <class H>
struct FlipMeasurement {
  using State = typename H::State;
  using Measurement = typename H::Measurement;
  H h;
  int i, j;
  Measurement predict(const State& x) const { return h.predict(x); }
  posefuse::MeasurementJacobianOf<H> jacobian(const State& x) const {
    posefuse::MeasurementJacobianOf<H> J = h.jacobian(x);
    J(i, j) = -J(i, j);
    return J;
  }
  posefuse::CovarianceOf<Measurement> noise() const { return h.noise(); }
};

template <class M>
struct MotionCase {
  typename M::State x;
  typename M::Control u;
  posefuse::ScalarOf<typename M::State> dt;
};

/// Runs check_motion_model on every case, then flips each Jacobian entry in
/// turn: an entry that is non-zero in some case must make some case fail.
template <class M>
void check_motion_cases(const M& model, const std::vector<MotionCase<M>>& cases, double tolerance) {
  using S = typename M::State;
  constexpr int n = posefuse::DimOf<S>;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const auto r = pt::check_motion_model(model, cases[k].x, cases[k].u, cases[k].dt, tolerance);
    INFO("case " << k << ": " << r.message);
    CHECK(r);
  }
  int flipped = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      bool nonzero = false, detected = false;
      const FlipMotion<M> bad{model, i, j};
      for (const auto& c : cases) {
        nonzero = nonzero || model.jacobian(c.x, c.u, c.dt)(i, j) != 0;
        detected = detected || !pt::check_motion_model(bad, c.x, c.u, c.dt, tolerance);
      }
      INFO("flipped entry (" << i << ", " << j << ")");
      if (nonzero) {
        CHECK(detected);
        ++flipped;
      } else {
        CHECK_FALSE(detected);  // flipping a zero changes nothing
      }
    }
  }
  CHECK(flipped >= n);  // at least the diagonal was exercised
}

/// The same for a measurement model at several states.
template <class H>
void check_measurement_cases(const H& model, const std::vector<typename H::State>& states,
                             double tolerance) {
  for (std::size_t k = 0; k < states.size(); ++k) {
    const auto r = pt::check_measurement_model(model, states[k], tolerance);
    INFO("state " << k << ": " << r.message);
    CHECK(r);
  }
  const auto J0 = model.jacobian(states.front());
  int flipped = 0;
  for (int i = 0; i < int(J0.rows()); ++i) {
    for (int j = 0; j < int(J0.cols()); ++j) {
      bool nonzero = false, detected = false;
      const FlipMeasurement<H> bad{model, i, j};
      for (const auto& x : states) {
        nonzero = nonzero || model.jacobian(x)(i, j) != 0;
        detected = detected || !pt::check_measurement_model(bad, x, tolerance);
      }
      INFO("flipped entry (" << i << ", " << j << ")");
      CHECK(detected == nonzero);
      flipped += nonzero ? 1 : 0;
    }
  }
  CHECK(flipped >= int(J0.rows()));
}

template <class T, int N>
Eigen::Matrix<T, N, 1> random_vector(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  Eigen::Matrix<T, N, 1> v;
  for (int i = 0; i < N; ++i) v(i) = T(n(rng));
  return v;
}

template <class T>
PlanarPose<T> random_pose(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 5.0);
  std::uniform_real_distribution<double> a(-std::numbers::pi, std::numbers::pi);
  return {T(n(rng)), T(n(rng)), T(a(rng))};
}

}  // namespace

TEMPLATE_TEST_CASE("Models conformance: ConstantVelocity2", "[testing][models]", float, double) {
  using T = TestType;
  using M = posefuse::ConstantVelocity2<T>;
  std::mt19937 rng(101);
  std::vector<MotionCase<M>> cases;
  for (const T dt : {T(0.01), T(0.1), T(1.0), T(2.5)})
    for (int k = 0; k < 4; ++k) cases.push_back({random_vector<T, 4>(rng, 5.0), {}, dt});
  check_motion_cases(M(T(0.5)), cases, tol<T>());
}

TEMPLATE_TEST_CASE("Models conformance: PlanarDisplacement", "[testing][models]", float, double) {
  using T = TestType;
  using M = posefuse::PlanarDisplacement<T>;
  std::mt19937 rng(102);
  std::vector<MotionCase<M>> cases;
  for (int k = 0; k < 8; ++k)
    cases.push_back({random_vector<T, 2>(rng, 10.0), random_vector<T, 2>(rng, 1.0), T(0.1)});
  check_motion_cases(M::from_sigmas(T(0.1), T(0.2)), cases, tol<T>());
}

TEMPLATE_TEST_CASE("Models conformance: PositionFix<2> and PositionFix<4, 2>", "[testing][models]",
                   float, double) {
  using T = TestType;
  std::mt19937 rng(103);
  {
    using H = posefuse::PositionFix<2, 2, T>;
    std::vector<typename H::State> xs;
    for (int k = 0; k < 6; ++k) xs.push_back(random_vector<T, 2>(rng, 10.0));
    Eigen::Matrix<T, 2, 2> Q;
    Q << T(0.04), T(0.01), T(0.01), T(0.09);
    check_measurement_cases(H(Q), xs, tol<T>());
  }
  {
    using H = posefuse::PositionFix<4, 2, T>;
    std::vector<typename H::State> xs;
    for (int k = 0; k < 6; ++k) xs.push_back(random_vector<T, 4>(rng, 10.0));
    check_measurement_cases(H::isotropic(T(0.3)), xs, tol<T>());
  }
}

TEMPLATE_TEST_CASE("Models conformance: Unicycle, both integrations, straight and turning",
                   "[testing][models]", float, double) {
  using T = TestType;
  using M = posefuse::Unicycle<T>;
  using U = typename M::Control;
  for (const Integration method : {Integration::kEuler, Integration::kExactArc}) {
    M model;
    model.method = method;
    model.control_cov << T(0.04), T(0.005), T(0.005), T(0.01);
    std::mt19937 rng(104);
    std::vector<MotionCase<M>> cases;
    // (v m/s, w rad/s): straight ahead, reversing, turning both ways, turning on
    // the spot, a hard turn (w dt = 3 rad) and a near-straight one (w dt = 1e-9).
    const U controls[] = {U(1.5, 0), U(-0.7, 0),  U(2.0, 0.5), U(1.0, -1.2),
                          U(0, 0.8), U(3.0, 6.0), U(1.0, 2e-9)};
    for (const U& u : controls)
      for (int k = 0; k < 3; ++k) cases.push_back({random_pose<T>(rng), u, T(0.5)});
    // Heading next to +-pi, where plus / minus wrap.
    cases.push_back({PlanarPose<T>{1, 2, T(std::numbers::pi - 1e-3)}, U(1.0, 0.3), T(0.2)});
    cases.push_back({PlanarPose<T>{-1, 0, T(-std::numbers::pi + 1e-3)}, U(2.0, -0.3), T(0.2)});
    INFO((method == Integration::kEuler ? "kEuler" : "kExactArc"));
    check_motion_cases(model, cases, tol<T>());
  }
}

TEMPLATE_TEST_CASE("Models conformance: unicycle_step's J_x and J_u", "[testing][models]", float,
                   double) {
  using T = TestType;
  using P = PlanarPose<T>;
  using U = Eigen::Matrix<T, 2, 1>;
  std::mt19937 rng(105);
  // dtheta: exactly 0, tiny, both sides of the sinc series switch (|dtheta/2| =
  // detail::kSincSeriesLimit), moderate, large, beyond pi.
  const T thr = T(2) * posefuse::detail::kSincSeriesLimit<T>;
  const T dthetas[] = {T(0),   T(1e-9), T(-1e-5), thr * T(0.99), thr * T(1.01),
                       T(0.3), T(-2.5), T(3.0),   T(6.0)};
  const T dss[] = {T(0.7), T(-1.3), T(5.0)};
  for (const Integration method : {Integration::kEuler, Integration::kExactArc}) {
    int n_cases = 0;
    // Track which entries are non-zero somewhere and whether flipping each is caught.
    Eigen::Matrix<bool, 3, 3> nz_x = Eigen::Matrix<bool, 3, 3>::Constant(false),
                              caught_x = Eigen::Matrix<bool, 3, 3>::Constant(false);
    Eigen::Matrix<bool, 3, 2> nz_u = Eigen::Matrix<bool, 3, 2>::Constant(false),
                              caught_u = Eigen::Matrix<bool, 3, 2>::Constant(false);
    for (const T dth : dthetas) {
      for (const T ds : dss) {
        const P x = random_pose<T>(rng);
        Eigen::Matrix<T, 3, 3> Jx;
        Eigen::Matrix<T, 3, 2> Ju;
        (void)posefuse::unicycle_step(x, ds, dth, method, &Jx, &Ju);
        const auto fx = [&](const P& s) { return posefuse::unicycle_step(s, ds, dth, method); };
        const auto fu = [&](const U& u) { return posefuse::unicycle_step(x, u(0), u(1), method); };
        const U u0(ds, dth);
        const auto rx = pt::check_jacobian("unicycle_step J_x", fx, x, Jx, tol<T>());
        const auto ru = pt::check_jacobian("unicycle_step J_u", fu, u0, Ju, tol<T>());
        INFO((method == Integration::kEuler ? "kEuler" : "kExactArc")
             << " ds " << ds << " dtheta " << dth << "\n"
             << rx.message << "\n"
             << ru.message);
        CHECK(rx);
        CHECK(ru);
        ++n_cases;
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) {
            nz_x(i, j) = nz_x(i, j) || Jx(i, j) != 0;
            Eigen::Matrix<T, 3, 3> bad = Jx;
            bad(i, j) = -bad(i, j);
            caught_x(i, j) = caught_x(i, j) || !pt::check_jacobian("J_x", fx, x, bad, tol<T>());
          }
          for (int j = 0; j < 2; ++j) {
            nz_u(i, j) = nz_u(i, j) || Ju(i, j) != 0;
            Eigen::Matrix<T, 3, 2> bad = Ju;
            bad(i, j) = -bad(i, j);
            caught_u(i, j) = caught_u(i, j) || !pt::check_jacobian("J_u", fu, u0, bad, tol<T>());
          }
        }
      }
    }
    CHECK(n_cases == 27);
    // Every entry that is ever non-zero is caught when flipped. Structural zeros:
    // J_x = [1 0 a; 0 1 b; 0 0 1] (5 non-zero); J_u = [c 0; s 0; 0 1] for kEuler
    // (3), [k c, p; k s, q; 0 1] for kExactArc (5).
    CHECK(nz_x == caught_x);
    CHECK(nz_u == caught_u);
    CHECK(nz_x.count() == 5);
    CHECK(nz_u.count() == (method == Integration::kEuler ? 3 : 5));
  }
}

TEMPLATE_TEST_CASE("Models conformance: HeadingFix and PlanarPoseFix", "[testing][models]", float,
                   double) {
  using T = TestType;
  std::mt19937 rng(107);
  std::vector<PlanarPose<T>> xs;
  for (int k = 0; k < 6; ++k) xs.push_back(random_pose<T>(rng));
  // Headings next to +-pi: the SO2 / PlanarPose measurement minus must wrap.
  xs.push_back({1, 2, T(std::numbers::pi - 1e-4)});
  xs.push_back({-3, 0, T(-std::numbers::pi + 1e-4)});
  check_measurement_cases(posefuse::HeadingFix<T>(T(0.05)), xs, tol<T>());
  check_measurement_cases(posefuse::PlanarPoseFix<T>::from_sigmas(T(0.5), T(0.1)), xs, tol<T>());
}

TEMPLATE_TEST_CASE("Models conformance: Se2Odometry, straight and turning increments",
                   "[testing][models]", float, double) {
  using T = TestType;
  using M = posefuse::Se2Odometry<T>;
  using D = posefuse::SE2<T>;
  std::mt19937 rng(108);
  std::vector<MotionCase<M>> cases;
  const D increments[] = {D(T(0.5), 0, 0),           D(T(-0.3), 0, 0),
                          D(T(0.4), T(0.1), T(0.2)), D(T(1.0), T(-0.2), T(-1.0)),
                          D(0, 0, T(0.7)),           D(T(0.2), T(0.3), T(3.0))};
  for (const D& d : increments)
    for (int k = 0; k < 3; ++k) cases.push_back({random_pose<T>(rng), d, T(0.1)});
  cases.push_back({PlanarPose<T>{1, 2, T(std::numbers::pi - 1e-3)}, D(T(0.5), 0, T(0.1)), T(0.1)});
  const M model;
  check_motion_cases(model, cases, tol<T>());
  // Its one-call form (what Ekf::predict uses) is checked as well: flipping
  // any non-zero entry of linearize().jacobian alone fails a case.
  static_assert(posefuse::HasLinearize<M>);
  static_assert(posefuse::HasLinearize<FlipLinearize<M>>);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      bool nonzero = false, detected = false;
      const FlipLinearize<M> bad{model, i, j};
      for (const auto& c : cases) {
        nonzero = nonzero || model.jacobian(c.x, c.u, c.dt)(i, j) != 0;
        detected = detected || !pt::check_motion_model(bad, c.x, c.u, c.dt, tol<T>());
      }
      INFO("flipped linearize() entry (" << i << ", " << j << ")");
      CHECK(detected == nonzero);
    }
  }
  // jacobian_increment: d(x (+) delta) / d(t_delta_x, t_delta_y, theta_delta), components additive.
  for (const auto& c : cases) {
    const Eigen::Matrix<T, 3, 1> v(c.u.x(), c.u.y(), c.u.angle());
    const auto f = [&](const Eigen::Matrix<T, 3, 1>& w) {
      return model.predict(c.x, D(w(0), w(1), w(2)), c.dt);
    };
    const auto r = pt::check_jacobian("Se2Odometry::jacobian_increment", f, v,
                                      model.jacobian_increment(c.x, c.u), tol<T>());
    INFO(r.message);
    CHECK(r);
  }
}

TEMPLATE_TEST_CASE("Models conformance: PlanarPose plus / minus", "[testing][models]", float,
                   double) {
  using T = TestType;
  std::mt19937 rng(106);
  const double t = std::is_same_v<T, float> ? 1e-5 : 1e-14;
  for (int k = 0; k < 20; ++k) {
    const PlanarPose<T> x = random_pose<T>(rng);
    const Eigen::Matrix<T, 3, 1> d = random_vector<T, 3>(rng, 1.0);
    const auto r = pt::check_manifold(x, d, t);
    INFO(r.message);
    CHECK(r);
  }
  // Across the wrap at pi.
  const auto r =
      pt::check_manifold(PlanarPose<T>{0, 0, T(3.1)}, Eigen::Matrix<T, 3, 1>(0, 0, T(0.2)), t);
  INFO(r.message);
  CHECK(r);
}

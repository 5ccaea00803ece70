// filters/noise_tuning.hpp: the innovation log-likelihood term against its
// closed form, the search on a known surface, and recovery of the noise
// levels that generated synthetic data from the filter's inputs alone (the
// generator hands the tuner the control and the measurements; the true
// positions never leave it).
#include <catch2/catch.hpp>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/noise_tuning.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>

using namespace posefuse;

namespace {

/// What a tuner may see of a run: the inputs, never the truth.
struct FilterInputs {
  std::vector<double> t;
  std::vector<Eigen::Vector2d> u;  ///< control (displacement) per step; u[0] unused
  std::vector<Eigen::Vector2d> z;  ///< position measurements
};

/// A 2-D random walk x_k = x_{k-1} + d_k driven by a known displacement d_k
/// (a slow circle); the control is u_k = d_k + w_k, w ~ N(0, r I), the
/// measurement z_k = x_k + v_k, v ~ N(0, q I). The truth stays inside.
FilterInputs make_displacement_run(double r, double q, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  FilterInputs in;
  Eigen::Vector2d x(0, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 0.01 * static_cast<double>(k);
    const Eigen::Vector2d d = k == 0 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(std::cos(a), std::sin(a));
    x += d;
    in.t.push_back(0.1 * static_cast<double>(k));
    in.u.push_back(d + std::sqrt(r) * Eigen::Vector2d(normal(rng), normal(rng)));
    in.z.push_back(x + std::sqrt(q) * Eigen::Vector2d(normal(rng), normal(rng)));
  }
  return in;
}

double displacement_log_likelihood(const FilterInputs& in, double r, double q) {
  Ekf<PlanarDisplacement<double>, PositionFix<2>> ekf(
      PlanarDisplacement<double>(Eigen::Matrix2d::Identity() * r),
      PositionFix<2>(Eigen::Matrix2d::Identity() * q));
  ekf.reset(in.z[0], Eigen::Matrix2d::Identity() * q);
  double ll = 0;
  for (std::size_t k = 1; k < in.z.size(); ++k) {
    if (ekf.predict(in.u[k], in.t[k] - in.t[k - 1]) != FilterStatus::kApplied)
      return -std::numeric_limits<double>::infinity();
    ll += innovation_log_likelihood(ekf.update<0>(in.z[k]));
  }
  return ll;
}

/// Constant-velocity motion with white acceleration of density `qa`
/// (exactly discretised), positions measured with variance `s2`.
FilterInputs make_cv_run(double qa, double s2, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double dt = 0.1;
  const ConstantVelocity2<double> model(qa);
  const Eigen::Matrix4d L = model.noise({}, {}, dt).llt().matrixL();
  FilterInputs in;
  Eigen::Vector4d x(0, 0, 5, 0);
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) {
      Eigen::Vector4d w;
      for (int i = 0; i < 4; ++i) w[i] = normal(rng);
      x = model.predict(x, {}, dt) + L * w;
    }
    in.t.push_back(dt * static_cast<double>(k));
    in.z.push_back(x.head<2>() + std::sqrt(s2) * Eigen::Vector2d(normal(rng), normal(rng)));
  }
  in.u.assign(n, Eigen::Vector2d::Zero());
  return in;
}

double cv_log_likelihood(const FilterInputs& in, double qa, double s2) {
  Ekf<ConstantVelocity2<double>, PositionFix<4>> ekf(ConstantVelocity2<double>(qa),
                                                     PositionFix<4>(Eigen::Matrix2d::Identity() * s2));
  Eigen::Vector4d x0;
  x0 << in.z[0], 0, 0;
  ekf.reset(x0, Eigen::Vector4d(s2, s2, 100, 100).asDiagonal().toDenseMatrix());
  double ll = 0;
  for (std::size_t k = 1; k < in.z.size(); ++k) {
    if (ekf.predict(NoControl{}, in.t[k] - in.t[k - 1]) != FilterStatus::kApplied)
      return -std::numeric_limits<double>::infinity();
    ll += innovation_log_likelihood(ekf.update<0>(in.z[k]));
  }
  return ll;
}

}  // namespace

TEST_CASE("innovation_log_likelihood is -1/2 (nu' S^-1 nu + log det S)", "[filters][tuning]") {
  const Eigen::Vector2d nu(0.3, -1.2);
  Eigen::Matrix2d S;
  S << 2.0, 0.4, 0.4, 0.5;
  const double expected = -0.5 * (nu.dot(S.inverse() * nu) + std::log(S.determinant()));
  CHECK(innovation_log_likelihood(nu, S) == Approx(expected).epsilon(1e-13));
  const Eigen::Matrix<double, 1, 1> s1(4.0), n1(2.0);
  CHECK(innovation_log_likelihood(n1, s1) == Approx(-0.5 * (1.0 + std::log(4.0))).epsilon(1e-14));

  Eigen::Matrix2d indefinite;
  indefinite << 1.0, 2.0, 2.0, 1.0;
  CHECK(innovation_log_likelihood(nu, indefinite) == -std::numeric_limits<double>::infinity());
  const Eigen::Vector2d nan_nu(std::nan(""), 0.0);
  CHECK(innovation_log_likelihood(nan_nu, S) == -std::numeric_limits<double>::infinity());
}

TEST_CASE("log_spaced covers [lo, hi] in equal ratios", "[filters][tuning]") {
  const auto v = log_spaced(1e-3, 1e1, 5);
  REQUIRE(v.size() == 5);
  CHECK(v.front() == 1e-3);
  CHECK(v.back() == 1e1);
  for (std::size_t i = 1; i < v.size(); ++i) CHECK(v[i] / v[i - 1] == Approx(10.0).epsilon(1e-12));
  CHECK_THROWS_AS(log_spaced(0.0, 1.0, 3), invalid_argument);
  CHECK_THROWS_AS(log_spaced(2.0, 1.0, 3), invalid_argument);
}

TEST_CASE("tune_noise finds the maximum of a known surface and flags a bound", "[filters][tuning]") {
  // A maximum between grid points: the refinement has to find it.
  const auto bowl = [](double p, double m) {
    const double a = std::log(p / 0.0317), b = std::log(m / 2.71);
    return -(a * a + 0.5 * b * b + 0.3 * a * b);
  };
  const NoiseTuningResult r = tune_noise(bowl, {1e-4, 1e2}, {1e-3, 1e3});
  CHECK(r.process == Approx(0.0317).epsilon(1e-3));
  CHECK(r.measurement == Approx(2.71).epsilon(1e-3));
  // The simplex stops at 1e-3 in log units: the value is within O(1e-6) of 0.
  CHECK(r.log_likelihood == Approx(0.0).margin(1e-5));
  CHECK_FALSE(r.process_at_bound);
  CHECK_FALSE(r.measurement_at_bound);
  CHECK(r.evaluations <= 81 + 200);

  // Rising without limit towards small p: the answer is the bound, flagged.
  const auto ramp = [](double p, double m) { return -std::log(p) - std::pow(std::log(m), 2); };
  const NoiseTuningResult b = tune_noise(ramp, {1e-3, 1.0}, {1e-2, 1e2});
  CHECK(b.process == Approx(1e-3).epsilon(1e-9));
  CHECK(b.process_at_bound);
  CHECK(b.measurement == Approx(1.0).epsilon(1e-3));
  CHECK_FALSE(b.measurement_at_bound);

  const auto never = [](double, double) { return std::nan(""); };
  CHECK_THROWS_AS(tune_noise(never, {1e-3, 1.0}, {1e-3, 1.0}), invalid_argument);
  CHECK_THROWS_AS(tune_noise(bowl, {0.0, 1.0}, {1e-3, 1.0}), invalid_argument);
}

TEST_CASE("tune_noise recovers the noise of a displacement-driven walk from its inputs alone",
          "[filters][tuning]") {
  // Generated with r = 0.04 m^2 (control) and q = 0.25 m^2 (position); 3000
  // steps. Tolerance: within 20 % of each true variance, for every seed.
  for (const unsigned seed : {1u, 2u, 3u}) {
    const FilterInputs in = make_displacement_run(0.04, 0.25, 3000, seed);
    const NoiseTuningResult r = tune_noise(
        [&](double p, double m) { return displacement_log_likelihood(in, p, m); }, {1e-4, 1e1},
        {1e-4, 1e1});
    INFO("seed " << seed << ": r " << r.process << ", q " << r.measurement);
    CHECK(r.process == Approx(0.04).epsilon(0.20));
    CHECK(r.measurement == Approx(0.25).epsilon(0.20));
    CHECK_FALSE(r.process_at_bound);
    CHECK_FALSE(r.measurement_at_bound);
  }
}

TEST_CASE("tune_noise recovers a constant-velocity model's noise from the measurements alone",
          "[filters][tuning]") {
  // Generated with acceleration density 0.5 m^2/s^3 and 0.09 m^2 position
  // noise at 10 Hz; 3000 steps. Tolerance: within 25 % of each, every seed.
  for (const unsigned seed : {4u, 5u, 6u}) {
    const FilterInputs in = make_cv_run(0.5, 0.09, 3000, seed);
    const NoiseTuningResult r = tune_noise(
        [&](double p, double m) { return cv_log_likelihood(in, p, m); }, {1e-3, 1e2}, {1e-4, 1e1});
    INFO("seed " << seed << ": q " << r.process << ", s2 " << r.measurement);
    CHECK(r.process == Approx(0.5).epsilon(0.25));
    CHECK(r.measurement == Approx(0.09).epsilon(0.25));
  }
}

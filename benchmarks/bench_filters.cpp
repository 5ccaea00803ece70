// Per-step cost of seed 000's EKF (predict + update, G = H = I, 2-D state).
//
//   cmake --preset release && cmake --build --preset release --target bench_filters
//   ./build-release/benchmarks/bench_filters
//
// Side by side in this binary:
//   BM_Seed000Ekf_Step/posefuse      posefuse::Ekf (fixed-size, Joseph form, LLT,
//                                    identity Jacobians skipped at compile time)
//   BM_Seed000Ekf_Step/posefuse_recompute
//                                    the same filter through update_with(), which
//                                    recomputes the gain every step (what any
//                                    filter whose covariance has not converged,
//                                    or whose noise varies, pays)
//   BM_Seed000Ekf_Step/naive_fixed   the textbook step written directly with
//                                    fixed-size Eigen (G, H multiplied, S inverted)
//   BM_Seed000Ekf_Step/dynamic       the same textbook step with Eigen::MatrixXd
//   BM_ConstantVelocityEkf_Step      4-D constant-velocity predict + 2-D fix
// The cost of the PSD checks inside those steps (core/gaussian.hpp's
// criterion; Ekf checks the predicted covariance every predict and the
// posterior whenever the gain is recomputed), without a knob on Ekf:
//   .../<step>_plus_check            the same step plus one more
//                                    is_positive_semidefinite() of the filter's
//                                    covariance, as the step itself does it:
//                                    the difference to <step> is the marginal
//                                    cost of one check inside the step
//   BM_PsdCheck/<n>                  is_positive_semidefinite() alone on the
//                                    covariances those filters produce
//   BM_PsdCheck_Reference/<n>        the same on the completely pivoted LDLT
//                                    alone (detail::psd_reference), i.e. without
//                                    the fast path
// Inputs are generated once outside the timed loop; each iteration runs one
// frame of a 1024-frame sequence.
#include <Eigen/Dense>
#include <benchmark/benchmark.h>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>
#include <array>
#include <random>
#include <vector>

namespace {

struct Frames {
  std::vector<Eigen::Vector2d> u, z;
};

const Frames& frames() {
  static const Frames f = [] {
    Frames out;
    std::mt19937 rng(3);
    std::normal_distribution<double> n(0.0, 0.3);
    Eigen::Vector2d p(0, 0);
    for (int k = 0; k < 1024; ++k) {
      const Eigen::Vector2d step(1.0 + n(rng), 0.2 * n(rng));
      p += step;
      out.u.push_back(step);
      out.z.push_back(p + Eigen::Vector2d(n(rng), n(rng)));
    }
    return out;
  }();
  return f;
}

// One posefuse seed-000 step; kRecompute: update_with() a sensor built once
// outside the loop, so the gain memo of update<0> is never used; kExtraCheck:
// one more is_positive_semidefinite of the predicted covariance per step
// (the `_plus_check` rows: the cost of one check in context).
template <bool kRecompute, bool kExtraCheck>
void BM_Seed000Ekf_Step_posefuse_variant(benchmark::State& state) {
  const Frames& f = frames();
  const posefuse::PositionFix<2> fix = posefuse::PositionFix<2>::isotropic(0.5);
  posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<2>> ekf(
      posefuse::PlanarDisplacement<double>::from_sigmas(0.1, 0.1), fix);
  ekf.reset(f.z[0], Eigen::Matrix2d::Identity());
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ekf.predict(f.u[k], 1.0));
    if constexpr (kExtraCheck)
      benchmark::DoNotOptimize(posefuse::is_positive_semidefinite(ekf.covariance()));
    if constexpr (kRecompute) {
      auto r = ekf.update_with(fix, f.z[k]);
      benchmark::DoNotOptimize(r);
    } else {
      auto r = ekf.update<0>(f.z[k]);
      benchmark::DoNotOptimize(r);
    }
    k = (k + 1) & 1023;
  }
  benchmark::DoNotOptimize(ekf.state());
}
BENCHMARK_TEMPLATE(BM_Seed000Ekf_Step_posefuse_variant, false, false)
    ->Name("BM_Seed000Ekf_Step/posefuse");
BENCHMARK_TEMPLATE(BM_Seed000Ekf_Step_posefuse_variant, false, true)
    ->Name("BM_Seed000Ekf_Step/posefuse_plus_check");
BENCHMARK_TEMPLATE(BM_Seed000Ekf_Step_posefuse_variant, true, false)
    ->Name("BM_Seed000Ekf_Step/posefuse_recompute");
BENCHMARK_TEMPLATE(BM_Seed000Ekf_Step_posefuse_variant, true, true)
    ->Name("BM_Seed000Ekf_Step/posefuse_recompute_plus_check");

void BM_Seed000Ekf_Step_naive_fixed(benchmark::State& state) {
  const Frames& f = frames();
  const Eigen::Matrix2d G = Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d H = Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  const Eigen::Matrix2d Q = Eigen::Matrix2d::Identity() * 0.25;
  Eigen::Vector2d mu = f.z[0];
  Eigen::Matrix2d S = Eigen::Matrix2d::Identity();
  std::size_t k = 0;
  for (auto _ : state) {
    const Eigen::Vector2d mubar = mu + f.u[k];
    const Eigen::Matrix2d Sbar = G * S * G.transpose() + R;
    const Eigen::Matrix2d K = Sbar * H.transpose() * (H * Sbar * H.transpose() + Q).inverse();
    mu = mubar + K * (f.z[k] - H * mubar);
    S = (Eigen::Matrix2d::Identity() - K * H) * Sbar;
    benchmark::DoNotOptimize(mu);
    benchmark::DoNotOptimize(S);
    k = (k + 1) & 1023;
  }
}
BENCHMARK(BM_Seed000Ekf_Step_naive_fixed)->Name("BM_Seed000Ekf_Step/naive_fixed");

void BM_Seed000Ekf_Step_dynamic(benchmark::State& state) {
  const Frames& f = frames();
  const Eigen::MatrixXd G = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::MatrixXd H = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(2, 2);
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(2, 2) * 0.01;
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(2, 2) * 0.25;
  Eigen::VectorXd mu = f.z[0];
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(2, 2);
  std::size_t k = 0;
  for (auto _ : state) {
    const Eigen::VectorXd u = f.u[k];
    const Eigen::VectorXd z = f.z[k];
    const Eigen::VectorXd mubar = mu + u;
    const Eigen::MatrixXd Sbar = G * S * G.transpose() + R;
    const Eigen::MatrixXd Sinn = H * Sbar * H.transpose() + Q;
    const Eigen::MatrixXd K = Sbar * H.transpose() * Sinn.inverse();
    mu = mubar + K * (z - H * mubar);
    S = (I - K * H) * Sbar;
    benchmark::DoNotOptimize(mu.data());
    benchmark::DoNotOptimize(S.data());
    k = (k + 1) & 1023;
  }
}
BENCHMARK(BM_Seed000Ekf_Step_dynamic)->Name("BM_Seed000Ekf_Step/dynamic");

// The constant-velocity step; kExtraCheck as above.
template <bool kExtraCheck>
void BM_ConstantVelocityEkf_Step_variant(benchmark::State& state) {
  const Frames& f = frames();
  posefuse::Ekf<posefuse::ConstantVelocity2<double>, posefuse::PositionFix<4>> ekf(
      posefuse::ConstantVelocity2<double>(1.0), posefuse::PositionFix<4>::isotropic(0.5));
  Eigen::Vector4d x0;
  x0 << f.z[0], 0, 0;
  ekf.reset(x0, Eigen::Matrix4d::Identity());
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(ekf.predict(posefuse::NoControl{}, 0.1));
    if constexpr (kExtraCheck)
      benchmark::DoNotOptimize(posefuse::is_positive_semidefinite(ekf.covariance()));
    auto r = ekf.update<0>(f.z[k]);
    benchmark::DoNotOptimize(r);
    k = (k + 1) & 1023;
  }
}
BENCHMARK_TEMPLATE(BM_ConstantVelocityEkf_Step_variant, false)->Name("BM_ConstantVelocityEkf_Step");
BENCHMARK_TEMPLATE(BM_ConstantVelocityEkf_Step_variant, true)
    ->Name("BM_ConstantVelocityEkf_Step_plus_check");

// Covariances as the filters above produce them (predicted and posterior,
// the first 128 steps of each, so they still change), cycled.
template <int N>
const std::vector<Eigen::Matrix<double, N, N>>& filter_covariances() {
  static const std::vector<Eigen::Matrix<double, N, N>> out = [] {
    std::vector<Eigen::Matrix<double, N, N>> v;
    const Frames& f = frames();
    if constexpr (N == 2) {
      const posefuse::PositionFix<2> fix = posefuse::PositionFix<2>::isotropic(0.5);
      posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<2>> ekf(
          posefuse::PlanarDisplacement<double>::from_sigmas(0.1, 0.1), fix);
      ekf.reset(f.z[0], Eigen::Matrix2d::Identity());
      for (std::size_t k = 0; k < 128; ++k) {
        (void)ekf.predict(f.u[k], 1.0);
        v.push_back(ekf.covariance());
        (void)ekf.update_with(fix, f.z[k]);
        v.push_back(ekf.covariance());
      }
    } else {
      static_assert(N == 4);
      const posefuse::PositionFix<4> fix = posefuse::PositionFix<4>::isotropic(0.5);
      posefuse::Ekf<posefuse::ConstantVelocity2<double>, posefuse::PositionFix<4>> ekf(
          posefuse::ConstantVelocity2<double>(1.0), fix);
      Eigen::Vector4d x0;
      x0 << f.z[0], 0, 0;
      ekf.reset(x0, Eigen::Matrix4d::Identity());
      for (std::size_t k = 0; k < 128; ++k) {
        (void)ekf.predict(posefuse::NoControl{}, 0.1);
        v.push_back(ekf.covariance());
        (void)ekf.update_with(fix, f.z[k]);
        v.push_back(ekf.covariance());
      }
    }
    return v;
  }();
  return out;
}

template <int N>
void BM_PsdCheck(benchmark::State& state) {
  const auto& P = filter_covariances<N>();
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::is_positive_semidefinite(P[k]));
    k = (k + 1) & 255;
  }
}
BENCHMARK_TEMPLATE(BM_PsdCheck, 2)->Name("BM_PsdCheck/2");
BENCHMARK_TEMPLATE(BM_PsdCheck, 4)->Name("BM_PsdCheck/4");

template <int N>
void BM_PsdCheck_Reference(benchmark::State& state) {
  const auto& P = filter_covariances<N>();
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::detail::psd_reference(P[k], false));
    k = (k + 1) & 255;
  }
}
BENCHMARK_TEMPLATE(BM_PsdCheck_Reference, 2)->Name("BM_PsdCheck_Reference/2");
BENCHMARK_TEMPLATE(BM_PsdCheck_Reference, 4)->Name("BM_PsdCheck_Reference/4");

}  // namespace

// Evaluation hot spots on KITTI-sized inputs (synthetic, fixed seeds):
// timestamp association, Umeyama alignment, APE and RPE.
#include <Eigen/Geometry>
#include <benchmark/benchmark.h>
#include <Eigen/SVD>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace {

// A 10 Hz drive along a gently curving road in KITTI's x-z plane, with a
// noisy, rotated copy as the estimate.
struct Pair {
  posefuse::Trajectory ref, est;
};

Pair make_pair(std::size_t n) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.3);
  Pair p;
  Eigen::Isometry3d G = Eigen::Isometry3d::Identity();
  G.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (std::size_t k = 0; k < n; ++k) {
    const double t = 0.1 * static_cast<double>(k);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.01 * t, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(50.0 * std::sin(0.01 * t), 0.0, 1000.0 * std::sin(0.001 * t));
    p.ref.push_back(t, T);
    Eigen::Isometry3d E = G * T;
    E.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    p.est.push_back(t + 0.003, E);
  }
  return p;
}

void BM_Association_Associate(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::associate(p.ref.t_s, p.est.t_s));
  }
}
BENCHMARK(BM_Association_Associate)->Arg(1101)->Arg(30000);

void BM_Umeyama_Sim3(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  const std::vector<Eigen::Vector3d> x = p.est.positions(), y = p.ref.positions();
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::umeyama_alignment(x, y, true));
}
BENCHMARK(BM_Umeyama_Sim3)->Arg(1101);

void BM_Ape_TranslationSE3(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::ape(p.ref, p.est, posefuse::PoseRelation::kTranslation,
                                           posefuse::Alignment::kSE3));
  }
}
BENCHMARK(BM_Ape_TranslationSE3)->Arg(1101);

void BM_Rpe_AngleByMeters(benchmark::State& state) {
  const Pair p = make_pair(static_cast<std::size_t>(state.range(0)));
  posefuse::RpeOptions o;
  o.relation = posefuse::PoseRelation::kRotationAngleDeg;
  o.delta = 10.0;
  o.delta_unit = posefuse::DeltaUnit::kMeters;
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::rpe(p.ref, p.est, o));
}
BENCHMARK(BM_Rpe_AngleByMeters)->Arg(1101);

}  // namespace

// ---------------------------------------------------------------------------
// Parsing: a 20 000-pose KITTI file and TUM file (written once to the temp
// folder; rotations as read from real files, i.e. orthonormal only to about
// 1e-7, so every pose goes through the rotation clean-up), and that clean-up
// alone: Newton's polar iteration (the reader's) against the SVD it replaced.

namespace {

std::filesystem::path parse_input(bool tum) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / (tum ? "posefuse_bench_20000.tum" : "posefuse_bench_20000.txt");
  if (std::filesystem::exists(file)) return file;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::ofstream out(file);
  out.precision(9);  // about what KITTI and TUM files store
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d w(n01(rng), n01(rng), n01(rng));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    const Eigen::Vector3d t(100 * n01(rng), 100 * n01(rng), 100 * n01(rng));
    if (tum) {
      const Eigen::Quaterniond q(R);
      out << 0.05 * k << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' '
          << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
    } else {
      for (int i = 0; i < 3; ++i)
        out << R(i, 0) << ' ' << R(i, 1) << ' ' << R(i, 2) << ' ' << t(i) << (i < 2 ? ' ' : '\n');
    }
  }
  return file;
}

void BM_Parse20000_Kitti(benchmark::State& state) {
  const std::filesystem::path file = parse_input(false);
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::read_kitti(file));
}
BENCHMARK(BM_Parse20000_Kitti)->Unit(benchmark::kMillisecond);

void BM_Parse20000_Tum(benchmark::State& state) {
  const std::filesystem::path file = parse_input(true);
  for (auto _ : state) benchmark::DoNotOptimize(posefuse::read_tum(file));
}
BENCHMARK(BM_Parse20000_Tum)->Unit(benchmark::kMillisecond);

std::vector<Eigen::Matrix3d> nearly_orthonormal(std::size_t n) {
  std::mt19937_64 rng(8);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<Eigen::Matrix3d> out;
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d w(n01(rng), n01(rng), n01(rng));
    Eigen::Matrix3d R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    for (int i = 0; i < 9; ++i) R(i / 3, i % 3) += 3e-8 * n01(rng);
    out.push_back(R);
  }
  return out;
}

void BM_RotationCleanup_Polar(benchmark::State& state) {
  const std::vector<Eigen::Matrix3d> Rs = nearly_orthonormal(1024);
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(posefuse::detail::traj_io::checked_rotation(Rs[k++ & 1023], 1e-3, "", 0));
  }
}
BENCHMARK(BM_RotationCleanup_Polar);

void BM_RotationCleanup_Svd(benchmark::State& state) {
  const std::vector<Eigen::Matrix3d> Rs = nearly_orthonormal(1024);
  std::size_t k = 0;
  for (auto _ : state) {
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(Rs[k++ & 1023], Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
    benchmark::DoNotOptimize(R);
  }
}
BENCHMARK(BM_RotationCleanup_Svd);

}  // namespace

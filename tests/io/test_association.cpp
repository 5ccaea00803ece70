// Timestamp association, checked against evo's rule (evo/core/sync.py):
// walk the shorter trajectory (the estimate on a tie), first argmin in the
// longer one, keep |dt| <= max_diff, error when nothing matches.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <posefuse/io/association.hpp>

#include "support/synthetic_trajectory.hpp"

namespace {

using Ids = std::vector<std::size_t>;

// A literal transcription of evo's matching_time_indices + the short/long
// choice of associate_trajectories (linear scan, first minimum).
posefuse::Association brute_force(const std::vector<double>& ref, const std::vector<double>& est,
                                  double max_diff, double offset) {
  const bool est_longer = est.size() > ref.size();
  const std::vector<double>& s = est_longer ? ref : est;
  std::vector<double> l = est_longer ? est : ref;
  for (double& t : l) t += est_longer ? offset : -offset;
  posefuse::Association a;
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::size_t best = 0;
    for (std::size_t j = 1; j < l.size(); ++j) {
      if (std::abs(l[j] - s[i]) < std::abs(l[best] - s[i])) best = j;
    }
    if (std::abs(l[best] - s[i]) <= max_diff) {
      (est_longer ? a.ref_ids : a.est_ids).push_back(i);
      (est_longer ? a.est_ids : a.ref_ids).push_back(best);
    }
  }
  return a;
}

}  // namespace

TEST_CASE("Association: walks the shorter reference", "[io][association]") {
  const std::vector<double> ref{0.0, 1.0, 2.0};
  const std::vector<double> est{0.0, 0.3, 0.995, 1.5, 2.02, 2.5};
  const posefuse::Association a = posefuse::associate(ref, est);
  CHECK(a.ref_ids == Ids{0, 1});  // 2.0 has no partner within 10 ms
  CHECK(a.est_ids == Ids{0, 2});
}

TEST_CASE("Association: walks the shorter estimate", "[io][association]") {
  const std::vector<double> ref{0.0, 0.1, 0.2, 0.3, 0.4};
  const std::vector<double> est{0.105, 0.305};
  const posefuse::Association a = posefuse::associate(ref, est);
  CHECK(a.ref_ids == Ids{1, 3});
  CHECK(a.est_ids == Ids{0, 1});
}

TEST_CASE("Association: equal lengths walk the estimate and may repeat indices",
          "[io][association]") {
  // Walking the reference would give one pair; evo walks the estimate
  // (its second trajectory) and matches reference 0 twice.
  const std::vector<double> ref{0.0, 1.0};
  const std::vector<double> est{0.004, 0.006};
  const posefuse::Association a = posefuse::associate(ref, est);
  CHECK(a.ref_ids == Ids{0, 0});
  CHECK(a.est_ids == Ids{0, 1});
}

TEST_CASE("Association: max_diff is inclusive", "[io][association]") {
  const std::vector<double> ref{0.5, 10.0, 20.0};
  const std::vector<double> est{0.75};
  CHECK(posefuse::associate(ref, est, 0.25).size() == 1);
  CHECK_THROWS_AS(posefuse::associate(ref, est, 0.2499), posefuse::invalid_argument);
}

TEST_CASE("Association: a tie picks the first index, as np.argmin", "[io][association]") {
  const std::vector<double> ref{0.0, 1.0, 2.0, 3.0};
  const std::vector<double> est{1.5};
  const posefuse::Association a = posefuse::associate(ref, est, 0.5);
  CHECK(a.ref_ids == Ids{1});
}

TEST_CASE("Association: the offset shifts the estimate either way", "[io][association]") {
  // Estimate clock runs 100 s ahead of the reference clock.
  const std::vector<double> ref{0.0, 0.1, 0.2};
  const std::vector<double> est_long{100.0, 100.05, 100.1, 100.15, 100.2};
  const std::vector<double> est_short{100.1};
  CHECK_THROWS_AS(posefuse::associate(ref, est_long), posefuse::invalid_argument);
  const posefuse::Association a = posefuse::associate(ref, est_long, 0.01, -100.0);
  CHECK(a.ref_ids == Ids{0, 1, 2});
  CHECK(a.est_ids == Ids{0, 2, 4});
  const posefuse::Association b = posefuse::associate(ref, est_short, 0.01, -100.0);
  CHECK(b.ref_ids == Ids{1});
  CHECK(b.est_ids == Ids{0});
}

TEST_CASE("Association: nothing matched and bad input are errors", "[io][association]") {
  const std::vector<double> ref{0.0, 1.0};
  const std::vector<double> est{5.0, 6.0};
  CHECK_THROWS_WITH(posefuse::associate(ref, est), Catch::Contains("found no matching timestamps"));
  CHECK_THROWS_AS(posefuse::associate(ref, std::vector<double>{}), posefuse::invalid_argument);
  CHECK_THROWS_AS(posefuse::associate(ref, ref, -0.1), posefuse::invalid_argument);
  const std::vector<double> unsorted{1.0, 0.0};
  CHECK_THROWS_WITH(posefuse::associate(unsorted, ref), Catch::Contains("sorted"));
}

TEST_CASE("Association: binary search equals evo's linear scan on random stamps",
          "[io][association]") {
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> step(0.001, 0.05);
  std::uniform_int_distribution<int> len(1, 300);
  std::uniform_real_distribution<double> off(-0.05, 0.05);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> ref(static_cast<std::size_t>(len(rng)));
    std::vector<double> est(static_cast<std::size_t>(len(rng)));
    double t = 1.7e9;
    for (double& s : ref) s = (t += step(rng));
    t = 1.7e9 + 0.01 * step(rng);
    for (double& s : est) s = (t += step(rng));
    if (trial % 3 == 0) {
      // Exact copies of reference stamps (zero diffs) and exact midpoints (ties).
      est.clear();
      for (std::size_t k = 0; k + 1 < ref.size(); ++k) {
        est.push_back(k % 2 == 0 ? ref[k] : 0.5 * (ref[k] + ref[k + 1]));
      }
      if (est.empty()) est.push_back(ref[0]);
    }
    const double offset = trial % 2 == 0 ? 0.0 : off(rng);
    const double max_diff = 0.002 + 0.01 * (trial % 4);
    const posefuse::Association expected = brute_force(ref, est, max_diff, offset);
    if (expected.size() == 0) {
      CHECK_THROWS_AS(posefuse::associate(ref, est, max_diff, offset), posefuse::invalid_argument);
      continue;
    }
    const posefuse::Association got = posefuse::associate(ref, est, max_diff, offset);
    REQUIRE(got.ref_ids == expected.ref_ids);
    REQUIRE(got.est_ids == expected.est_ids);
  }
}

TEST_CASE("Association: trajectories are reduced to the matched poses", "[io][association]") {
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(50, 1, 10.0);
  // Estimate at 5 Hz with 3 ms clock jitter-free offset.
  posefuse::Trajectory est;
  for (std::size_t k = 0; k < 50; k += 2) est.push_back(ref.t_s[k] + 0.003, ref.poses[k]);
  const posefuse::AssociatedTrajectories sync = posefuse::associate(ref, est);
  REQUIRE(sync.ref.size() == 25);
  REQUIRE(sync.est.size() == 25);
  for (std::size_t k = 0; k < 25; ++k) {
    CHECK(sync.ref.t_s[k] == ref.t_s[2 * k]);
    CHECK(sync.est.t_s[k] == est.t_s[k]);  // own clock kept
    CHECK(sync.ref.poses[k].matrix() == sync.est.poses[k].matrix());
  }
  posefuse::Trajectory broken = est;
  broken.t_s[1] = broken.t_s[0];
  CHECK_THROWS_AS(posefuse::associate(ref, broken), posefuse::invalid_argument);
}

TEST_CASE("Association: DuplicateStamps::kKeep reproduces evo on repeated stamps",
          "[io][association][duplicates]") {
  // evo reads every line (no duplicate policy) and associate_trajectories
  // walks the shorter trajectory: here the estimate (6 poses, stamp 2
  // repeated) against a 10-pose reference. Each repeated estimate stamp
  // pairs with its nearest reference pose, so reference pose 2 is used
  // twice. APE without alignment, by hand: errors 0, 0.1, 0.2, 0.4, 0, 0,
  // rmse = sqrt(0.21 / 6).
  posefuse::Trajectory ref, est;
  for (int k = 0; k < 10; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(k, 0.0, 0.0);
    ref.push_back(k, T);
  }
  const double stamps[] = {0, 1, 2, 2, 3, 4};
  const double dy[] = {0.0, 0.1, 0.2, 0.4, 0.0, 0.0};
  for (int k = 0; k < 6; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(stamps[k], dy[k], 0.0);
    est.push_back(stamps[k], T);
  }
  // Other policies refuse trajectories with equal stamps (the readers have
  // already dropped the repeats).
  CHECK_THROWS_AS(posefuse::associate(ref, est), posefuse::invalid_argument);
  const posefuse::AssociatedTrajectories sync =
      posefuse::associate(ref, est, 0.01, 0.0, posefuse::DuplicateStamps::kKeep);
  REQUIRE(sync.ref.size() == 6);
  CHECK(sync.ref.t_s == std::vector<double>{0, 1, 2, 2, 3, 4});
  CHECK(sync.est.poses[3].translation().y() == 0.4);
  double sse = 0.0;
  for (std::size_t k = 0; k < 6; ++k)
    sse += (sync.ref.poses[k].translation() - sync.est.poses[k].translation()).squaredNorm();
  CHECK(std::sqrt(sse / 6.0) == Approx(std::sqrt(0.21 / 6.0)).epsilon(1e-15));

  // The repeats in the longer trajectory: each shorter stamp takes the first
  // pose of the run (np.argmin's first minimum).
  posefuse::Trajectory short_ref;
  for (int k = 0; k < 4; ++k) short_ref.push_back(k, ref.poses[static_cast<std::size_t>(k)]);
  const posefuse::Association a = posefuse::associate(short_ref.t_s, est.t_s, 0.01, 0.0);
  CHECK(a.est_ids == Ids{0, 1, 2, 4});

  // Decreasing stamps stay an error.
  posefuse::Trajectory bad = est;
  bad.t_s[4] = 1.5;
  CHECK_THROWS_WITH(posefuse::associate(ref, bad, 0.01, 0.0, posefuse::DuplicateStamps::kKeep),
                    Catch::Contains("decrease at index 4"));
}

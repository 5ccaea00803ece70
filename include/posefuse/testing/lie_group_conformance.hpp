#pragma once
/// @file
/// Conformance check for Lie groups (check_lie_group): every analytic
/// Jacobian of lie/lie.hpp's members against long-double central
/// differences, the group axioms, Exp / Log (also at π), hat / vee against
/// the matrix exponential, the adjoint and the Jacobian identities, on
/// random, small-angle and near-π samples. LieGroupTraits names the rotation
/// components of SO2, SE2, SO3 and SE3; specialise it for another group.
/// In Catch2:
/// \code
///   const auto r = posefuse::testing::check_lie_group<posefuse::SE2d>(42, 200, 1e-9);
///   INFO(r.message);
///   CHECK(r);
/// \endcode

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/lie/so3.hpp>
#include <posefuse/testing/jacobian_check.hpp>

namespace posefuse::testing {

/// Which tangent components of a Lie group are rotation angles (so that
/// check_lie_group can place samples at small angles and near π), and a name
/// for messages. Specialise it for your own groups.
template <class G>
struct LieGroupTraits;
/// SO(2): [θ].
template <std::floating_point T>
struct LieGroupTraits<SO2<T>> {
  static constexpr const char* name = "SO2";  ///< for messages
  static constexpr int kRotationOffset = 0;   ///< first angle component
  static constexpr int kRotationDim = 1;      ///< number of angle components
};
/// SE(2): [ρx, ρy, θ].
template <std::floating_point T>
struct LieGroupTraits<SE2<T>> {
  static constexpr const char* name = "SE2";  ///< for messages
  static constexpr int kRotationOffset = 2;   ///< first angle component
  static constexpr int kRotationDim = 1;      ///< number of angle components
};
/// SO(3): [φ].
template <std::floating_point T>
struct LieGroupTraits<SO3<T>> {
  static constexpr const char* name = "SO3";  ///< for messages
  static constexpr int kRotationOffset = 0;   ///< first angle component
  static constexpr int kRotationDim = 3;      ///< number of angle components
};
/// SE(3): [ρ, φ].
template <std::floating_point T>
struct LieGroupTraits<SE3<T>> {
  static constexpr const char* name = "SE3";  ///< for messages
  static constexpr int kRotationOffset = 3;   ///< first angle component
  static constexpr int kRotationDim = 3;      ///< number of angle components
};

/// Default value tolerance of check_lie_group: \f$ 1000\,\epsilon \f$ of G's scalar.
template <class G>
[[nodiscard]] inline double default_value_tolerance() noexcept {
  return 1000.0 * double(std::numeric_limits<typename G::Scalar>::epsilon());
}

namespace detail {

/// Matrix exponential by scaling and squaring of the Taylor series, for the
/// independent check of Exp against hat (fixed-size square matrices).
template <class M>
M expm(const M& A) {
  using S = typename M::Scalar;
  const S norm = A.cwiseAbs().rowwise().sum().maxCoeff();
  int s = 0;
  S scale = S(1);
  while (norm * scale > S(0.25)) {
    scale /= S(2);
    ++s;
  }
  const M B = A * scale;
  M term = M::Identity();
  M sum = M::Identity();
  for (int k = 1; k <= 30; ++k) {
    term = (term * B / S(k)).eval();
    sum += term;
  }
  for (int i = 0; i < s; ++i) sum = (sum * sum).eval();
  return sum;
}

/// Kinds of samples check_lie_group draws.
enum class SampleKind { kRandom, kSmall, kNearPi };

inline const char* kind_name(SampleKind k) noexcept {
  switch (k) {
    case SampleKind::kRandom:
      return "random";
    case SampleKind::kSmall:
      return "small angle 1e-12";
    case SampleKind::kNearPi:
      return "near pi";
  }
  return "?";
}

/// A random tangent of G: translation parts N(0, 2²) m, rotation part of
/// magnitude `angle` about a uniform direction.
template <class G, class Rng>
typename G::Tangent random_tangent(Rng& rng, long double angle) {
  using T = typename G::Scalar;
  using Tr = LieGroupTraits<G>;
  std::normal_distribution<long double> n(0.0L, 1.0L);
  typename G::Tangent tau;
  for (int i = 0; i < G::Dim; ++i) tau(i) = T(2.0L * n(rng));
  Eigen::Matrix<long double, Tr::kRotationDim, 1> axis;
  for (int i = 0; i < Tr::kRotationDim; ++i) axis(i) = n(rng);
  if constexpr (Tr::kRotationDim == 1) {
    axis(0) = axis(0) < 0 ? -1.0L : 1.0L;
  } else {
    axis.normalize();
  }
  for (int i = 0; i < Tr::kRotationDim; ++i) tau(Tr::kRotationOffset + i) = T(angle * axis(i));
  // Rounding to T must not push the angle to pi or beyond (Log would then
  // return the other representative, which is correct but not tau).
  const auto rot_norm = [&] {
    long double n2 = 0;
    for (int i = 0; i < Tr::kRotationDim; ++i)
      n2 +=
          (long double)(tau(Tr::kRotationOffset + i)) * (long double)(tau(Tr::kRotationOffset + i));
    return std::sqrt(n2);
  };
  while (angle < std::numbers::pi_v<long double> && rot_norm() >= std::numbers::pi_v<long double>)
    tau.template segment<Tr::kRotationDim>(Tr::kRotationOffset) *=
        T(1) - T(4) * std::numeric_limits<T>::epsilon();
  return tau;
}

/// An angle for a sample of `kind`. Near π the margin is at least 8 ulps of
/// π in T (2e-6 rad in float), so that T's rounding of |φ| cannot reach π.
template <std::floating_point T, class Rng>
long double random_angle(Rng& rng, SampleKind kind, long double margin_to_pi) {
  constexpr long double pi = std::numbers::pi_v<long double>;
  switch (kind) {
    case SampleKind::kSmall:
      return 1e-12L;
    case SampleKind::kNearPi:
      return pi -
             std::max(margin_to_pi, 8.0L * pi * (long double)(std::numeric_limits<T>::epsilon()));
    case SampleKind::kRandom:
    default: {
      std::uniform_real_distribution<long double> u(0.0L, pi - 1e-3L);
      return u(rng);
    }
  }
}

}  // namespace detail

/// Checks a Lie group G (SO2, SE2, SO3, SE3 or any type with the members of
/// lie/lie.hpp and a LieGroupTraits specialisation) on `samples` random
/// elements: every analytic Jacobian (exp, log, inverse, compose x2, between
/// x2, act x2, plus x2, minus x2) against numeric differentiation, the group
/// axioms, Exp / Log round trips (also at exactly π), hat / vee and Exp
/// against the matrix exponential of hat, the adjoint identity
/// \f$ g\,\mathrm{Exp}(\tau)\,g^{-1} = \mathrm{Exp}(\mathrm{Ad}_g \tau) \f$, and the
/// Jacobian identities \f$ J_r J_r^{-1} = I \f$,
/// \f$ J_l = \mathrm{Ad}_{\mathrm{Exp}\,\tau} J_r \f$,
/// \f$ J_l(\tau) = J_r(-\tau) \f$.
///
/// Samples cycle through random angles, angles of 1e-12 and angles near π
/// (π − 1e-7 for values and exp / compose / act Jacobians, π − 1e-4 for the
/// Jacobians of log and minus, whose finite differences must not cross π;
/// for float the margin is at least 8 ulps of π, 2e-6 rad, since float
/// cannot hold π − 1e-7 apart from π), plus Log at exactly π.
/// The numeric reference is computed in long double on the same elements
/// (G::cast), so a float group is checked against an accurate reference.
/// @param[in] seed RNG seed (fixed seeds make failures reproducible)
/// @param[in] samples number of samples
/// @param[in] tol Jacobian entry tolerance (see check_jacobian)
/// @param[in] value_tol tolerance of the value identities, normalised by 1 + max|value|
template <class G>
[[nodiscard]] CheckResult check_lie_group(std::uint32_t seed, int samples, double tol,
                                          double value_tol = default_value_tolerance<G>()) {
  using T = typename G::Scalar;
  using L = long double;
  using GL = decltype(std::declval<const G&>().template cast<L>());
  using Tan = typename G::Tangent;
  using Jac = typename G::Jacobian;
  using Pt = typename G::Point;
  using TanL = typename GL::Tangent;
  using PtL = typename GL::Point;
  using Tr = LieGroupTraits<G>;
  constexpr L pi = std::numbers::pi_v<L>;
  const L h = default_step<L>();

  std::mt19937 rng(seed);
  std::normal_distribution<L> normal(0.0L, 1.0L);
  std::vector<CheckResult> r;
  r.reserve(std::size_t(samples) * 40);

  const auto L_of = [](const G& g) { return g.template cast<L>(); };
  const auto value_err = [](const G& a, const G& b) {
    // Normalised distance of a and b through their matrices.
    return detail::vector_error(a.matrix().reshaped(), b.matrix().reshaped());
  };

  for (int s = 0; s < samples; ++s) {
    const detail::SampleKind kind = s % 4 == 2   ? detail::SampleKind::kSmall
                                    : s % 4 == 3 ? detail::SampleKind::kNearPi
                                                 : detail::SampleKind::kRandom;
    std::ostringstream prefix;
    prefix << Tr::name << " sample " << s << " (" << detail::kind_name(kind) << ")";
    const std::string pre = prefix.str();
    const auto name = [&](const char* what) { return pre + ": " + what; };

    const auto draw = [&](L margin) {
      return detail::random_tangent<G>(rng, detail::random_angle<T>(rng, kind, margin));
    };
    const Tan tau = draw(1e-7L);      // for exp, values
    const Tan tau_b = draw(1e-7L);    // second element
    const Tan tau_c = draw(1e-7L);    // third element (associativity)
    const Tan d = draw(1e-7L);        // plus increment
    const Tan tau_log = draw(1e-4L);  // element whose log Jacobian is checked
    const Tan d_minus = draw(1e-4L);  // y = x (+) d_minus for minus
    Pt p;
    for (int i = 0; i < G::PointDim; ++i) p(i) = T(2.0L * normal(rng));

    const G a = G::exp(tau);
    const G b = G::exp(tau_b);
    const G c = G::exp(tau_c);
    const GL aL = L_of(a), bL = L_of(b);
    const PtL pL = p.template cast<L>();

    // ---- Jacobians against long-double central differences ----
    Jac J1, J2;
    {
      const G e = G::exp(tau, &J1);
      (void)e;
      const TanL tauL = tau.template cast<L>();
      r.push_back(detail::compare_jacobians(
          name("exp J_g_tau"), J1.template cast<L>(),
          numeric_jacobian([](const TanL& t) { return GL::exp(t); }, tauL, h), tol));
      r.push_back(detail::compare_jacobians(name("right_jacobian == exp's J_g_tau"),
                                            G::right_jacobian(tau), J1, value_tol));
    }
    {
      const G g = G::exp(tau_log);
      const Tan lg = g.log(&J1);
      (void)lg;
      r.push_back(detail::compare_jacobians(
          name("log J_tau_g"), J1.template cast<L>(),
          numeric_jacobian([](const GL& x) { return x.log(); }, L_of(g), h), tol));
    }
    {
      const G ai = a.inverse(&J1);
      (void)ai;
      r.push_back(detail::compare_jacobians(
          name("inverse J_inv_g"), J1.template cast<L>(),
          numeric_jacobian([](const GL& x) { return x.inverse(); }, aL, h), tol));
    }
    {
      const G ab = a.compose(b, &J1, &J2);
      (void)ab;
      r.push_back(detail::compare_jacobians(
          name("compose J_c_a"), J1.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return x.compose(bL); }, aL, h), tol));
      r.push_back(detail::compare_jacobians(
          name("compose J_c_b"), J2.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return aL.compose(x); }, bL, h), tol));
    }
    {
      const G dd = a.between(b, &J1, &J2);
      (void)dd;
      r.push_back(detail::compare_jacobians(
          name("between J_d_a"), J1.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return x.between(bL); }, aL, h), tol));
      r.push_back(detail::compare_jacobians(
          name("between J_d_b"), J2.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return aL.between(x); }, bL, h), tol));
    }
    {
      typename G::ActJacobianGroup Jg;
      typename G::ActJacobianPoint Jp;
      const Pt q = a.act(p, &Jg, &Jp);
      (void)q;
      r.push_back(detail::compare_jacobians(
          name("act J_q_g"), Jg.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return x.act(pL); }, aL, h), tol));
      r.push_back(detail::compare_jacobians(
          name("act J_q_p"), Jp.template cast<L>(),
          numeric_jacobian([&](const PtL& x) { return aL.act(x); }, pL, h), tol));
    }
    {
      const G y = a.plus(d, &J1, &J2);
      (void)y;
      const TanL dL = d.template cast<L>();
      r.push_back(detail::compare_jacobians(
          name("plus J_y_x"), J1.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return x.plus(dL); }, aL, h), tol));
      r.push_back(detail::compare_jacobians(
          name("plus J_y_d"), J2.template cast<L>(),
          numeric_jacobian([&](const TanL& t) { return aL.plus(t); }, dL, h), tol));
    }
    {
      const G y = a.plus(d_minus);
      const GL yL = L_of(y);
      const Tan m = y.minus(a, &J1, &J2);
      (void)m;
      r.push_back(detail::compare_jacobians(
          name("minus J_d_y"), J1.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return x.minus(aL); }, yL, h), tol));
      r.push_back(detail::compare_jacobians(
          name("minus J_d_x"), J2.template cast<L>(),
          numeric_jacobian([&](const GL& x) { return yL.minus(x); }, aL, h), tol));
    }

    // ---- Jacobian identities ----
    {
      const Jac I = Jac::Identity();
      const Jac Jr = G::right_jacobian(tau), Jl = G::left_jacobian(tau);
      r.push_back(detail::compare_jacobians(
          name("J_r * J_r^-1 == I"), Jac(Jr * G::right_jacobian_inverse(tau)), I, value_tol));
      r.push_back(detail::compare_jacobians(name("J_l * J_l^-1 == I"),
                                            Jac(Jl * G::left_jacobian_inverse(tau)), I, value_tol));
      r.push_back(detail::compare_jacobians(name("J_l == Ad_Exp(tau) J_r"), Jl,
                                            Jac(G::exp(tau).adjoint() * Jr), value_tol));
      r.push_back(detail::compare_jacobians(name("J_l(tau) == J_r(-tau)"), Jl,
                                            G::right_jacobian(Tan(-tau)), value_tol));
    }

    // ---- Group axioms and consistency of the representations ----
    const G e = G::identity();
    r.push_back(
        detail::value_check(name("a * a^-1 == e"), value_err(a * a.inverse(), e), value_tol));
    r.push_back(
        detail::value_check(name("a^-1 * a == e"), value_err(a.inverse() * a, e), value_tol));
    r.push_back(detail::value_check(name("e * a == a"), value_err(e * a, a), value_tol));
    r.push_back(detail::value_check(name("(a b) c == a (b c)"), value_err((a * b) * c, a * (b * c)),
                                    value_tol));
    r.push_back(detail::value_check(name("a.between(b) == a^-1 b"),
                                    value_err(a.between(b), a.inverse() * b), value_tol));
    r.push_back(detail::value_check(
        name("matrix(a b) == matrix(a) matrix(b)"),
        detail::vector_error((a * b).matrix().reshaped(), (a.matrix() * b.matrix()).reshaped()),
        value_tol));
    r.push_back(detail::value_check(
        name("matrix(a^-1) == matrix(a)^-1"),
        detail::vector_error((a.inverse().matrix() * a.matrix()).reshaped(),
                             decltype(a.matrix())::Identity().eval().reshaped()),
        value_tol));
    {
      const auto M = a.matrix();
      Pt q_m;
      if constexpr (int(decltype(M)::RowsAtCompileTime) == G::PointDim) {
        q_m = M * p;
      } else {
        q_m = M.template topLeftCorner<G::PointDim, G::PointDim>() * p +
              M.template topRightCorner<G::PointDim, 1>();
      }
      r.push_back(detail::value_check(name("act(p) == matrix * p"),
                                      detail::vector_error(a.act(p), q_m), value_tol));
      r.push_back(detail::value_check(name("a.act(b.act(p)) == (a b).act(p)"),
                                      detail::vector_error(a.act(b.act(p)), (a * b).act(p)),
                                      value_tol));
    }
    {
      // is_approx measures |a (-) o|: a step of 0.1 along the first tangent axis.
      const G o = a.plus(Tan(Tan::Unit(0) * T(0.1)));
      const bool ok =
          a.is_approx(a, T(value_tol)) && a.is_approx(o, T(0.11)) && !a.is_approx(o, T(0.09));
      r.push_back(detail::value_check(
          name("is_approx(a), is_approx(a + 0.1 e0) at 0.11, not at 0.09"), ok ? 0.0 : 1.0, 0.5));
    }

    // ---- Exp / Log ----
    r.push_back(detail::value_check(name("Log(Exp(tau)) == tau"),
                                    detail::vector_error(G::exp(tau).log(), tau), value_tol));
    r.push_back(
        detail::value_check(name("Exp(Log(a)) == a"), value_err(G::exp(a.log()), a), value_tol));
    {
      // Exp against the matrix exponential of hat, in long double.
      const TanL tauL = tau.template cast<L>();
      const auto W = GL::hat(tauL);
      const auto E = detail::expm(W);
      r.push_back(detail::value_check(
          name("Exp(tau) == expm(hat(tau))"),
          detail::vector_error(a.matrix().template cast<L>().reshaped(), E.reshaped()), value_tol));
      r.push_back(detail::value_check(name("vee(hat(tau)) == tau"),
                                      detail::vector_error(G::vee(G::hat(tau)), tau), value_tol));
    }
    if (kind == detail::SampleKind::kNearPi) {
      // Exactly pi: Log may return either sign of the axis; |angle| == pi and Exp(Log) == g.
      Tan tp = tau;
      const L n = L(tp.template segment<Tr::kRotationDim>(Tr::kRotationOffset).norm());
      for (int i = 0; i < Tr::kRotationDim; ++i)
        tp(Tr::kRotationOffset + i) = T(L(tp(Tr::kRotationOffset + i)) * pi / n);
      const G gp = G::exp(tp);
      const Tan lp = gp.log();
      const L ang = L(lp.template segment<Tr::kRotationDim>(Tr::kRotationOffset).norm());
      r.push_back(detail::value_check(name("|Log(Exp(pi axis))| == pi"),
                                      double(std::abs(ang - pi) / (1 + pi)), value_tol));
      r.push_back(detail::value_check(name("Exp(Log(g)) == g at angle pi"),
                                      value_err(G::exp(lp), gp), value_tol));
    }

    // ---- Adjoint ----
    {
      const G lhs = a * G::exp(d) * a.inverse();
      const G rhs = G::exp(Tan(a.adjoint() * d));
      r.push_back(detail::value_check(name("a Exp(d) a^-1 == Exp(Ad_a d)"), value_err(lhs, rhs),
                                      value_tol));
    }

    // ---- Manifold ----
    r.push_back(check_manifold(a, draw(1e-4L), value_tol));
    r.back().message = pre + ": " + r.back().message;
  }
  return combine(std::string("check_lie_group<") + Tr::name + ">", r);
}

}  // namespace posefuse::testing

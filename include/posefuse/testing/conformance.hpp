#pragma once
/// @file
/// Conformance checks for manifolds, Lie groups and models: numeric Jacobians
/// by central differences through plus / minus, and property checks that
/// users run from any test framework (no Catch2 dependency).
///
/// Every check returns a CheckResult: `ok`, the largest normalised error met,
/// and a message naming the check and — on failure — the worst entry (row,
/// column) with its analytic and numeric values. In Catch2:
/// \code
///   const auto r = posefuse::testing::check_lie_group<posefuse::SE2d>(42, 200, 1e-9);
///   INFO(r.message);
///   CHECK(r);
/// \endcode
///
/// **Jacobian tolerance.** An analytic Jacobian \f$ J^a \f$ passes against the
/// numeric \f$ J^n \f$ when every entry satisfies
/// \f$ |J^a_{ij} - J^n_{ij}| \le \mathrm{tol}\,(1 + |J^n_{ij}|) \f$ (relative for
/// large entries, absolute for small ones) and every entry is finite.
/// Central differences with step h are accurate to about
/// \f$ h^2 |f'''| / 6 + \epsilon |f(x)| / h \f$; the default step
/// \f$ h = \epsilon^{1/3} \f$ balances the two (about 6e-6 in double, 5e-3 in
/// float), so a tolerance of 1e-6 (double) or 1e-2 (float) suits functions
/// whose values and derivatives are of order one; scale it with |f(x)|.
///
/// Conventions are those of lie/lie.hpp: the numeric Jacobian of f at x is
/// \f$ \partial (f(x \oplus \tau) \ominus f(x)) / \partial\tau \f$, column i being
/// \f$ [(f(x \oplus h e_i) \ominus f(x)) - (f(x \oplus -h e_i) \ominus f(x))] / 2h \f$.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <numbers>
#include <ostream>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>
#include <posefuse/core/concepts.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/lie/so3.hpp>

namespace posefuse::testing {

/// The outcome of one check (or of several folded together).
struct CheckResult {
  bool ok{true};          ///< true when the check passed
  double max_error{0.0};  ///< largest normalised error met (see each check)
  std::string message;    ///< what was checked; on failure the entry, analytic and numeric values
  /// True when the check passed.
  explicit operator bool() const noexcept { return ok; }
};

/// Writes the message (so test frameworks that print values show it).
inline std::ostream& operator<<(std::ostream& os, const CheckResult& r) {
  return os << (r.ok ? "[ok] " : "[FAILED] ") << r.message;
}

/// True when every result passed.
[[nodiscard]] inline bool all_ok(const std::vector<CheckResult>& results) noexcept {
  return std::all_of(results.begin(), results.end(), [](const CheckResult& r) { return r.ok; });
}

/// Folds several results into one: ok when all are, the largest max_error,
/// and a message that lists every failing check (or says how many passed).
/// @param[in] name what the group of checks is about, prefixed to the message
/// @param[in] results the individual results
[[nodiscard]] inline CheckResult combine(std::string_view name,
                                         const std::vector<CheckResult>& results) {
  CheckResult out;
  std::size_t failed = 0;
  std::ostringstream failures;
  for (const CheckResult& r : results) {
    out.max_error = std::max(out.max_error, r.max_error);
    if (!r.ok) {
      out.ok = false;
      ++failed;
      failures << "\n  " << r.message;
    }
  }
  std::ostringstream msg;
  msg << name << ": ";
  if (out.ok) {
    msg << "all " << results.size() << " checks passed (max error " << out.max_error << ")";
  } else {
    msg << failed << " of " << results.size() << " checks failed:" << failures.str();
  }
  out.message = msg.str();
  return out;
}

namespace detail {

/// The value type a callable returns, with Eigen expressions evaluated.
template <class R>
struct Evaluated {
  using type = std::remove_cvref_t<R>;
};
template <class R>
requires std::is_base_of_v<Eigen::EigenBase<std::remove_cvref_t<R>>, std::remove_cvref_t<R>>
struct Evaluated<R> {
  using type = typename std::remove_cvref_t<R>::PlainObject;
};
template <class F, class X>
using ResultOf = typename Evaluated<std::invoke_result_t<const F&, const X&>>::type;

/// Normalised error |a - n| / (1 + |n|); infinite when either is not finite.
inline double entry_error(double a, double n) noexcept {
  if (!std::isfinite(a) || !std::isfinite(n)) return std::numeric_limits<double>::infinity();
  return std::abs(a - n) / (1.0 + std::abs(n));
}

/// Compares an analytic with a numeric Jacobian entry by entry (see the file comment).
template <class DA, class DN>
CheckResult compare_jacobians(std::string_view name, const Eigen::MatrixBase<DA>& Ja,
                              const Eigen::MatrixBase<DN>& Jn, double tol) {
  CheckResult r;
  std::ostringstream msg;
  msg.precision(10);
  if (Ja.rows() != Jn.rows() || Ja.cols() != Jn.cols()) {
    r.ok = false;
    r.max_error = std::numeric_limits<double>::infinity();
    msg << name << ": analytic Jacobian is " << Ja.rows() << "x" << Ja.cols() << ", numeric is "
        << Jn.rows() << "x" << Jn.cols();
    r.message = msg.str();
    return r;
  }
  Eigen::Index wr = 0, wc = 0;  // the worst entry
  int n_bad = 0;
  for (Eigen::Index i = 0; i < Ja.rows(); ++i) {
    for (Eigen::Index j = 0; j < Ja.cols(); ++j) {
      const double e = entry_error(double(Ja(i, j)), double(Jn(i, j)));
      if (!(e <= tol)) ++n_bad;
      if (e > r.max_error) {
        r.max_error = e;
        wr = i;
        wc = j;
      }
    }
  }
  r.ok = n_bad == 0;
  if (r.ok) {
    msg << name << ": ok (max error " << r.max_error << ")";
  } else {
    msg << name << ": entry (" << wr << ", " << wc << "): analytic " << double(Ja(wr, wc))
        << ", numeric " << double(Jn(wr, wc)) << ", error " << r.max_error << " > tol " << tol
        << " (|a - n| / (1 + |n|); " << n_bad << " entr" << (n_bad == 1 ? "y" : "ies")
        << " out of tolerance)";
  }
  r.message = msg.str();
  return r;
}

/// Normalised distance of two vectors: max_i |a_i - b_i| / (1 + max|b|).
template <class DA, class DB>
double vector_error(const Eigen::MatrixBase<DA>& a, const Eigen::MatrixBase<DB>& b) {
  const auto diff = (a - b).eval();
  if (!a.allFinite() || !b.allFinite()) return std::numeric_limits<double>::infinity();
  return double(diff.cwiseAbs().maxCoeff()) / (1.0 + double(b.cwiseAbs().maxCoeff()));
}

/// A check that `err <= tol`, described by `what`.
inline CheckResult value_check(std::string_view what, double err, double tol) {
  CheckResult r;
  r.max_error = std::isnan(err) ? std::numeric_limits<double>::infinity() : err;
  r.ok = err <= tol;
  std::ostringstream msg;
  msg << what << (r.ok ? ": ok (error " : ": error ") << err;
  if (r.ok) {
    msg << ")";
  } else {
    msg << " > tol " << tol;
  }
  r.message = msg.str();
  return r;
}

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

}  // namespace detail

/// Default finite-difference step for scalar type T: \f$ \epsilon^{1/3} \f$.
template <std::floating_point T>
[[nodiscard]] inline T default_step() noexcept {
  return std::cbrt(std::numeric_limits<T>::epsilon());
}

/// Numeric Jacobian of f at x by central differences through the manifolds'
/// plus / minus (see the file comment). X and f's result may be any
/// posefuse::Manifold, fixed-size Eigen vectors included (Eigen expressions
/// returned by f are evaluated).
/// @param[in] f callable X -> Y
/// @param[in] x linearisation point
/// @param[in] step h, in the units of X's tangent
/// @return Matrix<Scalar of Y, Dim of Y, Dim of X>
template <Manifold X, class F>
requires Manifold<detail::ResultOf<F, X>>
[[nodiscard]] auto numeric_jacobian(const F& f, const X& x,
                                    ScalarOf<X> step = default_step<ScalarOf<X>>()) {
  using Y = detail::ResultOf<F, X>;
  using TX = TangentOf<X>;
  using SY = ScalarOf<Y>;
  Eigen::Matrix<SY, DimOf<Y>, DimOf<X>> J;
  const Y y0 = f(x);
  for (int i = 0; i < DimOf<X>; ++i) {
    TX d = TX::Zero();
    d(i) = step;
    const Y yp = f(posefuse::plus(x, d));
    const Y ym = f(posefuse::plus(x, TX(-d)));
    J.col(i) = (posefuse::minus(yp, y0) - posefuse::minus(ym, y0)) / SY(SY(2) * SY(step));
  }
  return J;
}

/// Checks an analytic Jacobian of f at x against numeric_jacobian.
/// @param[in] name names the check in the message
/// @param[in] f callable X -> Y (Manifolds)
/// @param[in] x linearisation point
/// @param[in] J_analytic the Jacobian to check, Dim of Y x Dim of X
/// @param[in] tol entry tolerance: \f$ |a - n| \le \mathrm{tol}(1 + |n|) \f$
/// @param[in] step finite-difference step
/// @return ok when every entry is finite and within tolerance; max_error is
///         the largest \f$ |a - n| / (1 + |n|) \f$
template <Manifold X, class F, class Derived>
requires Manifold<detail::ResultOf<F, X>>
[[nodiscard]] CheckResult check_jacobian(std::string_view name, const F& f, const X& x,
                                         const Eigen::MatrixBase<Derived>& J_analytic, double tol,
                                         ScalarOf<X> step = default_step<ScalarOf<X>>()) {
  return detail::compare_jacobians(name, J_analytic, numeric_jacobian(f, x, step), tol);
}

/// Checks that x's plus and minus are consistent:
/// \f$ (x \oplus d) \ominus x = d \f$, \f$ x \oplus (y \ominus x) = y \f$ for
/// \f$ y = x \oplus d \f$, and \f$ x \ominus x = 0 \f$. d must lie inside the
/// region where minus inverts plus (angles below π).
/// @param[in] tol bound on the normalised errors \f$ \max|a - b| / (1 + \max|b|) \f$
template <Manifold X>
[[nodiscard]] CheckResult check_manifold(const X& x, const TangentOf<X>& d, double tol) {
  using posefuse::minus;
  using posefuse::plus;
  std::vector<CheckResult> r;
  const X y = plus(x, d);
  r.push_back(detail::value_check("(x + d) - x == d", detail::vector_error(minus(y, x), d), tol));
  const X z = plus(x, minus(y, x));
  r.push_back(detail::value_check(
      "x + (y - x) == y", detail::vector_error(minus(z, y), TangentOf<X>::Zero().eval()), tol));
  r.push_back(detail::value_check(
      "x - x == 0", detail::vector_error(minus(x, x), TangentOf<X>::Zero().eval()), tol));
  return combine("check_manifold", r);
}

/// Checks that a covariance is finite, symmetric and positive semi-definite:
/// \f$ \max|P - P^\top| \le \mathrm{tol}(1 + \max|P|) \f$ and
/// \f$ \lambda_{min}(P) \ge -\mathrm{tol}(1 + \max|P|) \f$.
template <class Derived>
[[nodiscard]] CheckResult check_covariance(std::string_view name,
                                           const Eigen::MatrixBase<Derived>& P, double tol) {
  using M = typename Derived::PlainObject;
  const M A = P;
  std::vector<CheckResult> r;
  std::string n(name);
  if (!A.allFinite()) {
    r.push_back(detail::value_check(n + " finite", std::numeric_limits<double>::infinity(), tol));
    return combine(n, r);
  }
  const double scale = 1.0 + double(A.cwiseAbs().maxCoeff());
  r.push_back(detail::value_check(n + " symmetric",
                                  double((A - A.transpose()).cwiseAbs().maxCoeff()) / scale, tol));
  const M S = (A + A.transpose()) / typename M::Scalar(2);
  const Eigen::SelfAdjointEigenSolver<M> es(S, Eigen::EigenvaluesOnly);
  const double lmin = double(es.eigenvalues().minCoeff());
  r.push_back(detail::value_check(n + " positive semi-definite (-min eigenvalue / scale)",
                                  std::max(0.0, -lmin) / scale, tol));
  return combine(n, r);
}

namespace detail {
/// A fixed, well-conditioned SPD test covariance with distinct entries,
/// \f$ A A^\top + I \f$ with \f$ A_{ij} = \sin(7i + 3j + 1) \f$, for checks of
/// covariance propagation.
template <class M>
M test_covariance() {
  M A;
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j)
      A(i, j) = typename M::Scalar(std::sin(7.0 * i + 3.0 * j + 1.0));
  return A * A.transpose() + M::Identity();
}

/// Largest |a - b| / (1 + max|b|) of two matrices.
template <class DA, class DB>
double matrix_error(const Eigen::MatrixBase<DA>& a, const Eigen::MatrixBase<DB>& b) {
  if (!a.allFinite() || !b.allFinite()) return std::numeric_limits<double>::infinity();
  return double((a - b).cwiseAbs().maxCoeff()) / (1.0 + double(b.cwiseAbs().maxCoeff()));
}

/// Checks declared Jacobian structure against the Jacobian J a model
/// returned: `kIdentityJacobian` (J must be I) and, for measurement models,
/// `kSelection` (row k of J must be the unit row of state index s_k).
template <class Model, class Derived>
void check_declared_structure(const Eigen::MatrixBase<Derived>& J, double tol,
                              std::vector<CheckResult>& r) {
  using Mat = typename Derived::PlainObject;
  if constexpr (has_identity_jacobian_v<Model>) {
    Mat I = Mat::Zero();
    for (int i = 0; i < std::min<int>(int(I.rows()), int(I.cols())); ++i) I(i, i) = 1;
    r.push_back(value_check("declared kIdentityJacobian: jacobian == I", matrix_error(J, I), tol));
  }
  if constexpr (requires { Model::kSelection; }) {
    Mat H = Mat::Zero();
    bool in_range = int(Model::kSelection.size()) == int(H.rows());
    for (std::size_t k = 0; in_range && k < Model::kSelection.size(); ++k) {
      const int c = Model::kSelection[k];
      if (c < 0 || c >= int(H.cols())) {
        in_range = false;
      } else {
        H(int(k), c) = 1;
      }
    }
    r.push_back(value_check("declared kSelection: jacobian == selection rows",
                            in_range ? matrix_error(J, H) : std::numeric_limits<double>::infinity(),
                            tol));
  }
}
}  // namespace detail

/// Checks a posefuse::MotionModel at (x, u, dt): `jacobian(x, u, dt)` against
/// the numeric \f$ \partial f / \partial x \f$ of `predict` through the
/// state's plus / minus, the prediction finite, and `noise(x, u, dt)`
/// finite, symmetric and PSD.
/// @param[in] tol Jacobian and covariance tolerance (see check_jacobian, check_covariance)
/// @param[in] step finite-difference step
template <MotionModel M>
[[nodiscard]] CheckResult check_motion_model(
    const M& model, const typename M::State& x, const typename M::Control& u,
    ScalarOf<typename M::State> dt_s, double tol,
    ScalarOf<typename M::State> step = default_step<ScalarOf<typename M::State>>()) {
  using S = typename M::State;
  std::vector<CheckResult> r;
  const S y = model.predict(x, u, dt_s);
  const TangentOf<S> dy = posefuse::minus(y, x);
  r.push_back(detail::value_check(
      "predict finite", dy.allFinite() ? 0.0 : std::numeric_limits<double>::infinity(), tol));
  const CovarianceOf<S> F = model.jacobian(x, u, dt_s);
  r.push_back(check_jacobian(
      "jacobian (J_f_x)", [&](const S& s) -> S { return model.predict(s, u, dt_s); }, x, F, tol,
      step));
  const CovarianceOf<S> Q = model.noise(x, u, dt_s);
  r.push_back(check_covariance("noise (Q)", Q, tol));
  detail::check_declared_structure<M>(F, tol, r);
  const CovarianceOf<S> P = detail::test_covariance<CovarianceOf<S>>();
  const CovarianceOf<S> FPFt = F * P * F.transpose();
  if constexpr (HasPropagate<M>) {
    r.push_back(detail::value_check("propagate(P) == F P F^T",
                                    detail::matrix_error(model.propagate(P, x, u, dt_s), FPFt),
                                    tol));
  }
  if constexpr (HasLinearizePropagate<M>) {
    const auto lin = model.linearize(x, u, dt_s);
    r.push_back(detail::value_check("linearize().propagate(P) == F P F^T",
                                    detail::matrix_error(lin.propagate(P), FPFt), tol));
  }
  if constexpr (HasLinearize<M>) {
    // The one-call form must agree with the three calls, and its Jacobian
    // is checked on its own: a wrong entry there alone must fail.
    const auto lin = model.linearize(x, u, dt_s);
    r.push_back(detail::value_check("linearize().state == predict()",
                                    double(posefuse::minus(lin.state, y).cwiseAbs().maxCoeff()),
                                    tol));
    r.push_back(detail::value_check("linearize().jacobian == jacobian()",
                                    double((lin.jacobian - F).cwiseAbs().maxCoeff()), tol));
    r.push_back(detail::value_check("linearize().noise == noise()",
                                    double((lin.noise - Q).cwiseAbs().maxCoeff()), tol));
    r.push_back(check_jacobian(
        "linearize().jacobian (J_f_x)",
        [&](const S& s) -> S { return model.predict(s, u, dt_s); }, x,
        CovarianceOf<S>(lin.jacobian), tol, step));
  }
  return combine("check_motion_model", r);
}

/// Checks a posefuse::MeasurementModel at x: `jacobian(x)` against the
/// numeric \f$ \partial h / \partial x \f$ of `predict` (outputs differenced
/// with the Measurement's minus, so angles wrap), and the noise — `noise(x)`
/// when the model has it, else `noise()` — finite, symmetric and PSD.
/// @param[in] tol Jacobian and covariance tolerance
/// @param[in] step finite-difference step
template <class H>
requires requires {
  typename H::State;
  typename H::Measurement;
} && Manifold<typename H::State> && Manifold<typename H::Measurement>
[[nodiscard]] CheckResult check_measurement_model(
    const H& model, const typename H::State& x, double tol,
    ScalarOf<typename H::State> step = default_step<ScalarOf<typename H::State>>()) {
  using S = typename H::State;
  using Z = typename H::Measurement;
  std::vector<CheckResult> r;
  const Z z = model.predict(x);
  r.push_back(detail::value_check(
      "predict finite",
      posefuse::minus(z, z).allFinite() ? 0.0 : std::numeric_limits<double>::infinity(), tol));
  const MeasurementJacobianOf<H> J = model.jacobian(x);
  r.push_back(check_jacobian(
      "jacobian (J_h_x)", [&](const S& s) -> Z { return model.predict(s); }, x, J, tol, step));
  detail::check_declared_structure<H>(J, tol, r);
  if constexpr (requires(const H& h, const S& s) { h.noise(s); }) {
    const CovarianceOf<Z> R = model.noise(x);
    r.push_back(check_covariance("noise(x) (R)", R, tol));
  } else {
    const CovarianceOf<Z> R = model.noise();
    r.push_back(check_covariance("noise() (R)", R, tol));
  }
  return combine("check_measurement_model", r);
}

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

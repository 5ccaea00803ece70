#pragma once
/// @file
/// The core of the conformance harness: the result type every check returns,
/// numeric Jacobians by central differences through plus / minus, the
/// Jacobian comparison, and the manifold and covariance checks that the model
/// and Lie group checks (model_conformance.hpp, lie_group_conformance.hpp)
/// build on. Users run them from any test framework (no Catch2 dependency).
///
/// Every check returns a CheckResult: `ok`, the largest normalised error met,
/// and a message naming the check and — on failure — the worst entry (row,
/// column) with its analytic and numeric values. In Catch2:
/// \code
///   const auto r = posefuse::testing::check_jacobian("J_f_x", f, x, J, 1e-6);
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
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>
#include <posefuse/core/concepts.hpp>

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
/// @param[in] x the point of the manifold
/// @param[in] d a tangent step
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

}  // namespace posefuse::testing

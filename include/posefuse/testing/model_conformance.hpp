#pragma once
/// @file
/// Conformance checks for motion and measurement models: each model's
/// analytic Jacobian against central differences of its `predict` (through
/// the state's and the measurement's plus / minus, so angles wrap), its noise
/// finite, symmetric and PSD, declared Jacobian structure (kIdentityJacobian,
/// kSelection) honoured, and the optional fast paths (propagate, linearize)
/// equal to the plain calls. Tolerances as in jacobian_check.hpp.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string_view>
#include <vector>
#include <posefuse/core/concepts.hpp>
#include <posefuse/testing/jacobian_check.hpp>

namespace posefuse::testing {

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
/// @param[in] model the motion model
/// @param[in] x the state at which it is checked
/// @param[in] u the control
/// @param[in] dt_s the time step (s)
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
/// @param[in] model the measurement model
/// @param[in] x the state at which it is checked
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

}  // namespace posefuse::testing

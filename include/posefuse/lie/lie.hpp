#pragma once
/// @file
/// The Lie groups SO(2), SE(2), SO(3), SE(3) (and lie/rotation.hpp's Euler
/// angles), with the conventions every header of lie/ follows.
///
/// **Right perturbations** (Solà, Deray, Atchuthan, "A micro Lie theory for
/// state estimation in robotics", arXiv:1812.01537, 2018, eq 25-26):
/// \f[ x \oplus \tau = x \cdot \mathrm{Exp}(\tau), \qquad
///     y \ominus x = \mathrm{Log}(x^{-1} \cdot y), \f]
/// so a perturbation \f$ \tau \f$ is expressed in the local (body) frame of x.
/// Every Jacobian is the right Jacobian
/// \f[ J = \frac{\partial\, f(x \oplus \tau) \ominus f(x)}{\partial \tau}\Big|_{\tau = 0}, \f]
/// with \f$ \oplus, \ominus \f$ = +, − for a Euclidean input or output (points,
/// tangent vectors). Jacobians are optional pointer out-parameters named
/// `J_<out>_<in>` (e.g. `c = a.compose(b, &J_c_a, &J_c_b)`), left untouched
/// when null.
///
/// **Tangent order**, translation part first:
/// SO2 `[θ]`, SE2 `[ρx, ρy, θ]`, SO3 `[φx, φy, φz]`, SE3 `[ρ(3), φ(3)]`
/// (ρ in m, θ and φ in rad). Note that ρ is not the translation: for SE(2)
/// and SE(3), \f$ t = V(\theta)\rho \f$.
///
/// **Frames.** An element used as a pose is the pose of a body frame b in a
/// world frame w (`T_w_b`): `act` maps body coordinates to world
/// coordinates, `a.between(b)` is b expressed in a.
///
/// **Accuracy.** Closed forms that cancel switch to Taylor series at small
/// angles (lie/detail/series.hpp); Exp / Log and the Jacobians are accurate to a
/// few ulps at |angle| = 1e-12, and Log stays accurate up to and at π (SO3 and
/// SE3 through the quaternion, SO2 and SE2 through atan2). Log returns angles
/// with |θ| <= π (SO2 / SE2: θ in [-π, π)).
///
/// **Validation.** Hot-path operations (exp, compose, act, ...) are noexcept
/// and do not validate: non-finite inputs give non-finite outputs, which
/// estimators detect. Constructors from external representations
/// (quaternion, rotation matrix, isometry, (cos, sin)) validate and throw
/// posefuse::invalid_argument.
///
/// Every group is a posefuse::Manifold (core/concepts.hpp), so a filter can
/// estimate it directly; testing/conformance.hpp checks all of the above.

#include <posefuse/lie/rotation.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/lie/so3.hpp>

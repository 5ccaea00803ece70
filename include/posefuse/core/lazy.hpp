#pragma once
/// @file
/// `dependent_t<T, Deps...>`: the type `T`, spelled so that it depends on
/// template parameters — half of the library's compile-cost idiom.
///
/// **The idiom.** A non-template inline function that does Eigen arithmetic
/// is compiled by every file that includes its header, whether it is called
/// or not. So such functions are templates, with a defaulted parameter where
/// nothing else is deduced:
///
///     template <class Lazy = void>
///     [[nodiscard]] Eigen::Vector3d f(const Eigen::Vector3d& x) { ... }
///
/// (callers write `f(x)` as before). A template alone is not enough when the
/// Eigen types in its body do not depend on its parameters: compilers check
/// non-dependent code when they parse the template, so
/// `Eigen::Matrix3d a = b + c;` instantiates Eigen's expression classes, and
/// `Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>` the solver, in every
/// includer. Spelling them `dependent_t<Eigen::Matrix3d, Lazy>` defers all of
/// that to the point of use. This keeps `<posefuse/posefuse.hpp>` within its
/// compile-cost budget (tests/compile_cost); docs/design.md says why and
/// what it measured.

namespace posefuse::detail {

/// Holds `T` (see the file comment).
template <class T, class... Deps>
struct dependent {
  using type = T;
};

/// `T`, dependent on `Deps` (see the file comment).
template <class T, class... Deps>
using dependent_t = typename dependent<T, Deps...>::type;

}  // namespace posefuse::detail

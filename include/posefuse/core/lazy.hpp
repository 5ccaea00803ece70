#pragma once
/// @file
/// `dependent_t<T, Deps...>`: the type `T`, spelled so that it depends on
/// template parameters.
///
/// Compilers check the non-dependent parts of a template when they parse
/// it: inside a function template, `Eigen::Matrix3d a = b + c;` instantiates
/// Eigen's expression classes for `b + c` (and an eigensolver's class for
/// `Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>`) in every file that
/// includes the header, whether the template is ever called or not.
/// Writing the Eigen types as `dependent_t<double, Lazy>` (or depending on
/// any other template parameter) defers all of that to the point of use.
/// This is what keeps `<posefuse/posefuse.hpp>` within its compile-cost
/// budget (tests/compile_cost).

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

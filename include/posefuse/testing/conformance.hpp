#pragma once
/// @file
/// The whole conformance harness in one include: it includes the three
/// headers below and nothing else. Include one of them directly to pull in
/// less.
///
/// * testing/jacobian_check.hpp — CheckResult, numeric_jacobian by central
///   differences, check_jacobian (the tolerance rule), check_manifold,
///   check_covariance;
/// * testing/model_conformance.hpp — check_motion_model,
///   check_measurement_model;
/// * testing/lie_group_conformance.hpp — check_lie_group, LieGroupTraits.
///
/// The checks need no test framework. In Catch2:
/// \code
///   const auto r = posefuse::testing::check_lie_group<posefuse::SE2d>(42, 200, 1e-9);
///   INFO(r.message);
///   CHECK(r);
/// \endcode

#include <posefuse/testing/jacobian_check.hpp>
#include <posefuse/testing/lie_group_conformance.hpp>
#include <posefuse/testing/model_conformance.hpp>

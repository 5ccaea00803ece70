#pragma once
/// @file
/// A Gaussian belief on a manifold: a mean and a covariance on its tangent
/// space, and require_covariance(), the check every covariance given to
/// posefuse passes (finite, symmetric, positive semi-definite by the
/// criterion of core/definiteness.hpp, which this header includes).

#include <Eigen/Core>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/definiteness.hpp>
#include <posefuse/core/error.hpp>
#include <string>

namespace posefuse {

/// Throws posefuse::invalid_argument unless `m` is a finite, symmetric,
/// positive semi-definite covariance. `what` names it in the message.
template <class Derived>
void require_covariance(const Eigen::MatrixBase<Derived>& m, const char* what) {
  if (!m.allFinite()) throw invalid_argument(std::string(what) + ": covariance has NaN or Inf");
  if (!is_symmetric(m)) throw invalid_argument(std::string(what) + ": covariance is not symmetric");
  if (!is_positive_semidefinite(m))
    throw invalid_argument(std::string(what) + ": covariance is not positive semi-definite");
}

/// A Gaussian \f$ N(\mu, \Sigma) \f$ on the state type S; \f$ \Sigma \f$ lives on
/// the tangent space at \f$ \mu \f$.
template <State S>
struct Gaussian {
  using StateType = S;
  using Scalar = ScalarOf<S>;
  static constexpr int Dim = DimOf<S>;
  using Covariance = CovarianceOf<S>;

  S mean{};
  Covariance cov = Covariance::Identity();

  Gaussian() = default;
  /// @throws posefuse::invalid_argument if `cov` is not a finite, symmetric
  ///         PSD matrix
  Gaussian(const S& m, const Covariance& c) : mean(m), cov(c) {
    require_covariance(cov, "Gaussian");
  }
};

}  // namespace posefuse

#pragma once
/// @file
/// The outcome of one estimator step, shared by every filter and fuser.
///
/// A step either applies (state and covariance change) or reports why not
/// and leaves the estimator exactly as it was: hot-path data failures are
/// statuses, never exceptions or silently propagated NaN (docs/design.md,
/// "Errors").

namespace posefuse {

/// Outcome of a filter step (prediction or update). Anything but kApplied
/// leaves the estimator untouched.
enum class FilterStatus {
  kApplied,              ///< the step changed the state and covariance
  kNonFinite,            ///< input or result had NaN/Inf
  kInvalidInput,         ///< e.g. a negative time step or a non-positive sigma
  kNotPositiveDefinite,  ///< the innovation covariance S was not positive definite, or the
                         ///< resulting covariance P would not be positive semi-definite
  kGated,                ///< a gate (NIS threshold or gate functor) rejected the measurement
  kNotInitialised,       ///< no belief yet (reset() was not called), or a fuser's
                         ///< measurement frame is not yet known; nothing was applied
};

/// Human-readable name of a status.
[[nodiscard]] constexpr const char* to_string(FilterStatus s) noexcept {
  switch (s) {
    case FilterStatus::kApplied: return "applied";
    case FilterStatus::kNonFinite: return "non-finite";
    case FilterStatus::kInvalidInput: return "invalid input";
    case FilterStatus::kNotPositiveDefinite: return "covariance not positive definite";
    case FilterStatus::kGated: return "rejected by gate";
    case FilterStatus::kNotInitialised: return "not initialised";
  }
  return "unknown";
}

}  // namespace posefuse

#pragma once
/// @file
/// The compile-time options of posefuse::BasicEkf (filters/ekf.hpp): how the
/// posterior covariance is formed, when the NIS is computed, whether the
/// prediction Jacobian is kept for a smoother, and the steady-state gain
/// memo. EkfOptions holds the defaults; a caller derives from it and hides
/// the members it changes.

#include <concepts>
#include <cstdint>

namespace posefuse {

/// How an Ekf forms the posterior covariance (EkfOptions::kCovarianceUpdate).
enum class CovarianceUpdate : std::uint8_t {
  /// Joseph's form \f$ (I - K H) P (I - K H)^\top + K R K^\top \f$ (Bucy &
  /// Joseph 1968; Grewal & Andrews, *Kalman Filtering*, 4th ed., eq. 4.23):
  /// PSD for any gain, so round-off in K does not make P indefinite. The
  /// default. Cost over kStandard: one Dim x Dim x M product more (one
  /// triangle of it), e.g. +20 multiplications for Dim 4, M 2. For a
  /// selection H with one to three rows it is evaluated expanded, \f$ P - K H P
  /// - P H^\top K^\top + K S K^\top \f$ (equal for a symmetric P; see
  /// detail::closed_form_selection_gain in filters/detail/ekf_update.hpp).
  kJoseph,
  /// The textbook \f$ (I - K H) P \f$ (one triangle, mirrored): fewer
  /// flops; exact only for the optimal gain, so round-off can leave P
  /// indefinite on ill-conditioned problems (the filter then refuses the
  /// step with kNotPositiveDefinite rather than store it).
  kStandard,
};

/// When an Ekf computes the NIS \f$ r^\top S^{-1} r \f$ of an update
/// (EkfOptions::kNis).
enum class NisPolicy : std::uint8_t {
  kAlways,     ///< every update: UpdateResult::nis is always set (the default)
  kWhenGated,  ///< only when a NIS gate is finite or a gate functor takes the
               ///< NIS; otherwise UpdateResult::nis stays NaN (saves one solve with S)
};

/// Compile-time options of BasicEkf. Derive from it and hide the members you
/// change; the defaults are the safe choices, and `Ekf<Motion, Sensors...>`
/// is BasicEkf with these defaults:
/// ```cpp
/// struct FastOptions : posefuse::EkfOptions {
///   static constexpr auto kNis = posefuse::NisPolicy::kWhenGated;
///   static constexpr bool kRecordJacobian = false;  // no smoother reads last_jacobian()
/// };
/// posefuse::BasicEkf<FastOptions, Motion, Sensor> ekf(motion, sensor);
/// ```
struct EkfOptions {
  /// Posterior covariance form (Joseph by default; see CovarianceUpdate).
  static constexpr CovarianceUpdate kCovarianceUpdate = CovarianceUpdate::kJoseph;
  /// NIS computation (always by default; see NisPolicy).
  static constexpr NisPolicy kNis = NisPolicy::kAlways;
  /// Keep the state Jacobian F of the last applied prediction for
  /// last_jacobian() (RTS smoothing). Cost: one Dim x Dim copy per predict,
  /// plus a `jacobian()` call for models that propagate the covariance
  /// themselves (HasPropagate). Off: last_jacobian() does not compile.
  static constexpr bool kRecordJacobian = true;
  /// Steady-state gain memo for time-invariant models (kTimeInvariant):
  /// keep the covariance half of the update and reuse it, bit for bit,
  /// while P repeats (kept once the same P has been seen three times in a
  /// row). Cost while P changes: two comparisons and two stores per update;
  /// in a steady state one Dim x Dim comparison per update; a copy of P and
  /// of the gain once per new steady state.
  static constexpr bool kGainMemo = true;
};

/// The lean option set: the cheapest step that still refuses what would
/// corrupt the belief. `BasicEkf<LeanEkfOptions, Motion, Sensors...>` (or
/// LeanEkf) against the defaults:
///  * kStandard covariance form: \f$ (I - K H) \bar P \f$, exact only for the
///    optimal gain, so round-off in K enters the covariance to first order
///    (Joseph's form: second order). Kept: every stored covariance still
///    passes is_positive_semidefinite(), so a step that round-off would
///    leave indefinite is refused (kNotPositiveDefinite), never stored.
///  * NIS only when gated (NisPolicy::kWhenGated): UpdateResult::nis is NaN
///    unless a finite NIS gate or a gate functor taking the NIS needs it.
///  * No Jacobian record: last_jacobian() does not compile (no RTS smoothing
///    from this filter's own record).
/// Kept as in EkfOptions: the steady-state gain memo, the finiteness checks
/// of state and innovation, S's positive-definiteness test and the PSD
/// check of every stored covariance.
struct LeanEkfOptions : EkfOptions {
  static constexpr CovarianceUpdate kCovarianceUpdate = CovarianceUpdate::kStandard;
  static constexpr NisPolicy kNis = NisPolicy::kWhenGated;
  static constexpr bool kRecordJacobian = false;
};

/// A type usable as BasicEkf's options (see EkfOptions).
template <class O>
concept EkfOptionSet = requires {
  { O::kCovarianceUpdate } -> std::convertible_to<CovarianceUpdate>;
  { O::kNis } -> std::convertible_to<NisPolicy>;
  { O::kRecordJacobian } -> std::convertible_to<bool>;
  { O::kGainMemo } -> std::convertible_to<bool>;
};

}  // namespace posefuse

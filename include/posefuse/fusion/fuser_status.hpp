#pragma once
/// @file
/// What GatedFuser reports about each measurement: the Ekf step's
/// FilterStatus plus, for SLAM poses, the anchoring event and the gate that
/// rejected it; and how it gates (GateMode).

#include <posefuse/core/status.hpp>

namespace posefuse {

/// How GatedFuser tests a SLAM pose against its prediction.
enum class GateMode { kSeparate, kMahalanobis, kBoth };

/// What a SLAM pose given to GatedFuser did about the map-frame anchor.
enum class AnchorEvent {
  kNone,        ///< nothing: the map frame was anchored already (or not a SLAM pose)
  kCollecting,  ///< kept to estimate a (new) map frame; not fused
  kAnchored,    ///< completed the estimate of the map frame; not fused itself
};

/// Which of GatedFuser's gates rejected a measurement.
enum class FuserGate {
  kNone,      ///< none (not rejected)
  kPosition,  ///< the 2-dof position gate
  kHeading,   ///< the 1-dof heading gate (SLAM heading or update_heading)
  kJoint,     ///< the 3-dof Mahalanobis gate
};

/// Human-readable name of an anchor event.
[[nodiscard]] constexpr const char* to_string(AnchorEvent e) noexcept {
  switch (e) {
    case AnchorEvent::kNone: return "none";
    case AnchorEvent::kCollecting: return "collecting anchor poses";
    case AnchorEvent::kAnchored: return "anchored";
  }
  return "unknown";
}

/// Human-readable name of a gate.
[[nodiscard]] constexpr const char* to_string(FuserGate g) noexcept {
  switch (g) {
    case FuserGate::kNone: return "none";
    case FuserGate::kPosition: return "position gate";
    case FuserGate::kHeading: return "heading gate";
    case FuserGate::kJoint: return "joint Mahalanobis gate";
  }
  return "unknown";
}

/// What happened to one measurement given to GatedFuser: the Ekf step's
/// FilterStatus, plus, for SLAM poses, the anchoring event and which gate
/// rejected it. Converts implicitly from a FilterStatus (no anchoring event,
/// no gate). The named constants are the common outcomes; compare with `==`.
struct FuserStatus {
  /// The filter step: kApplied (fused), kGated (see rejected_by), kNonFinite,
  /// kInvalidInput, kNotPositiveDefinite; kNotInitialised when the pose went
  /// to the anchor estimate instead (see anchor).
  FilterStatus step = FilterStatus::kApplied;
  AnchorEvent anchor = AnchorEvent::kNone;    ///< anchoring (SLAM poses)
  FuserGate rejected_by = FuserGate::kNone;   ///< the gate that failed, when step == kGated

  /// Applied, nothing else happened.
  constexpr FuserStatus() noexcept = default;
  /// A step outcome with its anchoring event and rejecting gate.
  constexpr FuserStatus(FilterStatus s, AnchorEvent a = AnchorEvent::kNone,  // NOLINT: implicit
                        FuserGate g = FuserGate::kNone) noexcept
      : step(s), anchor(a), rejected_by(g) {}

  /// True when the measurement changed the estimate.
  [[nodiscard]] constexpr bool applied() const noexcept { return step == FilterStatus::kApplied; }
  /// All fields equal.
  friend constexpr bool operator==(const FuserStatus&, const FuserStatus&) noexcept = default;

  static const FuserStatus kFused;              ///< {kApplied}: passed the gates and was fused
  static const FuserStatus kRejectedPosition;   ///< {kGated, -, kPosition}
  static const FuserStatus kRejectedHeading;    ///< {kGated, -, kHeading}
  static const FuserStatus kRejectedJoint;      ///< {kGated, -, kJoint}
  static const FuserStatus kAnchoring;          ///< {kNotInitialised, kCollecting}
  static const FuserStatus kAnchored;           ///< {kNotInitialised, kAnchored}
  static const FuserStatus kNonFinite;          ///< {kNonFinite}: NaN/Inf input; state untouched
  static const FuserStatus kSingularInnovation; ///< {kNotPositiveDefinite}; state untouched
  /// {kApplied}, the same value as kFused: kept for code written when
  /// predict() returned a FuserStatus (it now returns the FilterStatus).
  static const FuserStatus kPredicted;
};
inline constexpr FuserStatus FuserStatus::kFused{FilterStatus::kApplied};
inline constexpr FuserStatus FuserStatus::kRejectedPosition{FilterStatus::kGated, AnchorEvent::kNone,
                                                            FuserGate::kPosition};
inline constexpr FuserStatus FuserStatus::kRejectedHeading{FilterStatus::kGated, AnchorEvent::kNone,
                                                           FuserGate::kHeading};
inline constexpr FuserStatus FuserStatus::kRejectedJoint{FilterStatus::kGated, AnchorEvent::kNone,
                                                         FuserGate::kJoint};
inline constexpr FuserStatus FuserStatus::kAnchoring{FilterStatus::kNotInitialised,
                                                     AnchorEvent::kCollecting};
inline constexpr FuserStatus FuserStatus::kAnchored{FilterStatus::kNotInitialised,
                                                    AnchorEvent::kAnchored};
inline constexpr FuserStatus FuserStatus::kNonFinite{FilterStatus::kNonFinite};
inline constexpr FuserStatus FuserStatus::kSingularInnovation{FilterStatus::kNotPositiveDefinite};
inline constexpr FuserStatus FuserStatus::kPredicted{FilterStatus::kApplied};

/// True when a gate rejected the measurement.
[[nodiscard]] constexpr bool is_rejection(const FuserStatus& s) noexcept {
  return s.step == FilterStatus::kGated;
}

}  // namespace posefuse

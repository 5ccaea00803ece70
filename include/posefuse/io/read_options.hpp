#pragma once
/// @file
/// What the trajectory readers accept: rotation tolerances and the policy for
/// repeated timestamps, and what they report about the lines they dropped.

#include <cstddef>
#include <string>
#include <string_view>

#include <posefuse/core/error.hpp>

namespace posefuse {

/// What a reader does with a line whose stamp equals the previous line's.
///
/// Real recordings repeat stamps: the TUM RGB-D ground truth of `fr2_desk`
/// repeats one, evo's own EuRoC `V102` test file four. Decreasing stamps are
/// always an error (file:line); only *equal consecutive* stamps fall under
/// this policy.
enum class DuplicateStamps {
  kError,  ///< refuse the file at the repeated line (file:line)
  kFirst,  ///< keep the first pose of a run of equal stamps, drop the others
  kLast,   ///< keep the last pose of a run of equal stamps, drop the others
  /// keep every pose, as evo does: the trajectory then has equal stamps
  /// (it fails `Trajectory::validate()`), and `associate(..., kKeep)` pairs
  /// each repeated stamp of the shorter trajectory with its nearest partner
  /// in the longer one (of a longer trajectory's run, the first pose is used)
  kKeep,
};

/// Parses "error", "first", "last" or "keep".
/// @throws posefuse::invalid_argument for any other text
template <class Lazy = void>
[[nodiscard]] DuplicateStamps parse_duplicate_stamps(std::string_view name) {
  if (name == "error") return DuplicateStamps::kError;
  if (name == "first") return DuplicateStamps::kFirst;
  if (name == "last") return DuplicateStamps::kLast;
  if (name == "keep") return DuplicateStamps::kKeep;
  throw invalid_argument("unknown duplicate-stamp policy '" + std::string(name) +
                         "' (expected first, last, keep or error)");
}

/// The name `parse_duplicate_stamps` accepts for `policy`.
[[nodiscard]] constexpr std::string_view to_string(DuplicateStamps policy) noexcept {
  switch (policy) {
    case DuplicateStamps::kError: return "error";
    case DuplicateStamps::kFirst: return "first";
    case DuplicateStamps::kLast: return "last";
    case DuplicateStamps::kKeep: return "keep";
  }
  return "?";
}

/// How strictly the KITTI and TUM readers check what they read.
///
/// Real files are written with 6 to 9 significant digits and some come from
/// odometry that composes poses in single precision, so their rotations are
/// only nearly orthonormal. On KITTI 06, the largest
/// \f$ \max_{ij} |(R^\top R - I)_{ij}| \f$ is 1.7e-7 (ground truth), 5.0e-7
/// (ORB-SLAM2 stereo) and 4.1e-4 (CVO odometry). Accepted rotations are
/// re-orthonormalised (nearest rotation in the Frobenius norm), accepted
/// quaternions are normalised.
struct ReadOptions {
  /// Largest accepted \f$ \max_{ij} |(R^\top R - I)_{ij}| \f$ of a KITTI rotation.
  double rotation_tolerance = 1e-3;
  /// Largest accepted \f$ |\lVert q \rVert - 1| \f$ of a TUM quaternion.
  double quaternion_norm_tolerance = 1e-3;
  /// Equal consecutive stamps (TUM files, KITTI `times.txt`). The library's
  /// default refuses them so that nothing is dropped silently; programs
  /// that accept them (`evaluate_trajectory --duplicates first`) report
  /// what was dropped through ReadReport. A refused repeat is thrown as
  /// repeated_stamp_error.
  DuplicateStamps duplicates = DuplicateStamps::kError;
};

/// A repeated stamp refused under DuplicateStamps::kError: an io_error
/// (file:line) of its own type, so that a program that offers another
/// policy can say so (`evaluate_trajectory --duplicates`) while the others
/// print the reader's message alone.
class repeated_stamp_error : public io_error {
 public:
  using io_error::io_error;
};

/// What a reader dropped (or, under DuplicateStamps::kKeep, kept) under
/// `ReadOptions::duplicates`.
struct ReadReport {
  std::size_t duplicates_dropped = 0;     ///< poses dropped for a repeated stamp
  std::size_t duplicates_kept = 0;        ///< poses kept with a repeated stamp (kKeep)
  std::size_t first_duplicate_line = 0;   ///< 1-based line of the first repeat (0: none)
};

}  // namespace posefuse

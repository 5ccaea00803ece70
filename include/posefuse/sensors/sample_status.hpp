#pragma once
/// @file
/// What a sensor stage did with one sample.

#include <cstdint>

namespace posefuse {

/// Outcome of one sample in a sensor stage. Stages never drop a sample
/// silently: a sample they cannot use leaves their state untouched and is
/// reported in the `status` field of their output.
enum class SampleStatus : std::uint8_t {
  kOk,         ///< the sample was used
  kFirst,      ///< first sample: the stage initialised itself (no increment yet)
  kNonFinite,  ///< a value was NaN or infinite; the previous estimate is held
};

}  // namespace posefuse

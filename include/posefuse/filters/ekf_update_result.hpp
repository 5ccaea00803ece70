#pragma once
/// @file
/// What a Kalman update returns, UpdateResult (status, innovation, its
/// covariance S and the NIS), what a whole step returns, EkfStepResult, and
/// the gates an update accepts, InnovationGate: a NIS threshold or a
/// functor of the innovation.

#include <limits>
#include <posefuse/core/concepts.hpp>
#include <cstddef>
#include <posefuse/core/status.hpp>
#include <tuple>
#include <type_traits>

namespace posefuse {

/// What an update did, with its innovation statistics (valid whenever S could
/// be formed, also for gated updates).
template <MeasurementModel H>
struct UpdateResult {
  using Innovation = TangentOf<typename H::Measurement>;
  using InnovationCovariance = CovarianceOf<typename H::Measurement>;

  FilterStatus status = FilterStatus::kNonFinite;
  Innovation innovation = Innovation::Zero();  ///< \f$ r = z \boxminus h(\bar x) \f$
  InnovationCovariance S = InnovationCovariance::Zero();  ///< \f$ H P H^\top + R \f$
  ScalarOf<typename H::State> nis = std::numeric_limits<ScalarOf<typename H::State>>::quiet_NaN();

  /// True when the update was applied.
  [[nodiscard]] explicit operator bool() const noexcept { return status == FilterStatus::kApplied; }
};

/// What BasicEkf::step() did: the prediction's status and, in order, the
/// UpdateResult of each measurement model's update.
template <MeasurementModel... Sensors>
struct EkfStepResult {
  FilterStatus predict = FilterStatus::kNonFinite;  ///< as predict() would return
  std::tuple<UpdateResult<Sensors>...> updates;     ///< as update<I>() would return

  /// The I-th update's result.
  template <std::size_t I>
  [[nodiscard]] const auto& update() const noexcept {
    return std::get<I>(updates);
  }
  /// True when the prediction and every update were applied.
  [[nodiscard]] explicit operator bool() const noexcept {
    return predict == FilterStatus::kApplied &&
           std::apply([](const auto&... r) { return (static_cast<bool>(r) && ...); }, updates);
  }
};

/// A gate for updates with measurement model H: a NIS threshold (any
/// arithmetic type), or a functor `bool(const Innovation& r, const
/// InnovationCovariance& S)` or `bool(r, S, Scalar nis)` returning true to
/// accept the measurement.
template <class G, class H>
concept InnovationGate =
    MeasurementModel<H> &&
    ((std::is_arithmetic_v<G> && !std::is_same_v<G, bool>) ||
     std::is_invocable_r_v<bool, const G&, const typename UpdateResult<H>::Innovation&,
                           const typename UpdateResult<H>::InnovationCovariance&> ||
     std::is_invocable_r_v<bool, const G&, const typename UpdateResult<H>::Innovation&,
                           const typename UpdateResult<H>::InnovationCovariance&,
                           ScalarOf<typename H::State>>);

}  // namespace posefuse

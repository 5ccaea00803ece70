#pragma once
/// @file
/// Post-processing correction of a SLAM trajectory on the road plane (seed 000),
/// as compile-time pipelines, plus the models that go beyond it.
///
/// Seed 000's corrector is the pipeline
///
///     ProjectToPlane  ->  DisplacementControl  ->  DisplacementEkf
///     StampedPose        StampedPoint              CorrectorStep -> CorrectedPoint
///
/// with state \f$ \mu = [x, y] \f$, control \f$ u_t = z_t - z_{t-1} \f$ (the SLAM's
/// frame-to-frame displacement), measurement \f$ z_t \f$ (the SLAM position) and
/// \f$ G = H = I \f$. As docs/reproductions.md shows, the error \f$ e_t = \mu_t - z_t \f$ then obeys
/// \f$ e_t = (I - K_t) e_{t-1} \f$, so a filter started at \f$ z_0 \f$ returns its
/// input exactly, for every R and Q. `make_seed000_corrector` reproduces that.
///
/// `make_constant_velocity_corrector` replaces the displacement control by a
/// constant-velocity model of its own (models/constant_velocity.hpp); its
/// forward run can be smoothed offline with rts_smooth.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <posefuse/core/pipeline.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/noise_tuning.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/core/plane.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/position.hpp>
#include <vector>

namespace posefuse {

/// A timestamped 3-D pose \f$ T_{world,body} \f$; t in seconds.
struct StampedPose {
  double t = 0;
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
};

/// A timestamped road-plane position (s, m).
struct StampedPoint {
  double t = 0;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
};

/// Input of seed 000's filter for one frame: control and measurement.
struct CorrectorStep {
  double t = 0;
  double dt = 0;                                   ///< s since the previous frame; 0 at the first
  bool first = true;                               ///< the first frame initialises the filter
  Eigen::Vector2d u = Eigen::Vector2d::Zero();     ///< \f$ z_t - z_{t-1} \f$ (m)
  Eigen::Vector2d z = Eigen::Vector2d::Zero();     ///< SLAM position (m)
};

/// A corrected road-plane position with its covariance and the status of the
/// frame's step: the prediction's status when it was not applied (then no
/// update was tried and `p`, `P` are the previous frame's belief), else the
/// update's (a rejected update leaves the prediction in place).
struct CorrectedPoint {
  double t = 0;
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  Eigen::Matrix2d P = Eigen::Matrix2d::Identity();
  FilterStatus status = FilterStatus::kApplied;
  double nis = 0;
  /// The frame's innovation log-likelihood term
  /// \f$ -\tfrac12 (\nu^\top S^{-1} \nu + \log\det S) \f$ (filters/noise_tuning.hpp);
  /// 0 when no update was tried (the first frame, a prediction not applied).
  double log_likelihood = 0;
};

/// Stage: pose -> road-plane position (drops height, roll and pitch).
struct ProjectToPlane {
  using Input = StampedPose;
  using Output = StampedPoint;
  Plane plane = Plane::kXZ;
  Output operator()(const Input& in) const {
    return {in.t, project_to_plane(in.T_world_body, plane)};
  }
};

/// Stage: position stream -> seed 000's (control, measurement) pairs,
/// \f$ u_t = z_t - z_{t-1} \f$.
class DisplacementControl {
 public:
  using Input = StampedPoint;
  using Output = CorrectorStep;
  Output operator()(const Input& in) {
    CorrectorStep s;
    s.t = in.t;
    s.z = in.p;
    if (previous_) {
      s.first = false;
      s.dt = in.t - previous_->t;
      s.u = in.p - previous_->p;
    }
    previous_ = in;
    return s;
  }
  void reset() { previous_.reset(); }

 private:
  std::optional<StampedPoint> previous_;
};

/// Seed 000's EKF: PlanarDisplacement motion, PositionFix measurement.
using Seed000Ekf = Ekf<PlanarDisplacement<double>, PositionFix<2>>;

/// Stage: seed 000's EKF step (predict with u, update with z).
class DisplacementEkf {
 public:
  using Input = CorrectorStep;
  using Output = CorrectedPoint;

  /// @param[in] R  process noise (m^2 per frame), the seed's R
  /// @param[in] Q  measurement noise (m^2), the seed's Q
  /// @param[in] P0 initial covariance (m^2); the filter starts at the first z
  /// @throws posefuse::invalid_argument for non-PSD R / P0 or non-PD Q
  DisplacementEkf(const Eigen::Matrix2d& R, const Eigen::Matrix2d& Q, const Eigen::Matrix2d& P0)
      : ekf_(PlanarDisplacement<double>(R), PositionFix<2>(Q)), P0_(P0) {
    require_covariance(P0_, "DisplacementEkf: initial covariance P0");
  }

  Output operator()(const Input& in) {
    CorrectedPoint out;
    out.t = in.t;
    if (in.first) {
      ekf_.reset(in.z, P0_);
    } else {
      out.status = ekf_.predict(in.u, in.dt);
      if (out.status == FilterStatus::kApplied) {
        const auto r = ekf_.update<0>(in.z);
        out.status = r.status;
        out.nis = r.nis;
        out.log_likelihood = innovation_log_likelihood(r);
      }
    }
    out.p = ekf_.state();
    out.P = ekf_.covariance();
    return out;
  }
  [[nodiscard]] const Seed000Ekf& filter() const noexcept { return ekf_; }

 private:
  Seed000Ekf ekf_;
  Eigen::Matrix2d P0_;
};

/// Seed 000's corrector as one compile-time pipeline:
/// ProjectToPlane -> DisplacementControl -> DisplacementEkf.
/// @param[in] R process noise diag (m^2), seed naming
/// @param[in] Q measurement noise diag (m^2), seed naming
/// @param[in] P0 initial covariance (m^2)
[[nodiscard]] inline auto make_seed000_corrector(Plane plane, const Eigen::Matrix2d& R,
                                                 const Eigen::Matrix2d& Q,
                                                 const Eigen::Matrix2d& P0) {
  return make_pipeline(ProjectToPlane{plane}, DisplacementControl{}, DisplacementEkf(R, Q, P0));
}

/// Constant-velocity EKF with position fixes, as used by the CV corrector.
using ConstantVelocityEkf = Ekf<ConstantVelocity2<double>, PositionFix<4>>;

/// Stage: constant-velocity EKF on road-plane positions. Keeps a record of
/// the run for RTS smoothing (`history()`). A frame whose prediction is not
/// applied (e.g. its time goes backwards: kInvalidInput) is reported in the
/// output's status and recorded as "no change" (F = I), and the next
/// prediction starts from the time of the belief, not of that frame.
class ConstantVelocityFilter {
 public:
  using Input = StampedPoint;
  using Output = CorrectedPoint;

  /// @param[in] q     acceleration noise density (m^2/s^3)
  /// @param[in] sigma position-fix standard deviation (m)
  /// @param[in] gate  NIS gate on the 2-D innovation (+inf: none)
  /// @param[in] record keep the run for rts_smooth
  ConstantVelocityFilter(double q, double sigma,
                         double gate = std::numeric_limits<double>::infinity(),
                         bool record = true)
      : ekf_(ConstantVelocity2<double>(q), PositionFix<4>::isotropic(sigma)),
        sigma_(sigma),
        record_(record) {
    if (gate != std::numeric_limits<double>::infinity()) ekf_.set_gate<0>(gate);
  }

  Output operator()(const Input& in) {
    CorrectedPoint out;
    out.t = in.t;
    SmootherStep<Eigen::Vector4d> rec;
    if (!started_) {
      // Position from the first fix; velocity unknown (10 m/s standard deviation).
      Eigen::Vector4d x0;
      x0 << in.p, 0, 0;
      Eigen::Vector4d var;
      var << sigma_ * sigma_, sigma_ * sigma_, 100, 100;
      ekf_.reset(x0, var.asDiagonal().toDenseMatrix());
      started_ = true;
      t_prev_ = in.t;
      rec.predicted_mean = x0;
      rec.predicted_cov = ekf_.covariance();
    } else {
      out.status = ekf_.predict(NoControl{}, in.t - t_prev_);
      rec.predicted_mean = ekf_.state();
      rec.predicted_cov = ekf_.covariance();
      if (out.status == FilterStatus::kApplied) {
        rec.F = ekf_.last_jacobian();
        t_prev_ = in.t;
        const auto r = ekf_.update<0>(in.p);
        out.status = r.status;
        out.nis = r.nis;
        out.log_likelihood = innovation_log_likelihood(r);
      } else {
        // Not applied: the belief is still the previous one, at the previous
        // time. Record that (F = I, predicted = filtered = unchanged) rather
        // than the Jacobian of an earlier prediction.
        rec.F.setIdentity();
      }
    }
    rec.filtered_mean = ekf_.state();
    rec.filtered_cov = ekf_.covariance();
    if (record_) history_.push_back(rec);
    out.p = ekf_.state().head<2>();
    out.P = ekf_.covariance().topLeftCorner<2, 2>();
    return out;
  }

  /// The recorded forward run, for rts_smooth.
  [[nodiscard]] const std::vector<SmootherStep<Eigen::Vector4d>>& history() const noexcept {
    return history_;
  }

 private:
  ConstantVelocityEkf ekf_;
  double sigma_;
  bool record_;
  bool started_ = false;
  double t_prev_ = 0;  ///< time of the current belief (s)
  std::vector<SmootherStep<Eigen::Vector4d>> history_;
};

/// ProjectToPlane -> ConstantVelocityFilter.
[[nodiscard]] inline auto make_constant_velocity_corrector(Plane plane, double q, double sigma,
                                                           double gate = std::numeric_limits<
                                                               double>::infinity()) {
  return make_pipeline(ProjectToPlane{plane}, ConstantVelocityFilter(q, sigma, gate));
}

}  // namespace posefuse

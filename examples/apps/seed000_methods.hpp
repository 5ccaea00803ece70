#pragma once
/// @file
/// The correctors of orb_trajectory_correction run on one estimate's
/// road-plane positions, each with two noise levels, and the innovation
/// log-likelihood of each run (what `--tune` maximises, filters/noise_tuning.hpp).
///
/// Families and what their two levels mean:
///
/// | family | filter | process | measurement |
/// |---|---|---|---|
/// | seed000 | seed 000's EKF, u = the SLAM's own displacement | R (m^2/frame) | Q (m^2) |
/// | control | seed 000's EKF, u = the displacement of an independent trajectory | R (m^2/frame) | Q (m^2) |
/// | cv (+rts) | constant velocity, position fixes | q (m^2/s^3) | sigma^2 (m^2) |
/// | ctrv (+rts) | constant turn rate and velocity (models/ctrv.hpp), position fixes | q_a (m^2/s^3) | sigma^2 (m^2) |
///
/// CTRV has two process densities; one level sets both: the acceleration
/// density q_a and the yaw-acceleration density q_a / (10 m/s)^2 (rad^2/s^5),
/// i.e. a yaw acceleration of 0.1 rad/s^2 counts as much as a linear one of
/// 1 m/s^2. Its filter starts at the first position with heading and speed
/// from the first displacement (variances 1 rad^2, 100 m^2/s^2; yaw rate 0
/// with 0.25 rad^2/s^2).
///
/// Nothing here sees ground truth: a run takes the estimate's positions and
/// stamps (and the control's positions), so a noise level chosen from these
/// runs cannot depend on the reference.

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <apps/cli.hpp>
#include <apps/trajectory_correction.hpp>
#include <posefuse/filters/noise_tuning.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/models/ctrv.hpp>

namespace posefuse::apps::seed000 {

/// What the correctors see of one estimate (never the ground truth).
struct PlanarInput {
  std::string source;                    ///< the estimate file, for messages
  std::vector<double> t;                 ///< stamps (s)
  std::vector<Eigen::Vector2d> z;        ///< SLAM road-plane positions (m)
  std::vector<Eigen::Vector2d> control;  ///< the control trajectory at the same frames; empty: none
};

/// One corrector's output.
struct MethodRun {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> variance;  ///< mean position variance, trace(P)/2 (m^2)
  double log_likelihood = 0;     ///< sum of the innovation terms
};

/// The families (see the file comment).
enum class Family { kSeed, kControl, kCv, kCtrv };

/// The name of a family's method(s) in the table.
[[nodiscard]] inline const char* family_name(Family f) {
  switch (f) {
    case Family::kSeed: return "seed000";
    case Family::kControl: return "control";
    case Family::kCv: return "cv";
    case Family::kCtrv: return "ctrv";
  }
  return "?";
}

/// Units of a family's (process, measurement) levels, for printing.
[[nodiscard]] inline std::pair<const char*, const char*> family_units(Family f) {
  if (f == Family::kCv) return {"q [m^2/s^3]", "sigma^2 [m^2]"};
  if (f == Family::kCtrv) return {"q_a [m^2/s^3]", "sigma^2 [m^2]"};
  return {"R [m^2/frame]", "Q [m^2]"};
}

/// The range `--tune` searches and `--sweep` covers, per family.
struct FamilyRanges {
  NoiseRange process, measurement;
};
[[nodiscard]] inline FamilyRanges family_ranges(Family f) {
  if (f == Family::kCv || f == Family::kCtrv) return {{1e-4, 1e3}, {1e-6, 1e2}};
  return {{1e-6, 1e2}, {1e-6, 1e2}};
}

/// Throws a data error naming the frame when a step was not applied.
inline void require_step(const CorrectedPoint& c, const PlanarInput& in, const char* method,
                         std::size_t k) {
  if (c.status != FilterStatus::kApplied)
    throw data_error(in.source + ": frame " + std::to_string(k) + " (t = " + shortest(c.t) +
                     " s): the " + method + " filter step was not applied (" + to_string(c.status) +
                     ")");
}

/// Seed 000's EKF on `in.z` with u_t = d_t - d_{t-1} of `drive` (the SLAM's
/// own positions for seed000, the control for control).
/// @throws data_error when a step is not applied
inline MethodRun run_displacement(const PlanarInput& in, const std::vector<Eigen::Vector2d>& drive,
                                  const Eigen::Matrix2d& R, const Eigen::Matrix2d& Q,
                                  const char* method) {
  DisplacementEkf ekf(R, Q, Eigen::Matrix2d::Identity());
  MethodRun run;
  run.points.reserve(in.z.size());
  run.variance.reserve(in.z.size());
  for (std::size_t k = 0; k < in.z.size(); ++k) {
    CorrectorStep s;
    s.t = in.t[k];
    s.z = in.z[k];
    if (k > 0) {
      s.first = false;
      s.dt = in.t[k] - in.t[k - 1];
      s.u = drive[k] - drive[k - 1];
    }
    const CorrectedPoint c = ekf(s);
    require_step(c, in, method, k);
    run.points.push_back(c.p);
    run.variance.push_back(0.5 * c.P.trace());
    run.log_likelihood += c.log_likelihood;
  }
  return run;
}

/// Constant-velocity filter and its RTS smoothing (`smoothed` when asked).
/// @throws data_error when a step is not applied or the smoother fails
inline MethodRun run_cv(const PlanarInput& in, double q, double sigma2,
                        std::optional<MethodRun>* smoothed = nullptr) {
  ConstantVelocityFilter filter(q, std::sqrt(sigma2), std::numeric_limits<double>::infinity(),
                                smoothed != nullptr);
  MethodRun run;
  for (std::size_t k = 0; k < in.z.size(); ++k) {
    const CorrectedPoint c = filter(StampedPoint{in.t[k], in.z[k]});
    require_step(c, in, "cv", k);
    run.points.push_back(c.p);
    run.variance.push_back(0.5 * c.P.trace());
    run.log_likelihood += c.log_likelihood;
  }
  if (smoothed != nullptr) {
    MethodRun s;
    s.log_likelihood = run.log_likelihood;
    try {
      for (const auto& b : rts_smooth(filter.history())) {
        s.points.push_back(b.mean.head<2>());
        s.variance.push_back(0.5 * b.cov.topLeftCorner<2, 2>().trace());
      }
    } catch (const posefuse::invalid_argument& e) {
      throw data_error(in.source + ": cv+rts: " + e.what());
    }
    *smoothed = std::move(s);
  }
  return run;
}

/// The CTRV yaw-acceleration density for an acceleration density `q_a`.
[[nodiscard]] inline double ctrv_yaw_density(double q_a) { return q_a / 100.0; }

/// CTRV filter (see the file comment) and its RTS smoothing when asked.
/// @throws data_error when a step is not applied or the smoother fails
inline MethodRun run_ctrv(const PlanarInput& in, double q_a, double sigma2,
                          std::optional<MethodRun>* smoothed = nullptr) {
  using S = CtrvState<double>;
  Ekf<Ctrv<double>, CtrvPositionFix<double>> ekf(
      Ctrv<double>(q_a, ctrv_yaw_density(q_a)),
      CtrvPositionFix<double>(Eigen::Matrix2d::Identity() * sigma2));
  double heading = 0, speed = 0;
  if (in.z.size() > 1 && in.t[1] > in.t[0]) {
    const Eigen::Vector2d d = in.z[1] - in.z[0];
    heading = std::atan2(d.y(), d.x());
    speed = d.norm() / (in.t[1] - in.t[0]);
  }
  Eigen::Matrix<double, 5, 1> var;
  var << sigma2, sigma2, 1.0, 100.0, 0.25;
  ekf.reset(S(in.z[0].x(), in.z[0].y(), heading, speed, 0.0), var.asDiagonal().toDenseMatrix());
  std::vector<SmootherStep<S>> history;
  MethodRun run;
  const auto record = [&](SmootherStep<S> step) {
    step.filtered_mean = ekf.state();
    step.filtered_cov = ekf.covariance();
    if (smoothed != nullptr) history.push_back(step);
    run.points.push_back(ekf.state().position());
    run.variance.push_back(0.5 * ekf.covariance().topLeftCorner<2, 2>().trace());
  };
  SmootherStep<S> first;
  first.predicted_mean = ekf.state();
  first.predicted_cov = ekf.covariance();
  record(first);
  for (std::size_t k = 1; k < in.z.size(); ++k) {
    CorrectedPoint c;
    c.t = in.t[k];
    c.status = ekf.predict(NoControl{}, in.t[k] - in.t[k - 1]);
    SmootherStep<S> step;
    step.predicted_mean = ekf.state();
    step.predicted_cov = ekf.covariance();
    step.F = ekf.last_jacobian();
    if (c.status == FilterStatus::kApplied) {
      const auto r = ekf.update<0>(in.z[k]);
      c.status = r.status;
      run.log_likelihood += innovation_log_likelihood(r);
    }
    require_step(c, in, "ctrv", k);
    record(step);
  }
  if (smoothed != nullptr) {
    MethodRun s;
    s.log_likelihood = run.log_likelihood;
    try {
      for (const auto& b : rts_smooth(history)) {
        s.points.push_back(b.mean.position());
        s.variance.push_back(0.5 * b.cov.template topLeftCorner<2, 2>().trace());
      }
    } catch (const posefuse::invalid_argument& e) {
      throw data_error(in.source + ": ctrv+rts: " + e.what());
    }
    *smoothed = std::move(s);
  }
  return run;
}

/// A family's forward run with isotropic levels (process, measurement); the
/// smoothed run too when `smoothed` is given and the family has one.
inline MethodRun run_family(const PlanarInput& in, Family f, double process, double measurement,
                            std::optional<MethodRun>* smoothed = nullptr) {
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * process;
  const Eigen::Matrix2d Q = Eigen::Matrix2d::Identity() * measurement;
  switch (f) {
    case Family::kSeed: return run_displacement(in, in.z, R, Q, "seed000");
    case Family::kControl: return run_displacement(in, in.control, R, Q, "control");
    case Family::kCv: return run_cv(in, process, measurement, smoothed);
    case Family::kCtrv: return run_ctrv(in, process, measurement, smoothed);
  }
  return {};
}

/// A family's noise chosen by maximising the innovation log-likelihood of
/// its forward run on `in` (no ground truth enters).
struct TunedNoise {
  Family family = Family::kCv;
  NoiseTuningResult result;
};

/// Tunes `f` on `in` over family_ranges(f). A setting whose run fails counts
/// as -infinity.
/// @throws data_error when no setting of the grid runs
inline TunedNoise tune_family(const PlanarInput& in, Family f) {
  const FamilyRanges r = family_ranges(f);
  const auto objective = [&](double p, double m) {
    try {
      return run_family(in, f, p, m).log_likelihood;
    } catch (const std::exception&) {
      return -std::numeric_limits<double>::infinity();
    }
  };
  try {
    return {f, tune_noise(objective, r.process, r.measurement)};
  } catch (const posefuse::invalid_argument& e) {
    throw data_error(in.source + ": --tune " + family_name(f) + ": " + e.what());
  }
}

}  // namespace posefuse::apps::seed000

// orb_trajectory_correction: seed 000's EKF post-processing of a SLAM
// trajectory on the road plane, with the models that go beyond it.
//
// Scenario (seed 000, docs/reproductions.md): ORB-SLAM ran unchanged; its output
// trajectory is filtered on the road plane and the planar RMSE against ground
// truth is compared before and after (seed 000, Table 1). The correctors:
//
//   seed000   the seed's EKF exactly: x = [x, y], u = SLAM displacement,
//             z = SLAM position, G = H = I, R (process) and Q (measurement).
//             It returns its input (docs/reproductions.md), so its reduction is 0 %.
//   cv        a constant-velocity EKF (own dynamics) on the SLAM positions.
//   cv+rts    the same run smoothed offline (Rauch-Tung-Striebel).
//   ctrv      a constant turn rate and velocity EKF [x, y, heading, v, yaw rate].
//   ctrv+rts  the same run smoothed offline.
//   control   (--control FILE) the seed's EKF with u from a second, independent
//             trajectory, z still the SLAM position.
//
// --tune adds each method with its noise chosen by the innovation likelihood
// of the estimate alone (apps/seed000_methods.hpp; the ground truth only
// scores the result); --sweep prints the RMSE over a grid of noise levels
// (apps/seed000_sweep.hpp) and --sweep-svg draws it. --groundtruth and
// --estimate may be folders of same-named files: one row per sequence and
// method, and a mean row. --format auto reads each file in its own format (a
// TUM monocular estimate against KITTI ground truth, with --align sim3).
//
// With no arguments it runs on a built-in synthetic drive (a KITTI-06-like
// 1.2 km loop with heading drift, scale error and 0.35 m position jitter;
// include/posefuse/sim/kitti_like_drive.hpp) and prints:
//
//   estimate     method    RMSE before [m]  RMSE after [m]  reduction   verdict
//   synthetic    seed000             1.150           1.150     0.00 %   returns its input (docs/reproductions.md)
//   synthetic    cv                  1.150           1.143     0.60 %   no real gain
//   synthetic    cv+rts              1.150           1.049     8.72 %   helps
//   synthetic    ctrv                1.150           1.071     6.84 %   helps
//   synthetic    ctrv+rts            1.150           1.049     8.72 %   helps
//
// KITTI odometry sequence 06 (kitti/06 of the data folder, docs/programs.md),
// figures in docs/reproductions.md:
//
//   orb_trajectory_correction --groundtruth groundtruth.txt --times times.txt
//       --estimate orbslam2_stereo.txt --control cvo_vo.txt --tune
//
// Options: see --help. Exit status 0 ok, 1 bad data (one line on stderr,
// naming file:line where a file is at fault; also a filter step that was not
// applied or a non-finite result), 2 bad usage. --out, --plot and --sweep-svg
// are written only when everything was computed, each through a temporary file.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <apps/seed000_methods.hpp>
#include <apps/seed000_sweep.hpp>
#include <apps/svg.hpp>
#include <apps/trajectory_correction.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>
#include <posefuse/sim/kitti_like_drive.hpp>

namespace {

using namespace posefuse;
namespace fs = std::filesystem;
using apps::seed000::Family;

struct Options {
  std::optional<fs::path> groundtruth, times, control, out, plot, sweep_svg;
  std::vector<fs::path> estimates;
  Format format = Format::kKitti;
  bool auto_format = false;  ///< --format auto: each file's own (io/formats.hpp detect_format)
  Plane plane = Plane::kXZ;
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  Eigen::Matrix2d Q = Eigen::Matrix2d::Identity() * 0.25;
  double cv_q = 1.0;
  double ctrv_q = 1.0;
  double max_time_diff = 0.01;
  Alignment alignment = Alignment::kNone;
  std::string method = "seed000";
  bool json = false, tune = false, sweep = false;
  bool folders = false;  ///< --groundtruth / --estimate are folders of same-named files
};

/// Noise values (variances, acceleration noise) the filters can use: beyond
/// these every filter step fails (a covariance overflows or vanishes), so a
/// value outside is a usage error naming its flag.
constexpr double kMinNoise = 1e-8, kMaxNoise = 1e8;

/// One noise value in [kMinNoise, kMaxNoise].
double parse_noise(std::string_view text) {
  const double v = apps::parse_real(text, apps::Domain::kPositive);
  if (!(v >= kMinNoise && v <= kMaxNoise))
    throw apps::usage_error("expected a number from " + apps::num(kMinNoise) + " to " + apps::num(kMaxNoise) +
                            ", got '" + std::string(text) + "'");
  return v;
}

/// "VAR" or "VAR,VAR": a diagonal covariance, each variance in [kMinNoise, kMaxNoise].
Eigen::Matrix2d parse_diag(std::string_view text) {
  const auto items = apps::split_commas(text, 1, 2, "VAR or VAR,VAR");
  const double a = parse_noise(items[0]);
  const double b = items.size() == 1 ? a : parse_noise(items[1]);
  return Eigen::Vector2d(a, b).asDiagonal();
}

const std::vector<std::string> kMethods{"seed000", "cv", "cv+rts", "ctrv", "ctrv+rts", "control"};
const std::vector<std::string> kTunable{"cv", "cv+rts", "ctrv", "ctrv+rts", "control"};

/// The options, or nothing when --help was printed.
std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  apps::Parser cli(cmd.program,
                   "[--groundtruth REF --estimate EST [--estimate EST2 ...]] [options]",
                   "Filters SLAM trajectories on the road plane (seed 000) and compares the planar "
                   "RMSE\nagainst ground truth before and after. Without files it uses a built-in "
                   "synthetic drive.");
  cli.input({.name = "--groundtruth", .value = "FILE|DIR",
            .help = "reference trajectory; a folder: one same-named file per sequence\n"
                    "of the --estimate folder (00.txt, 05.txt, ...)"},
           o.groundtruth);
  cli.inputs({.name = "--estimate", .value = "FILE|DIR",
             .help = "trajectory to correct (repeat for several), or one folder"},
            o.estimates);
  cli.input({.name = "--control", .value = "FILE|DIR",
            .help = "independent trajectory whose planar displacement is the control u\n"
                    "of method 'control' (associated with the estimate by timestamp)"},
           o.control);
  cli.custom({.name = "--format", .value = "kitti|tum|auto",
              .help = "format of all files; auto: each file's own (e.g. a TUM monocular\n"
                      "estimate against KITTI ground truth, associated by timestamp)",
              .default_text = "kitti"},
             [&](std::string_view v) {
               if (v == "auto") {
                 o.auto_format = true;
                 return;
               }
               o.format = parse_format(v);
               if (o.format == Format::kEuroc)
                 throw apps::usage_error("expected kitti or tum (EuRoC files: evaluate_trajectory)");
             });
  cli.input({.name = "--times", .value = "FILE|DIR",
            .help = "KITTI times.txt for all KITTI files (a folder: one per sequence)"},
           o.times);
  cli.custom({.name = "--plane", .value = "xz|xy|yz", .help = "road plane",
              .default_text = "xz: KITTI camera frame"},
             [&](std::string_view v) { o.plane = parse_plane(v); });
  cli.custom({.name = "--R", .value = "VAR[,VAR]", .help = "seed's process noise R = diag; 1e-08 to 1e+08",
              .default_text = "0.01 m^2/frame"},
             [&](std::string_view v) { o.R = parse_diag(v); });
  cli.custom({.name = "--Q", .value = "VAR[,VAR]", .help = "seed's measurement noise Q = diag; 1e-08 to 1e+08",
              .default_text = "0.25 m^2"},
             [&](std::string_view v) { o.Q = parse_diag(v); });
  cli.real_in({.name = "--cv-q", .value = "Q", .help = "constant-velocity acceleration noise",
               .unit = "m^2/s^3"},
              o.cv_q, kMinNoise, kMaxNoise);
  cli.real_in({.name = "--ctrv-q", .value = "Q",
               .help = "CTRV acceleration noise (yaw acceleration: Q / (10 m/s)^2)", .unit = "m^2/s^3"},
              o.ctrv_q, kMinNoise, kMaxNoise);
  cli.custom({.name = "--align", .value = "none|se3|sim3",
              .help = "align each estimate to the ground truth first (sim3: monocular);\n"
                      "a control is aligned to its estimate the same way",
              .default_text = "none"},
             [&](std::string_view v) { o.alignment = parse_alignment(v); });
  cli.real({.name = "--max-time-diff", .value = "S",
            .help = "TUM / control timestamp association tolerance", .unit = "s"},
           o.max_time_diff, apps::Domain::kNonNegative);
  cli.flag({.name = "--tune",
            .help = "add each method with noise chosen by its innovation likelihood\n"
                    "on the estimate alone; with --estimate and no --groundtruth: only that"},
           o.tune);
  cli.flag({.name = "--sweep",
            .help = "print the RMSE over a decade grid of process x measurement noise\n"
                    "for each method (one estimate)"},
           o.sweep);
  cli.output({.name = "--sweep-svg", .value = "FILE.svg", .help = "the --sweep grid as heat maps"},
           o.sweep_svg);
  cli.custom({.name = "--method", .value = "NAME",
              .help = "corrector whose output --out writes: seed000, cv, cv+rts, ctrv,\n"
                      "ctrv+rts, control; with --tune also <method>/tuned (not seed000)",
              .default_text = "seed000"},
             [&](std::string_view v) {
               std::string name(v);
               const bool tuned = name.size() > 6 && name.ends_with("/tuned");
               const std::string base = tuned ? name.substr(0, name.size() - 6) : name;
               const auto& list = tuned ? kTunable : kMethods;
               if (std::find(list.begin(), list.end(), base) == list.end())
                 throw apps::usage_error("expected seed000, cv, cv+rts, ctrv, ctrv+rts, control "
                                         "or one of those but seed000 followed by /tuned, got '" +
                                         name + "'");
               o.method = name;
             });
  cli.output({.name = "--out", .value = "PATH",
            .help = "write the corrected trajectory (input format); with several\n"
                    "estimates PATH is a folder of <estimate>_<method> files"},
           o.out);
  cli.output({.name = "--plot", .value = "FILE.svg",
            .help = "paths of the first estimate (truth, raw, corrected) and covariance\n"
                    "over time (seed 000 Fig. 8)"},
           o.plot);
  cli.flag({.name = "--json", .help = "print the results as JSON instead of a table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (one line on stderr, file:line where a file is at "
               "fault),\n2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;

  const bool tune_only = o.tune && !o.groundtruth && !o.estimates.empty();
  if (o.groundtruth.has_value() != !o.estimates.empty() && !tune_only)
    throw apps::usage_error("give --groundtruth and at least one --estimate, or neither (synthetic data)");
  if (o.times && o.format == Format::kTum)
    throw apps::usage_error("--times only applies to KITTI files");
  if (o.control && o.estimates.empty())
    throw apps::usage_error("--control needs --estimate (the built-in drive has no control)");
  if (cli.given("--method") && !o.out) throw apps::usage_error("--method chooses what --out writes; give --out");
  if (o.method.ends_with("/tuned") && !o.tune) throw apps::usage_error("--method " + o.method + " needs --tune");
  if (o.method.starts_with("control") && !o.control)
    throw apps::usage_error("--method " + o.method + " needs --control");
  if (o.sweep_svg && !o.sweep) throw apps::usage_error("--sweep-svg draws the --sweep grid; give --sweep");
  if (tune_only && o.alignment != Alignment::kNone && !o.control)
    throw apps::usage_error("--align aligns to the ground truth (or a --control to its estimate); without "
                            "--groundtruth and --control it does nothing");
  if (tune_only && (o.out || o.plot || o.sweep))
    throw apps::usage_error("without --groundtruth, --tune only chooses noise: --out, --plot and "
                            "--sweep need --groundtruth");

  // Folder mode: --groundtruth DIR and one --estimate DIR (or --estimate DIR alone with --tune).
  const auto is_dir = [](const fs::path& p) { std::error_code ec; return fs::is_directory(p, ec); };
  const bool est_dir = o.estimates.size() == 1 && is_dir(o.estimates.front());
  o.folders = (o.groundtruth && is_dir(*o.groundtruth)) || est_dir;
  if (o.folders) {
    if (o.estimates.size() != 1 || !est_dir || (o.groundtruth && !is_dir(*o.groundtruth)))
      throw apps::usage_error("folder mode needs --groundtruth DIR and one --estimate DIR of same-named files");
    if (o.control && !is_dir(*o.control))
      throw apps::usage_error("with folders, --control is a folder of same-named files too");
    if (o.times && !is_dir(*o.times))
      throw apps::usage_error("with folders, --times is a folder of same-named times files");
    if (o.sweep) throw apps::usage_error("--sweep studies one estimate, not a folder");
  } else {
    if (o.control && is_dir(*o.control))
      throw apps::usage_error("--control is a folder but --estimate is not");
    if (o.sweep && o.estimates.size() > 1) throw apps::usage_error("--sweep studies one estimate; give one --estimate");
  }
  if (o.out && o.estimates.size() > 1) {
    std::set<std::string> names;
    for (const auto& e : o.estimates)
      if (!names.insert(e.stem().string()).second)
        throw apps::usage_error("two estimates are named '" + e.stem().string() +
                                "'; --out would write both to one file");
  }
  return o;
}

/// One corrector's output on one estimate.
struct MethodResult {
  std::string name;
  std::vector<Eigen::Vector2d> points;
  std::vector<double> variance;  ///< mean position variance, trace(P)/2 (m^2)
  double rmse = 0;
};

struct EstimateResult {
  std::string name;        ///< the estimate file's stem ("synthetic" for the built-in drive)
  std::string source;      ///< the estimate file, for error messages
  bool has_truth = true;   ///< false in the tune-only mode
  Trajectory groundtruth;  ///< associated with the estimate
  Trajectory estimate;     ///< aligned as requested
  std::vector<Eigen::Vector2d> truth_xy, raw_xy;
  apps::seed000::PlanarInput input;  ///< what the filters see
  double rmse_before = 0;
  std::vector<MethodResult> methods;
  std::vector<apps::seed000::TunedNoise> tuned;
  Format format = Format::kKitti;  ///< the estimate file's, for --out
};

/// Throws a data error when `v` is not finite: no inf or nan reaches the output.
void require_finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw apps::data_error(what + " is not finite (" + apps::num(v) + ")");
}

void require_finite(const std::vector<Eigen::Vector2d>& points, const std::string& what) {
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!points[k].allFinite())
      throw apps::data_error(what + " is not finite at frame " + std::to_string(k));
}

/// `base` with its road-plane coordinates replaced by `points` (height and
/// attitude kept).
Trajectory with_plane_points(const Trajectory& base, const std::vector<Eigen::Vector2d>& points,
                             Plane plane) {
  Trajectory out = base;
  for (std::size_t k = 0; k < out.size(); ++k) {
    Eigen::Vector3d t = out.poses[k].translation();
    const Eigen::Vector2d& p = points[k];
    switch (plane) {
      case Plane::kXZ: t.x() = p.x(); t.z() = p.y(); break;
      case Plane::kXY: t.x() = p.x(); t.y() = p.y(); break;
      case Plane::kYZ: t.y() = p.x(); t.z() = p.y(); break;
    }
    out.poses[k].translation() = t;
  }
  out.validate();
  return out;
}

/// "<first> to <last> s" of a trajectory's stamps (exact), or "no poses".
std::string span_of(const Trajectory& t) {
  if (t.size() == 0) return "no poses";
  return posefuse::detail::traj_io::format_number(t.t_s.front()) + " to " +
         posefuse::detail::traj_io::format_number(t.t_s.back()) + " s";
}

/// The frames of `est` that also have a control pose (by timestamp), with
/// `gt` (same frames as `est`, may be empty) reduced alike.
/// @throws data_error naming the control file when fewer than 2 frames match
Trajectory associate_control(const std::string& est_source, Trajectory& est, Trajectory* gt,
                             const Trajectory& control, const std::string& control_source,
                             double max_time_diff) {
  Association a;
  try {
    a = associate(std::span<const double>(est.t_s), std::span<const double>(control.t_s), max_time_diff);
  } catch (const posefuse::invalid_argument&) {
    a = {};  // no pair: reported below with the time spans
  }
  // Keep pairs where both indices advance (the nearest-stamp rule can repeat one).
  std::vector<std::size_t> ei, ci;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (ei.empty() || (a.ref_ids[k] > ei.back() && a.est_ids[k] > ci.back()))
      ei.push_back(a.ref_ids[k]), ci.push_back(a.est_ids[k]);
  if (ei.size() < 2)
    throw apps::data_error(control_source + ": only " + std::to_string(ei.size()) +
                           " frame(s) associate with " + est_source + " within --max-time-diff " +
                           apps::num(max_time_diff) + " s (the control spans " + span_of(control) +
                           ", the estimate " + span_of(est) + "); the control needs at least 2");
  est = select(est, ei);
  if (gt != nullptr) *gt = select(*gt, ei);
  return select(control, ci);
}

/// `traj` aligned to `ref` as --align asks; a pair that cannot be aligned
/// (too few poses, all on one point or line) is a data error naming `source`.
AlignedTrajectory aligned_to(const Trajectory& traj, const Trajectory& ref, Alignment alignment,
                             const std::string& source, const std::string& ref_source) {
  try {
    return align_trajectory(traj, ref, alignment);
  } catch (const posefuse::invalid_argument&) {
    throw apps::data_error(source + ": --align " + std::string(to_string(alignment)) + " cannot align its " +
                           std::to_string(traj.size()) + " poses to " + ref_source +
                           " (it needs at least 3 that do not all lie on one point or line); try --align none");
  }
}

/// @param by_stamps associate the estimate with the ground truth by
///        timestamp (a TUM file is involved), else pose by pose (KITTI)
EstimateResult correct(std::string name, std::string source, const Trajectory* gt_full,
                       const Trajectory& est_full, const Trajectory* control_full,
                       const std::string& control_source, bool by_stamps, const Options& o) {
  EstimateResult r;
  r.name = std::move(name);
  r.source = std::move(source);
  r.has_truth = gt_full != nullptr;
  if (!r.has_truth) {
    r.estimate = est_full;
  } else if (by_stamps) {
    AssociatedTrajectories a;
    try {
      a = associate(*gt_full, est_full, o.max_time_diff);
    } catch (const posefuse::invalid_argument&) {
      throw apps::data_error(r.source + ": no pose within --max-time-diff " + apps::num(o.max_time_diff) +
                             " s of a ground-truth pose (the ground truth spans " + span_of(*gt_full) +
                             ", the estimate " + span_of(est_full) + ")");
    }
    r.groundtruth = a.ref;
    r.estimate = a.est;
  } else {
    if (gt_full->size() != est_full.size())
      throw apps::data_error(r.source + " has " + std::to_string(est_full.size()) +
                             " poses but the ground truth has " + std::to_string(gt_full->size()));
    r.groundtruth = *gt_full;
    r.estimate = est_full;
  }
  if (r.estimate.size() == 0) throw apps::data_error(r.source + " has no poses");
  Trajectory control;
  if (control_full != nullptr)
    control = associate_control(r.source, r.estimate, r.has_truth ? &r.groundtruth : nullptr,
                                *control_full, control_source, o.max_time_diff);
  // The estimate in its own frame, with the control aligned to it: what
  // --tune sees (the alignment to the ground truth would carry the truth's
  // scale and orientation into the chosen noise).
  const Trajectory own = r.estimate;
  Trajectory own_control = control;
  if (control_full != nullptr && o.alignment != Alignment::kNone)
    own_control = aligned_to(control, own, o.alignment, control_source, r.source).trajectory;
  AlignmentResult to_truth;
  if (r.has_truth) {
    AlignedTrajectory aligned = aligned_to(r.estimate, r.groundtruth, o.alignment, r.source, "the ground truth");
    r.estimate = std::move(aligned.trajectory);
    to_truth = aligned.transform;
  }
  if (control_full != nullptr && o.alignment != Alignment::kNone)
    control = aligned_to(control, r.estimate, o.alignment, control_source, r.source).trajectory;
  r.raw_xy = project_to_plane(r.estimate, o.plane);
  require_finite(r.raw_xy, r.source + ": the estimate on the road plane" +
                               std::string(o.alignment == Alignment::kNone ? "" : " after alignment"));
  r.input.source = r.source;
  r.input.t = r.estimate.t_s;
  r.input.z = r.raw_xy;
  if (control_full != nullptr) {
    r.input.control = project_to_plane(control, o.plane);
    require_finite(r.input.control, control_source + ": the control on the road plane");
  }

  apps::seed000::PlanarInput own_input = r.input;
  if (o.alignment != Alignment::kNone) {
    own_input.t = own.t_s;
    own_input.z = project_to_plane(own, o.plane);
    if (control_full != nullptr) own_input.control = project_to_plane(own_control, o.plane);
  }

  namespace s0 = apps::seed000;
  std::vector<MethodResult> runs;
  const auto add = [&](std::string method, s0::MethodRun run) {
    runs.push_back({std::move(method), std::move(run.points), std::move(run.variance), 0});
  };
  const double sigma2 = 0.5 * o.Q.trace();
  if (r.has_truth) {
    add("seed000", s0::run_displacement(r.input, r.input.z, o.R, o.Q, "seed000"));
    std::optional<s0::MethodRun> smoothed;
    add("cv", s0::run_cv(r.input, o.cv_q, sigma2, &smoothed));
    add("cv+rts", std::move(*smoothed));
    add("ctrv", s0::run_ctrv(r.input, o.ctrv_q, sigma2, &smoothed));
    add("ctrv+rts", std::move(*smoothed));
    if (control_full != nullptr)
      add("control", s0::run_displacement(r.input, r.input.control, o.R, o.Q, "control"));
  }
  if (o.tune) {
    for (Family f : {Family::kCv, Family::kCtrv, Family::kControl}) {
      if (f == Family::kControl && control_full == nullptr) continue;
      const s0::TunedNoise t = s0::tune_family(own_input, f);
      r.tuned.push_back(t);
      if (!r.has_truth) continue;
      // Run in the estimate's own frame, then moved by the raw estimate's alignment.
      const auto to_aligned = [&](s0::MethodRun run) {
        if (o.alignment == Alignment::kNone) return run;
        const Trajectory moved = apply_alignment(with_plane_points(own, run.points, o.plane), to_truth);
        run.points = project_to_plane(moved, o.plane);
        for (double& v : run.variance) v *= to_truth.scale * to_truth.scale;
        return run;
      };
      std::optional<s0::MethodRun> smoothed;
      const std::string base = s0::family_name(f);
      add(base + "/tuned", to_aligned(s0::run_family(own_input, f, t.result.process, t.result.measurement,
                                                     f == Family::kControl ? nullptr : &smoothed)));
      if (smoothed) add(base + "+rts/tuned", to_aligned(std::move(*smoothed)));
    }
  }
  if (!r.has_truth) return r;

  r.truth_xy = project_to_plane(r.groundtruth, o.plane);
  require_finite(r.truth_xy, r.source + ": the ground truth on the road plane");
  r.rmse_before = rmse_2d(r.truth_xy, r.raw_xy);
  require_finite(r.rmse_before, r.source + ": the planar RMSE before correction");
  for (MethodResult& m : runs) {
    const std::string what = r.source + ": " + m.name;
    require_finite(m.points, what + " corrected position");
    for (std::size_t k = 0; k < m.variance.size(); ++k)
      require_finite(m.variance[k], what + " variance at frame " + std::to_string(k));
    m.rmse = rmse_2d(r.truth_xy, m.points);
    require_finite(m.rmse, what + " RMSE after correction");
    r.methods.push_back(std::move(m));
  }
  return r;
}

/// 100 (before - after) / before; 0 when both are 0; none when the ratio is
/// not a finite number (after > 0 = before).
std::optional<double> reduction_percent(double before, double after) {
  if (before == 0) return after == 0 ? std::optional<double>(0.0) : std::nullopt;
  const double red = 100.0 * (before - after) / before;
  return std::isfinite(red) ? std::optional<double>(red) : std::nullopt;
}

/// "helps" only for a reduction of at least 1 % (so never when after > before).
std::string verdict(const std::string& method, double before, double after) {
  const std::optional<double> red = reduction_percent(before, after);
  if (!red) return "worse than raw";
  if (method == "seed000" && std::abs(*red) < 1e-6) return "returns its input (docs/reproductions.md)";
  if (*red >= 1.0 && after < before) return "helps";
  if (*red > -1.0) return "no real gain";
  return "worse than raw";
}

/// One row of the folder table's mean: the means over the sequences, and
/// how many sequences the method made worse.
struct MeanRow {
  std::string method;
  double before = 0, after = 0;
  std::size_t worse = 0, sequences = 0;
};

std::vector<MeanRow> mean_rows(const std::vector<EstimateResult>& results) {
  std::vector<MeanRow> rows;
  for (const auto& m : results.front().methods) rows.push_back({m.name, 0, 0, 0, 0});
  for (MeanRow& row : rows) {
    for (const auto& r : results)
      for (const auto& m : r.methods)
        if (m.name == row.method) {
          row.before += r.rmse_before;
          row.after += m.rmse;
          row.worse += m.rmse > r.rmse_before ? 1 : 0;
          ++row.sequences;
        }
    row.before /= static_cast<double>(row.sequences);
    row.after /= static_cast<double>(row.sequences);
  }
  return rows;
}

/// The mean row's verdict: "helps" only when no sequence got worse.
std::string mean_verdict(const MeanRow& row) {
  const std::string v = verdict(row.method, row.before, row.after);
  if (row.worse == 0 || v == "worse than raw") return v;
  return "worse on " + std::to_string(row.worse) + " of " + std::to_string(row.sequences) + " sequences";
}

/// Seed 000 Fig. 8: the first frame at which |d(variance)/dframe| < 0.01.
std::pair<std::size_t, double> steady_state(const std::vector<double>& v) {
  for (std::size_t k = 1; k < v.size(); ++k)
    if (std::abs(v[k] - v[k - 1]) < 0.01) return {k, v[k]};
  return {v.size(), v.empty() ? 0.0 : v.back()};
}

/// The estimate with the method's road-plane positions (height, attitude kept).
Trajectory corrected_trajectory(const EstimateResult& r, const MethodResult& m, Plane plane) {
  return with_plane_points(r.estimate, m.points, plane);
}

/// Left: the first estimate's road-plane paths. Right: seed 000 Fig. 8, the
/// mean position variance trace(P)/2 per frame.
std::string plot_svg(const EstimateResult& r, Plane plane) {
  const std::string axes(to_string(plane));
  apps::svg::Plot paths(r.name + ": road-plane paths");
  paths.x_axis(axes.substr(0, 1), "m").y_axis(axes.substr(1, 1), "m").equal_aspect();
  paths.line("ground truth", r.truth_xy, {"#000000", 2.0, {}});
  paths.line("raw estimate", r.raw_xy, {"#d62728", 1.0, {}});
  paths.line("cv+rts", r.methods[2].points, {"#1f77b4", 1.0, {}});
  paths.line("seed000 (= raw)", r.methods[0].points, {"#2ca02c", 0.6, "4,3"});

  const auto curve = [](const std::vector<double>& v) {
    std::vector<apps::svg::Point> p;
    for (std::size_t k = 0; k < v.size(); ++k) p.push_back({double(k), v[k]});
    return p;
  };
  apps::svg::Plot variance("position variance trace(P)/2 per frame (seed 000 Fig. 8)");
  variance.x_axis("frame").y_axis("variance", "m^2").include({0, 0});
  variance.line("seed000", curve(r.methods[0].variance), {"#2ca02c", 1.5, {}});
  variance.line("cv", curve(r.methods[1].variance), {"#1f77b4", 1.0, {}});

  apps::svg::Document doc(1100, 520);
  doc.plot(paths, {0, 0, 550, 520}).plot(variance, {550, 0, 550, 520});
  return doc.str();
}

/// The tuned noise levels, one line per estimate and method.
void print_tuned(const Options& o, const std::vector<EstimateResult>& results) {
  std::printf("\nNoise chosen by the innovation likelihood of each estimate alone (no ground truth):\n\n");
  for (const auto& r : results)
    for (const auto& t : r.tuned) {
      const auto [pu, mu] = apps::seed000::family_units(t.family);
      const auto& x = t.result;
      std::printf("%-22s %-8s %s = %-9.4g %s = %-9.4g log-likelihood %.2f%s\n", r.name.c_str(),
                  apps::seed000::family_name(t.family), pu, x.process, mu, x.measurement,
                  x.log_likelihood,
                  x.process_at_bound || x.measurement_at_bound ? " (at the edge of the range searched)" : "");
    }
  std::printf("\nX/tuned and X+rts/tuned share the X filter's values. seed000 is not tuned: its "
              "innovations are zero\n(it returns its input), so its likelihood only grows as R and Q "
              "shrink.\n");
  if (o.alignment != Alignment::kNone)
    std::printf("With --align the noise is chosen in each estimate's own frame and units, before "
                "the alignment.\n");
}

void print_json(const Options& o, const std::vector<EstimateResult>& results) {
  using Layout = apps::JsonWriter::Layout;
  apps::JsonWriter j(std::cout);
  j.begin_object();
  j.member("plane", to_string(o.plane)).member("alignment", to_string(o.alignment));
  const bool truth = results.front().has_truth;
  j.key("estimates").begin_array(Layout::kBlock);
  for (const auto& r : results) {
    j.begin_object();
    j.member("name", r.name).member("frames", r.estimate.size());
    if (truth) {
      j.member("rmse_before", r.rmse_before);
      j.key("methods").begin_array(Layout::kBlock);
      for (const auto& m : r.methods) {
        j.begin_object(Layout::kInline).member("method", m.name).member("rmse_after", m.rmse);
        const std::optional<double> red = reduction_percent(r.rmse_before, m.rmse);
        j.key("reduction_percent");
        if (red) j.value(*red);
        else j.null();
        j.member("verdict", verdict(m.name, r.rmse_before, m.rmse)).end_object();
      }
      j.end_array();
    }
    if (o.tune) {
      j.key("tuned").begin_array(Layout::kBlock);
      for (const auto& t : r.tuned) {
        const auto [pu, mu] = apps::seed000::family_units(t.family);
        j.begin_object(Layout::kInline)
            .member("method", apps::seed000::family_name(t.family))
            .member("process", t.result.process)
            .member("process_unit", pu)
            .member("measurement", t.result.measurement)
            .member("measurement_unit", mu)
            .member("log_likelihood", t.result.log_likelihood)
            .member("at_bound", t.result.process_at_bound || t.result.measurement_at_bound)
            .end_object();
      }
      j.end_array();
    }
    j.end_object();
  }
  j.end_array();
  if (truth) {
    // One row per sequence and method, and (folders) the mean rows.
    const auto row = [&](const std::string& sequence, const std::string& method, double before,
                         double after, const std::string& v) {
      j.begin_object(Layout::kInline).member("sequence", sequence).member("method", method);
      j.member("rmse_before", before).member("rmse_after", after);
      const std::optional<double> red = reduction_percent(before, after);
      j.key("reduction_percent");
      if (red) j.value(*red);
      else j.null();
      j.member("verdict", v).end_object();
    };
    j.key("rows").begin_array(Layout::kBlock);
    for (const auto& r : results)
      for (const auto& m : r.methods)
        row(r.name, m.name, r.rmse_before, m.rmse, verdict(m.name, r.rmse_before, m.rmse));
    j.end_array();
    if (o.folders) {
      j.key("mean").begin_array(Layout::kBlock);
      for (const MeanRow& m : mean_rows(results))
        row("mean", m.method, m.before, m.after, mean_verdict(m));
      j.end_array();
    }
    const auto [steady_frame, steady_value] = steady_state(results.front().methods[0].variance);
    j.key("seed000_covariance").begin_object(Layout::kInline);
    j.member("initial", results.front().methods[0].variance.front())
        .member("steady", steady_value)
        .member("steady_frame", steady_frame);
    j.end_object();
  }
  j.end_object().finish();
}

void print_table(const Options& o, const std::vector<EstimateResult>& results) {
  if (!results.front().has_truth) {
    print_tuned(o, results);
    return;
  }
  std::size_t width = 8;
  for (const auto& m : results.front().methods) width = std::max(width, m.name.size());
  const int w = static_cast<int>(width);
  const auto [steady_frame, steady_value] = steady_state(results.front().methods[0].variance);
  std::printf("Planar RMSE against ground truth (seed 000, Table 1), plane %s, alignment %s\n\n",
              std::string(to_string(o.plane)).c_str(), std::string(to_string(o.alignment)).c_str());
  std::printf("%-22s %-*s %16s %15s %10s   %s\n", o.folders ? "sequence" : "estimate", w, "method",
              "RMSE before [m]", "RMSE after [m]", "reduction", "verdict");
  const auto line = [&](const std::string& name, const std::string& method, double before,
                        double after, const std::string& v) {
    const std::optional<double> red = reduction_percent(before, after);
    std::printf("%-22s %-*s %16.3f %15.3f ", name.c_str(), w, method.c_str(), before, after);
    if (red) std::printf("%8.2f %%", *red);
    else std::printf("%10s", "n/a");
    std::printf("   %s\n", v.c_str());
  };
  for (const auto& r : results)
    for (const auto& m : r.methods) line(r.name, m.name, r.rmse_before, m.rmse, verdict(m.name, r.rmse_before, m.rmse));
  if (o.folders)
    for (const MeanRow& m : mean_rows(results)) line("mean", m.method, m.before, m.after, mean_verdict(m));
  std::printf("\nseed000 position variance trace(P)/2: %.4f m^2 at the first frame, steady "
              "(|dP/dframe| < 0.01) at %.4f m^2 from frame %zu.\n",
              results.front().methods[0].variance.front(), steady_value, steady_frame);
  std::printf("seed000 returns its input whatever R and Q (u = z_t - z_{t-1} cancels the gain; "
              "docs/reproductions.md).\n");
  if (o.tune) print_tuned(o, results);
}

/// One sequence's files.
struct SequenceFiles {
  std::string name;
  fs::path estimate;
  std::optional<fs::path> groundtruth, control, times;
};

/// The sequences to run: the --estimate files, or the files of the
/// --estimate folder with their same-named ground truth (and control, times).
std::vector<SequenceFiles> sequences(const Options& o) {
  std::vector<SequenceFiles> out;
  if (!o.folders) {
    for (const auto& e : o.estimates)
      out.push_back({e.stem().string(), e, o.groundtruth, o.control, o.times});
    return out;
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(o.estimates.front()))
    if (entry.is_regular_file() && entry.path().filename().string().front() != '.')
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw apps::data_error(o.estimates.front().string() + ": no estimate files in the folder");
  const auto partner = [&](const std::optional<fs::path>& dir, const fs::path& f,
                           const char* what) -> std::optional<fs::path> {
    if (!dir) return std::nullopt;
    const fs::path p = *dir / f.filename();
    if (!fs::is_regular_file(p))
      throw apps::data_error(p.string() + ": no " + what + " for " + f.string() +
                             " (folders pair files by name)");
    return p;
  };
  for (const auto& f : files)
    out.push_back({f.stem().string(), f, partner(o.groundtruth, f, "ground truth"),
                   partner(o.control, f, "control"), partner(o.times, f, "times file")});
  return out;
}

int run(const Options& o, const std::string& program) {
  // On a terminal, standard error shows the sequence being corrected.
  apps::TerminalProgress progress(program);
  // 1. Compute everything; any failure stops here, before an output exists.
  std::vector<EstimateResult> results;
  if (o.estimates.empty()) {
    const sim::SyntheticDrive drive = sim::make_kitti_like_drive();
    results.push_back(correct("synthetic", "built-in synthetic drive", &drive.groundtruth,
                              drive.estimate, nullptr, {}, o.format == Format::kTum, o));
    results.back().format = o.format;
  } else {
    const std::vector<SequenceFiles> seqs = sequences(o);
    for (const SequenceFiles& s : seqs) {
      progress.stage("correcting " + s.estimate.string() + " (" + std::to_string(results.size() + 1) + "/" +
                     std::to_string(seqs.size()) + ")");
      const auto format_of = [&](const fs::path& p) {
        if (!o.auto_format) return o.format;
        const Format f = detect_format(p);
        if (f == Format::kEuroc)
          throw apps::data_error(p.string() + ": a EuRoC file (read those with evaluate_trajectory)");
        return f;
      };
      const auto read = [&](const fs::path& p, Format f) {
        return read_trajectory(p, f, f == Format::kKitti ? s.times : std::nullopt);
      };
      std::optional<Trajectory> gt, control;
      const Format est_format = format_of(s.estimate);
      bool by_stamps = est_format == Format::kTum;
      if (s.groundtruth) {
        const Format f = format_of(*s.groundtruth);
        by_stamps = by_stamps || f == Format::kTum;
        gt = read(*s.groundtruth, f);
      }
      if (s.control) control = read(*s.control, format_of(*s.control));
      results.push_back(correct(s.name, s.estimate.string(), gt ? &*gt : nullptr,
                                read(s.estimate, est_format), control ? &*control : nullptr,
                                s.control ? s.control->string() : std::string(), by_stamps, o));
      results.back().format = est_format;
    }
  }
  std::vector<apps::seed000::SweepTable> sweep;
  if (o.sweep) {
    const EstimateResult& r = results.front();
    std::vector<std::pair<Family, std::pair<double, double>>> families{
        {Family::kSeed, {0.5 * o.R.trace(), 0.5 * o.Q.trace()}},
        {Family::kCv, {o.cv_q, 0.5 * o.Q.trace()}},
        {Family::kCtrv, {o.ctrv_q, 0.5 * o.Q.trace()}}};
    if (!r.input.control.empty())
      families.push_back({Family::kControl, {0.5 * o.R.trace(), 0.5 * o.Q.trace()}});
    progress.stage("sweeping the noise grid of " + r.source);
    sweep = apps::seed000::sweep(r.input, r.truth_xy, families);
  }
  progress.clear();

  // 2. The output files, in memory (the SVG refuses non-finite numbers).
  apps::OutputFiles files;
  if (o.out) {
    std::vector<std::tuple<std::string, Trajectory, Format>> corrected;
    for (const auto& r : results) {
      const std::string ext = r.format == Format::kTum ? ".tum" : ".txt";
      const auto m = std::find_if(r.methods.begin(), r.methods.end(),
                                  [&](const MethodResult& x) { return x.name == o.method; });
      const std::string file = r.name + "_" + std::string(o.method.substr(0, o.method.find('/'))) +
                               (o.method.ends_with("/tuned") ? "_tuned" : "") + ext;
      corrected.emplace_back(file, corrected_trajectory(r, *m, o.plane), r.format);
    }
    if (results.size() == 1 && !o.folders) {
      files.add_with(*o.out, [t = std::move(std::get<1>(corrected.front())),
                              f = std::get<2>(corrected.front())](const fs::path& p) {
        write_trajectory(p, t, f);
      });
    } else {
      files.add_folder(*o.out, [c = std::move(corrected)](const fs::path& dir) {
        for (const auto& [name, t, f] : c) write_trajectory(dir / name, t, f);
      });
    }
  }
  if (o.plot) files.add(*o.plot, plot_svg(results.front(), o.plane));
  if (o.sweep_svg)
    files.add(*o.sweep_svg,
              apps::seed000::sweep_svg(sweep, results.front().name, results.front().rmse_before));

  // 3. Write the files (all or none), then the report.
  files.commit();
  if (o.json) {
    print_json(o, results);
  } else {
    print_table(o, results);
    if (o.sweep) apps::seed000::print_sweep(sweep, results.front().name, results.front().rmse_before);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return posefuse::apps::run_main(argc, argv, [](const posefuse::apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o, cmd.program) : 0;
  });
}

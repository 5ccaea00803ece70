// evaluate_trajectory: evo-style APE / RPE of an estimated trajectory
// against ground truth, with posefuse's readers, association, Umeyama
// alignment and metrics (numbers agree with evo_ape / evo_rpe).
//
// Scenario: score ORB-SLAM2 on KITTI odometry sequence 06 (kitti/06 of the
// data folder, docs/programs.md). Stereo output is metric, so align with SE(3):
//
//   evaluate_trajectory --groundtruth kitti/06/groundtruth.txt
//                       --estimate kitti/06/orbslam2_stereo.txt --align se3
//
// Expected output (the definitions of evo_ape kitti ... -a; cross-checked
// independently by tests/eval/evo_crosscheck.py):
//
//   APE w.r.t. translation part (m), alignment se3
//   pairs         1101
//   max       1.524709
//   mean      0.682740
//   median    0.668036
//   min       0.219585
//   rmse      0.750409
//   sse     619.987665
//   std       0.311416
//
// Monocular output has an arbitrary scale; its TUM file is associated by
// time with the KITTI ground truth stamped by times.txt, then Sim(3)-aligned:
//
//   evaluate_trajectory --groundtruth kitti/06/groundtruth.txt --times kitti/06/times.txt
//                       --estimate kitti/06/orbslam2_mono.tum --estimate-format tum
//                       --align sim3
//
// prints rmse 12.978526 m and "scale 24.841695". Add --metric rpe --delta 100
// --delta-unit m for the relative error per 100 m, --json for machine-readable
// output, --plot FILE.svg for a picture, --save-results FILE to keep everything (statistics, per-pose errors,
// options) as JSON. evo_ape / evo_rpe options are spelled with dashes
// (--t-offset, --align-origin, --n-to-align, ...; see --help and docs/evaluation.md).
// Repeated timestamps are kept first by default (--duplicates) and reported
// as a "warning:" line on stderr. Bad input exits with 2 (usage) or 1 (data,
// naming file:line where a file is at fault), one line on stderr.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <apps/cli.hpp>
#include <apps/evaluation.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <apps/spooled_input.hpp>
#include <apps/svg.hpp>
#include <posefuse/eval/consistency.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/eval/trajectory_filters.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace {

namespace apps = posefuse::apps;

// The evaluation's own settings (apps/evaluation.hpp) and the program's files and outputs.
struct Options : apps::EvaluationSetup {
  std::filesystem::path groundtruth, estimate;
  std::optional<std::filesystem::path> times, save_results, plot;
  posefuse::Plane plot_mode = posefuse::Plane::kXY;
  bool json = false;
};

/// "D,A" -> (D, A), both finite and >= 0.
std::pair<double, double> parse_pair(std::string_view v) {
  const auto items = apps::split_commas(v, 2, 2, "DIST,ANGLE (two numbers separated by a comma)");
  return {apps::parse_real(items[0], apps::Domain::kNonNegative),
          apps::parse_real(items[1], apps::Domain::kNonNegative)};
}

/// The options, or nothing when --help was printed.
std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  std::optional<std::filesystem::path> ref, est;
  std::optional<posefuse::Format> format, ref_format, est_format;
  std::optional<double> t_start, t_end;
  std::optional<std::size_t> n_to_align;
  bool all_pairs = false, pairs_from_reference = false;
  double delta_tol = o.rpe.delta_tol;
  const auto format_flag = [](std::optional<posefuse::Format>& f) {
    return [&f](std::string_view v) {
      if (v == "auto") {
        f.reset();
      } else {
        f = posefuse::parse_format(v);
      }
    };
  };
  apps::Parser cli(cmd.program, "--groundtruth REF --estimate EST [options]",
                   "Absolute (APE) or relative (RPE) pose error of EST against REF, as evo_ape / "
                   "evo_rpe.");
  cli.input({.name = "--groundtruth", .value = "FILE", .help = "reference trajectory (required)"}, ref);
  cli.input({.name = "--estimate", .value = "FILE", .help = "estimated trajectory (required)"}, est);
  cli.custom({.name = "--format", .value = "auto|kitti|tum|euroc",
              .help = "format of both files (auto: told from the content, printed)",
              .default_text = "auto"},
             format_flag(format));
  cli.custom({.name = "--groundtruth-format", .value = "F",
              .help = "format of REF only (overrides --format)"},
             format_flag(ref_format));
  cli.custom({.name = "--estimate-format", .value = "F",
              .help = "format of EST only (overrides --format)"},
             format_flag(est_format));
  cli.input({.name = "--times", .value = "FILE", .help = "KITTI times.txt, stamps every KITTI file given"},
           o.times);
  cli.custom({.name = "--duplicates", .value = "first|last|keep|error",
              .help = "equal consecutive stamps: keep the first or last pose (reported\n"
                      "as a warning), keep every pose as evo does (each repeat pairs\n"
                      "with its nearest partner) or refuse the file",
              .default_text = "first"},
             [&](std::string_view v) { o.duplicates = posefuse::parse_duplicate_stamps(v); });
  cli.custom({.name = "--metric", .value = "ape|rpe", .help = "the error", .default_text = "ape"},
             [&](std::string_view v) {
               if (v != "ape" && v != "rpe")
                 throw apps::usage_error("expected ape or rpe, got '" + std::string(v) + "'");
               o.metric_rpe = v == "rpe";
             });
  cli.custom({.name = "--align", .value = "none|se3|sim3|scale|posyaw",
              .help = "alignment of EST to REF: Umeyama (scale: scale only, evo's\n"
                      "--correct_scale without --align), or posyaw: position and yaw\n"
                      "(4-DoF, roll and pitch errors stay visible)",
              .default_text = "none"},
             [&](std::string_view v) { o.align.alignment = posefuse::parse_alignment(v); });
  cli.flag({.name = "--align-origin", .help = "move EST so that its first pose is REF's first pose"},
           o.align.align_origin);
  cli.integer({.name = "--n-to-align", .value = "N",
               .help = "compute the alignment from the first N pose pairs only"},
              n_to_align, std::size_t{3});
  cli.custom({.name = "--project-to-plane", .value = "xy|xz|yz",
              .help = "project both trajectories onto a plane after alignment"},
             [&](std::string_view v) { o.align.project_to_plane = posefuse::parse_plane(v); });
  cli.custom({.name = "--pose-relation", .value = "R",
              .help = "trans, angle_deg, angle_rad, full, rot_part, point_distance,\n"
                      "point_distance_error_ratio (RPE only)",
              .default_text = "trans"},
             [&](std::string_view v) { o.relation = posefuse::parse_pose_relation(v); });
  cli.real({.name = "--delta", .value = "N", .help = "RPE step"}, o.rpe.delta,
           apps::Domain::kPositive);
  cli.custom({.name = "--delta-unit", .value = "frames|m|deg|rad", .help = "RPE step unit",
              .default_text = "frames"},
             [&](std::string_view v) { o.rpe.delta_unit = posefuse::parse_delta_unit(v); });
  cli.flag({.name = "--all-pairs", .help = "RPE over every start pose, not consecutive pairs"},
           all_pairs);
  cli.real({.name = "--delta-tol", .value = "F",
            .help = "relative tolerance of --all-pairs with m/deg/rad deltas"},
           delta_tol, apps::Domain::kNonNegative);
  cli.flag({.name = "--pairs-from-reference",
            .help = "choose RPE pairs on REF instead of the aligned EST"},
           pairs_from_reference);
  cli.real({.name = "--max-time-diff", .value = "S", .help = "association tolerance", .unit = "s"},
           o.max_time_diff, apps::Domain::kNonNegative);
  cli.real({.name = "--t-offset", .value = "S", .help = "constant offset added to EST's stamps",
            .unit = "s"},
           o.t_offset);
  cli.custom({.name = "--t-start", .value = "S", .help = "first REF stamp used (absolute, s)"},
             [&](std::string_view v) { t_start = apps::parse_real(v); });
  cli.custom({.name = "--t-end", .value = "S", .help = "last REF stamp used (absolute, s)"},
             [&](std::string_view v) { t_end = apps::parse_real(v); });
  cli.integer({.name = "--downsample", .value = "N",
               .help = "keep at most N evenly spaced poses of each file"},
              o.downsample, std::size_t{1});
  cli.custom({.name = "--motion-filter", .value = "DIST,DEG",
              .help = "keep a pose only after DIST m or DEG degrees of motion\n"
                      "since the last kept one (each file)"},
             [&](std::string_view v) { o.motion_filter = parse_pair(v); });
  cli.output({.name = "--save-results", .value = "FILE",
            .help = "write statistics, per-pose errors and options as JSON"},
           o.save_results);
  cli.output({.name = "--plot", .value = "FILE.svg",
            .help = "draw both trajectories (EST aligned, coloured by error) and the\n"
                    "error over time with its statistics"},
           o.plot);
  cli.custom({.name = "--plot-mode", .value = "xy|xz|yz", .help = "the plane of the trajectory view",
              .default_text = "xy"},
             [&](std::string_view v) { o.plot_mode = posefuse::parse_plane(v); });
  cli.flag({.name = "--json", .help = "print one JSON object instead of the table"}, o.json);
  cli.epilogue(
      "Two KITTI files without --times are compared frame by frame (equal counts);\n"
      "otherwise poses are associated by timestamp like evo's --t_max_diff.\n"
      "Order as evo: --downsample/--motion-filter, --t-start/--t-end (REF),\n"
      "association (--t-offset), alignment, --project-to-plane, metric.\n"
      "A TUM estimate may carry a covariance per pose (14 or 29 columns, docs/programs.md):\n"
      "APE then also reports NEES with its chi-square bounds.\n"
      "Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;

  if (!ref || !est) throw apps::usage_error("--groundtruth and --estimate are required");
  o.groundtruth = *ref;
  o.estimate = *est;
  o.groundtruth_name = o.groundtruth.string();
  o.estimate_name = o.estimate.string();
  o.ref_format_given = ref_format ? ref_format : format;
  o.est_format_given = est_format ? est_format : format;
  o.rpe.all_pairs = all_pairs;
  o.rpe.delta_tol = delta_tol;
  o.rpe.pairs_from_reference = pairs_from_reference;
  o.rpe.relation = o.relation;
  if (o.rpe.delta_unit == posefuse::DeltaUnit::kFrames &&
      (o.rpe.delta < 1.0 || o.rpe.delta != std::floor(o.rpe.delta)))
    throw apps::usage_error("--delta in frames must be an integer >= 1");
  if (!o.metric_rpe && o.relation == posefuse::PoseRelation::kPointDistanceErrorRatio)
    throw apps::usage_error("--pose-relation point_distance_error_ratio needs --metric rpe");
  if (o.align.align_origin && o.align.alignment != posefuse::Alignment::kNone)
    throw apps::usage_error("--align-origin and --align exclude each other");
  if (n_to_align) {
    if (o.align.alignment == posefuse::Alignment::kNone)
      throw apps::usage_error("--n-to-align needs --align se3, sim3, scale or posyaw");
    o.align.n_to_align = *n_to_align;
  }
  if (t_start && t_end && *t_start > *t_end)
    throw apps::usage_error("--t-start is after --t-end");
  o.t_start = t_start;
  o.t_end = t_end;
  o.rpe.alignment = o.align.alignment;
  o.rpe.n_to_align = o.align.n_to_align;
  o.rpe.align_origin = o.align.align_origin;
  o.rpe.project_to_plane = o.align.project_to_plane;
  return o;
}

using Loaded = apps::LoadedTrajectory;

/// Reads one trajectory file (and, for KITTI, its times) into `out`.
void read_into(Loaded& out, const std::filesystem::path& file, posefuse::Format format,
               const std::optional<std::filesystem::path>& times, const posefuse::ReadOptions& options,
               posefuse::ReadReport& report, bool allow_covariance) {
  if (format == posefuse::Format::kKitti) {
    out.trajectory = posefuse::read_kitti(file, times, options, &report);
  } else if (format == posefuse::Format::kEuroc) {
    out.trajectory = posefuse::read_euroc_groundtruth(file, options, &report).trajectory;
  } else if (allow_covariance) {
    posefuse::TumWithCovariance t = posefuse::read_tum_with_covariance(file, options, &report);
    out.trajectory = std::move(t.trajectory);
    out.covariance_dim = t.covariance_dim;
    out.covariance = std::move(t.covariance);
  } else {
    out.trajectory = posefuse::read_tum(file, options, &report);
  }
}

Loaded load(const std::filesystem::path& file, posefuse::Format format,
            const std::optional<std::filesystem::path>& times, posefuse::DuplicateStamps duplicates,
            bool allow_covariance, std::vector<std::string>& warnings) {
  posefuse::ReadOptions options;
  options.duplicates = duplicates;
  posefuse::ReadReport report;
  Loaded out;
  try {
    read_into(out, file, format, times, options, report, allow_covariance);
  } catch (const posefuse::repeated_stamp_error& e) {  // this program offers the other policies
    throw apps::data_error(std::string(e.what()) + "; repeated stamps can be kept first, last or all instead (--duplicates)");
  }
  // Repeats are only possible in a KITTI times file, never in a KITTI pose file.
  const std::filesystem::path& where = format == posefuse::Format::kKitti && times ? *times : file;
  for (std::string& w : apps::duplicate_warnings(where.string(), report, duplicates)) warnings.push_back(std::move(w));
  return out;
}

std::string relation_title(posefuse::PoseRelation r) {
  switch (r) {
    case posefuse::PoseRelation::kTranslation: return "translation part (m)";
    case posefuse::PoseRelation::kRotationAngleDeg: return "rotation angle in degrees (deg)";
    case posefuse::PoseRelation::kRotationAngleRad: return "rotation angle in radians (rad)";
    case posefuse::PoseRelation::kFull: return "full transformation (unit-less)";
    case posefuse::PoseRelation::kRotationPart: return "rotation part (unit-less)";
    case posefuse::PoseRelation::kPointDistance: return "point distance (m)";
    case posefuse::PoseRelation::kPointDistanceErrorRatio: return "point distance error ratio (%)";
  }
  return "?";
}

void print_table(const Options& o, const posefuse::MetricResult& r,
                 const std::optional<posefuse::NeesResult>& nees, std::size_t n_ref,
                 std::size_t n_est) {
  std::printf("%s w.r.t. %s, alignment %s", o.metric_rpe ? "RPE" : "APE",
              relation_title(o.relation).c_str(), alignment_name(o).c_str());
  if (o.align.n_to_align > 0) std::printf(" (first %zu poses)", o.align.n_to_align);
  if (o.align.project_to_plane)
    std::printf(", projected to %s", std::string(posefuse::to_string(*o.align.project_to_plane)).c_str());
  if (o.metric_rpe) {
    std::printf(", delta %g %s%s", o.rpe.delta, std::string(posefuse::to_string(o.rpe.delta_unit)).c_str(),
                o.rpe.all_pairs ? ", all pairs" : "");
  }
  std::printf("\n");
  std::printf("files  groundtruth %s (%s), estimate %s (%s)\n",
              std::string(posefuse::to_string(o.ref_format)).c_str(),
              o.ref_format_given ? "given" : "detected",
              std::string(posefuse::to_string(o.est_format)).c_str(),
              o.est_format_given ? "given" : "detected");
  std::printf("pairs  %11zu\n", r.stats.count);
  if (!o.metric_rpe && (r.stats.count != n_ref || r.stats.count != n_est)) {
    std::printf("poses  %zu reference, %zu estimate\n", n_ref, n_est);
  }
  const posefuse::Statistics& s = r.stats;
  std::printf("max    %11.6f\nmean   %11.6f\nmedian %11.6f\nmin    %11.6f\n", s.max, s.mean,
              s.median, s.min);
  std::printf("rmse   %11.6f\nsse    %11.6f\nstd    %11.6f\n", s.rmse, s.sse, s.std);
  if (o.align.alignment == posefuse::Alignment::kSim3 ||
      o.align.alignment == posefuse::Alignment::kScale)
    std::printf("scale  %11.6f\n", r.alignment.scale);
  if (nees) {
    std::printf("NEES   %11.6f  (%d-D; consistent between %.4f and %.4f at %g %%: %s)\n",
                nees->mean, nees->dim, nees->lower, nees->upper, 100.0 * nees->confidence,
                nees->consistent()             ? "consistent"
                : nees->mean > nees->upper     ? "overconfident, covariance too small"
                                               : "underconfident, covariance too large");
  }
}

/// One JSON object on one line; numbers round-trip, non-finite ones are null.
void print_json(const Options& o, const posefuse::MetricResult& r,
                const std::optional<posefuse::NeesResult>& nees) {
  apps::JsonWriter j(std::cout);
  j.begin_object(apps::JsonWriter::Layout::kInline);
  apps::write_summary(j, o, r, nees);
  j.end_object().finish();
}

/// The --plot document: top, the trajectories in the chosen plane (REF
/// dashed black, EST aligned, its segments coloured by the error at their
/// end pose in six bins between the smallest and largest error); bottom, the
/// error over time (s from REF's first associated stamp) with rmse, mean and
/// median as horizontal lines.
std::string plot_svg(const Options& o, const posefuse::MetricResult& r,
                     const posefuse::Trajectory& ref_used, const posefuse::Trajectory& est_used) {
  namespace svg = apps::svg;
  const posefuse::Trajectory est_aligned = posefuse::apply_alignment(est_used, r.alignment);
  const std::string unit(posefuse::unit_of(o.relation));
  const std::string metric = o.metric_rpe ? "RPE" : "APE";
  const std::string plane(posefuse::to_string(o.plot_mode));
  const auto xy = [&](const Eigen::Isometry3d& T) {
    const Eigen::Vector2d p = posefuse::project_to_plane(T, o.plot_mode);
    return svg::Point{p.x(), p.y()};
  };
  // Error per pose: APE one per pose; RPE the pair ending at that pose.
  std::vector<double> error(ref_used.size(), std::nan(""));
  if (o.metric_rpe) {
    for (std::size_t k = 0; k < r.pairs.size(); ++k) error[r.pairs[k].second] = r.errors[k];
  } else {
    error = r.errors;
  }
  svg::Plot paths(metric + " " + relation_title(o.relation) + " along the path, alignment " +
                  alignment_name(o));
  paths.x_axis(std::string(1, plane[0]), "m").y_axis(std::string(1, plane[1]), "m").equal_aspect();
  std::vector<svg::Point> ref_points, est_points;
  for (const auto& T : ref_used.poses) ref_points.push_back(xy(T));
  for (const auto& T : est_aligned.poses) est_points.push_back(xy(T));
  paths.line("reference", ref_points, {"#000000", 1.5, "6,3"});
  paths.line("", est_points, {"#b0b0b0", 1.0, {}});
  static constexpr const char* kColours[] = {"#440154", "#414487", "#2a788e",
                                             "#22a884", "#7ad151", "#fde725"};  // viridis
  constexpr int kBins = 6;
  const double lo = r.stats.min, hi = r.stats.max;
  const auto bin_of = [&](double e) {
    if (!(hi > lo)) return 0;
    return std::min(kBins - 1, static_cast<int>((e - lo) / (hi - lo) * kBins));
  };
  for (int b = 0; b < kBins; ++b) {
    bool legend_done = false;
    std::vector<svg::Point> run;
    const auto flush = [&]() {
      if (run.size() >= 2) {
        char label[96];
        std::snprintf(label, sizeof(label), "estimate, error %.3g to %.3g %s",
                      lo + (hi - lo) * b / kBins, lo + (hi - lo) * (b + 1) / kBins, unit.c_str());
        paths.line(legend_done ? "" : label, run, {kColours[b], 2.5, {}});
        legend_done = true;
      }
      run.clear();
    };
    for (std::size_t k = 1; k < est_points.size(); ++k) {
      if (std::isfinite(error[k]) && bin_of(error[k]) == b) {
        if (run.empty()) run.push_back(est_points[k - 1]);
        run.push_back(est_points[k]);
      } else {
        flush();
      }
    }
    flush();
  }
  // KITTI files without --times carry frame indices, not times.
  const bool indices = o.frame_by_frame();
  svg::Plot over_time(metric + (indices ? " per pose (" : " over time (") +
                      std::to_string(r.stats.count) + " values)");
  if (indices) {
    over_time.x_axis("pose index");
  } else {
    over_time.x_axis("t", "s");
  }
  over_time.y_axis(metric, unit);
  std::vector<svg::Point> series;
  const double t0 = ref_used.t_s.front();
  for (std::size_t k = 0; k < error.size(); ++k)
    if (std::isfinite(error[k])) series.push_back({ref_used.t_s[k] - t0, error[k]});
  over_time.line(metric, series, {"#1f77b4", 1.2, {}});
  const double t1 = ref_used.t_s.back() - t0;
  const auto level = [&](const char* name, double v, const char* colour, const char* dash) {
    char label[64];
    std::snprintf(label, sizeof(label), "%s %.4g %s", name, v, unit.c_str());
    over_time.line(label, std::vector<svg::Point>{{0.0, v}, {t1, v}}, {colour, 1.5, dash});
  };
  level("rmse", r.stats.rmse, "#d62728", "");
  level("mean", r.stats.mean, "#2ca02c", "6,3");
  level("median", r.stats.median, "#9467bd", "2,2");
  over_time.include({0.0, 0.0});
  svg::Document doc(760, 1180);
  doc.plot(paths, {0, 0, 760, 700});
  doc.plot(over_time, {0, 700, 760, 480});
  return doc.str();
}

/// Fills in the formats not given on the command line from the files'
/// content, then checks what depends on them (usage errors, exit 2).
/// `ref_path`, `est_path`: where the files are read from (see run).
Options resolve_formats(Options o, const std::filesystem::path& ref_path, const std::filesystem::path& est_path) {
  o.ref_format = o.ref_format_given ? *o.ref_format_given : posefuse::detect_format(ref_path);
  o.est_format = o.est_format_given ? *o.est_format_given : posefuse::detect_format(est_path);
  const bool any_kitti =
      o.ref_format == posefuse::Format::kKitti || o.est_format == posefuse::Format::kKitti;
  if (o.times && !any_kitti) throw apps::usage_error("--times only applies to KITTI files");
  if (any_kitti && o.ref_format != o.est_format && !o.times)
    throw apps::usage_error("comparing a KITTI file with a " +
                            std::string(posefuse::to_string(o.ref_format == posefuse::Format::kKitti
                                                                ? o.est_format
                                                                : o.ref_format)) +
                            " file needs --times for the KITTI one");
  o.stamped_by_times = o.times.has_value();
  if (o.frame_by_frame() && (o.motion_filter || o.t_start || o.t_end || o.t_offset != 0.0))
    throw apps::usage_error(
        "--motion-filter, --t-start, --t-end and --t-offset need timestamps: give --times "
        "(KITTI files without it are compared frame by frame)");
  return o;
}

int run_read(const Options& given, apps::SpooledInputs& spool) {
  // A file whose format is detected is read twice (detection, then the
  // reader): a pipe or <(command) is then copied once (apps/spooled_input.hpp).
  const std::filesystem::path ref_path =
      given.ref_format_given ? given.groundtruth : spool.readable(given.groundtruth);
  const std::filesystem::path est_path = given.est_format_given ? given.estimate : spool.readable(given.estimate);
  const Options o = resolve_formats(given, ref_path, est_path);
  // On a terminal, standard error shows the stage (reading, associating, the metric).
  apps::TerminalProgress progress("evaluate_trajectory");
  std::vector<std::string> warnings;
  progress.stage("reading " + o.groundtruth.string());
  const Loaded ref_loaded = load(ref_path, o.ref_format, o.times, o.duplicates, false, warnings);
  const posefuse::Trajectory& ref_file = ref_loaded.trajectory;
  progress.stage("reading " + o.estimate.string());
  const Loaded est_loaded = load(est_path, o.est_format, o.times, o.duplicates, true, warnings);
  const posefuse::Trajectory& est_file = est_loaded.trajectory;
  progress.clear();
  for (std::string& w : warnings) w = spool.shown(w);
  for (const std::string& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  progress.stage("associating " + std::to_string(ref_file.size()) + " and " + std::to_string(est_file.size()) +
                 " poses");
  const apps::Evaluation evaluation =
      apps::evaluate(o, ref_loaded, est_loaded, [&](const std::string& what) { progress.stage(what); });
  const posefuse::MetricResult& result = evaluation.result;
  const std::optional<posefuse::NeesResult>& nees = evaluation.nees;
  progress.clear();
  apps::OutputFiles outputs;
  if (o.save_results) outputs.add(*o.save_results, apps::results_json(o, evaluation, warnings));
  if (o.plot) outputs.add(*o.plot, plot_svg(o, result, evaluation.ref_used(), evaluation.est_used()));
  outputs.commit();
  if (o.json) {
    print_json(o, result, nees);
  } else {
    print_table(o, result, nees, ref_file.size(), est_file.size());
  }
  return 0;
}

/// run_read with the messages naming the files as given.
int run(const Options& given) {
  apps::SpooledInputs spool;
  try {
    return run_read(given, spool);
  } catch (const apps::usage_error&) {
    throw;
  } catch (const std::exception& e) {
    const std::string what = e.what(), shown = spool.shown(what);
    if (shown == what) throw;
    throw apps::data_error(shown);
  }
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

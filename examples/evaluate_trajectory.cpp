// evaluate_trajectory: evo-style APE / RPE of an estimated trajectory
// against ground truth, with posefuse's readers, association, Umeyama
// alignment and metrics (numbers agree with evo_ape / evo_rpe).
//
// Scenario: score ORB-SLAM2 on KITTI odometry sequence 06 (../shared/data,
// see its README). Stereo output is metric, so align with SE(3):
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
// output. Bad input exits with 2 (usage) or 1 (data, naming file:line where
// a file is at fault), one line on stderr.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace {

namespace apps = posefuse::apps;

struct Options {
  std::filesystem::path groundtruth, estimate;
  std::optional<std::filesystem::path> times;
  posefuse::Format ref_format = posefuse::Format::kKitti;
  posefuse::Format est_format = posefuse::Format::kKitti;
  bool metric_rpe = false;
  posefuse::Alignment align = posefuse::Alignment::kNone;
  posefuse::PoseRelation relation = posefuse::PoseRelation::kTranslation;
  double delta = 1.0;
  posefuse::DeltaUnit delta_unit = posefuse::DeltaUnit::kFrames;
  double max_time_diff = 0.01;
  bool json = false;
};

/// The options, or nothing when --help was printed.
std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  std::optional<std::filesystem::path> ref, est;
  std::optional<posefuse::Format> format, ref_format, est_format;
  const auto format_flag = [](std::optional<posefuse::Format>& f) {
    return [&f](std::string_view v) { f = posefuse::parse_format(v); };
  };
  apps::Parser cli(cmd.program, "--groundtruth REF --estimate EST [options]",
                   "Absolute (APE) or relative (RPE) pose error of EST against REF, as evo_ape / "
                   "evo_rpe.");
  cli.path({.name = "--groundtruth", .value = "FILE", .help = "reference trajectory (required)"}, ref);
  cli.path({.name = "--estimate", .value = "FILE", .help = "estimated trajectory (required)"}, est);
  cli.custom({.name = "--format", .value = "kitti|tum", .help = "format of both files",
              .default_text = "kitti"},
             format_flag(format));
  cli.custom({.name = "--groundtruth-format", .value = "F",
              .help = "format of REF only (overrides --format)"},
             format_flag(ref_format));
  cli.custom({.name = "--estimate-format", .value = "F",
              .help = "format of EST only (overrides --format)"},
             format_flag(est_format));
  cli.path({.name = "--times", .value = "FILE", .help = "KITTI times.txt, stamps every KITTI file given"},
           o.times);
  cli.custom({.name = "--metric", .value = "ape|rpe", .help = "the error", .default_text = "ape"},
             [&](std::string_view v) {
               if (v != "ape" && v != "rpe")
                 throw apps::usage_error("expected ape or rpe, got '" + std::string(v) + "'");
               o.metric_rpe = v == "rpe";
             });
  cli.custom({.name = "--align", .value = "none|se3|sim3", .help = "Umeyama alignment of EST to REF",
              .default_text = "none"},
             [&](std::string_view v) { o.align = posefuse::parse_alignment(v); });
  cli.custom({.name = "--pose-relation", .value = "R",
              .help = "trans, angle_deg, angle_rad or full", .default_text = "trans"},
             [&](std::string_view v) { o.relation = posefuse::parse_pose_relation(v); });
  cli.real({.name = "--delta", .value = "N", .help = "RPE step"}, o.delta, apps::Domain::kPositive);
  cli.custom({.name = "--delta-unit", .value = "frames|m", .help = "RPE step unit",
              .default_text = "frames"},
             [&](std::string_view v) { o.delta_unit = posefuse::parse_delta_unit(v); });
  cli.real({.name = "--max-time-diff", .value = "S", .help = "association tolerance", .unit = "s"},
           o.max_time_diff, apps::Domain::kNonNegative);
  cli.flag({.name = "--json", .help = "print one JSON object instead of the table"}, o.json);
  cli.epilogue(
      "Two KITTI files without --times are compared frame by frame (equal counts);\n"
      "otherwise poses are associated by timestamp like evo's --t_max_diff.\n"
      "Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;

  if (!ref || !est) throw apps::usage_error("--groundtruth and --estimate are required");
  o.groundtruth = *ref;
  o.estimate = *est;
  o.ref_format = ref_format.value_or(format.value_or(posefuse::Format::kKitti));
  o.est_format = est_format.value_or(format.value_or(posefuse::Format::kKitti));
  const bool any_kitti =
      o.ref_format == posefuse::Format::kKitti || o.est_format == posefuse::Format::kKitti;
  if (o.times && !any_kitti) throw apps::usage_error("--times only applies to KITTI files");
  if (o.ref_format != o.est_format && !o.times)
    throw apps::usage_error("comparing a KITTI with a TUM file needs --times for the KITTI one");
  if (o.delta_unit == posefuse::DeltaUnit::kFrames &&
      (o.delta < 1.0 || o.delta != std::floor(o.delta)))
    throw apps::usage_error("--delta in frames must be an integer >= 1");
  return o;
}

posefuse::Trajectory load(const std::filesystem::path& file, posefuse::Format format,
                          const std::optional<std::filesystem::path>& times) {
  return format == posefuse::Format::kKitti ? posefuse::read_kitti(file, times)
                                            : posefuse::read_tum(file);
}

std::string relation_title(posefuse::PoseRelation r) {
  switch (r) {
    case posefuse::PoseRelation::kTranslation: return "translation part (m)";
    case posefuse::PoseRelation::kRotationAngleDeg: return "rotation angle in degrees (deg)";
    case posefuse::PoseRelation::kRotationAngleRad: return "rotation angle in radians (rad)";
    case posefuse::PoseRelation::kFull: return "full transformation (unit-less)";
  }
  return "?";
}

std::string_view relation_name(posefuse::PoseRelation r) {
  switch (r) {
    case posefuse::PoseRelation::kTranslation: return "trans";
    case posefuse::PoseRelation::kRotationAngleDeg: return "angle_deg";
    case posefuse::PoseRelation::kRotationAngleRad: return "angle_rad";
    case posefuse::PoseRelation::kFull: return "full";
  }
  return "?";
}

void print_table(const Options& o, const posefuse::MetricResult& r, std::size_t n_ref,
                 std::size_t n_est) {
  std::printf("%s w.r.t. %s, alignment %s", o.metric_rpe ? "RPE" : "APE",
              relation_title(o.relation).c_str(),
              std::string(posefuse::to_string(o.align)).c_str());
  if (o.metric_rpe) {
    std::printf(", delta %g %s", o.delta,
                o.delta_unit == posefuse::DeltaUnit::kFrames ? "frames" : "m");
  }
  std::printf("\n");
  std::printf("pairs  %11zu\n", r.stats.count);
  if (!o.metric_rpe && (r.stats.count != n_ref || r.stats.count != n_est)) {
    std::printf("poses  %zu reference, %zu estimate\n", n_ref, n_est);
  }
  const posefuse::Statistics& s = r.stats;
  std::printf("max    %11.6f\nmean   %11.6f\nmedian %11.6f\nmin    %11.6f\n", s.max, s.mean,
              s.median, s.min);
  std::printf("rmse   %11.6f\nsse    %11.6f\nstd    %11.6f\n", s.rmse, s.sse, s.std);
  if (o.align == posefuse::Alignment::kSim3) std::printf("scale  %11.6f\n", r.alignment.scale);
}

/// One JSON object on one line; numbers round-trip, non-finite ones are null.
void print_json(const Options& o, const posefuse::MetricResult& r) {
  const posefuse::Statistics& s = r.stats;
  apps::JsonWriter j(std::cout);
  j.begin_object(apps::JsonWriter::Layout::kInline);
  j.member("metric", o.metric_rpe ? "rpe" : "ape")
      .member("pose_relation", relation_name(o.relation))
      .member("unit", posefuse::unit_of(o.relation))
      .member("alignment", posefuse::to_string(o.align))
      .member("scale", r.alignment.scale);
  if (o.metric_rpe) {
    j.member("delta", o.delta)
        .member("delta_unit", o.delta_unit == posefuse::DeltaUnit::kFrames ? "frames" : "m");
  }
  j.member("count", s.count).member("rmse", s.rmse).member("mean", s.mean).member("median", s.median);
  j.member("std", s.std).member("min", s.min).member("max", s.max).member("sse", s.sse);
  j.end_object().finish();
}

int run(const Options& o) {
  const posefuse::Trajectory ref = load(o.groundtruth, o.ref_format, o.times);
  const posefuse::Trajectory est = load(o.estimate, o.est_format, o.times);
  posefuse::Trajectory ref_sync, est_sync;
  const bool frame_by_frame = o.ref_format == posefuse::Format::kKitti &&
                              o.est_format == posefuse::Format::kKitti && !o.times;
  if (frame_by_frame) {
    if (ref.size() != est.size()) {
      throw apps::data_error("reference has " + std::to_string(ref.size()) +
                             " poses but estimate " + std::to_string(est.size()) +
                             "; KITTI files without --times are compared frame by frame");
    }
    ref_sync = ref;
    est_sync = est;
  } else {
    posefuse::AssociatedTrajectories sync = posefuse::associate(ref, est, o.max_time_diff);
    ref_sync = std::move(sync.ref);
    est_sync = std::move(sync.est);
  }
  posefuse::MetricResult result;
  if (o.metric_rpe) {
    posefuse::RpeOptions rpe_options;
    rpe_options.relation = o.relation;
    rpe_options.delta = o.delta;
    rpe_options.delta_unit = o.delta_unit;
    rpe_options.alignment = o.align;
    result = posefuse::rpe(ref_sync, est_sync, rpe_options);
  } else {
    result = posefuse::ape(ref_sync, est_sync, o.relation, o.align);
  }
  if (o.json) {
    print_json(o, result);
  } else {
    print_table(o, result, ref.size(), est.size());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

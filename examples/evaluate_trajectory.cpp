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
// output. Bad input exits with 2 (usage) or 1 (data), one line on stderr.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace {

constexpr const char* kUsage =
    "usage: evaluate_trajectory --groundtruth REF --estimate EST [options]\n"
    "\n"
    "Absolute (APE) or relative (RPE) pose error of EST against REF, as evo_ape / evo_rpe.\n"
    "\n"
    "  --groundtruth FILE       reference trajectory\n"
    "  --estimate FILE          estimated trajectory\n"
    "  --format kitti|tum       format of both files (default kitti)\n"
    "  --groundtruth-format F   format of REF only (overrides --format)\n"
    "  --estimate-format F      format of EST only (overrides --format)\n"
    "  --times FILE             KITTI times.txt, stamps every KITTI file given\n"
    "  --metric ape|rpe         default ape\n"
    "  --align none|se3|sim3    Umeyama alignment of EST to REF (default none)\n"
    "  --pose-relation R        trans (default), angle_deg, angle_rad or full\n"
    "  --delta N                RPE step (default 1)\n"
    "  --delta-unit frames|m    RPE step unit (default frames)\n"
    "  --max-time-diff S        association tolerance in seconds (default 0.01)\n"
    "  --json                   print one JSON object instead of the table\n"
    "  --help                   print this help\n"
    "\n"
    "Two KITTI files without --times are compared frame by frame (equal counts);\n"
    "otherwise poses are associated by timestamp like evo's --t_max_diff.\n"
    "Exit status: 0 ok, 1 bad data, 2 bad usage.\n";

/// A command-line mistake: exit code 2.
struct UsageError {
  std::string message;
};

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
  bool help = false;
};

double parse_double(std::string_view flag, std::string_view text) {
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || ptr != text.data() + text.size() || !std::isfinite(v)) {
    throw UsageError{std::string(flag) + " expects a number, got '" + std::string(text) + "'"};
  }
  return v;
}

// Runs a posefuse parse_* function, turning its invalid_argument into a usage error.
template <class F>
auto parse_value(std::string_view flag, F&& parse) {
  try {
    return parse();
  } catch (const posefuse::invalid_argument& e) {
    throw UsageError{std::string(flag) + ": " + e.what()};
  }
}

Options parse_args(int argc, char** argv) {
  Options o;
  std::optional<posefuse::Format> format, ref_format, est_format;
  bool have_ref = false, have_est = false;
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      o.help = true;
      return o;
    }
    if (flag == "--json") {
      o.json = true;
      continue;
    }
    if (flag.substr(0, 2) != "--")
      throw UsageError{"unexpected argument '" + std::string(flag) + "'"};
    if (i + 1 >= argc) throw UsageError{std::string(flag) + " needs a value"};
    const std::string_view value = argv[++i];
    if (flag == "--groundtruth") {
      o.groundtruth = value;
      have_ref = true;
    } else if (flag == "--estimate") {
      o.estimate = value;
      have_est = true;
    } else if (flag == "--times") {
      o.times = std::filesystem::path(value);
    } else if (flag == "--format") {
      format = parse_value(flag, [&] { return posefuse::parse_format(value); });
    } else if (flag == "--groundtruth-format") {
      ref_format = parse_value(flag, [&] { return posefuse::parse_format(value); });
    } else if (flag == "--estimate-format") {
      est_format = parse_value(flag, [&] { return posefuse::parse_format(value); });
    } else if (flag == "--metric") {
      if (value != "ape" && value != "rpe") {
        throw UsageError{"--metric expects ape or rpe, got '" + std::string(value) + "'"};
      }
      o.metric_rpe = value == "rpe";
    } else if (flag == "--align") {
      o.align = parse_value(flag, [&] { return posefuse::parse_alignment(value); });
    } else if (flag == "--pose-relation") {
      o.relation = parse_value(flag, [&] { return posefuse::parse_pose_relation(value); });
    } else if (flag == "--delta") {
      o.delta = parse_double(flag, value);
    } else if (flag == "--delta-unit") {
      o.delta_unit = parse_value(flag, [&] { return posefuse::parse_delta_unit(value); });
    } else if (flag == "--max-time-diff") {
      o.max_time_diff = parse_double(flag, value);
      if (o.max_time_diff < 0.0) throw UsageError{"--max-time-diff must be >= 0"};
    } else {
      throw UsageError{"unknown option '" + std::string(flag) + "'"};
    }
  }
  if (!have_ref || !have_est) throw UsageError{"--groundtruth and --estimate are required"};
  o.ref_format = ref_format.value_or(format.value_or(posefuse::Format::kKitti));
  o.est_format = est_format.value_or(format.value_or(posefuse::Format::kKitti));
  const bool any_kitti =
      o.ref_format == posefuse::Format::kKitti || o.est_format == posefuse::Format::kKitti;
  if (o.times && !any_kitti) throw UsageError{"--times only applies to KITTI files"};
  if (o.ref_format != o.est_format && !o.times) {
    throw UsageError{"comparing a KITTI with a TUM file needs --times for the KITTI one"};
  }
  if (o.delta_unit == posefuse::DeltaUnit::kFrames &&
      (o.delta < 1.0 || o.delta != std::floor(o.delta))) {
    throw UsageError{"--delta in frames must be an integer >= 1"};
  }
  if (o.delta_unit == posefuse::DeltaUnit::kMeters && !(o.delta > 0.0)) {
    throw UsageError{"--delta in metres must be > 0"};
  }
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

void print_json(const Options& o, const posefuse::MetricResult& r) {
  const posefuse::Statistics& s = r.stats;
  std::printf(
      "{\"metric\": \"%s\", \"pose_relation\": \"%s\", \"unit\": \"%s\", \"alignment\": \"%s\", "
      "\"scale\": %.17g, ",
      o.metric_rpe ? "rpe" : "ape", std::string(relation_name(o.relation)).c_str(),
      std::string(posefuse::unit_of(o.relation)).c_str(),
      std::string(posefuse::to_string(o.align)).c_str(), r.alignment.scale);
  if (o.metric_rpe) {
    std::printf("\"delta\": %.17g, \"delta_unit\": \"%s\", ", o.delta,
                o.delta_unit == posefuse::DeltaUnit::kFrames ? "frames" : "m");
  }
  std::printf(
      "\"count\": %zu, \"rmse\": %.17g, \"mean\": %.17g, \"median\": %.17g, \"std\": %.17g, "
      "\"min\": %.17g, \"max\": %.17g, \"sse\": %.17g}\n",
      s.count, s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse);
}

int run(const Options& o) {
  const posefuse::Trajectory ref = load(o.groundtruth, o.ref_format, o.times);
  const posefuse::Trajectory est = load(o.estimate, o.est_format, o.times);
  posefuse::Trajectory ref_sync, est_sync;
  const bool frame_by_frame = o.ref_format == posefuse::Format::kKitti &&
                              o.est_format == posefuse::Format::kKitti && !o.times;
  if (frame_by_frame) {
    if (ref.size() != est.size()) {
      throw posefuse::invalid_argument("reference has " + std::to_string(ref.size()) +
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
  Options options;
  try {
    options = parse_args(argc, argv);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "evaluate_trajectory: %s (see --help)\n", e.message.c_str());
    return 2;
  }
  if (options.help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {  // io_error names file:line; invalid_argument the reason
    std::fprintf(stderr, "evaluate_trajectory: %s\n", e.what());
    return 1;
  }
}

// corridor_fusion — seed 001's corridor experiment.
//
// Scenario: a four-wheel robot drives a 14 m x 9 m corridor loop counter-
// clockwise from point 1 and back. ORB-SLAM alone loses tracking at the
// feature-poor corner 3 (here: its pose first freezes for 3 s, then it is
// lost, and it re-initialises 3 m into the next leg in a new map frame).
// Four methods run on the same data: SLAM alone, odometry alone (wheels +
// IMU, the seed's O_m), the seed's threshold fuser (eq 14-15 as printed) and
// the gated fuser (covariance weighting, gates, re-anchoring). Without
// --log it simulates the run (posefuse/sim/corridor.hpp documents every noise
// figure); with --log DIR it runs on a recorded log folder (wheels.csv,
// imu.csv, slam.csv, robot.txt, optional groundtruth.csv).
//
// Usage: corridor_fusion [--seed N | --log DIR] [--write-log DIR] [--json] [--svg FILE]
// (see --help). Exit status 0 ok, 1 bad data (one line on stderr naming
// file:line of the log file at fault, or an output that cannot be written),
// 2 bad usage. --write-log and --svg are written only after the run
// succeeded, each file through a temporary.
//
// Expected output (default: simulation, seed 1):
//
//   method          loop closure (m)  RMSE (m)  no pose (s)  max yaw err (deg)  max yaw err (deg)
//                                                                  after turns          all poses
//   slam_only                  3.461     2.509         14.4               38.0               39.6
//   odometry_only              2.025     1.063          0.0                3.5                6.5
//   seed_fuser                 1.862     0.968          0.0                2.0              180.0
//   gated_fuser                0.531     0.315          0.0                1.4                2.2
//
//   yaw error after each 90-degree turn (deg; seed 001 reports about 1.9):
//   slam_only          +0.6     lost    +37.9    +38.0
//   odometry_only      +0.3     +0.5     +3.5     +0.4
//   seed_fuser         +0.9     +0.5     +2.0     -0.5
//   gated_fuser        +0.1     +1.1     +1.3     +1.4
//
// i.e. SLAM alone has no pose for 14 s after corner 3 and then reports poses
// in the wrong frame; the gated fuser completes the loop; the seed's fuser
// follows odometry once SLAM is lost and, averaging raw angles near ±180°,
// once reports a heading 180° off ("all poses"). Doubts about a log (see
// posefuse/io/robot_log_checks.hpp) are printed as "warning:" lines on
// standard error and, with --json, listed under "warnings".

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>

#include <apps/cli.hpp>
#include <apps/corridor_runner.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <posefuse/sim/corridor.hpp>
#include <apps/svg.hpp>
#include <posefuse/io/robot_log.hpp>

namespace {

namespace apps = posefuse::apps;

struct Options {
  std::optional<std::uint64_t> seed;
  std::optional<std::filesystem::path> log, write_log, svg;
  bool json = false;
};

/// The options, or nothing when --help was printed.
std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  apps::Parser cli(cmd.program, "[--seed N | --log DIR] [--write-log DIR] [--json] [--svg FILE]",
                   "Seed 001's corridor experiment: SLAM alone, odometry alone, the seed's threshold "
                   "fuser\nand the gated fuser on one simulated or recorded run.");
  cli.integer({.name = "--seed", .value = "N", .help = "simulate the corridor with RNG seed N",
               .default_text = "1"},
              o.seed, std::uint64_t{0});
  cli.input({.name = "--log", .value = "DIR",
            .help = "run on a recorded log folder (wheels.csv, imu.csv, slam.csv,\n"
                    "robot.txt, optional groundtruth.csv)"},
           o.log);
  cli.output({.name = "--write-log", .value = "DIR", .help = "save the simulated log to DIR (simulation only)"},
           o.write_log);
  cli.flag({.name = "--json", .help = "print the figures as JSON instead of the table"}, o.json);
  cli.output({.name = "--svg", .value = "FILE", .help = "write the four paths (and ground truth) as an SVG plot"},
           o.svg);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line of the log file at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (o.log && o.seed) throw apps::usage_error("--seed and --log exclude each other");
  if (o.log && o.write_log)
    throw apps::usage_error("--write-log saves a simulated log; it cannot be used with --log");
  return o;
}

/// `v` with `prec` decimals, or "n/a" when it is not finite.
std::string num(double v, int prec) {
  if (!std::isfinite(v)) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}

void print_table(const posefuse::CorridorRunResult& r, const std::string& source) {
  using posefuse::kCorridorMethodNames;
  std::printf("corridor_fusion: %s, %.1f s, %zu turns (%s)\n\n", source.c_str(), r.duration_s,
              r.turns.size(), r.turns_from_groundtruth ? "from ground truth" : "from odometry; "
              "yaw errors against square corners");
  std::printf("%-14s  %16s  %8s  %11s  %17s  %17s\n", "method", "loop closure (m)", "RMSE (m)",
              "no pose (s)", "max yaw err (deg)", "max yaw err (deg)");
  std::printf("%-14s  %16s  %8s  %11s  %17s  %17s\n", "", "", "", "", "after turns", "all poses");
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& m = r.metrics[k];
    std::printf("%-14s  %16s  %8s  %11.1f  %17s  %17s\n", kCorridorMethodNames[k],
                m.poses ? num(m.loop_closure_error_m, 3).c_str() : "no pose", num(m.rmse_m, 3).c_str(),
                m.time_without_pose_s, num(m.max_yaw_error_deg, 1).c_str(),
                num(m.max_yaw_error_all_deg, 1).c_str());
  }
  std::printf("\nyaw error after each 90-degree turn (deg; seed 001 reports about 1.9):\n");
  for (std::size_t k = 0; k < 4; ++k) {
    std::printf("%-14s", kCorridorMethodNames[k]);
    for (double e : r.metrics[k].yaw_error_after_turn_deg) {
      if (std::isfinite(e)) std::printf("  %+7.1f", e);
      else std::printf("  %7s", "lost");
    }
    std::printf("\n");
  }
  const auto& m = r.metrics;
  std::printf("\nSLAM rows: %d valid (%d tilted), %d lost, %d re-initialisations. Magnetometer: %s.\n",
              r.slam_valid, r.slam_tilted, r.slam_lost, r.slam_reinit, r.magnetometer_note.c_str());
  std::printf("seed fuser: %d SLAM poses averaged (eq 15-a), %d fell back to O_m (eq 15-b).\n",
              r.seed_averaged, r.seed_fallback);
  std::printf("gated fuser: %d SLAM poses fused, %d rejected by the gates, %d map frames anchored.\n",
              r.gated_fused, r.gated_rejected, r.gated_anchors);
  const double so = m[0].loop_closure_error_m, od = m[1].loop_closure_error_m,
               sf = m[2].loop_closure_error_m, gf = m[3].loop_closure_error_m;
  std::printf("\nSLAM alone: %.1f s without a pose, ends %s m from the start. ", m[0].time_without_pose_s,
              num(so, 2).c_str());
  std::printf("Gated fuser: ends %s m from the start (%s than odometry alone, %s m).\n",
              num(gf, 2).c_str(), gf < od ? "better" : "NOT better", num(od, 2).c_str());
  std::printf("Seed fuser: ends %s m from the start — %s than odometry alone.\n", num(sf, 2).c_str(),
              sf < od ? "better" : "worse or no better");
}

/// The figures as JSON (numbers round-trip; a figure that does not exist is null).
void print_json(const posefuse::CorridorRunResult& r, const std::string& source) {
  using Layout = apps::JsonWriter::Layout;
  apps::JsonWriter j(std::cout);
  j.begin_object();
  j.member("source", source).member("duration_s", r.duration_s).member("turns", r.turns.size());
  j.member("turns_from_groundtruth", r.turns_from_groundtruth);
  j.key("methods").begin_object();
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& m = r.metrics[k];
    j.key(posefuse::kCorridorMethodNames[k]).begin_object(Layout::kInline);
    j.member("loop_closure_error", m.loop_closure_error_m).member("rmse", m.rmse_m);
    j.member("time_without_pose_s", m.time_without_pose_s);
    j.member("max_yaw_error_deg", m.max_yaw_error_deg).member("max_yaw_error_all_deg", m.max_yaw_error_all_deg);
    j.key("yaw_error_after_turn_deg").begin_array();
    for (const double e : m.yaw_error_after_turn_deg) j.value(e);
    j.end_array().member("poses", m.poses).end_object();
  }
  j.end_object();
  j.key("slam").begin_object(Layout::kInline);
  j.member("valid", r.slam_valid).member("lost", r.slam_lost).member("reinit", r.slam_reinit);
  j.member("tilted", r.slam_tilted).end_object();
  j.key("seed_fuser").begin_object(Layout::kInline);
  j.member("averaged", r.seed_averaged).member("fallback", r.seed_fallback).end_object();
  j.key("gated_fuser").begin_object(Layout::kInline);
  j.member("fused", r.gated_fused).member("rejected", r.gated_rejected);
  j.member("anchors", r.gated_anchors).end_object();
  j.member("magnetometer_calibrated", r.magnetometer_calibrated);
  j.member("magnetometer_note", r.magnetometer_note);
  j.member("attitude_stale_s", r.attitude_stale_s);
  j.key("warnings").begin_array(Layout::kBlock);
  for (const auto& w : r.warnings) j.value(w);
  j.end_array().end_object().finish();
}

/// The paths of the four methods and the ground truth, x-y in metres.
std::string paths_svg(const posefuse::CorridorRunResult& r, const std::string& source) {
  apps::svg::Plot plot("corridor_fusion: " + source);
  plot.x_axis("x", "m").y_axis("y", "m").equal_aspect();
  if (!r.groundtruth.empty()) plot.line("ground truth", r.groundtruth.positions(), {"#000000", 3.0, {}});
  const char* colours[4] = {"#d62728", "#ff7f0e", "#9467bd", "#1f77b4"};
  for (std::size_t k = 0; k < 4; ++k)
    plot.line(std::string(posefuse::kCorridorMethodNames[k]) + " (loop closure " +
                  num(r.metrics[k].loop_closure_error_m, 2) + " m)",
              r.tracks[k].positions(), {colours[k], 1.5, k == 2 ? "6,3" : ""});
  apps::svg::Document doc(800, 720);
  doc.plot(plot, {0, 0, 800, 720});
  return doc.str();
}

int run(const Options& o) {
  // 1. Compute: read or simulate the log, run the four methods.
  posefuse::RobotLog log;
  std::string source;
  if (o.log) {
    log = posefuse::read_robot_log(*o.log);
    source = "log " + o.log->string();
  } else {
    const std::uint64_t seed = o.seed.value_or(1);
    log = posefuse::sim::simulate_corridor({}, seed).log;
    source = "simulation, seed " + std::to_string(seed);
  }
  const posefuse::CorridorRunResult r = posefuse::run_corridor(log);

  // 2. Write the files (all or none), then the report.
  apps::OutputFiles files;
  if (o.write_log)
    files.add_folder(*o.write_log, [&log](const std::filesystem::path& dir) {
      posefuse::write_robot_log(dir, log);
    });
  if (o.svg) files.add(*o.svg, paths_svg(r, source));
  files.commit();
  if (o.json) print_json(r, source);
  else print_table(r, source);
  // Doubts about the log go to standard error (stdout stays the report).
  std::fflush(stdout);
  for (const auto& w : r.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

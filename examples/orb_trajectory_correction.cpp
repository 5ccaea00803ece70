// orb_trajectory_correction: seed 000's EKF post-processing of a SLAM
// trajectory on the road plane, with the models that go beyond it.
//
// Scenario (seed 000, docs/reproductions.md): ORB-SLAM ran unchanged; its output
// trajectory is filtered on the road plane and the planar RMSE against ground
// truth is compared before and after (seed 000, Table 1). Three correctors:
//
//   seed000   the seed's EKF exactly: x = [x, y], u = SLAM displacement,
//             z = SLAM position, G = H = I, R (process) and Q (measurement).
//             It returns its input (docs/reproductions.md), so its reduction is 0 %.
//   cv        a constant-velocity EKF (own dynamics) on the SLAM positions.
//   cv+rts    the same run smoothed offline (Rauch-Tung-Striebel).
//
// With no arguments it runs on a built-in synthetic drive (a KITTI-06-like
// 1.2 km loop with heading drift, scale error and 0.35 m position jitter;
// include/posefuse/sim/kitti_like_drive.hpp) and prints:
//
//   estimate     method    RMSE before [m]  RMSE after [m]  reduction   verdict
//   synthetic    seed000             1.150           1.150     0.00 %   returns its input (docs/reproductions.md)
//   synthetic    cv                  1.150           1.143     0.60 %   no real gain
//   synthetic    cv+rts              1.150           1.049     8.72 %   helps
//
// On KITTI 06 none of them reduces the error of ORB-SLAM2 stereo (0.874 m
// before; seed000 0 %, cv -8 %, cv+rts -0.05 %): its error is drift.
//
// On KITTI 06 (kitti/06 of the data folder, docs/programs.md):
//
//   orb_trajectory_correction --groundtruth groundtruth.txt --times times.txt
//       --estimate orbslam2_stereo.txt --estimate cvo_vo.txt --plot kitti06.svg
//
// Options: see --help. Exit status 0 ok, 1 bad data (one line on stderr,
// naming file:line where a file is at fault; also a filter step that was not
// applied or a non-finite result), 2 bad usage. --out and --plot are written
// only when everything was computed, each through a temporary file.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <posefuse/sim/kitti_like_drive.hpp>
#include <apps/svg.hpp>
#include <apps/trajectory_correction.hpp>
#include <posefuse/eval/alignment.hpp>
#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

namespace {

using namespace posefuse;

struct Options {
  std::optional<std::filesystem::path> groundtruth, times, out, plot;
  std::vector<std::filesystem::path> estimates;
  Format format = Format::kKitti;
  Plane plane = Plane::kXZ;
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  Eigen::Matrix2d Q = Eigen::Matrix2d::Identity() * 0.25;
  double cv_q = 1.0;
  double max_time_diff = 0.01;
  Alignment alignment = Alignment::kNone;
  std::string method = "seed000";
  bool json = false;
};

/// "VAR" or "VAR,VAR": a diagonal covariance, each variance finite and > 0.
Eigen::Matrix2d parse_diag(std::string_view text) {
  const auto comma = text.find(',');
  const double a = apps::parse_real(text.substr(0, comma), apps::Domain::kPositive);
  const double b = comma == std::string_view::npos
                       ? a
                       : apps::parse_real(text.substr(comma + 1), apps::Domain::kPositive);
  return Eigen::Vector2d(a, b).asDiagonal();
}

/// The options, or nothing when --help was printed.
std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  apps::Parser cli(cmd.program,
                   "[--groundtruth REF --estimate EST [--estimate EST2 ...]] [options]",
                   "Filters SLAM trajectories on the road plane (seed 000) and compares the planar "
                   "RMSE\nagainst ground truth before and after. Without files it uses a built-in "
                   "synthetic drive.");
  cli.path({.name = "--groundtruth", .value = "FILE", .help = "reference trajectory"},
           o.groundtruth);
  cli.paths({.name = "--estimate", .value = "FILE", .help = "trajectory to correct (repeat for several)"},
            o.estimates);
  cli.custom({.name = "--format", .value = "kitti|tum", .help = "format of all files",
              .default_text = "kitti"},
             [&](std::string_view v) {
               o.format = parse_format(v);
               if (o.format == Format::kEuroc)
                 throw apps::usage_error("expected kitti or tum (EuRoC files: evaluate_trajectory)");
             });
  cli.path({.name = "--times", .value = "FILE",
            .help = "KITTI times.txt for the ground truth and KITTI estimates"},
           o.times);
  cli.custom({.name = "--plane", .value = "xz|xy|yz", .help = "road plane",
              .default_text = "xz: KITTI camera frame"},
             [&](std::string_view v) { o.plane = parse_plane(v); });
  cli.custom({.name = "--R", .value = "VAR[,VAR]", .help = "seed's process noise R = diag",
              .default_text = "0.01 m^2/frame"},
             [&](std::string_view v) { o.R = parse_diag(v); });
  cli.custom({.name = "--Q", .value = "VAR[,VAR]", .help = "seed's measurement noise Q = diag",
              .default_text = "0.25 m^2"},
             [&](std::string_view v) { o.Q = parse_diag(v); });
  cli.real({.name = "--cv-q", .value = "Q", .help = "constant-velocity acceleration noise",
            .unit = "m^2/s^3"},
           o.cv_q, apps::Domain::kPositive);
  cli.custom({.name = "--align", .value = "none|se3|sim3",
              .help = "align each estimate to the ground truth first", .default_text = "none"},
             [&](std::string_view v) { o.alignment = parse_alignment(v); });
  cli.real({.name = "--max-time-diff", .value = "S", .help = "TUM timestamp association tolerance",
            .unit = "s"},
           o.max_time_diff, apps::Domain::kNonNegative);
  cli.custom({.name = "--method", .value = "seed000|cv|cv+rts",
              .help = "corrector whose output --out writes", .default_text = "seed000"},
             [&](std::string_view v) {
               if (v != "seed000" && v != "cv" && v != "cv+rts")
                 throw apps::usage_error("expected seed000, cv or cv+rts, got '" + std::string(v) + "'");
               o.method = std::string(v);
             });
  cli.path({.name = "--out", .value = "PATH",
            .help = "write the corrected trajectory (input format); with several\n"
                    "estimates PATH is a folder of <estimate>_<method> files"},
           o.out);
  cli.path({.name = "--plot", .value = "FILE.svg",
            .help = "paths of the first estimate (truth, raw, corrected) and covariance\n"
                    "over time (seed 000 Fig. 8)"},
           o.plot);
  cli.flag({.name = "--json", .help = "print the results as JSON instead of a table"}, o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (one line on stderr, file:line where a file is at "
               "fault),\n2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;

  if (o.groundtruth.has_value() != !o.estimates.empty())
    throw apps::usage_error("give --groundtruth and at least one --estimate, or neither (synthetic data)");
  if (o.times && o.format == Format::kTum)
    throw apps::usage_error("--times only applies to KITTI files");
  if (cli.given("--method") && !o.out) throw apps::usage_error("--method chooses what --out writes; give --out");
  {
    std::vector<std::pair<std::string, std::filesystem::path>> outputs, inputs;
    if (o.groundtruth) inputs.emplace_back("--groundtruth", *o.groundtruth);
    if (o.times) inputs.emplace_back("--times", *o.times);
    for (const auto& e : o.estimates) inputs.emplace_back("--estimate", e);
    if (o.out && o.estimates.size() <= 1) outputs.emplace_back("--out", *o.out);
    if (o.plot) outputs.emplace_back("--plot", *o.plot);
    apps::refuse_output_over_input(outputs, inputs);
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
  Trajectory groundtruth;  ///< associated with the estimate
  Trajectory estimate;     ///< aligned as requested
  std::vector<Eigen::Vector2d> truth_xy, raw_xy;
  double rmse_before = 0;
  std::vector<MethodResult> methods;
};

/// Throws a data error when `v` is not finite: no inf or nan reaches the output.
void require_finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw apps::data_error(what + " is not finite (" + apps::shortest(v) + ")");
}

void require_finite(const std::vector<Eigen::Vector2d>& points, const std::string& what) {
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!points[k].allFinite())
      throw apps::data_error(what + " is not finite at frame " + std::to_string(k));
}

/// A filter step that was not applied leaves a stale state: reported, not ignored.
void require_applied(const CorrectedPoint& c, const std::string& source, const char* method,
                     std::size_t k) {
  if (c.status != FilterStatus::kApplied)
    throw apps::data_error(source + ": frame " + std::to_string(k) + " (t = " + apps::shortest(c.t) +
                           " s): the " + method + " filter step was not applied (" +
                           to_string(c.status) + ")");
}

EstimateResult correct(std::string name, std::string source, const Trajectory& gt_full,
                       const Trajectory& est_full, const Options& o) {
  EstimateResult r;
  r.name = std::move(name);
  r.source = std::move(source);
  if (o.format == Format::kTum) {
    const AssociatedTrajectories a = associate(gt_full, est_full, o.max_time_diff);
    r.groundtruth = a.ref;
    r.estimate = a.est;
  } else {
    if (gt_full.size() != est_full.size())
      throw apps::data_error(r.source + " has " + std::to_string(est_full.size()) +
                             " poses but the ground truth has " + std::to_string(gt_full.size()));
    r.groundtruth = gt_full;
    r.estimate = est_full;
  }
  if (r.estimate.size() == 0) throw apps::data_error(r.source + " has no poses");
  r.estimate = align_trajectory(r.estimate, r.groundtruth, o.alignment).trajectory;
  r.truth_xy = project_to_plane(r.groundtruth, o.plane);
  r.raw_xy = project_to_plane(r.estimate, o.plane);
  require_finite(r.truth_xy, r.source + ": the ground truth on the road plane");
  require_finite(r.raw_xy, r.source + ": the estimate on the road plane" +
                               std::string(o.alignment == Alignment::kNone ? "" : " after alignment"));
  r.rmse_before = rmse_2d(r.truth_xy, r.raw_xy);
  require_finite(r.rmse_before, r.source + ": the planar RMSE before correction");

  MethodResult seed{"seed000", {}, {}, 0};
  auto seed_pipeline = make_seed000_corrector(o.plane, o.R, o.Q, Eigen::Matrix2d::Identity());
  const double sigma = std::sqrt(0.5 * o.Q.trace());
  auto cv_pipeline = make_constant_velocity_corrector(o.plane, o.cv_q, sigma);
  MethodResult cv{"cv", {}, {}, 0};
  for (std::size_t k = 0; k < r.estimate.size(); ++k) {
    const StampedPose in{r.estimate.t_s[k], r.estimate.poses[k]};
    const CorrectedPoint s = seed_pipeline(in);
    require_applied(s, r.source, "seed000", k);
    seed.points.push_back(s.p);
    seed.variance.push_back(0.5 * s.P.trace());
    const CorrectedPoint c = cv_pipeline(in);
    require_applied(c, r.source, "cv", k);
    cv.points.push_back(c.p);
    cv.variance.push_back(0.5 * c.P.trace());
  }
  MethodResult rts{"cv+rts", {}, {}, 0};
  try {
    for (const auto& b : rts_smooth(cv_pipeline.stage<1>().history())) {
      rts.points.push_back(b.mean.head<2>());
      rts.variance.push_back(0.5 * b.cov.topLeftCorner<2, 2>().trace());
    }
  } catch (const posefuse::invalid_argument& e) {
    throw apps::data_error(r.source + ": cv+rts: " + e.what());
  }
  for (MethodResult* m : {&seed, &cv, &rts}) {
    const std::string what = r.source + ": " + m->name;
    require_finite(m->points, what + " corrected position");
    for (std::size_t k = 0; k < m->variance.size(); ++k)
      require_finite(m->variance[k], what + " variance at frame " + std::to_string(k));
    m->rmse = rmse_2d(r.truth_xy, m->points);
    require_finite(m->rmse, what + " RMSE after correction");
    r.methods.push_back(std::move(*m));
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

std::string verdict(const std::string& method, double before, double after) {
  const std::optional<double> red = reduction_percent(before, after);
  if (!red) return "worse than raw";
  if (method == "seed000" && std::abs(*red) < 1e-6) return "returns its input (docs/reproductions.md)";
  if (*red >= 1.0) return "helps";
  if (*red > -1.0) return "no real gain";
  return "worse than raw";
}

/// Seed 000 Fig. 8: the first frame at which |d(variance)/dframe| < 0.01.
std::pair<std::size_t, double> steady_state(const std::vector<double>& v) {
  for (std::size_t k = 1; k < v.size(); ++k)
    if (std::abs(v[k] - v[k - 1]) < 0.01) return {k, v[k]};
  return {v.size(), v.empty() ? 0.0 : v.back()};
}

/// The estimate with the method's road-plane positions (height, attitude kept).
Trajectory corrected_trajectory(const EstimateResult& r, const MethodResult& m, Plane plane) {
  Trajectory out = r.estimate;
  for (std::size_t k = 0; k < out.size(); ++k) {
    Eigen::Vector3d t = out.poses[k].translation();
    const Eigen::Vector2d& p = m.points[k];
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

void print_json(const Options& o, const std::vector<EstimateResult>& results) {
  const auto [steady_frame, steady_value] = steady_state(results.front().methods[0].variance);
  using Layout = apps::JsonWriter::Layout;
  apps::JsonWriter j(std::cout);
  j.begin_object();
  j.member("plane", to_string(o.plane)).member("alignment", to_string(o.alignment));
  j.key("estimates").begin_array(Layout::kBlock);
  for (const auto& r : results) {
    j.begin_object();
    j.member("name", r.name).member("frames", r.estimate.size()).member("rmse_before", r.rmse_before);
    j.key("methods").begin_array(Layout::kBlock);
    for (const auto& m : r.methods) {
      j.begin_object(Layout::kInline).member("method", m.name).member("rmse_after", m.rmse);
      const std::optional<double> red = reduction_percent(r.rmse_before, m.rmse);
      j.key("reduction_percent");
      if (red) j.value(*red);
      else j.null();
      j.member("verdict", verdict(m.name, r.rmse_before, m.rmse)).end_object();
    }
    j.end_array().end_object();
  }
  j.end_array();
  j.key("seed000_covariance").begin_object(Layout::kInline);
  j.member("initial", results.front().methods[0].variance.front())
      .member("steady", steady_value)
      .member("steady_frame", steady_frame);
  j.end_object().end_object().finish();
}

void print_table(const Options& o, const std::vector<EstimateResult>& results) {
  const auto [steady_frame, steady_value] = steady_state(results.front().methods[0].variance);
  std::printf("Planar RMSE against ground truth (seed 000, Table 1), plane %s, alignment %s\n\n",
              std::string(to_string(o.plane)).c_str(), std::string(to_string(o.alignment)).c_str());
  std::printf("%-22s %-8s %16s %15s %10s   %s\n", "estimate", "method", "RMSE before [m]",
              "RMSE after [m]", "reduction", "verdict");
  for (const auto& r : results) {
    for (const auto& m : r.methods) {
      const std::optional<double> red = reduction_percent(r.rmse_before, m.rmse);
      std::printf("%-22s %-8s %16.3f %15.3f ", r.name.c_str(), m.name.c_str(), r.rmse_before, m.rmse);
      if (red) std::printf("%8.2f %%", *red);
      else std::printf("%10s", "n/a");
      std::printf("   %s\n", verdict(m.name, r.rmse_before, m.rmse).c_str());
    }
  }
  std::printf("\nseed000 position variance trace(P)/2: %.4f m^2 at the first frame, steady "
              "(|dP/dframe| < 0.01) at %.4f m^2 from frame %zu.\n",
              results.front().methods[0].variance.front(), steady_value, steady_frame);
  std::printf("seed000 returns its input whatever R and Q (u = z_t - z_{t-1} cancels the gain; "
              "docs/reproductions.md).\n");
}

int run(const Options& o) {
  // 1. Compute everything; any failure stops here, before an output exists.
  std::vector<EstimateResult> results;
  if (!o.groundtruth) {
    const sim::SyntheticDrive drive = sim::make_kitti_like_drive();
    results.push_back(correct("synthetic", "built-in synthetic drive", drive.groundtruth,
                              drive.estimate, o));
  } else {
    const auto times = o.format == Format::kKitti ? o.times : std::nullopt;
    const Trajectory gt = read_trajectory(*o.groundtruth, o.format, times);
    for (const auto& e : o.estimates)
      results.push_back(
          correct(e.stem().string(), e.string(), gt, read_trajectory(e, o.format, times), o));
  }

  // 2. The output files, in memory (the SVG refuses non-finite numbers).
  apps::OutputFiles files;
  if (o.out) {
    const std::string ext = o.format == Format::kTum ? ".tum" : ".txt";
    std::vector<std::pair<std::string, Trajectory>> corrected;
    for (const auto& r : results) {
      const auto m = std::find_if(r.methods.begin(), r.methods.end(),
                                  [&](const MethodResult& x) { return x.name == o.method; });
      corrected.emplace_back(r.name + "_" + o.method + ext, corrected_trajectory(r, *m, o.plane));
    }
    if (results.size() == 1) {
      files.add_with(*o.out, [t = std::move(corrected.front().second), f = o.format](
                                 const std::filesystem::path& p) { write_trajectory(p, t, f); });
    } else {
      files.add_folder(*o.out, [c = std::move(corrected), f = o.format](
                                   const std::filesystem::path& dir) {
        for (const auto& [name, t] : c) write_trajectory(dir / name, t, f);
      });
    }
  }
  if (o.plot) files.add(*o.plot, plot_svg(results.front(), o.plane));

  // 3. Write the files (all or none), then the report.
  files.commit();
  if (o.json) print_json(o, results);
  else print_table(o, results);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return posefuse::apps::run_main(argc, argv, [](const posefuse::apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o) : 0;
  });
}

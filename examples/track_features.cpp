// track_features: the image front end (include/posefuse/frontend/,
// docs/frontend.md) on a EuRoC camera folder: KLT feature tracks written as
// t_ns,feature_id,u,v csv (docs/feature-tracks.md), the input of
// visual_inertial_odometry --tracks.
//
//   track_features --images mav0/cam0 --out cam0_tracks.csv
//
// The folder holds data.csv (#timestamp [ns],filename), data/*.png and
// sensor.yaml (the camera; --camera names another). Prints one summary
// (or --json one object with per-frame counts and timing): frames, features
// per frame, track lengths, milliseconds per frame and per part. Built only
// with OpenCV. Exit status: 0 ok, 1 bad data (file:line where a file is at
// fault), 2 bad usage.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/output_file.hpp>
#include <apps/progress.hpp>
#include <posefuse/frontend/image_folder.hpp>
#include <posefuse/frontend/klt_tracker.hpp>
#include <posefuse/io/feature_tracks.hpp>
#include <posefuse/vio/camera.hpp>

namespace {

namespace apps = posefuse::apps;
namespace fe = posefuse::frontend;

struct Options {
  std::optional<std::filesystem::path> images, out, camera;
  fe::KltTrackerOptions tracker;
  bool json = false;
};

std::optional<Options> parse_options(const apps::CommandLine& cmd) {
  Options o;
  fe::KltTrackerOptions& t = o.tracker;
  apps::Parser cli(cmd.program, "--images DIR --out FILE [options]",
                   "Tracks features through the images of a EuRoC camera folder (data.csv, data/, "
                   "sensor.yaml) with the KLT front end and writes them as t_ns,feature_id,u,v csv "
                   "for visual_inertial_odometry --tracks.");
  cli.input({.name = "--images", .value = "DIR", .help = "EuRoC camera folder: data.csv and data/*.png (required)"},
            o.images);
  cli.output({.name = "--out", .value = "FILE", .help = "feature-track csv to write (required)"}, o.out);
  cli.input({.name = "--camera", .value = "YAML", .help = "EuRoC camera sensor.yaml", .default_text = "DIR/sensor.yaml"},
            o.camera);
  cli.integer({.name = "--max-features", .value = "N", .help = "features kept per frame at most"}, t.max_features, 1,
              100000);
  cli.integer({.name = "--min-distance", .value = "PX", .help = "smallest distance between two features",
               .unit = "px"},
              t.min_distance_px, 0, 10000);
  cli.real_in({.name = "--ransac-px", .value = "PX",
               .help = "RANSAC inlier distance to the epipolar line\n(on a pinhole of focal length 460 px)",
               .unit = "px"},
              t.ransac_threshold_px, 1e-3, 1000.0);
  cli.flag({.name = "--clahe", .help = "equalise each image by CLAHE before tracking"}, t.clahe);
  cli.flag({.name = "--json", .help = "print one JSON object (with per-frame counts and timing)\ninstead of the summary"},
           o.json);
  cli.epilogue("Exit status: 0 ok, 1 bad data (file:line where a file is at fault), 2 bad usage.");
  if (!cli.parse(cmd)) return std::nullopt;
  if (!o.images) throw apps::usage_error("--images is required");
  if (!o.out) throw apps::usage_error("--out is required");
  // The parser refuses --out equal to --images; it must not name a file the
  // run reads inside the folder either.
  const std::filesystem::path out_key = apps::path_key(*o.out);
  if (out_key == apps::path_key(*o.images / "data.csv") ||
      (!o.camera && out_key == apps::path_key(*o.images / "sensor.yaml")) ||
      out_key.parent_path() == apps::path_key(*o.images / "data"))
    throw apps::usage_error("--out " + o.out->string() + " names a file that --images " + o.images->string() +
                            " reads");
  t.validate();  // every field is bounded by its flag above; a failure here is a bug
  return o;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 == 1 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

int run(const Options& o, const std::string& program) {
  apps::TerminalProgress progress(program);
  const std::filesystem::path yaml = o.camera ? *o.camera : *o.images / "sensor.yaml";
  progress.stage("reading " + yaml.string());
  const posefuse::PinholeRadtan camera = posefuse::read_euroc_camera(yaml);
  progress.stage("reading " + (*o.images / "data.csv").string());
  const fe::EurocImageFolder folder(*o.images, camera.width, camera.height);

  fe::KltTracker tracker(camera, o.tracker);
  posefuse::FeatureTracks tracks;
  std::vector<fe::KltFrameStats> stats;
  tracks.reserve(folder.size());
  stats.reserve(folder.size());
  for (std::size_t k = 0; k < folder.size(); ++k) {
    progress.update([&] {
      return "frame " + std::to_string(k + 1) + "/" + std::to_string(folder.size()) + ", " +
             std::to_string(tracker.stats().features) + " features";
    });
    const cv::Mat image = folder.image(k);
    stats.push_back(tracker.track(folder.entries()[k].t_ns, image));
    tracks.push_back(tracker.frame());
  }

  apps::OutputFiles files;
  files.add_with(*o.out, [&tracks](const std::filesystem::path& p) { posefuse::write_feature_tracks(p, tracks); });
  progress.stage("writing " + o.out->string());
  files.commit();
  progress.clear();

  // Track lengths: frames each id was seen in.
  std::unordered_map<std::uint64_t, int> length;
  std::size_t observations = 0;
  for (const posefuse::TrackFrame& f : tracks) {
    observations += f.features.size();
    for (const posefuse::FeatureObservation& x : f.features) ++length[x.id];
  }
  std::vector<double> lengths, per_frame, ms, ms_klt, ms_ransac, ms_detect;
  for (const auto& [id, n] : length) lengths.push_back(n);
  std::size_t rejected = 0, tracked = 0, lost_klt = 0, lost_border = 0;
  int fewest = o.tracker.max_features;
  for (const fe::KltFrameStats& s : stats) {
    per_frame.push_back(s.features);
    fewest = std::min(fewest, s.features);
    ms.push_back(s.ms_total);
    ms_klt.push_back(s.ms_klt);
    ms_ransac.push_back(s.ms_ransac);
    ms_detect.push_back(s.ms_detect);
    rejected += std::size_t(s.rejected_ransac);
    tracked += std::size_t(s.tracked);
    lost_klt += std::size_t(s.lost_klt);
    lost_border += std::size_t(s.lost_border);
  }
  const double longest = lengths.empty() ? 0.0 : *std::max_element(lengths.begin(), lengths.end());

  if (o.json) {
    apps::JsonWriter j(std::cout);
    j.begin_object();
    j.member("frames", stats.size()).member("observations", observations);
    j.member("features_per_frame", mean(per_frame)).member("fewest_features", fewest);
    j.member("tracks", lengths.size()).member("mean_track_length", mean(lengths));
    j.member("median_track_length", median(lengths)).member("longest_track", longest);
    j.member("tracked", tracked).member("lost_klt", lost_klt).member("lost_border", lost_border);
    j.member("rejected_ransac", rejected);
    j.member("ms_per_frame", mean(ms)).member("ms_klt", mean(ms_klt));
    j.member("ms_ransac", mean(ms_ransac)).member("ms_detect", mean(ms_detect));
    j.key("per_frame").begin_array(apps::JsonWriter::Layout::kBlock);
    for (const fe::KltFrameStats& s : stats) {
      j.begin_object(apps::JsonWriter::Layout::kInline);
      j.member("t_ns", s.t_ns).member("features", s.features).member("tracked", s.tracked);
      j.member("detected", s.detected).member("lost_klt", s.lost_klt).member("lost_border", s.lost_border);
      j.member("rejected_ransac", s.rejected_ransac).member("dropped_min_distance", s.dropped_min_distance);
      j.member("ms", s.ms_total).member("ms_klt", s.ms_klt).member("ms_ransac", s.ms_ransac);
      j.member("ms_detect", s.ms_detect);
      j.end_object();
    }
    j.end_array();
    j.end_object().finish();
  } else {
    std::printf("%zu frames, %.1f features per frame (fewest %d, at most %d), %zu observations\n", stats.size(),
                mean(per_frame), fewest, o.tracker.max_features, observations);
    std::printf("%zu tracks: mean length %.1f frames, median %.1f, longest %.0f\n", lengths.size(), mean(lengths),
                median(lengths), longest);
    std::printf("kept by tracking %zu; lost by KLT %zu, at the border %zu; rejected by RANSAC %zu\n", tracked,
                lost_klt, lost_border, rejected);
    std::printf("%.2f ms per frame: KLT %.2f, RANSAC %.2f, detection %.2f\n", mean(ms), mean(ms_klt),
                mean(ms_ransac), mean(ms_detect));
    std::printf("wrote %s\n", o.out->string().c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    const std::optional<Options> o = parse_options(cmd);
    return o ? run(*o, cmd.program) : 0;
  });
}

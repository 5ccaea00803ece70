// The evaluate_trajectory example end to end: its JSON is valid and its
// numbers equal the library's, and bad input exits with 2 (usage) or 1
// (data, naming file:line) and one line on stderr. Skipped visibly when the
// example has not been built.
#include <catch2/catch.hpp>

#include <filesystem>
#include <iterator>
#include <numbers>
#include <sstream>
#include <fstream>
#include <string>
#include <utility>

#include <posefuse/eval/metrics.hpp>
#include <posefuse/eval/trajectory_filters.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

#include "support/synthetic_trajectory.hpp"
#include "support/run_program.hpp"
#include "support/xml_check.hpp"

namespace {

using posefuse::test::count_lines;
using posefuse::test::Json;
using posefuse::test::Run;
using posefuse::test::run;

}  // namespace

TEST_CASE("Evaluate CLI: JSON output equals the library and errors exit cleanly", "[eval][cli]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(400, 21, 100.0);
  posefuse::Trajectory est = posefuse::test::perturb(ref, 0.3, 0.01, 22);
  for (double& t : est.t_s) t += 0.004;  // within the default 10 ms
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  posefuse::write_tum(dir.path() / "est.tum", est);
  const std::string files = "--groundtruth '" + (dir.path() / "ref.tum").string() +
                            "' --estimate '" + (dir.path() / "est.tum").string() + "' --format tum";

  const posefuse::Trajectory ref_read = posefuse::read_tum(dir.path() / "ref.tum");
  const posefuse::Trajectory est_read = posefuse::read_tum(dir.path() / "est.tum");
  const posefuse::AssociatedTrajectories sync = posefuse::associate(ref_read, est_read);

  SECTION("APE, SE(3)") {
    const Run r = run(exe, files + " --align se3 --json", dir);
    REQUIRE(r.status == 0);
    CHECK(r.err.empty());
    CHECK(count_lines(r.out) == 1);  // one object on one line
    const auto lib = posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation,
                                   posefuse::Alignment::kSE3);
    const Json j = Json::parse(r.out);
    CHECK(j["metric"].string() == "ape");
    CHECK(j["pose_relation"].string() == "trans");
    CHECK(j["unit"].string() == "m");
    CHECK(j["alignment"].string() == "se3");
    CHECK(j["rmse"].number() == lib.stats.rmse);  // round-trip digits: bit-exact
    CHECK(j["median"].number() == lib.stats.median);
    CHECK(j["std"].number() == lib.stats.std);
    CHECK(j["sse"].number() == lib.stats.sse);
    CHECK(j["scale"].number() == lib.alignment.scale);
    CHECK(j["count"].number() == 400.0);
    CHECK_FALSE(j.has("delta"));
  }
  SECTION("RPE angle, 10 m, table output") {
    const Run r =
        run(exe, files + " --metric rpe --delta 10 --delta-unit m --pose-relation angle_deg", dir);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("RPE w.r.t. rotation angle in degrees (deg)") != std::string::npos);
    CHECK(r.out.find("rmse") != std::string::npos);
    const Run js =
        run(exe, files + " --metric rpe --delta 10 --delta-unit m --pose-relation angle_deg --json", dir);
    REQUIRE(js.status == 0);
    const Json j = Json::parse(js.out);
    CHECK(j["metric"].string() == "rpe");
    CHECK(j["delta"].number() == 10.0);
    CHECK(j["delta_unit"].string() == "m");
    CHECK(j["unit"].string() == "deg");
  }
  SECTION("usage errors exit 2 with one line") {
    for (const std::string& args :
         {std::string(""), files + " --align affine", files + " --delta 0", files + " --delta 1.5",
          files + " --delta 1e400", files + " --delta-unit km", files + " --times x",
          files + " extra", files + " --max-time-diff -0.1", files + " --max-time-diff nan",
          files + " --metric xyz", files + " --estimate-format csv", files + " --json=yes",
          files + " --pose-relation", std::string("--groundtruth x --estimate y --groundtruth z")}) {
      INFO(args);
      const Run r = run(exe, args, dir);
      CHECK(r.status == 2);
      CHECK(count_lines(r.err) == 1);
      CHECK(r.err.rfind("evaluate_trajectory: ", 0) == 0);
      CHECK(r.err.find("(try --help)") != std::string::npos);
      CHECK(r.out.empty());
    }
    const Run help = run(exe, files + " --help", dir);
    CHECK(help.status == 0);
    CHECK(help.out.rfind("usage: evaluate_trajectory --groundtruth REF --estimate EST", 0) == 0);
    CHECK(help.out.find("--max-time-diff S") != std::string::npos);
  }
  SECTION("data errors exit 1 and name file:line") {
    std::ofstream(dir.path() / "bad.tum") << "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0\n";
    const Run r = run(exe,
                      "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                          "' --estimate '" + (dir.path() / "bad.tum").string() + "'",
                      dir);
    CHECK(r.status == 1);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.find("bad.tum:2: expected 8") != std::string::npos);
    CHECK(r.out.empty());
    // An empty input names its file (it used to pass as 0 poses), and an
    // endless one without line ends stops at the line-length cap.
    std::ofstream(dir.path() / "empty.tum") << "# no poses\n";
    for (const auto& [gt, message] :
         {std::pair<std::string, std::string>{(dir.path() / "empty.tum").string(),
                                              "empty.tum: no poses"},
          {"/dev/zero", "/dev/zero:1: line longer than 1048576 bytes"}}) {
      INFO(gt);
      const Run e = run(exe,
                        "--format tum --groundtruth '" + gt + "' --estimate '" +
                            (dir.path() / "ref.tum").string() + "'",
                        dir);
      CHECK(e.status == 1);
      CHECK(count_lines(e.err) == 1);
      CHECK(e.err.rfind("evaluate_trajectory: ", 0) == 0);
      CHECK(e.err.find(message) != std::string::npos);
      CHECK(e.out.empty());
    }
    const Run far = run(exe, files + " --max-time-diff 0.001", dir);
    CHECK(far.status == 1);
    CHECK(far.err.find("found no matching timestamps") != std::string::npos);
  }
}

TEST_CASE("Evaluate CLI: evo options reach the library unchanged", "[eval][cli][evo-options]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli-evo");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(300, 31, 1000.0);
  posefuse::Trajectory est = posefuse::test::perturb(ref, 0.2, 0.01, 32);
  for (double& t : est.t_s) t += 0.25;  // a 0.25 s clock offset: needs --t-offset
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  posefuse::write_tum(dir.path() / "est.tum", est);
  const std::string files = "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                            "' --estimate '" + (dir.path() / "est.tum").string() + "' --json";
  const posefuse::Trajectory ref_read = posefuse::read_tum(dir.path() / "ref.tum");
  const posefuse::Trajectory est_read = posefuse::read_tum(dir.path() / "est.tum");
  const posefuse::AssociatedTrajectories sync = posefuse::associate(ref_read, est_read, 0.01, -0.25);
  REQUIRE(sync.ref.size() == 300);

  const auto rmse_of = [&](const std::string& args) {
    const Run r = run(exe, files + " --t-offset -0.25 " + args, dir);
    INFO(args << "\n" << r.err);
    REQUIRE(r.status == 0);
    return Json::parse(r.out)["rmse"].number();
  };
  SECTION("without --t-offset nothing matches, and the message says why") {
    const Run r = run(exe, files, dir);
    CHECK(r.status == 1);
    CHECK(r.err.find("found no matching timestamps") != std::string::npos);
  }
  SECTION("alignment options") {
    posefuse::AlignmentOptions a;
    a.alignment = posefuse::Alignment::kScale;
    CHECK(rmse_of("--align scale") ==
          posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation, a).stats.rmse);
    a.alignment = posefuse::Alignment::kSE3;
    a.n_to_align = 50;
    CHECK(rmse_of("--align se3 --n-to-align 50") ==
          posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation, a).stats.rmse);
    a.alignment = posefuse::Alignment::kPosYaw;
    a.n_to_align = 0;
    CHECK(rmse_of("--align posyaw") ==
          posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation, a).stats.rmse);
    a = {};
    a.align_origin = true;
    CHECK(rmse_of("--align-origin") ==
          posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation, a).stats.rmse);
    a.project_to_plane = posefuse::Plane::kXZ;
    CHECK(rmse_of("--align-origin --project-to-plane xz") ==
          posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation, a).stats.rmse);
  }
  SECTION("RPE options") {
    posefuse::RpeOptions o;
    o.relation = posefuse::PoseRelation::kPointDistanceErrorRatio;
    o.delta = 20.0;
    o.delta_unit = posefuse::DeltaUnit::kMeters;
    o.all_pairs = true;
    o.delta_tol = 0.05;
    CHECK(rmse_of("--metric rpe --pose-relation point_distance_error_ratio --delta 20 "
                  "--delta-unit m --all-pairs --delta-tol 0.05") ==
          posefuse::rpe(sync.ref, sync.est, o).stats.rmse);
    o = {};
    o.relation = posefuse::PoseRelation::kRotationPart;
    o.delta = 5.0;
    o.delta_unit = posefuse::DeltaUnit::kDegrees;
    CHECK(rmse_of("--metric rpe --pose-relation rot_part --delta 5 --delta-unit deg") ==
          posefuse::rpe(sync.ref, sync.est, o).stats.rmse);
  }
  SECTION("selection before association: time range, down-sampling, motion filter") {
    const posefuse::Trajectory ranged = posefuse::reduce_to_time_range(ref_read, 1010.0, 1020.0);
    const auto s1 = posefuse::associate(ranged, est_read, 0.01, -0.25);
    CHECK(rmse_of("--t-start 1010 --t-end 1020") == posefuse::ape(s1.ref, s1.est).stats.rmse);
    const auto s2 = posefuse::associate(posefuse::downsample(ref_read, 40),
                                        posefuse::downsample(est_read, 40), 0.01, -0.25);
    CHECK(rmse_of("--downsample 40") == posefuse::ape(s2.ref, s2.est).stats.rmse);
    const double deg = std::numbers::pi / 180.0;
    const auto s3 = posefuse::associate(posefuse::motion_filter(ref_read, 2.0, 5.0 * deg),
                                        posefuse::motion_filter(est_read, 2.0, 5.0 * deg), 0.01,
                                        -0.25);
    CHECK(rmse_of("--motion-filter 2,5") == posefuse::ape(s3.ref, s3.est).stats.rmse);
    const Run none = run(exe, files + " --t-offset -0.25 --t-start 5000", dir);
    CHECK(none.status == 1);
    CHECK(none.err.find("no pose between --t-start and --t-end") != std::string::npos);
  }
  SECTION("--save-results keeps statistics, per-pose errors and options") {
    const auto out = dir.path() / "res.json";
    const Run r = run(exe, files + " --t-offset -0.25 --align se3 --save-results '" + out.string() + "'", dir);
    REQUIRE(r.status == 0);
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const Json j = Json::parse(text);
    const auto lib = posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation,
                                   posefuse::Alignment::kSE3);
    CHECK(j["rmse"].number() == lib.stats.rmse);
    REQUIRE(j["errors"].array().size() == 300);
    CHECK(j["errors"][17].number() == lib.errors[17]);
    CHECK(j["stamps_s"][17].number() == sync.ref.t_s[17]);
    CHECK(j["options"]["t_offset_s"].number() == -0.25);
    CHECK(j["options"]["duplicates"].string() == "first");
  }
  SECTION("usage errors for the new options exit 2") {
    for (const std::string& args :
         {files + " --align-origin --align se3", files + " --n-to-align 10",
          files + " --n-to-align 2 --align se3", files + " --pose-relation point_distance_error_ratio",
          files + " --t-start 5 --t-end 4", files + " --downsample 0", files + " --motion-filter 1",
          files + " --motion-filter 1,-2", files + " --duplicates all", files + " --delta-tol -1"}) {
      INFO(args);
      const Run r = run(exe, args, dir);
      CHECK(r.status == 2);
      CHECK(count_lines(r.err) == 1);
    }
  }
}

TEST_CASE("Evaluate CLI: repeated stamps, byte-order marks and stamp units", "[eval][cli][input-policy]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli-input");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(50, 41, 100.0);
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  // The estimate repeats the stamp of its line 11 twice (lines 12 and 13).
  std::ifstream in(dir.path() / "ref.tum");
  std::string line, text;
  int n = 0;
  while (std::getline(in, line)) {
    text += line + "\n";
    if (++n == 11) text += line + "\n" + line + "\n";
  }
  std::ofstream(dir.path() / "dup.tum") << text;
  const std::string files = "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                            "' --estimate '" + (dir.path() / "dup.tum").string() + "'";
  const Run first = run(exe, files + " --json", dir);
  REQUIRE(first.status == 0);
  CHECK(count_lines(first.err) == 1);
  CHECK(first.err.rfind("warning: " + (dir.path() / "dup.tum").string() + ":12: 2 pose(s) with a repeated timestamp dropped", 0) == 0);
  CHECK(Json::parse(first.out)["count"].number() == 50.0);
  CHECK(Json::parse(first.out)["rmse"].number() == 0.0);
  const Run last = run(exe, files + " --duplicates last --json", dir);
  CHECK(last.status == 0);
  // keep (evo): the repeats are in the longer file here, so each reference
  // stamp still pairs with the first pose of the run: 50 pairs, as first.
  const Run keep = run(exe, files + " --duplicates keep --json", dir);
  REQUIRE(keep.status == 0);
  CHECK(keep.err.rfind("warning: " + (dir.path() / "dup.tum").string() + ":12: 2 pose(s) with a repeated timestamp kept", 0) == 0);
  CHECK(Json::parse(keep.out)["count"].number() == 50.0);
  {
    // A shorter estimate with the repeats: under keep every repeated line is
    // a pair of its own (evo's association walks the shorter file).
    std::istringstream all(text);
    std::string short_text;
    for (int k = 0; k < 33 && std::getline(all, line); ++k) short_text += line + "\n";  // a header, 32 poses
    std::ofstream(dir.path() / "dup_short.tum") << short_text;
    const std::string short_files = "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                                    "' --estimate '" + (dir.path() / "dup_short.tum").string() + "' --json";
    const Run kept = run(exe, short_files + " --duplicates keep", dir);
    REQUIRE(kept.status == 0);
    CHECK(Json::parse(kept.out)["count"].number() == 32.0);
    CHECK(Json::parse(kept.out)["rmse"].number() == 0.0);
    const Run dropped = run(exe, short_files, dir);
    REQUIRE(dropped.status == 0);
    CHECK(Json::parse(dropped.out)["count"].number() == 30.0);
  }
  const Run refused = run(exe, files + " --duplicates error", dir);
  CHECK(refused.status == 1);
  CHECK(refused.err.find("dup.tum:12: timestamp") != std::string::npos);
  CHECK(refused.err.find("repeats the previous one") != std::string::npos);
  CHECK(refused.err.find("(--duplicates)") != std::string::npos);  // this program has the flag
  CHECK(count_lines(refused.err) == 1);

  // A byte-order mark in front of the first stamp.
  std::ofstream(dir.path() / "bom.tum") << "\xEF\xBB\xBF" << text;
  const Run bom = run(exe, "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                               "' --estimate '" + (dir.path() / "bom.tum").string() + "' --json",
                      dir);
  CHECK(bom.status == 0);

  // Nanosecond stamps against seconds: the error says so.
  posefuse::Trajectory ns = ref;
  for (double& t : ns.t_s) t *= 1e9;
  posefuse::write_tum(dir.path() / "ns.tum", ns);
  const Run units = run(exe, "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                                 "' --estimate '" + (dir.path() / "ns.tum").string() + "'",
                        dir);
  CHECK(units.status == 1);
  CHECK(units.err.find("is one file in ns and the other in s?") != std::string::npos);
  // Same unit, another origin: the error suggests --t-offset.
  posefuse::Trajectory shifted = ref;
  for (double& t : shifted.t_s) t += 5000.0;
  posefuse::write_tum(dir.path() / "shifted.tum", shifted);
  const Run origin = run(exe, "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                                  "' --estimate '" + (dir.path() / "shifted.tum").string() + "'",
                         dir);
  CHECK(origin.status == 1);
  CHECK(origin.err.find("different time origins? A constant offset is given with --t-offset") !=
        std::string::npos);
}

TEST_CASE("Evaluate CLI: --plot draws both views as well-formed SVG", "[eval][cli][plot]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli-plot");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(200, 51, 10.0);
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  posefuse::write_tum(dir.path() / "est.tum", posefuse::test::perturb(ref, 0.3, 0.01, 52));
  const std::string files = "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                            "' --estimate '" + (dir.path() / "est.tum").string() + "'";
  for (const std::string& extra : {std::string(" --align se3"), std::string(" --metric rpe --delta 5 --plot-mode xz")}) {
    INFO(extra);
    const auto svg = dir.path() / "plot.svg";
    const Run r = run(exe, files + extra + " --plot '" + svg.string() + "'", dir);
    REQUIRE(r.status == 0);
    const std::string text = posefuse::test::slurp(svg);
    CHECK(posefuse::test::xml_problem(text).empty());
    CHECK(posefuse::test::xml_problem(text + "<g>") == "more than one root element");  // the checker bites
    CHECK(text.find(">reference</text>") != std::string::npos);
    CHECK(text.find(">t (s)</text>") != std::string::npos);
    CHECK(text.find(">rmse ") != std::string::npos);
    CHECK(text.find("estimate, error ") != std::string::npos);
    CHECK(text.find("font-family") != std::string::npos);
  }
  CHECK(posefuse::test::xml_problem("<svg a=\"1\" a=\"2\"/>") == "attribute a twice in <svg");
  CHECK(posefuse::test::xml_problem("<svg><g></svg>") == "</svg> does not close the open element");
  CHECK(posefuse::test::xml_problem("<svg>a & b</svg>") == "unterminated entity");
}

TEST_CASE("Evaluate CLI: an estimate with covariance columns reports NEES", "[eval][cli][nees]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli-nees");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(100, 71, 10.0);
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  // Every estimate pose is 0.1 m off along x with covariance 0.01 I (6x6):
  // NEES = 0.1^2 / 0.01 = 1 at every pose.
  std::ofstream est(dir.path() / "est.tum");
  est.precision(17);
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Eigen::Vector3d p = ref.poses[k].translation() + Eigen::Vector3d(0.1, 0, 0);
    const Eigen::Quaterniond q(ref.poses[k].linear());
    est << ref.t_s[k] << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << q.x() << ' '
        << q.y() << ' ' << q.z() << ' ' << q.w();
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) est << (i == j ? " 0.01" : " 0");
    est << '\n';
  }
  est.close();
  const std::string files = "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                            "' --estimate '" + (dir.path() / "est.tum").string() + "'";
  const Run r = run(exe, files + " --json", dir);
  REQUIRE(r.status == 0);
  const Json j = Json::parse(r.out);
  CHECK(j["nees_dim"].number() == 6.0);
  CHECK(j["nees_mean"].number() == Approx(1.0).epsilon(1e-9));
  CHECK(j["nees_consistent"].boolean() == false);  // 1 is far below 6: covariance too large
  const Run table = run(exe, files, dir);
  CHECK(table.out.find("underconfident, covariance too large") != std::string::npos);
  const Run rpe = run(exe, files + " --metric rpe --json", dir);
  CHECK_FALSE(Json::parse(rpe.out).has("nees_mean"));  // NEES is an APE check
}

TEST_CASE("compare_results: tabulates saved results and ranks comparable ones", "[eval][cli][compare]") {
  POSEFUSE_REQUIRE_EXAMPLE(eval, "evaluate_trajectory");
  POSEFUSE_REQUIRE_EXAMPLE(exe, "compare_results");
  posefuse::test::TempDir dir("cli-compare");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(150, 81, 10.0);
  posefuse::write_tum(dir.path() / "ref.tum", ref);
  posefuse::write_tum(dir.path() / "good.tum", posefuse::test::perturb(ref, 0.1, 0.01, 82));
  posefuse::write_tum(dir.path() / "bad.tum", posefuse::test::perturb(ref, 0.5, 0.01, 83));
  const auto save = [&](const std::string& est, const std::string& name, const std::string& extra) {
    const auto out = dir.path() / (name + ".json");
    const Run r = run(eval, "--format tum --groundtruth '" + (dir.path() / "ref.tum").string() +
                                "' --estimate '" + (dir.path() / (est + ".tum")).string() +
                                "' --save-results '" + out.string() + "'" + extra,
                      dir);
    REQUIRE(r.status == 0);
    return out;
  };
  const auto good = save("good", "good", ""), bad = save("bad", "bad", "");
  const Run r = run(exe, "--result '" + bad.string() + "' --result '" + good.string() + "' --json", dir);
  REQUIRE(r.status == 0);
  const Json j = Json::parse(r.out);
  REQUIRE(j.array().size() == 2);
  CHECK(j[0]["name"].string() == "bad");
  CHECK(j[1]["rmse"].number() == Json::parse(posefuse::test::slurp(good))["rmse"].number());
  const Run table = run(exe, "--result '" + bad.string() + "' --result '" + good.string() +
                                 "' --label B,G", dir);
  CHECK(table.out.find("lowest rmse: G") != std::string::npos);
  CHECK(table.err.empty());
  // A different metric is listed but not ranked.
  const auto rpe = save("good", "good_rpe", " --metric rpe");
  const Run mixed = run(exe, "--result '" + good.string() + "' --result '" + rpe.string() + "'", dir);
  CHECK(mixed.status == 0);
  CHECK(mixed.err.rfind("warning: the results measure different metrics", 0) == 0);
  CHECK(mixed.out.find("lowest rmse") == std::string::npos);
  // Errors: no result (usage), a file that is not a result (data, named).
  CHECK(run(exe, "", dir).status == 2);
  CHECK(run(exe, "--result '" + good.string() + "' --label a,b", dir).status == 2);
  std::ofstream(dir.path() / "x.json") << "{\"rmse\": 1}";
  const Run broken = run(exe, "--result '" + (dir.path() / "x.json").string() + "'", dir);
  CHECK(broken.status == 1);
  CHECK(broken.err.find("x.json: not a saved result") != std::string::npos);
}

TEST_CASE("Evaluate CLI: formats are detected (EuRoC included) and printed", "[eval][cli][detect]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli-detect");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(120, 91, 1403715273.0);
  posefuse::write_tum(dir.path() / "est.tum", posefuse::test::perturb(ref, 0.1, 0.01, 92));
  // The reference as a EuRoC ground truth (ns stamps, q w x y z), with four
  // repeated stamps as in evo's V102 test file.
  std::ofstream csv(dir.path() / "gt.csv");
  csv << "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
  csv.precision(17);
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const Eigen::Vector3d p = ref.poses[k].translation();
    const Eigen::Quaterniond q(ref.poses[k].linear());
    const long long t_ns = std::llround(ref.t_s[k] * 1e9);
    for (int copy = 0; copy < (k % 30 == 5 ? 2 : 1); ++copy)
      csv << t_ns << ',' << p.x() << ',' << p.y() << ',' << p.z() << ',' << q.w() << ',' << q.x()
          << ',' << q.y() << ',' << q.z() << '\n';
  }
  csv.close();
  const std::string files = "--groundtruth '" + (dir.path() / "gt.csv").string() + "' --estimate '" +
                            (dir.path() / "est.tum").string() + "'";
  const Run r = run(exe, files + " --align se3 --json", dir);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const Json j = Json::parse(r.out);
  CHECK(j["groundtruth_format"].string() == "euroc");
  CHECK(j["estimate_format"].string() == "tum");
  CHECK(j["formats_detected"].boolean());
  CHECK(j["count"].number() == 120.0);
  CHECK(r.err.find("4 pose(s) with a repeated timestamp dropped") != std::string::npos);
  const Run table = run(exe, files, dir);
  CHECK(table.out.find("files  groundtruth euroc (detected), estimate tum (detected)") != std::string::npos);
  const Run given = run(exe, files + " --groundtruth-format euroc --estimate-format tum", dir);
  CHECK(given.out.find("files  groundtruth euroc (given), estimate tum (given)") != std::string::npos);
  // Content that fits no format, or two, is an error, not a guess.
  std::ofstream(dir.path() / "odd.txt") << "1 2 3 4 5 6 7\n";
  const Run odd = run(exe, "--groundtruth '" + (dir.path() / "odd.txt").string() + "' --estimate '" +
                               (dir.path() / "est.tum").string() + "'", dir);
  CHECK(odd.status == 1);
  CHECK(odd.err.find("odd.txt:1: cannot tell the format: 7 whitespace-separated fields") != std::string::npos);
}

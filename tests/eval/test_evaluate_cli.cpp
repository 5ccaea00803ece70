// The evaluate_trajectory example end to end: its JSON is valid and its
// numbers equal the library's, and bad input exits with 2 (usage) or 1
// (data, naming file:line) and one line on stderr. Skipped visibly when the
// example has not been built.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

#include "support/synthetic_trajectory.hpp"
#include "support/run_program.hpp"

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

// The evaluate_trajectory example end to end: its JSON numbers equal the
// library's, and bad input exits with 2 (usage) or 1 (data) and one line
// on stderr. Skipped visibly when the example has not been built.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include <posefuse/eval/metrics.hpp>
#include <posefuse/io/association.hpp>
#include <posefuse/io/formats.hpp>

#include "support/synthetic_trajectory.hpp"
#include "support/run_program.hpp"

namespace {

using posefuse::test::Run;
using posefuse::test::run;

double json_number(const std::string& json, const std::string& key) {
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = json.find(tag);
  REQUIRE(at != std::string::npos);
  return std::stod(json.substr(at + tag.size()));
}

std::size_t count_lines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

}  // namespace

TEST_CASE("Evaluate CLI: JSON output equals the library and errors exit cleanly", "[eval][cli]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "evaluate_trajectory");
  posefuse::test::TempDir dir("cli");
  const posefuse::Trajectory ref = posefuse::test::make_vehicle_trajectory(400, 21, 100.0);
  posefuse::Trajectory est = posefuse::test::perturb(ref, 0.3, 0.01, 22);
  for (double& t : est.stamps) t += 0.004;  // within the default 10 ms
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
    const auto lib = posefuse::ape(sync.ref, sync.est, posefuse::PoseRelation::kTranslation,
                                   posefuse::Alignment::kSE3);
    CHECK(json_number(r.out, "rmse") == lib.stats.rmse);  // printed with 17 digits
    CHECK(json_number(r.out, "median") == lib.stats.median);
    CHECK(json_number(r.out, "count") == 400.0);
  }
  SECTION("RPE angle, 10 m, table output") {
    const Run r =
        run(exe, files + " --metric rpe --delta 10 --delta-unit m --pose-relation angle_deg", dir);
    REQUIRE(r.status == 0);
    CHECK(r.out.find("RPE w.r.t. rotation angle in degrees (deg)") != std::string::npos);
    CHECK(r.out.find("rmse") != std::string::npos);
  }
  SECTION("usage errors exit 2 with one line") {
    for (const std::string& args : {std::string(""), files + " --align affine",
                                    files + " --delta 0", files + " --times x", files + " extra"}) {
      INFO(args);
      const Run r = run(exe, args, dir);
      CHECK(r.status == 2);
      CHECK(count_lines(r.err) == 1);
    }
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
    const Run far = run(exe, files + " --max-time-diff 0.001", dir);
    CHECK(far.status == 1);
    CHECK(far.err.find("found no matching timestamps") != std::string::npos);
  }
}

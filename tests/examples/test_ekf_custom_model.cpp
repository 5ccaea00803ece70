// The tutorial example end to end: it builds, its own conformance checks of
// the user's models pass, the EKF beats dead reckoning by far, and what it
// prints is exactly the expected output in its header comment (so the
// tutorial cannot drift from the code).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "support/run_program.hpp"

namespace {
// The lines of the "Expected output" block of the example's header comment.
std::string expected_output_in_header(const std::filesystem::path& source) {
  std::ifstream in(source);
  REQUIRE(in);
  std::string line, out;
  bool in_block = false;
  while (std::getline(in, line)) {
    if (line.rfind("// Expected output", 0) == 0) {
      in_block = true;
      continue;
    }
    if (!in_block) continue;
    if (line == "//") {
      if (!out.empty()) break;  // blank comment line after the block
      continue;
    }
    if (line.rfind("//   ", 0) != 0) break;
    out += line.substr(5) + "\n";
  }
  return out;
}
}  // namespace

TEST_CASE("ekf_custom_model: the tutorial runs and prints its documented output",
          "[examples][tutorial]") {
  POSEFUSE_REQUIRE_EXAMPLE(exe, "ekf_custom_model");
  const posefuse::test::TempDir dir("tutorial");
  const posefuse::test::Run r = posefuse::test::run(exe, "", dir);
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("conformance: Rover ok, BeaconSensor ok") != std::string::npos);
  // The EKF with beacons must do far better than dead reckoning.
  double dead = 0, ekf = 0;
  const auto at = r.out.find("position RMSE: dead reckoning ");
  REQUIRE(at != std::string::npos);
  std::istringstream nums(r.out.substr(at + 30));
  std::string unit, label;
  nums >> dead >> unit >> label >> ekf;
  CHECK(label == "EKF");
  CHECK(ekf > 0);
  CHECK(ekf < dead / 5);
  const std::filesystem::path source =
      std::filesystem::path(POSEFUSE_SOURCE_DIR) / "examples" / "ekf_custom_model.cpp";
  CHECK(r.out == expected_output_in_header(source));
}

// libFuzzer harness: compare_results' reader of saved results (the JSON
// files evaluate_trajectory --save-results writes; read_result in
// examples/compare_results.cpp, through apps/json_read.hpp).
//
// Input: the file. Expected rejection: posefuse::apps::data_error whose
// message starts with the file's path (the program prints it as its one
// error line). Any other exception, a crash or a sanitizer report is a
// finding. Properties of an accepted file: metric, pose relation,
// alignment and unit were read; count is a whole number from 1 to 2^53;
// rmse, mean, median, std, min, max and, when present, nees_mean are
// finite and not negative (what the program's table prints).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "compare_results_reader.hpp"
#include "fuzz_support.hpp"

namespace {

using posefuse_fuzz::require;

void check_figure(double v, const char* name) {
  require(std::isfinite(v) && v >= 0.0, [&] {
    return std::string("read_result accepted ") + name + " = " + posefuse::apps::shortest(v);
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const posefuse_fuzz::ScratchDir dir("compare-results");
  const auto file = dir / "result.json";
  posefuse_fuzz::write_bytes(file, std::string_view(reinterpret_cast<const char*>(data), size));
  posefuse_fuzz::SavedResult r;
  try {
    r = posefuse_fuzz::read_saved_result(file);
  } catch (const posefuse::apps::data_error& e) {
    require(std::string_view(e.what()).rfind(file.string() + ": ", 0) == 0,
            [&] { return std::string("read_result: error without the file's path: ") + e.what(); });
    return 0;
  }
  require(r.count >= 1.0 && r.count == std::floor(r.count) && r.count <= 9007199254740992.0,
          [&] { return "read_result accepted count = " + posefuse::apps::shortest(r.count); });
  check_figure(r.rmse, "rmse");
  check_figure(r.mean, "mean");
  check_figure(r.median, "median");
  check_figure(r.std, "std");
  check_figure(r.min, "min");
  check_figure(r.max, "max");
  if (r.nees_mean) check_figure(*r.nees_mean, "nees_mean");
  return 0;
}

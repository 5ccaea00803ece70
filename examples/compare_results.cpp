// compare_results: tabulates several results saved by
// `evaluate_trajectory --save-results FILE` side by side, as evo_res does.
//
// Scenario: two estimators on KITTI 06, each evaluated and saved, then
// compared (paths in the data folder, docs/programs.md):
//
//   evaluate_trajectory --groundtruth kitti/06/groundtruth.txt
//       --estimate kitti/06/orbslam2_stereo.txt --align se3 --save-results orb.json
//   evaluate_trajectory --groundtruth kitti/06/groundtruth.txt
//       --estimate kitti/06/cvo_vo.txt --align se3 --save-results cvo.json
//   compare_results --result orb.json --result cvo.json
//
// Expected output:
//
//   result                  metric  relation    alignment  count       rmse      mean    median       std       min       max  unit
//   orb                     ape     trans       se3         1101   0.750409  0.682740  0.668036  0.311416  0.219585  1.524709  m
//   cvo                     ape     trans       se3         1101   7.348157  6.666496  6.352208  3.090832  1.198183 14.675583  m
//   lowest rmse: orb
//
// Names are the files' stems unless --label gives them. Results of
// different metrics, relations or units are listed but not ranked (a
// "warning:" line says why). --json prints the same as one JSON array. Bad
// input exits with 2 (usage) or 1 (data: an unreadable or malformed file,
// named), one line on stderr.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include <apps/cli.hpp>
#include <apps/json.hpp>
#include <apps/json_read.hpp>

namespace {

namespace apps = posefuse::apps;

struct Row {
  std::string name, metric, relation, alignment, unit;
  double count = 0, rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
  std::optional<double> nees_mean;
};

/// One saved result; a missing member or a wrong type names the file.
Row read_result(const std::filesystem::path& file, std::string name) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw apps::data_error(file.string() + ": cannot open file for reading: it is a folder");
  std::string text;
  try {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw apps::data_error(file.string() + ": cannot open file for reading");
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) throw apps::data_error(file.string() + ": read error");
  } catch (const apps::data_error&) {
    throw;
  } catch (const std::exception&) {  // the library's stream errors name no file
    throw apps::data_error(file.string() + ": read error");
  }
  try {
    const apps::JsonValue j = apps::JsonValue::parse(text);
    // evaluate_trajectory saves only finite statistics (it refuses a
    // non-finite result), so a null or negative one is not its file.
    const auto number = [&](const char* key) {
      if (j[key].is_null())
        throw apps::data_error(file.string() + ": \"" + key + "\" is null; a saved result has finite statistics");
      const double v = j[key].number();
      if (!(v >= 0.0))
        throw apps::data_error(file.string() + ": \"" + key + "\" is negative (" + apps::num(v) + ")");
      return v;
    };
    Row r;
    r.name = std::move(name);
    r.metric = j["metric"].string();
    r.relation = j["pose_relation"].string();
    r.alignment = j["alignment"].string();
    r.unit = j["unit"].string();
    r.count = number("count");
    if (r.count < 1.0 || r.count != std::floor(r.count) || r.count > 9007199254740992.0)
      throw apps::data_error(file.string() + ": \"count\" must be a whole number of pairs >= 1, got " +
                             apps::num(r.count));
    r.rmse = number("rmse");
    r.mean = number("mean");
    r.median = number("median");
    r.std = number("std");
    r.min = number("min");
    r.max = number("max");
    if (j.has("nees_mean")) r.nees_mean = number("nees_mean");
    return r;
  } catch (const apps::data_error&) {
    throw;
  } catch (const std::runtime_error& e) {
    throw apps::data_error(file.string() + ": not a saved result (" + e.what() + ")");
  }
}

int run(const std::vector<std::filesystem::path>& files, const std::vector<std::string>& labels,
        bool json) {
  std::vector<Row> rows;
  for (std::size_t k = 0; k < files.size(); ++k)
    rows.push_back(read_result(files[k], k < labels.size() ? labels[k] : files[k].stem().string()));
  bool comparable = true;
  for (const Row& r : rows)
    comparable = comparable && r.metric == rows[0].metric && r.relation == rows[0].relation &&
                 r.unit == rows[0].unit;
  std::size_t best = 0;
  for (std::size_t k = 1; k < rows.size(); ++k)
    if (rows[k].rmse < rows[best].rmse) best = k;
  if (!comparable)
    std::fprintf(stderr, "warning: the results measure different metrics, relations or units; not ranked\n");

  if (json) {
    apps::JsonWriter j(std::cout);
    j.begin_array(apps::JsonWriter::Layout::kBlock);
    for (const Row& r : rows) {
      j.begin_object(apps::JsonWriter::Layout::kInline);
      j.member("name", r.name).member("metric", r.metric).member("pose_relation", r.relation);
      j.member("alignment", r.alignment).member("unit", r.unit).member("count", r.count);
      j.member("rmse", r.rmse).member("mean", r.mean).member("median", r.median);
      j.member("std", r.std).member("min", r.min).member("max", r.max);
      if (r.nees_mean) j.member("nees_mean", *r.nees_mean);
      j.end_object();
    }
    j.end_array().finish();
    return 0;
  }
  bool any_nees = false;
  for (const Row& r : rows) any_nees = any_nees || r.nees_mean.has_value();
  std::printf("%-22s  %-6s  %-10s  %-9s  %5s  %9s %9s %9s %9s %9s %9s  %s%s\n", "result", "metric",
              "relation", "alignment", "count", "rmse", "mean", "median", "std", "min", "max", "unit",
              any_nees ? "  nees" : "");
  for (const Row& r : rows) {
    std::printf("%-22s  %-6s  %-10s  %-9s  %5.0f  %9.6f %9.6f %9.6f %9.6f %9.6f %9.6f  %s", r.name.c_str(),
                r.metric.c_str(), r.relation.c_str(), r.alignment.c_str(), r.count, r.rmse, r.mean,
                r.median, r.std, r.min, r.max, r.unit.c_str());
    if (r.nees_mean) std::printf("  %.3f", *r.nees_mean);
    std::printf("\n");
  }
  if (comparable && rows.size() > 1) std::printf("lowest rmse: %s\n", rows[best].name.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return apps::run_main(argc, argv, [](const apps::CommandLine& cmd) {
    std::vector<std::filesystem::path> files;
    std::vector<std::string> labels;
    std::string label_list;
    bool json = false;
    apps::Parser cli(cmd.program, "--result FILE --result FILE ... [options]",
                     "Tabulates results saved by evaluate_trajectory --save-results (as evo_res).");
    cli.inputs({.name = "--result", .value = "FILE", .help = "a saved result (repeat for each)"}, files);
    cli.text({.name = "--label", .value = "A,B,...", .help = "names of the results, in order"},
             label_list);
    cli.flag({.name = "--json", .help = "print one JSON array instead of the table"}, json);
    cli.epilogue("Exit status: 0 ok, 1 bad data (the file is named), 2 bad usage.");
    if (!cli.parse(cmd)) return 0;
    if (files.empty()) throw apps::usage_error("give at least one --result FILE");
    if (!label_list.empty())
      for (const std::string_view label : apps::split_commas(label_list, 1, label_list.size() + 1, "A,B,..."))
        labels.emplace_back(label);
    if (!labels.empty() && labels.size() != files.size())
      throw apps::usage_error("--label names " + std::to_string(labels.size()) + " results but " +
                              std::to_string(files.size()) + " are given");
    return run(files, labels, json);
  });
}

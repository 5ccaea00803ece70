#pragma once
/// @file
/// The saved-result reader of compare_results (`read_result` in
/// examples/compare_results.cpp, private to that program) for the fuzz
/// harness and the seed generator. This header compiles the program's source
/// into the including file with its `main` renamed, so that both call the
/// reader the program runs rather than a copy of it. Include it in one
/// translation unit only, after nothing that names `main`.

// The program's own includes, first, so that the `main` macro below touches
// only the program's text (these headers are #pragma once or guarded).
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

#define main posefuse_compare_results_main
#include "../../examples/compare_results.cpp"
#undef main

namespace posefuse_fuzz {

/// One saved result as compare_results reads it.
using SavedResult = Row;

/// compare_results' reader of one saved result.
/// @throws posefuse::apps::data_error naming `file` when it is not a saved
///         result evaluate_trajectory could have written
inline SavedResult read_saved_result(const std::filesystem::path& file) {
  return read_result(file, "fuzz");
}

}  // namespace posefuse_fuzz

#pragma once
// The message of the posefuse::io_error a callable throws, for tests that
// check the file:line sentence of a reader's refusal.
#include <string>

#include <posefuse/core/error.hpp>

namespace posefuse::test {

/// The what() of the io_error thrown by f, or "" when f throws none (any
/// other exception propagates, so a wrong exception type fails the test).
template <class F>
std::string io_error_of(F f) {
  try {
    f();
  } catch (const posefuse::io_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace posefuse::test

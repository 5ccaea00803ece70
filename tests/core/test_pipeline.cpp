#include <catch2/catch.hpp>
#include <posefuse/core/pipeline.hpp>
#include <string>

using namespace posefuse;

namespace {
struct Scale {
  using Input = double;
  using Output = double;
  double k = 2;
  double operator()(double x) const { return k * x; }
};
struct Accumulate {  // keeps state between samples
  using Input = double;
  using Output = double;
  double sum = 0;
  double operator()(double x) { return sum += x; }
};
struct ToText {
  using Input = double;
  using Output = std::string;
  std::string operator()(double x) const { return std::to_string(int(x)); }
};
struct NotAStage {};
}  // namespace

static_assert(Stage<Scale>);
static_assert(!Stage<NotAStage>);
static_assert(!Stage<int>);
static_assert(std::is_same_v<decltype(make_pipeline(Scale{}, ToText{}))::Output, std::string>);
static_assert(Stage<decltype(make_pipeline(Scale{}, Accumulate{}))>);

TEST_CASE("Pipeline: stages run in order and keep their state", "[core][pipeline]") {
  auto p = make_pipeline(Scale{3}, Accumulate{}, ToText{});
  CHECK(p(1) == "3");
  CHECK(p(2) == "9");
  CHECK(p.stage<1>().sum == 9);
  p.stage<0>().k = 1;
  CHECK(p(1) == "10");
}

TEST_CASE("Pipeline: nested pipelines flatten and operator| composes", "[core][pipeline]") {
  auto inner = make_pipeline(Scale{2}, Scale{5});
  auto outer = inner | ToText{};
  static_assert(decltype(outer)::size == 3);
  CHECK(outer(1.5) == "15");
}

// Stages of a user's own namespace compose with `|` without any using-declaration.
namespace user_code {
struct Offset {
  using Input = double;
  using Output = double;
  double d = 1;
  double operator()(double x) const { return x + d; }
};
struct Twice {
  using Input = double;
  using Output = double;
  double operator()(double x) const { return 2 * x; }
};
inline double run_user_pipeline(double x) {
  auto p = Offset{0.5} | Twice{} | Offset{-1};  // found from here, outside posefuse
  static_assert(decltype(p)::size == 3);
  return p(x);
}
// A namespace with an operator| of its own hides the global one (C++ lookup);
// one using-declaration brings it back.
enum class Flags : unsigned { kA = 1, kB = 2 };
inline Flags operator|(Flags a, Flags b) { return Flags(unsigned(a) | unsigned(b)); }
inline double run_with_own_operator(double x) {
  using ::operator|;
  auto p = Offset{1} | Twice{};
  return p(x) + double(unsigned(Flags::kA | Flags::kB));
}
}  // namespace user_code

TEST_CASE("Pipeline: operator| composes stages defined in any namespace", "[core][pipeline]") {
  CHECK(user_code::run_user_pipeline(1.0) == Approx(2.0));    // (1 + 0.5) * 2 - 1
  CHECK(user_code::run_with_own_operator(1.0) == Approx(7.0));  // (1 + 1) * 2 + 3
}

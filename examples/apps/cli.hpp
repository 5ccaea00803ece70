#pragma once
/// @file
/// The example programs' command line: declared flags, a generated `--help`,
/// strict locale-free numbers, and one mapping of failures to exit codes.
///
/// A program declares its flags once, each bound to a variable:
///
///     Options o;
///     apps::Parser cli("corridor_fusion", "[--seed N | --log DIR] [options]",
///                      "Seed 001's corridor experiment.");
///     cli.integer({.name = "--seed", .value = "N", .help = "RNG seed"}, o.seed);
///     cli.flag({.name = "--json", .help = "print JSON"}, o.json);
///     if (!cli.parse(cmd)) return 0;  // --help was printed
///
/// and its `main` is `return apps::run_main(argc, argv, body);`. Exit codes,
/// the same in every program:
///
/// | code | meaning | stderr |
/// |---|---|---|
/// | 0 | success (also `--help`) | nothing |
/// | 1 | bad data: io_error, a non-finite result, an output that cannot be written | one line `<program>: <file>:<line>: <reason>` (`<program>: <reason>` when no file is at fault) |
/// | 2 | bad usage: usage_error | one line `<program>: <reason> (try --help)` |

#include <algorithm>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/message_number.hpp>

namespace posefuse::apps {

/// Exit status of a successful run (and of `--help`).
inline constexpr int kExitOk = 0;
/// Exit status when the data (input files, results, outputs) are at fault.
inline constexpr int kExitData = 1;
/// Exit status when the command line is at fault.
inline constexpr int kExitUsage = 2;

/// A mistake on the command line (unknown flag, missing or malformed value,
/// flags that exclude each other); run_main exits with kExitUsage.
class usage_error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Data that parse but give no usable result (a non-finite figure, a filter
/// step that was not applied); run_main exits with kExitData. Errors about a
/// line of a file are posefuse::io_error instead.
class data_error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a real-valued flag accepts. Every domain excludes inf and NaN.
enum class Domain {
  kFinite,       ///< any finite number
  kNonNegative,  ///< finite and >= 0
  kPositive,     ///< finite and > 0 (variances, densities)
};

/// Parses all of `text` as a double: std::from_chars, so locale-free, no
/// leading spaces or '+', no hexadecimal; "inf", "nan" and out-of-range text
/// ("1e400") are rejected.
/// @param[in] text   the value as typed
/// @param[in] domain what the value must satisfy
/// @return the number
/// @throws usage_error naming the expectation and the text
[[nodiscard]] inline double parse_real(std::string_view text, Domain domain = Domain::kFinite) {
  const char* expected = domain == Domain::kPositive      ? "a finite number > 0"
                         : domain == Domain::kNonNegative ? "a finite number >= 0"
                                                          : "a finite number";
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (ec == std::errc::result_out_of_range)
    throw usage_error("expected " + std::string(expected) + ", got '" + std::string(text) +
                      "' (out of the range of a double)");
  const bool ok = ec == std::errc{} && ptr == end && std::isfinite(v) &&
                  (domain != Domain::kPositive || v > 0.0) &&
                  (domain != Domain::kNonNegative || v >= 0.0);
  if (!ok) throw usage_error("expected " + std::string(expected) + ", got '" + std::string(text) + "'");
  return v;
}

/// Parses all of `text` as a base-10 integer in [lo, hi] (std::from_chars:
/// no sign on unsigned types, no '+', no spaces; overflow is rejected, never
/// wrapped or clamped).
/// @return the number
/// @throws usage_error naming the range and the text
template <std::integral T>
  requires(!std::same_as<T, bool>)
[[nodiscard]] T parse_integer(std::string_view text, T lo = std::numeric_limits<T>::min(),
                              T hi = std::numeric_limits<T>::max()) {
  const std::string expected =
      lo == 0 && hi == std::numeric_limits<T>::max()
          ? std::string("a non-negative integer")
          : "an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
  T v{};
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v, 10);
  if (ec == std::errc::result_out_of_range || (ec == std::errc{} && ptr == end && (v < lo || v > hi)))
    throw usage_error("expected " + expected + ", got '" + std::string(text) + "' (out of range)");
  if (ec != std::errc{} || ptr != end)
    throw usage_error("expected " + expected + ", got '" + std::string(text) + "'");
  return v;
}

/// The items of a comma-separated list ("A,B,C"; an empty text is one empty
/// item), views into `text`.
/// @param[in] text      the flag's value
/// @param[in] min_items fewest items accepted
/// @param[in] max_items most items accepted
/// @param[in] expected  what a valid value looks like, for the message
/// @return the items, in order
/// @throws usage_error "expected <expected>, got '<text>'" for another count
[[nodiscard]] inline std::vector<std::string_view> split_commas(std::string_view text, std::size_t min_items,
                                                                std::size_t max_items, std::string_view expected) {
  std::vector<std::string_view> items;
  for (std::size_t start = 0;;) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    items.push_back(text.substr(start, comma - start));
    if (comma == text.size()) break;
    start = comma + 1;
  }
  if (items.size() < min_items || items.size() > max_items)
    throw usage_error("expected " + std::string(expected) + ", got '" + std::string(text) + "'");
  return items;
}

/// Shortest text that reads back to the same double (std::to_chars; "inf"
/// and "nan" for non-finite values). Used for defaults in `--help`.
[[nodiscard]] inline std::string shortest(double v) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  (void)ec;  // 64 characters always suffice for a double
  return std::string(buf, ptr);
}

/// A number for a message (error, warning, `--help`): posefuse's one
/// message formatter, see posefuse::detail::message_number ("105" for
/// 104.99993599999999, "1e-09" for 1e-9).
[[nodiscard]] inline std::string num(double v) { return posefuse::detail::message_number(v); }

/// What a path-valued flag names: the parser refuses (usage_error) an output
/// that names an input file or folder, and two outputs that name one file.
enum class PathRole {
  kInput,   ///< read by the run (a file or a folder)
  kOutput,  ///< written by the run (a file or a folder)
};

/// The file or folder `p` names, for comparing two paths: absolute, with the
/// symbolic links of its existing part resolved, normalised, without a
/// trailing separator (`./t.csv`, `t.csv` and `dir/../t.csv` give one key).
[[nodiscard]] inline std::filesystem::path path_key(const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::path k = std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec);
  if (ec) k = std::filesystem::absolute(p, ec);
  k = k.lexically_normal();
  if (!k.has_filename() && k.has_parent_path()) k = k.parent_path();
  return k;
}

/// True when `a` and `b` name one file or folder: the same file when both
/// exist (hard links too), else the same path_key.
[[nodiscard]] inline bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  if (std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec)) {
    const bool eq = std::filesystem::equivalent(a, b, ec);
    if (!ec) return eq;
  }
  return path_key(a) == path_key(b);
}

/// True for an output that replaces no file when written: an existing
/// device or pipe (`/dev/null`, `/dev/stdout`, a FIFO) or a path under /dev.
[[nodiscard]] inline bool writes_no_file(const std::filesystem::path& out) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(out, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st) &&
      !std::filesystem::is_directory(st))
    return true;
  const std::filesystem::path k = path_key(out);
  auto it = k.begin();
  return it != k.end() && *it == "/" && ++it != k.end() && *it == "dev";
}

/// Refuses (usage_error, exit 2) an output that names an input (writing it
/// would replace the input) and two outputs that name one file (one would
/// replace the other). Parser::parse calls it for the flags declared with a
/// PathRole; a program calls it itself only for paths it derives.
/// @param[in] outputs (flag, path) of each output given
/// @param[in] inputs  (flag, path) of each input given
inline void refuse_output_over_input(
    const std::vector<std::pair<std::string, std::filesystem::path>>& outputs,
    const std::vector<std::pair<std::string, std::filesystem::path>>& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& [out_flag, out] = outputs[i];
    if (writes_no_file(out)) continue;
    for (const auto& [in_flag, in] : inputs)
      if (same_file(out, in))
        throw usage_error(out_flag + " " + out.string() + " is the input of " + in_flag +
                          "; it would be overwritten");
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(out, outputs[j].second))
        throw usage_error(outputs[j].first + " " + outputs[j].second.string() + " and " + out_flag + " " +
                          out.string() + " name the same file; one would overwrite the other");
  }
}

/// The command line of one run.
struct CommandLine {
  std::string program;            ///< file name of argv[0] ("program" when absent)
  std::vector<std::string> args;  ///< argv[1..argc)

  /// @param[in] argc, argv as given to main
  [[nodiscard]] static CommandLine from(int argc, const char* const* argv) {
    CommandLine c;
    c.program = argc > 0 && argv[0] != nullptr && *argv[0] != '\0'
                    ? std::filesystem::path(argv[0]).filename().string()
                    : std::string("program");
    for (int i = 1; i < argc; ++i) c.args.emplace_back(argv[i]);
    return c;
  }
};

/// One flag as `--help` shows it.
struct FlagSpec {
  std::string name{};        ///< "--seed"
  std::string value{};       ///< the value's name in the help, "N"; empty for a switch
  std::string help{};        ///< one line; '\n' starts an indented continuation line
  std::string default_text{};  ///< shown as "(default ...)"; filled in from the target when empty
  std::string unit{};        ///< appended to an automatic default ("0.01 s")
  /// For a custom flag whose value is a path (or a keyword): its role in the
  /// output-over-input check. input(), inputs() and output() set it.
  std::optional<PathRole> role{};
  /// Values of a custom flag with a role that are keywords, not paths
  /// ("recurring-ids").
  std::vector<std::string> keywords{};
};

/// A declarative command-line parser: flags are declared with the variable
/// they set; `parse` fills them in, `help` is generated from the declarations.
///
/// Rules: flags are `--name VALUE` or `--name=VALUE`; a value that starts with
/// "--" must use the `=` form (so a forgotten value is reported, not
/// swallowed); a flag given twice is an error unless declared repeatable;
/// there are no positional arguments; `--help` / `-h` anywhere prints the
/// help and nothing else is checked.
class Parser {
 public:
  /// @param[in] program     name in the usage line and in error messages
  /// @param[in] synopsis    the usage line after the program's name
  /// @param[in] description paragraph between the usage line and the flags
  Parser(std::string program, std::string synopsis, std::string description)
      : program_(std::move(program)), synopsis_(std::move(synopsis)),
        description_(std::move(description)) {}

  /// Text printed after the flags (exit codes, notes).
  Parser& epilogue(std::string text) {
    epilogue_ = std::move(text);
    return *this;
  }

  /// A switch: `target` becomes true when the flag is given.
  Parser& flag(FlagSpec spec, bool& target) {
    spec.value.clear();
    return add(std::move(spec), false, [&target](std::string_view) { target = true; });
  }

  /// A string value.
  Parser& text(FlagSpec spec, std::string& target) {
    if (spec.default_text.empty() && !target.empty()) spec.default_text = target;
    return add(std::move(spec), false, [&target](std::string_view v) { target = std::string(v); });
  }

  /// An input path (file or folder), absent unless given. Every path flag is
  /// declared as an input or an output, and parse() refuses an output that
  /// names an input or another output (refuse_output_over_input).
  Parser& input(FlagSpec spec, std::optional<std::filesystem::path>& target) {
    spec.role = PathRole::kInput;
    return add(std::move(spec), false, path_setter(target));
  }

  /// A repeatable input path: every occurrence is appended, in order.
  Parser& inputs(FlagSpec spec, std::vector<std::filesystem::path>& target) {
    spec.role = PathRole::kInput;
    return add(std::move(spec), true, [&target](std::string_view v) {
      if (v.empty()) throw usage_error("expected a path, got ''");
      target.emplace_back(v);
    });
  }

  /// An output path (file or folder), absent unless given; see input().
  Parser& output(FlagSpec spec, std::optional<std::filesystem::path>& target) {
    spec.role = PathRole::kOutput;
    return add(std::move(spec), false, path_setter(target));
  }

  /// A real number in `domain` (see parse_real).
  Parser& real(FlagSpec spec, double& target, Domain domain = Domain::kFinite) {
    if (spec.default_text.empty())
      spec.default_text = shortest(target) + (spec.unit.empty() ? "" : " " + spec.unit);
    return add(std::move(spec), false,
               [&target, domain](std::string_view v) { target = parse_real(v, domain); });
  }

  /// A real number in [lo, hi]: for a value that can only fail (or do
  /// nothing) outside that range; `--help` shows the range.
  Parser& real_in(FlagSpec spec, double& target, double lo, double hi) {
    if (spec.default_text.empty())
      spec.default_text = num(target) + (spec.unit.empty() ? "" : " " + spec.unit);
    spec.help += "; " + num(lo) + " to " + num(hi);
    return add(std::move(spec), false, [&target, lo, hi](std::string_view v) {
      const double x = parse_real(v);
      if (!(x >= lo && x <= hi))
        throw usage_error("expected a number from " + num(lo) + " to " + num(hi) + ", got '" + std::string(v) + "'");
      target = x;
    });
  }

  /// An integer in [lo, hi], absent unless given (see parse_integer).
  template <std::integral T>
    requires(!std::same_as<T, bool>)
  Parser& integer(FlagSpec spec, std::optional<T>& target, T lo = std::numeric_limits<T>::min(),
                  T hi = std::numeric_limits<T>::max()) {
    return add(std::move(spec), false,
               [&target, lo, hi](std::string_view v) { target = parse_integer<T>(v, lo, hi); });
  }

  /// An integer in [lo, hi] with the target's value as default.
  template <std::integral T>
    requires(!std::same_as<T, bool>)
  Parser& integer(FlagSpec spec, T& target, T lo = std::numeric_limits<T>::min(),
                  T hi = std::numeric_limits<T>::max()) {
    if (spec.default_text.empty())
      spec.default_text = std::to_string(target) + (spec.unit.empty() ? "" : " " + spec.unit);
    return add(std::move(spec), false,
               [&target, lo, hi](std::string_view v) { target = parse_integer<T>(v, lo, hi); });
  }

  /// A value converted by `apply` (enumerations, lists). `apply` reports a bad
  /// value by throwing usage_error or (std/posefuse) invalid_argument; either
  /// becomes a usage_error naming the flag.
  Parser& custom(FlagSpec spec, std::function<void(std::string_view)> apply) {
    return add(std::move(spec), false, std::move(apply));
  }

  /// Parses `cmd.args`, setting the declared targets.
  /// @param[in]  cmd      the command line
  /// @param[out] help_out where `--help` prints the help
  /// @return false when `--help` was printed (the program should exit 0)
  /// @throws usage_error for an unknown flag, a missing or bad value, a
  ///         repeated flag or a positional argument
  [[nodiscard]] bool parse(const CommandLine& cmd, std::ostream& help_out = std::cout) {
    for (const std::string& a : cmd.args) {
      if (a == "--help" || a == "-h") {
        help_out << help();
        help_out.flush();
        return false;
      }
    }
    for (Flag& f : flags_) {
      f.count = 0;
      f.values.clear();
    }
    for (std::size_t i = 0; i < cmd.args.size(); ++i) {
      const std::string_view arg = cmd.args[i];
      if (arg.substr(0, 2) != "--" || arg.size() == 2)
        throw usage_error("unexpected argument '" + std::string(arg) + "'");
      const std::size_t eq = arg.find('=');
      const std::string_view name = arg.substr(0, eq);
      Flag* f = find(name);
      if (f == nullptr) throw usage_error("unknown option '" + std::string(name) + "'");
      std::string_view value;
      if (f->spec.value.empty()) {
        if (eq != std::string_view::npos)
          throw usage_error(std::string(name) + " takes no value");
      } else if (eq != std::string_view::npos) {
        value = arg.substr(eq + 1);
      } else {
        if (i + 1 >= cmd.args.size() || cmd.args[i + 1].rfind("--", 0) == 0)
          throw usage_error(std::string(name) + " needs a value (" + f->spec.value + ")");
        value = cmd.args[++i];
      }
      if (++f->count > 1 && !f->repeatable)
        throw usage_error(std::string(name) + " is given more than once");
      try {
        f->apply(value);
      } catch (const usage_error& e) {
        throw usage_error(std::string(name) + ": " + e.what());
      } catch (const std::invalid_argument& e) {  // also posefuse::invalid_argument
        throw usage_error(std::string(name) + ": " + e.what());
      }
      f->values.emplace_back(value);
    }
    check_paths();
    return true;
  }

  /// (flag, path) of every path given to a flag declared with `role`, in
  /// the order of declaration.
  [[nodiscard]] std::vector<std::pair<std::string, std::filesystem::path>> paths_given(PathRole role) const {
    std::vector<std::pair<std::string, std::filesystem::path>> out;
    for (const Flag& f : flags_) {
      if (f.spec.role != role) continue;
      for (const std::string& v : f.values)
        if (std::find(f.spec.keywords.begin(), f.spec.keywords.end(), v) == f.spec.keywords.end())
          out.emplace_back(f.spec.name, std::filesystem::path(v));
    }
    return out;
  }

  /// True when the last parse saw flag `name`.
  [[nodiscard]] bool given(std::string_view name) const {
    for (const Flag& f : flags_)
      if (f.spec.name == name) return f.count > 0;
    return false;
  }

  /// The `--help` text, generated from the declarations.
  [[nodiscard]] std::string help() const {
    std::ostringstream h;
    h << "usage: " << program_ << (synopsis_.empty() ? "" : " ") << synopsis_ << "\n";
    if (!description_.empty()) h << "\n" << description_ << "\n";
    std::vector<std::string> heads;
    std::size_t width = 0;
    for (const Flag& f : flags_) {
      heads.push_back(f.spec.name + (f.spec.value.empty() ? "" : " " + f.spec.value));
      width = std::max(width, heads.back().size());
    }
    heads.emplace_back("--help");
    width = std::min<std::size_t>(std::max(width, heads.back().size()), 28);
    h << "\n";
    const auto row = [&](const std::string& head, const std::string& text) {
      h << "  " << head;
      if (head.size() > width) h << "\n" << std::string(width + 4, ' ');  // a long head: own line
      else h << std::string(width + 2 - head.size(), ' ');
      for (const char c : text) {
        h << c;
        if (c == '\n') h << std::string(width + 4, ' ');
      }
      h << "\n";
    };
    for (std::size_t k = 0; k < flags_.size(); ++k) {
      const FlagSpec& s = flags_[k].spec;
      row(heads[k], s.help + (s.default_text.empty() ? "" : " (default " + s.default_text + ")"));
    }
    row("--help", "print this help and exit");
    if (!epilogue_.empty()) h << "\n" << epilogue_ << "\n";
    return h.str();
  }

  /// The program's name given to the constructor.
  [[nodiscard]] const std::string& program() const noexcept { return program_; }

 private:
  struct Flag {
    FlagSpec spec;
    bool repeatable = false;
    std::function<void(std::string_view)> apply;
    int count = 0;
    std::vector<std::string> values{};  ///< as given, in order
  };

  static std::function<void(std::string_view)> path_setter(std::optional<std::filesystem::path>& target) {
    return [&target](std::string_view v) {
      if (v.empty()) throw usage_error("expected a path, got ''");
      target = std::filesystem::path(v);
    };
  }

  void check_paths() const {
    refuse_output_over_input(paths_given(PathRole::kOutput), paths_given(PathRole::kInput));
  }

  Parser& add(FlagSpec spec, bool repeatable, std::function<void(std::string_view)> apply) {
    if (spec.name.size() < 3 || spec.name.rfind("--", 0) != 0 || spec.name == "--help" ||
        spec.name.find('=') != std::string::npos || find(spec.name) != nullptr)
      throw std::logic_error("Parser: bad or duplicate flag name '" + spec.name + "'");
    flags_.push_back({std::move(spec), repeatable, std::move(apply), 0, {}});
    return *this;
  }

  Flag* find(std::string_view name) {
    for (Flag& f : flags_)
      if (f.spec.name == name) return &f;
    return nullptr;
  }

  std::string program_, synopsis_, description_, epilogue_;
  std::vector<Flag> flags_;
};

/// One line for stderr: `what` with line breaks turned into spaces.
[[nodiscard]] inline std::string one_line(std::string_view what) {
  std::string s(what);
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

/// Runs a program's body and maps its outcome to the exit code (table in the
/// file comment): usage_error -> 2, any other exception (io_error naming
/// file:line, data_error, invalid_argument, filesystem_error, bad_alloc) -> 1,
/// each with one line on stderr. A body that returns normally but whose
/// standard output could not be written (`> /dev/full`) also exits 1.
/// @param[in] argc, argv as given to main
/// @param[in] body `int(const CommandLine&)` or `void(const CommandLine&)`;
///            an int it returns is the exit code
/// @return the exit code
template <class Body>
  requires std::invocable<Body&, const CommandLine&>
[[nodiscard]] int run_main(int argc, const char* const* argv, Body&& body) noexcept {
  std::string program = "program";
  const auto report = [&program](std::string_view reason) {
    std::fprintf(stderr, "%s: %s\n", program.c_str(), one_line(reason).c_str());
  };
  int code = kExitOk;
  try {
    const CommandLine cmd = CommandLine::from(argc, argv);
    program = cmd.program;
    if constexpr (std::is_void_v<std::invoke_result_t<Body&, const CommandLine&>>) {
      body(cmd);
    } else {
      code = static_cast<int>(body(cmd));
    }
  } catch (const usage_error& e) {
    report(std::string(e.what()) + " (try --help)");
    return kExitUsage;
  } catch (const std::exception& e) {  // io_error's what() is "<file>:<line>: <reason>"
    report(e.what());
    return kExitData;
  } catch (...) {
    report("unknown error");
    return kExitData;
  }
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0 || !std::cout) {
    report("cannot write to standard output");
    return kExitData;
  }
  return code;
}

}  // namespace posefuse::apps

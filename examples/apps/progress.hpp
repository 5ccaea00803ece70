#pragma once
/// @file
/// Progress of a long run on a terminal: one status line on standard error,
/// rewritten in place (`program: text`), shown only when standard error is a
/// terminal, so pipes, files and tests see nothing. A stage is drawn at
/// once; updates within a stage at most ten times a second (the first one
/// always), and their text is built only when drawn. The line is
/// erased by clear() and when the object goes out of scope (also when an
/// error unwinds, before the program prints its error line).

#include <chrono>
#include <cstdio>
#include <string>
#include <utility>

#include <unistd.h>

namespace posefuse::apps {

class TerminalProgress {
 public:
  /// @param[in] program the name printed before each status
  explicit TerminalProgress(std::string program)
      : program_(std::move(program)), enabled_(::isatty(STDERR_FILENO) == 1) {}
  TerminalProgress(const TerminalProgress&) = delete;
  TerminalProgress& operator=(const TerminalProgress&) = delete;
  ~TerminalProgress() { clear(); }

  /// True when standard error is a terminal (the status is drawn).
  [[nodiscard]] bool enabled() const noexcept { return enabled_; }

  /// Draws `text()` (a callable returning std::string) unless the last status
  /// was drawn less than 0.1 s ago; `now`: draw in any case (a new stage).
  template <class Text>
  void update(const Text& text, bool now = false) {
    if (!enabled_) return;
    const auto t = std::chrono::steady_clock::now();
    if (!now && shown_ && t - last_ < std::chrono::milliseconds(100)) return;
    last_ = t;
    shown_ = true;
    const std::string line = text();
    std::fprintf(stderr, "\r%s: %s\033[K", program_.c_str(), line.c_str());
    std::fflush(stderr);
  }

  /// Draws a new stage now (`text` as is); the first update() after it is
  /// drawn too.
  void stage(const std::string& text) {
    update([&] { return text; }, true);
    last_ = {};
  }

  /// Erases the status line, if one is drawn.
  void clear() noexcept {
    if (!shown_) return;
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
    shown_ = false;
  }

 private:
  std::string program_;
  bool enabled_ = false;
  bool shown_ = false;
  std::chrono::steady_clock::time_point last_{};
};

/// A pose-graph solver callback that shows each iteration (iteration of
/// `max_iterations`, cost, step; rejected steps marked) on `progress`.
template <class Iteration>
auto solver_progress(TerminalProgress& progress, int max_iterations) {
  return [&progress, max_iterations](const Iteration& it) {
    progress.update([&] {
      char line[160];
      std::snprintf(line, sizeof line, "iteration %d/%d  cost %.6g  step %.3g%s", it.iteration, max_iterations,
                    it.cost, it.step_norm, it.accepted ? "" : " (rejected)");
      return std::string(line);
    });
  };
}

}  // namespace posefuse::apps

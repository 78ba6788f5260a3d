#pragma once
// Progress of a long command on stderr: done/total, rate and ETA.
//
//   ProgressReporter bar("Monte Carlo", "runs", 1024, ProgressMode::Auto);
//   ... from any thread: bar.update(done);  or  bar.add(1);
//   bar.message("a log line");   // printed on its own line; the bar is redrawn below it
//   bar.finish();                // last line ("... done in 12.3 s"); also done by the destructor
//
// When it shows (show_progress()): Auto shows only when the stream is a terminal; Always (the
// commands' --progress flag) shows also when stderr is a file or a pipe; Never is silent.
// On a terminal the line is redrawn in place ("\r" and erase-to-end-of-line) at most every 0.1 s;
// elsewhere one full line is written at most every 5 s, and a last one at the end.
// update/add/message are thread-safe; an update that comes within the redraw interval costs one
// atomic store and one clock read.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <string>

namespace abuopt {

enum class ProgressMode { Auto, Always, Never };

// Auto: only on a terminal; Always: always; Never: never.
bool show_progress(ProgressMode mode, bool stream_is_terminal);

// The text of one progress line (no "\r", no newline), e.g.
//   "Monte Carlo: 512/1024 runs (50.0 %)  85.3 runs/s  ETA 6 s"
//   "Monte Carlo: 1024/1024 runs (100.0 %)  85.3 runs/s  done in 12.0 s"
// The rate needs elapsed_s > 0 and done > 0 (else "-- runs/s"); the ETA is (total - done) / rate,
// written as s below 100 s, "m:ss" below an hour, "h:mm:ss" above; total 0 means unknown (no % and
// no ETA). `ended`: the last line of a task that stopped before its total (an optimiser within its
// budget): "ended after 12.0 s" instead of an ETA.
std::string format_progress_line(const std::string& label, const std::string& unit, std::size_t done,
                                 std::size_t total, double elapsed_s, bool ended = false);
// "42 s", "3:05", "1:02:03" (rounded to whole seconds).
std::string format_duration(double seconds);

class ProgressReporter {
 public:
  // `out`: stderr unless a test passes its own stream; `is_terminal`: whether `out` redraws in place
  // (default: isatty of `out`).
  ProgressReporter(std::string label, std::string unit, std::size_t total, ProgressMode mode = ProgressMode::Auto,
                   std::FILE* out = stderr);
  ProgressReporter(std::string label, std::string unit, std::size_t total, ProgressMode mode, std::FILE* out,
                   bool is_terminal);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  bool enabled() const { return enabled_; }
  void set_total(std::size_t total);
  void update(std::size_t done);  // done so far (the largest value seen wins)
  void add(std::size_t n = 1);
  // A line of its own (log output that would otherwise collide with the redrawn bar), to `to`
  // (default: the bar's stream; stdout for a command that logs there). Printed even when the bar
  // is not shown.
  void message(const std::string& line, std::FILE* to = nullptr);
  void finish();

 private:
  void maybe_draw(std::size_t done, bool force);
  void draw_locked(std::size_t done, bool final_line);
  double elapsed() const;

  std::string label_, unit_;
  std::atomic<std::size_t> total_;
  std::atomic<std::size_t> done_{0};
  std::FILE* out_;
  bool terminal_;
  bool enabled_;
  bool finished_ = false;
  bool drawn_ = false;  // a bar is on the current terminal line
  std::chrono::steady_clock::time_point start_;
  std::atomic<double> next_draw_s_{0.0};
  std::mutex mutex_;
};

}  // namespace abuopt

#include "abuopt/common/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace abuopt {

namespace {

constexpr double kTerminalInterval_s = 0.1;
constexpr double kLogInterval_s = 5.0;

std::string fixed1(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string rate_text(double rate) {
  char buf[64];
  if (rate >= 100) std::snprintf(buf, sizeof buf, "%.0f", rate);
  else if (rate >= 1) std::snprintf(buf, sizeof buf, "%.1f", rate);
  else std::snprintf(buf, sizeof buf, "%.3g", rate);
  return buf;
}

}  // namespace

bool show_progress(ProgressMode mode, bool stream_is_terminal) {
  switch (mode) {
    case ProgressMode::Always: return true;
    case ProgressMode::Never: return false;
    case ProgressMode::Auto: return stream_is_terminal;
  }
  return false;
}

std::string format_duration(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "--";
  const long s = std::lround(seconds);
  char buf[64];
  if (s < 100) std::snprintf(buf, sizeof buf, "%ld s", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  return buf;
}

std::string format_progress_line(const std::string& label, const std::string& unit, std::size_t done,
                                 std::size_t total, double elapsed_s, bool ended) {
  // Appended piece by piece: GCC 12 warns -Wrestrict on long "..." + std::string chains.
  std::string s;
  if (!label.empty()) {
    s += label;
    s += ": ";
  }
  s += std::to_string(done);
  if (total > 0) {
    s += '/';
    s += std::to_string(total);
  }
  s += ' ';
  s += unit;
  if (total > 0) {
    s += " (";
    s += fixed1(100.0 * static_cast<double>(std::min(done, total)) / static_cast<double>(total));
    s += " %)";
  }
  const bool have_rate = elapsed_s > 0 && done > 0;
  const double rate = have_rate ? static_cast<double>(done) / elapsed_s : 0.0;
  s += "  ";
  s += have_rate ? rate_text(rate) : std::string("--");
  s += ' ';
  s += unit;
  s += "/s  ";
  if (total > 0 && done >= total) {
    s += "done in ";
    s += fixed1(elapsed_s);
    s += " s";
  } else if (ended) {
    s += "ended after ";
    s += fixed1(elapsed_s);
    s += " s";
  } else if (total > 0) {
    s += "ETA ";
    s += have_rate ? format_duration(static_cast<double>(total - done) / rate) : std::string("--");
  } else {
    s += fixed1(elapsed_s);
    s += " s";
  }
  return s;
}

ProgressReporter::ProgressReporter(std::string label, std::string unit, std::size_t total, ProgressMode mode,
                                   std::FILE* out)
    : ProgressReporter(std::move(label), std::move(unit), total, mode, out, out && ::isatty(::fileno(out))) {}

ProgressReporter::ProgressReporter(std::string label, std::string unit, std::size_t total, ProgressMode mode,
                                   std::FILE* out, bool is_terminal)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      out_(out),
      terminal_(is_terminal),
      enabled_(out != nullptr && show_progress(mode, is_terminal)),
      start_(std::chrono::steady_clock::now()) {}

ProgressReporter::~ProgressReporter() { finish(); }

double ProgressReporter::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressReporter::set_total(std::size_t total) { total_.store(total); }

void ProgressReporter::update(std::size_t done) {
  std::size_t prev = done_.load(std::memory_order_relaxed);
  while (prev < done && !done_.compare_exchange_weak(prev, done, std::memory_order_relaxed)) {
  }
  maybe_draw(std::max(prev, done), false);
}

void ProgressReporter::add(std::size_t n) { maybe_draw(done_.fetch_add(n, std::memory_order_relaxed) + n, false); }

void ProgressReporter::maybe_draw(std::size_t done, bool force) {
  if (!enabled_) return;
  const double t = elapsed();
  if (!force && t < next_draw_s_.load(std::memory_order_relaxed)) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock() || finished_) return;  // another thread is drawing: skip this frame
  next_draw_s_.store(t + (terminal_ ? kTerminalInterval_s : kLogInterval_s), std::memory_order_relaxed);
  draw_locked(std::max(done, done_.load(std::memory_order_relaxed)), false);
}

void ProgressReporter::draw_locked(std::size_t done, bool final_line) {
  const std::string line = format_progress_line(label_, unit_, done, total_.load(), elapsed(), final_line);
  if (terminal_) {
    std::fprintf(out_, "\r%s\x1b[K%s", line.c_str(), final_line ? "\n" : "");
    drawn_ = !final_line;
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
}

void ProgressReporter::message(const std::string& line, std::FILE* to) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!to) to = out_;
  if (!to) return;
  if (drawn_) {
    std::fputs("\r\x1b[K", out_);
    std::fflush(out_);
    drawn_ = false;
  }
  std::fprintf(to, "%s\n", line.c_str());
  std::fflush(to);
  if (enabled_ && !finished_ && terminal_) draw_locked(done_.load(), false);
}

void ProgressReporter::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!enabled_) return;
  draw_locked(done_.load(), true);
}

}  // namespace abuopt

#include "progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace feeddrive::study {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[64];
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lds", s);
  }
  return buf;
}

Progress::Progress(std::size_t total, std::size_t already_done, bool enabled)
    : total_(total),
      done_(already_done),
      enabled_(enabled),
      tty_(::isatty(2) == 1),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {
  if (enabled_ && tty_) draw(false);
}

void Progress::step(bool failed) {
  ++done_;
  ++ran_;
  failed_ += failed ? 1 : 0;
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (tty_ ? since >= 0.1 : since >= 10.0) draw(false);
}

void Progress::finish() {
  if (enabled_) draw(true);
}

void Progress::draw(bool final_line) {
  last_ = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(last_ - start_).count();
  const std::size_t left = total_ - done_;
  // ETA from the rate of the cases run in this invocation (the cached ones cost nothing).
  const double eta = ran_ > 0 ? elapsed / static_cast<double>(ran_) * static_cast<double>(left) : NAN;
  const double frac = total_ > 0 ? static_cast<double>(done_) / static_cast<double>(total_) : 1.0;
  char line[256];
  const std::string eta_text = final_line ? "elapsed " + format_duration(elapsed) : "ETA " + format_duration(eta);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(frac * kWidth);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar += std::string(static_cast<std::size_t>(kWidth - filled), '.');
    std::snprintf(line, sizeof line, "\r[%s] %zu/%zu %3.0f%%  %zu failed  %s   ", bar.c_str(), done_, total_,
                  100 * frac, failed_, eta_text.c_str());
    std::fputs(line, stderr);
    if (final_line) std::fputc('\n', stderr);
  } else {
    std::snprintf(line, sizeof line, "progress: %zu/%zu cases (%.0f%%), %zu failed, %s\n", done_, total_, 100 * frac,
                  failed_, eta_text.c_str());
    std::fputs(line, stderr);
  }
  std::fflush(stderr);
}

}  // namespace feeddrive::study

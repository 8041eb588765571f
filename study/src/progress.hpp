#pragma once
// feeddrive-study's progress display (the tool's, not the library's: run_study reports through
// study::Reporter, session.hpp).

#include <chrono>
#include <cstddef>
#include <string>

namespace feeddrive::study {

/// Progress on stderr: a bar with the count, percentage and ETA, redrawn in place on a terminal;
/// on anything else (a log file, CI) a plain line at most every 10 s and at the end.
class Progress {
 public:
  Progress(std::size_t total, std::size_t already_done, bool enabled);
  void step(bool failed);
  /// A case finished in an earlier run (no time spent on it here).
  void reused() { ++done_; }
  void finish();

 private:
  void draw(bool final_line);
  std::size_t total_, done_, ran_{0}, failed_{0};
  bool enabled_, tty_;
  std::chrono::steady_clock::time_point start_, last_;
};

/// "1h02m", "3m05s", "12s".
std::string format_duration(double seconds);

}  // namespace feeddrive::study

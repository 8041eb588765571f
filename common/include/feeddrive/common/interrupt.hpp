#pragma once
// How a library learns that it should stop (Ctrl-C, SIGTERM): through a StopToken its caller hands
// in, never a global. Long loops poll it (stop_requested(), check()) and unwind, so destructors
// run: a staged output folder is removed (output::StagedFolder), a child gnuplot is stopped
// (output::run_gnuplot). The flag itself, and the SIGINT/SIGTERM handlers that set it, live in one
// place, feeddrive::tool (common/tool/src/main.cpp): only a tool's main installs them
// (tool::install_interrupt_handlers) and hands the process's token (tool::stop_token()) to the
// libraries; tool::report turns the Interrupted a library threw into the exit 128 + signal.

#include <atomic>
#include <csignal>
#include <stdexcept>
#include <string>

namespace feeddrive::interrupt {

/// "SIGINT", "SIGTERM" or "signal N".
inline std::string signal_name(int sig) {
  if (sig == SIGINT) return "SIGINT";
  if (sig == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(sig);
}

/// Thrown by a loop that saw the flag; the tools exit 128 + signal. detail completes the one line
/// the tool prints ("interrupted by SIGINT" + detail, e.g. "; nothing written").
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int sig, const std::string& detail = "")
      : std::runtime_error("interrupted by " + signal_name(sig) + detail), sig_(sig) {}
  int signal() const { return sig_; }
  int exit_code() const { return 128 + sig_; }

 private:
  int sig_;
};

/// The flag a StopToken reads: the signal that asked to stop (0: none) and how many came. Written
/// only by the process's signal handler (tool::install_interrupt_handlers) or by a test, read by
/// any thread (feeddrive-study's workers too). Lock-free std::atomic, not volatile sig_atomic_t:
/// a signal handler may touch a lock-free atomic ([support.signal]), and the readers on other
/// threads need the atomic's ordering (volatile sig_atomic_t is a data race there).
struct StopFlag {
  std::atomic<int> signal{0};
  std::atomic<int> count{0};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs a lock-free std::atomic<int>");

/// A read-only view of a StopFlag: what a library polls. A default-made token never stops (a
/// library used without a tool, a unit test); tools hand in tool::stop_token().
class StopToken {
 public:
  StopToken() = default;
  /// A token that sees every signal that came to the flag.
  explicit StopToken(const StopFlag* flag) : flag_(flag) {}
  /// The signal that asked to stop, or 0.
  int signal() const { return flag_ != nullptr && flag_->count.load() != seen_ ? flag_->signal.load() : 0; }
  bool stop_requested() const { return signal() != 0; }
  /// Throws Interrupted if a stop was asked for.
  void check() const {
    if (const int s = signal(); s != 0) throw Interrupted(s);
  }
  /// A token on the same flag that ignores the signals that came so far: for a job that, once
  /// interrupted, still finishes a short task it must not lose (the monitor writing the steps it
  /// recorded); a second signal then stops that too.
  StopToken renewed() const {
    StopToken t(flag_);
    t.seen_ = flag_ != nullptr ? flag_->count.load() : 0;
    return t;
  }

 private:
  const StopFlag* flag_{nullptr};
  int seen_{0};
};

/// Set (to "1") by feeddrive-launch for the processes it starts: the launcher reports the
/// interrupt once, its children stay silent about it.
inline constexpr const char* kQuietEnv = "FEEDDRIVE_INTERRUPT_QUIET";
/// Set by feeddrive-launch for the processes it starts: the number of a file descriptor (a
/// pipe's write end). A refusal (bad input, exit 2) is written there as its one line instead of
/// to stderr, and the launcher prints each different one once (four processes refusing one
/// swapped scenario make one line, not four).
inline constexpr const char* kRefusalFdEnv = "FEEDDRIVE_REFUSAL_FD";

}  // namespace feeddrive::interrupt

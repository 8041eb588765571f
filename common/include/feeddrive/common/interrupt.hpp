#pragma once
// The one interrupt flag of every feeddrive process, as libraries read it: long loops poll it
// (interrupted(), check()) and unwind, so destructors run: a staged output folder is removed
// (output::StagedFolder), a child gnuplot is stopped (output::run_gnuplot). Libraries only read
// it; what sets it (the SIGINT and SIGTERM handlers) is installed by the process, in
// feeddrive::tool (tool::install_interrupt_handlers, common/tool/), which also reports it.

#include <csignal>
#include <stdexcept>
#include <string>

namespace feeddrive::interrupt {

namespace detail {
/// Written only by the process's signal handler (tool::install_interrupt_handlers).
inline volatile std::sig_atomic_t g_signal = 0;
}  // namespace detail

/// The signal that interrupted the process, or 0.
inline int signal_number() { return detail::g_signal; }
inline bool interrupted() { return detail::g_signal != 0; }

/// "SIGINT", "SIGTERM" or "signal N".
inline std::string signal_name(int sig) {
  if (sig == SIGINT) return "SIGINT";
  if (sig == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(sig);
}

/// Thrown by a loop that saw the flag; the tools exit 128 + signal.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int sig) : std::runtime_error("interrupted by " + signal_name(sig)), sig_(sig) {}
  int signal() const { return sig_; }
  int exit_code() const { return 128 + sig_; }

 private:
  int sig_;
};

/// Throws Interrupted if a signal came.
inline void check() {
  if (const int s = detail::g_signal; s != 0) throw Interrupted(s);
}

/// Forgets the signal: for a tool that, once interrupted, still finishes a short job it must not
/// lose (the monitor writing the steps it recorded); a second signal then stops that too.
inline void clear() { detail::g_signal = 0; }

/// Set (to "1") by feeddrive-launch for the processes it starts: the launcher reports the
/// interrupt once, its children stay silent about it.
inline constexpr const char* kQuietEnv = "FEEDDRIVE_INTERRUPT_QUIET";
/// Set by feeddrive-launch for the processes it starts: the number of a file descriptor (a
/// pipe's write end). A refusal (bad input, exit 2) is written there as its one line instead of
/// to stderr, and the launcher prints each different one once (four processes refusing one
/// swapped scenario make one line, not four).
inline constexpr const char* kRefusalFdEnv = "FEEDDRIVE_REFUSAL_FD";

}  // namespace feeddrive::interrupt

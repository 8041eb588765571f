#pragma once
// The one interrupt flag of every feeddrive process: SIGINT and SIGTERM set it, long loops poll
// it (interrupted()) and unwind, so destructors run: a staged output folder is removed
// (output::StagedFolder), a child gnuplot is stopped (output::run_gnuplot).
//
// The handler only stores the signal number (async-signal-safe). It is installed without
// SA_RESTART, so a blocking system call (poll, nanosleep, waitpid) returns EINTR at once and the
// caller sees the flag.

#include <signal.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace feeddrive::interrupt {

namespace detail {
inline volatile std::sig_atomic_t g_signal = 0;
extern "C" inline void on_signal(int sig) { g_signal = sig; }
}  // namespace detail

/// Installs the SIGINT/SIGTERM handlers (idempotent). SIGXFSZ is ignored: a file grown past
/// the file-size limit (ulimit -f) is then a write error (EFBIG) reported as such, with the
/// staging folder removed, not a process killed mid-write.
inline void install_handlers() {
  struct sigaction sa {};
  sa.sa_handler = detail::on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking call returns EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGXFSZ, SIG_IGN);
  // feeddrive-launch starts its processes with the two blocked (so a Ctrl-C during their start
  // is kept pending, not lost): from here on the handlers take them.
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

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

/// The end of an interrupted tool (docs/scenario.md, "Exit codes and Ctrl-C"): prints the one
/// line "error: interrupted by SIGINT<detail>" (unless started by feeddrive-launch) and returns
/// the exit code 128 + signal. Usage: `catch (const Interrupted& e) { return report(e); }`.
inline int report(const Interrupted& e, const std::string& detail = "") {
  const char* quiet = std::getenv(kQuietEnv);
  if (quiet == nullptr || std::string(quiet) != "1") std::fprintf(stderr, "error: %s%s\n", e.what(), detail.c_str());
  return e.exit_code();
}

}  // namespace feeddrive::interrupt

#pragma once
// The one interrupt flag of every feeddrive process (issue 13, point 8: Ctrl-C ends any phase
// within a second).
//
// install() sets SIGINT/SIGTERM handlers (without SA_RESTART, so a blocking wait returns EINTR)
// that only record the signal. Every long loop (simulating, writing, plotting, fitting, reading
// a log, waiting on the bus) calls check(), which throws Interrupted once a signal came. The
// process then removes what it had begun (a staged output folder), prints one line
//   error: interrupted by SIGINT
// and exits with exit_code(): 128 + the signal number (130 for SIGINT, 143 for SIGTERM), the
// shell's convention for a process ended by a signal. docs/deployment.md, "Exit codes".
// Header-only (C++17 inline variables), shared by every library and tool.

#include <signal.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace feeddrive::interrupt {

/// The signal received (0: none). Written only by the handler.
inline volatile std::sig_atomic_t g_signal = 0;

extern "C" inline void on_signal(int sig) { g_signal = sig; }

/// Installs the handlers for SIGINT and SIGTERM. Idempotent.
inline void install() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking poll, read or waitpid returns EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

/// The signal that interrupted the process, or 0.
inline int signal_number() { return g_signal; }
inline bool requested() { return g_signal != 0; }

inline std::string signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : "signal " + std::to_string(sig);
}

/// Thrown by check() once a signal came: the process stops what it does, cleans up, prints
/// what() and exits with exit_code().
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int sig) : std::runtime_error("interrupted by " + signal_name(sig)), sig_(sig) {}
  int signal() const { return sig_; }

 private:
  int sig_;
};

/// Throws Interrupted if a signal came. Cheap (one load): call it in every long loop.
inline void check() {
  if (g_signal != 0) throw Interrupted(g_signal);
}

/// The exit code of a process ended by signal `sig`: 128 + sig (130 for SIGINT).
inline int exit_code(int sig) { return 128 + (sig > 0 ? sig : SIGINT); }

/// Set (to "1") by feeddrive-launch for the processes it starts: the launcher reports the
/// interrupt once, its children stay silent about it.
inline constexpr const char* kQuietEnv = "FEEDDRIVE_INTERRUPT_QUIET";

/// The end of an interrupted tool: prints the one line "error: interrupted by SIGINT" (unless
/// started by feeddrive-launch) and returns the exit code. Usage: `catch (const Interrupted& e)
/// { return interrupt::report(e); }`.
inline int report(const Interrupted& e) {
  const char* quiet = std::getenv(kQuietEnv);
  if (quiet == nullptr || std::string(quiet) != "1") std::fprintf(stderr, "error: %s\n", e.what());
  return exit_code(e.signal());
}

}  // namespace feeddrive::interrupt

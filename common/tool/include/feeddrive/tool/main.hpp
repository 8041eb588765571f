#pragma once
// The one main() of every feeddrive tool: command-line parsing, one logging style, the interrupt
// handlers, and the one mapping from what the work threw to an exit code and a one-line message
// (feeddrive/common/errors.hpp for the codes). A tool's main only declares its options and wires
// its body; no tool writes its own catch ladder.

#include <CLI/CLI.hpp>

#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/fields.hpp"
#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::tool {

/// Installs the process's SIGINT/SIGTERM handlers, which set the interrupt flag the libraries
/// poll (feeddrive/common/interrupt.hpp); idempotent. No SA_RESTART: a blocking system call (poll,
/// nanosleep, waitpid) returns EINTR at once and the caller sees the flag. SIGXFSZ is ignored: a
/// file grown past the file-size limit (ulimit -f) is then a write error (EFBIG) reported as
/// such, with the staging folder removed, not a process killed mid-write. The two signals are
/// unblocked (feeddrive-launch starts its processes with them blocked, so that a Ctrl-C during
/// their start is kept pending, not lost).
void install_interrupt_handlers();

/// The process's stop token, set by those handlers: what a tool hands to the libraries it calls
/// (feeddrive/common/interrupt.hpp). Without the handlers installed it never stops.
interrupt::StopToken stop_token();

/// The end of an interrupted tool (docs/scenario.md, "Exit codes and Ctrl-C"): prints the one
/// line "error: interrupted by SIGINT<detail>" (unless started by feeddrive-launch:
/// interrupt::kQuietEnv) and returns the exit code 128 + signal.
int report_interrupt(const interrupt::Interrupted& e, const std::string& detail = "");

/// The exit code and the one line on stderr for an exception a tool's work threw:
///   interrupt::Interrupted          128 + signal  "error: interrupted by SIGINT<interrupt_detail>"
///                                                 (no line under feeddrive-launch: it reports once)
///   BadInput, std::invalid_argument 2             "error: <what>"
///   any other std::exception        1             spdlog::error("<what>"): "[time] [tool] [error] <what>"
int report(std::exception_ptr e, const std::string& interrupt_detail = "");

/// Parses the command line. nullopt: go on; else the exit code: 0 after --help, 2 after a parse
/// error, reported in one line "error: <what> (see --help)"; an option the tool does not have is
/// "error: --bogus: no such option (see --help)". speak = false prints nothing, neither help nor
/// error (the MPI ranks but rank 0 of feeddrive-study: one process speaks).
std::optional<int> parse(CLI::App& app, int argc, char** argv, bool speak = true);

/// An option whose value is the name of an enum listed by enum_names (feeddrive/common/fields.hpp):
/// read into `target` by fields::enum_from_name, its type shown as "a|b|c"; any other name is the
/// parse error "--name = 'x': expected one of a, b, c" (exit 2).
template <typename E>
CLI::Option* add_enum_option(CLI::App& app, const std::string& name, E& target, const std::string& description) {
  std::string choices;
  for (const auto& [v, n] : enum_names(E{})) choices += (choices.empty() ? "" : "|") + std::string(n);
  return app
      .add_option_function<std::string>(
          name,
          [&target, name](const std::string& v) {
            try {
              target = fields::enum_from_name<E>(v);
            } catch (const std::invalid_argument& e) {
              throw CLI::ValidationError(name + " = '" + v + "': " + e.what());
            }
          },
          description)
      ->type_name(choices);
}

/// The one range check of a numeric option, for every tool: a finite number (an integer where
/// `integer`) in [lo, hi], or exactly 0 where `zero_default` (0 = the default). Otherwise the parse
/// error "--name: '1.5' is not an integer" / "'abc' is not a finite number" / "'0' is outside
/// [1, 256]" (exit 2); CLI::Range's wording and its NaN are not used.
CLI::Validator within(double lo, double hi, bool integer = false, bool zero_default = false);

/// The one logging style: spdlog on stderr, "[HH:MM:SS.mmm] [name] [level] message"; quiet:
/// warnings and errors only.
void setup_logging(const std::string& name, bool quiet);

/// What run() needs besides the body.
struct Options {
  std::string name;            ///< the logger's name: the tool ("feeddrive-sim")
  const bool* quiet{nullptr};  ///< the tool's --quiet flag, read after parsing
  /// Appended to the interrupt's line, computed after parsing ("; nothing written to DIR").
  std::function<std::string()> interrupt_detail;
};

/// Runs f(), a step that only reads and checks the input before any work: whatever it throws,
/// but an interrupt, is the input's fault (BadInput: exit 2).
template <typename F>
auto input_step(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const interrupt::Interrupted&) {
    throw;
  } catch (const BadInput&) {
    throw;
  } catch (const std::exception& e) {
    throw BadInput(e.what());
  }
}

/// parse(), setup_logging(), install_interrupt_handlers(), then body(): its return value, or
/// report() of what it threw.
int run(CLI::App& app, int argc, char** argv, const Options& opt, const std::function<int()>& body);

}  // namespace feeddrive::tool

#include "feeddrive/tool/main.hpp"

#include <cmath>
#include <cstdlib>

#include "feeddrive/common/validate.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::tool {
namespace {
// The process's one stop flag: written only by on_signal, read through stop_token().
interrupt::StopFlag g_stop;
extern "C" void on_signal(int sig) {
  g_stop.signal.store(sig);  // lock-free (static_assert in interrupt.hpp): safe in a handler
  g_stop.count.fetch_add(1);
}
}  // namespace

interrupt::StopToken stop_token() { return interrupt::StopToken(&g_stop); }

void install_interrupt_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking call returns EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGXFSZ, SIG_IGN);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

int report_interrupt(const interrupt::Interrupted& e, const std::string& detail) {
  const char* quiet = std::getenv(interrupt::kQuietEnv);
  if (quiet == nullptr || std::string(quiet) != "1") std::fprintf(stderr, "error: %s%s\n", e.what(), detail.c_str());
  return e.exit_code();
}

namespace {

// A refusal's one line: to the launcher's pipe when started by feeddrive-launch (it prints each
// different line once), else to stderr. One write(2) of under PIPE_BUF bytes: never interleaved.
int refuse(const char* what) {
  const std::string line = std::string("error: ") + what + "\n";
  if (const char* fd = std::getenv(interrupt::kRefusalFdEnv); fd != nullptr && *fd != '\0') {
    const std::string cut = line.size() < 4000 ? line : line.substr(0, 3999) + "\n";
    if (::write(std::atoi(fd), cut.data(), cut.size()) == static_cast<ssize_t>(cut.size())) return kExitBadInput;
  }
  std::fputs(line.c_str(), stderr);
  return kExitBadInput;
}

}  // namespace

int report(std::exception_ptr e, const std::string& interrupt_detail) {
  try {
    std::rethrow_exception(e);
  } catch (const interrupt::Interrupted& i) {
    return report_interrupt(i, interrupt_detail);
  } catch (const BadInput& b) {
    return refuse(b.what());
  } catch (const std::invalid_argument& b) {
    return refuse(b.what());
  } catch (const std::exception& f) {
    // A failure of the run, logged with the process's name: under feeddrive-launch the lines of
    // four processes meet on one terminal, and each must say whose it is.
    spdlog::error("{}", f.what());
    return kExitFailed;
  }
}

namespace {

// The one line of a parse error. CLI11 checks the required options before the unknown ones: a
// misspelt option would only read "scenario is required", and an argument it could not place
// "The following argument was not expected: --bogus". The first argument it could not place
// names the real mistake: an option the tool does not have, else an argument too many.
std::string parse_error_line(CLI::App& app, const CLI::ParseError& e) {
  const std::vector<std::string> extra = app.remaining(true);
  const bool extras_only = dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr;
  for (const std::string& a : extra)
    if (a.size() > 1 && a[0] == '-') return a + ": no such option";
  if (extra.empty()) return e.what();
  return extra.front() + ": unexpected argument" + (extras_only ? std::string() : std::string("; ") + e.what());
}

}  // namespace

CLI::Validator within(double lo, double hi, bool integer, bool zero_default) {
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) return "'" + s + "' is not a finite number";
        if (integer && v != std::floor(v)) return "'" + s + "' is not an integer";
        if (zero_default && v == 0.0) return "";
        if (v < lo || v > hi)
          return "'" + s + "' is outside [" + validate::format_number(lo) + ", " + validate::format_number(hi) + "]" +
                 (zero_default ? " (or 0 for the default)" : "");
        return "";
      },
      "");
}

std::optional<int> parse(CLI::App& app, int argc, char** argv, bool speak) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const bool help = e.get_exit_code() == 0;  // --help
    if (!speak) return help ? 0 : kExitBadInput;
    if (help) return app.exit(e);
    std::fprintf(stderr, "error: %s (see --help)\n",
                 parse_error_line(app, e).c_str());  // one line, as for every bad input
    return kExitBadInput;
  }
  return std::nullopt;
}

void setup_logging(const std::string& name, bool quiet) {
  auto logger = spdlog::get(name);
  if (!logger) logger = spdlog::stderr_color_mt(name);
  logger->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(quiet ? spdlog::level::warn : spdlog::level::info);
}

int run(CLI::App& app, int argc, char** argv, const Options& opt, const std::function<int()>& body) {
  if (const std::optional<int> rc = parse(app, argc, argv)) return *rc;
  setup_logging(opt.name, opt.quiet != nullptr && *opt.quiet);
  install_interrupt_handlers();
  try {
    return body();
  } catch (...) {
    return report(std::current_exception(), opt.interrupt_detail ? opt.interrupt_detail() : std::string());
  }
}

}  // namespace feeddrive::tool

#include "feeddrive/tool/main.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::tool {

int report(std::exception_ptr e, const std::string& interrupt_detail) {
  try {
    std::rethrow_exception(e);
  } catch (const interrupt::Interrupted& i) {
    return interrupt::report(i, interrupt_detail);
  } catch (const BadInput& b) {
    std::fprintf(stderr, "error: %s\n", b.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& b) {
    std::fprintf(stderr, "error: %s\n", b.what());
    return kExitBadInput;
  } catch (const std::exception& f) {
    std::fprintf(stderr, "error: %s\n", f.what());
    return kExitFailed;
  }
}

std::optional<int> parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {  // one line, as for every bad input
    std::fprintf(stderr, "error: %s (see --help)\n", e.what());
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
  interrupt::install_handlers();
  try {
    return body();
  } catch (...) {
    return report(std::current_exception(), opt.interrupt_detail ? opt.interrupt_detail() : std::string());
  }
}

}  // namespace feeddrive::tool

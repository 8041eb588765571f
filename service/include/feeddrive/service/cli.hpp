#pragma once
// Command-line wiring shared by the service processes: the common options and one main()
// skeleton (logging, signals, exit codes: 0 done, 1 the run failed, 2 bad input).

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

#include "feeddrive/service/node.hpp"

namespace feeddrive::service {

/// --lcm-url, --prefix, --start-timeout, --step-timeout, --resend-interval, --monitor-window,
/// --linger, --realtime, --max-bad-commands, --quiet.
void add_node_options(CLI::App& app, NodeOptions& opt);

/// Parses the arguments and runs body(). body returns the exit code; std::invalid_argument
/// (bad input) gives 2, RunFailure and other exceptions 1, each as one line on stderr.
/// `announce` is called with the failure message before exiting on a RunFailure.
int run_process(CLI::App& app, int argc, char** argv, const NodeOptions& opt, const std::function<int()>& body);

}  // namespace feeddrive::service

#pragma once
// Command-line wiring shared by the service processes: the common options, the run's scenario
// and the main() body of a run process, on tool::run (feeddrive/tool/main.hpp: logging, the
// interrupt handlers and the one exit-code mapping: 0 done, 1 the run failed, 2 bad input,
// 128 + signal interrupted).

#include <CLI/CLI.hpp>

#include <functional>
#include <string>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::service {

/// Adds the options every run process shares (the protocol's timeouts and pace, real time, the
/// run's identity and --key, --quiet): their list is docs/cli.md, "Options of every run process",
/// checked against --help by tests/docs/cli_docs_test.py.
void add_node_options(CLI::App& app, NodeOptions& opt);

/// Parses the arguments and runs body() with tool::run (feeddrive/tool/main.hpp): body returns
/// the exit code; what it throws gets the one mapping of every tool (bad input 2, RunFailure and
/// other failures 1, interrupt::Interrupted 128 + signal), each as one line on stderr.
int run_process(CLI::App& app, int argc, char** argv, const NodeOptions& opt, const std::function<int()>& body);

/// The scenario of a run process: loaded once, its bytes hashed (SHA-256, FIPS 180-4, by
/// libcrypto; with --set, the scenario as run: sim::load_scenario's text). With opt.scenario_hash set (--scenario-hash:
/// feeddrive-launch sets it), a file whose bytes hash otherwise (replaced while the run started) throws
/// std::invalid_argument, one line: exit 2.
struct RunScenario {
  sim::Scenario scenario;
  std::string sha256;  ///< hex
};
RunScenario load_run_scenario(const std::string& path, const NodeOptions& opt);

/// Runs node.run() and returns 0; a RunFailure is first announced on <prefix>_STATUS (so the
/// other processes stop at once) and then passed on to run_process.
template <typename NodeType>
int run_node(NodeType& node) {
  try {
    node.run();
  } catch (const RunFailure& e) {
    node.announce_failure(e.what());
    throw;
  } catch (const interrupt::Interrupted& e) {
    node.announce_failure(e.what());
    throw;
  }
  return 0;
}

/// The main() body of a run process built from the scenario alone (feeddrive-plant,
/// feeddrive-trajectory): the scenario argument and the common options, the scenario loaded and
/// its hash checked against the monitor's run_info_t, then NodeType(scenario, opt) under
/// run_node, all inside run_process.
template <typename NodeType>
int run_scenario_node(CLI::App& app, int argc, char** argv) {
  std::string scenario_path;
  NodeOptions opt;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  add_node_options(app, opt);
  return run_process(app, argc, argv, opt, [&] {
    const RunScenario rs = load_run_scenario(scenario_path, opt);  // the launcher's scenario, or exit 2
    opt.scenario_hash = rs.sha256;                                 // checked against the monitor's run_info_t
    NodeType node(rs.scenario, opt);
    return run_node(node);
  });
}

}  // namespace feeddrive::service

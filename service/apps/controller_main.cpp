// feeddrive-controller: the scenario's controller (sliding mode, cascade, open loop or a plugin) as
// an LCM process; --plugin PATH hosts the controller plugin at PATH instead (docs/plugins.md).
// Wiring only: scenario -> make_controller -> ControllerNode (service/controller_node.hpp).
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/controller_node.hpp"
#include "feeddrive/sim/scenario.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{
      "feeddrive-controller: answers <prefix>_STATE with <prefix>_CMD using <prefix>_REF "
      "(docs/lcm-contract.md)",
      "feeddrive-controller"};
  std::string scenario_path;
  std::string plugin;
  service::NodeOptions opt;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--plugin", plugin, "host the controller plugin (shared library) at PATH (docs/plugins.md)");
  service::add_node_options(app, opt);
  return service::run_process(app, argc, argv, opt, [&] {
    const service::RunScenario rs =
        service::load_run_scenario(scenario_path, opt);  // the launcher's scenario, or exit 2
    // Checked against the monitor's run_info_t, except for a --plugin host: its scenario gives the
    // plugin's parameters and may be another file than the run's (docs/plugins.md).
    if (plugin.empty()) opt.scenario_hash = rs.sha256;
    sim::Scenario s = rs.scenario;
    if (!plugin.empty()) sim::use_plugin(s, plugin);
    service::ControllerNode node(sim::make_controller(s), opt);
    return service::run_node(node);
  });
}

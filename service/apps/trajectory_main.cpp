// feeddrive-trajectory: the scenario's reference as an LCM process. Wiring only:
// scenario -> make_reference -> TrajectoryNode (service/trajectory_node.hpp).
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/trajectory_node.hpp"
#include "feeddrive/sim/scenario.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-trajectory: publishes <prefix>_REF ahead of <prefix>_STATE (docs/lcm-contract.md)",
               "feeddrive-trajectory"};
  std::string scenario_path;
  service::NodeOptions opt;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  service::add_node_options(app, opt);
  return service::run_process(app, argc, argv, opt, [&] {
    const service::RunScenario rs = service::load_run_scenario(scenario_path, opt);  // the launcher's scenario, or exit 2
    opt.scenario_hash = rs.sha256;  // checked against the monitor's run_info_t
    const sim::Scenario s = rs.scenario;
    service::TrajectoryNode node(s, opt);
    return service::run_node(node);
  });
}

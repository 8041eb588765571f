// feeddrive-trajectory: the scenario's reference as an LCM process. Wiring only:
// scenario -> make_reference -> TrajectoryNode (service/trajectory_node.hpp).
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/trajectory_node.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-trajectory: publishes <prefix>_REF ahead of <prefix>_STATE (docs/lcm-contract.md)",
               "feeddrive-trajectory"};
  return service::run_scenario_node<service::TrajectoryNode>(app, argc, argv);
}

// feeddrive-plant: the simulated feed drive (feeddrive::plant + CVODE) as an LCM process.
// Wiring only: scenario -> PlantNode (service/plant_node.hpp).
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/plant_node.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{
      "feeddrive-plant: the simulated linear-motor feed drive, publishing <prefix>_STATE and "
      "applying <prefix>_CMD (docs/lcm-contract.md)",
      "feeddrive-plant"};
  return service::run_scenario_node<service::PlantNode>(app, argc, argv);
}

// feeddrive-launch: runs a scenario as four LCM processes (plant, controller, trajectory,
// monitor) in lockstep and collects the results in DIR. Wiring only: options -> launch().
#include <spdlog/spdlog.h>

#include <nlohmann/json.hpp>
#include <fstream>

#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/launch.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-launch: runs SCENARIO as four lockstep LCM processes and writes DIR "
               "(timeseries.csv, summary.json, plots)",
               "feeddrive-launch"};
  service::LaunchOptions lo;
  service::NodeOptions opt;
  std::vector<std::string> external;
  bool no_plots = false;
  app.add_option("scenario", lo.scenario, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", lo.out_dir, "output folder (replaced atomically)")->required();
  app.add_option("--external", external, "leave ROLE (controller, plant or trajectory) to a process you start")
      ->type_name("ROLE");
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  std::string cpus;
  app.add_option("--cpus", cpus, "pin every process to these CPUs, e.g. 0 or 0,1 (a lockstep chain runs fastest on one core where cross-core wake-ups are slow)")
      ->type_name("LIST");
  service::add_node_options(app, opt);
  return service::run_process(app, argc, argv, opt, [&] {
    lo.external.insert(external.begin(), external.end());
    lo.plots = !no_plots;
    if (!cpus.empty()) lo.cpus = service::parse_cpu_list(cpus);
    const sim::Scenario s = sim::load_scenario(lo.scenario);  // bad input fails here, before any process starts
    sim::check_output_dir(lo.out_dir);
    spdlog::info("{}: {} steps of {} s on {} (prefix {})", s.name, s.steps(), s.control_period, opt.lcm_url, opt.prefix);
    const service::LaunchResult r = service::launch(lo, opt);
    std::ifstream in(lo.out_dir + "/summary.json");
    if (in) {
      const auto j = nlohmann::json::parse(in, nullptr, false);
      if (!j.is_discarded() && j.contains("lockstep"))
        spdlog::info("{} steps, max |e| {:.4g} m, resends {}, lost {}, state->command p50 {} us -> {}",
                     j.value("steps", 0L), j.value("position_error_max_abs_m", 0.0),
                     j["lockstep"].value("resends", 0L), j["lockstep"].value("lost", 0L),
                     j["lockstep"]["latency_us"]["state_to_command"]["p50"].dump(), lo.out_dir);
    }
    for (const auto& f : r.failed) spdlog::error("failed: {}", f);
    return r.exit_code;
  });
}

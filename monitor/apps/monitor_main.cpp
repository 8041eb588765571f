// feeddrive-monitor: records a run from its LCM channels into DIR/{timeseries.csv, summary.json,
// *.png} (feeddrive-sim's format plus lockstep statistics). Wiring only: scenario -> MonitorNode.
#include <cstdio>
#include <string>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/monitor/monitor_node.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/record/lcm_log.hpp"
#include "feeddrive/service/cli.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{
      "feeddrive-monitor: records every step of a run, prints progress, writes the results "
      "(docs/lcm-contract.md)",
      "feeddrive-monitor"};
  std::string scenario_path;
  service::NodeOptions opt;
  monitor::MonitorOptions mopt;
  bool no_plots = false;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", mopt.out_dir,
                 "output folder (written atomically; replaces only an earlier feeddrive output)")
      ->required();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--attach", mopt.attach,
               "join a running system or an lcm-logplayer playback: record from the first state seen, "
               "ask for what it missed but never acknowledge; its failure never stops the run (docs/lcm-contract.md)");
  app.add_option("--lcm-log", mopt.lcm_log,
                 "also write every message of the run to FILE in the standard LCM log format (as lcm-logger, "
                 "without its cost; lcm-logplayer, lcm-spy and feeddrive-log2csv read it)");
  service::add_node_options(app, opt);
  return service::run_process(app, argc, argv, opt, [&] {
    mopt.plots = !no_plots;
    const service::RunScenario rs =
        service::load_run_scenario(scenario_path, opt);  // the launcher's scenario, or exit 2
    const sim::Scenario& s = rs.scenario;
    opt.scenario_hash = rs.sha256;           // run_info_t.scenario_hash: of the bytes read here
    output::check_output_dir(mopt.out_dir);  // before the run
    output::check_outside(mopt.lcm_log, "--lcm-log", mopt.out_dir);
    output::check_output_file(mopt.lcm_log, "--lcm-log", record::kLcmLogMagic);
    sim::check_run_size(s, mopt.out_dir);
    // The progress line, each over the one before; the last one ends it.
    mopt.progress = [](const std::string& line, bool last) {
      std::fprintf(stderr, "\r%s   %s", line.c_str(), last ? "\n" : "");
    };
    monitor::MonitorNode node(s, opt, mopt);
    const bool ok = node.run();
    opt.stop.check();  // a Ctrl-C while the plots were drawn: the data are written, the exit says interrupted
    return ok ? 0 : node.record_too_big() ? 2 : 1;
  });
}

// feeddrive-sim: runs one scenario in-process and writes DIR/{timeseries.csv, summary.json, *.png}.
//
//   scenario.yaml --> load_scenario --> run (reference -> controller -> CVODE plant) --> RunWriter
//                                        each record streamed to timeseries.csv, summary, plots
//
// Exit codes: 0 ok, 2 bad input (scenario, arguments, a run too large), 1 runtime failure,
// 128 + signal after Ctrl-C / SIGTERM (the staged output folder is removed).
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

int main(int argc, char** argv) {
  CLI::App app{"feeddrive-sim: in-process simulation of a linear-motor feed drive"};
  std::string scenario_path, out_dir;
  bool no_plots = false, quiet = false;
  std::vector<std::string> sets;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")->required();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_option("--set", sets, "KEY=VALUE: set a scenario key (dotted, e.g. plant.mass=110) as if the file said so; repeatable")
      ->type_name("KEY=VALUE");
  app.add_flag("--quiet,-q", quiet, "print only errors");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  spdlog::set_level(quiet ? spdlog::level::warn : spdlog::level::info);
  feeddrive::interrupt::install_handlers();

  feeddrive::sim::Scenario scenario;
  try {
    std::vector<feeddrive::sim::KeySetting> settings;
    for (const std::string& k : sets) settings.push_back(feeddrive::sim::parse_key_setting(k));
    scenario = feeddrive::sim::load_scenario(scenario_path, settings);
    feeddrive::output::check_output_dir(out_dir);  // before any work
    feeddrive::sim::check_run_size(scenario, out_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  try {
    spdlog::info("{}: {} steps of {} s", scenario.name, scenario.steps(), scenario.control_period);
    if (scenario.controller.type == feeddrive::sim::ControllerType::kCascade)
      spdlog::info("cascade gains: kp = {:.6g} 1/s, kv = {:.6g} 1/s, ki = {:.6g} 1/s^2", scenario.controller.cascade.kp,
                   scenario.controller.cascade.kv, scenario.controller.cascade.ki);
    feeddrive::sim::RunWriter out(out_dir, scenario, "feeddrive-sim");
    const auto stats = feeddrive::sim::run(scenario, [&](const feeddrive::sim::Record& r) { out.add(r); });
    const auto summary = out.summary(stats.wall_time_s, stats.integrator);
    out.finish(summary, !no_plots);
    if (!out.plot_error().empty())
      spdlog::warn("plots not drawn ({}); the data are in {}", out.plot_error(), feeddrive::output::shown(out_dir));
    else if (!no_plots)
      spdlog::info("plots drawn in {:.3f} s", out.plot_seconds());
    // After the run (a run that then fails says only why, in one line): the values that load but
    // are implausible for a linear feed drive, and a move the run cut off (summary.json too).
    for (const std::string& w : scenario.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());  // stderr, as the errors
    spdlog::info("max |e| = {:.4g} m, rms e = {:.4g} m, u in [{:.4g}, {:.4g}], wall {:.3f} s -> {}",
                 summary.position_error_max_abs_m, summary.position_error_rms_m, summary.control_min,
                 summary.control_max, summary.wall_time_s, out_dir);
  } catch (const feeddrive::interrupt::Interrupted& e) {
    std::fprintf(stderr, "error: %s; nothing written to %s\n", e.what(), feeddrive::output::shown(out_dir).c_str());
    return e.exit_code();
  } catch (const feeddrive::plant::IntegrationError& e) {  // the scenario's keys make it unintegrable
    std::fprintf(stderr, "error: %s: %s\n", scenario_path.c_str(), e.what());
    return 2;
  } catch (const feeddrive::sim::ScenarioError& e) {  // a non-finite value at run time (check_finite_step)
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {  // the run's CSV cannot fit (RunWriter's check on its first rows)
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}

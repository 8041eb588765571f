// feeddrive-sim: runs one scenario in-process and writes DIR/{timeseries.csv, summary.json, *.png}.
//
//   scenario.yaml --> load_scenario --> run (reference -> controller -> CVODE plant) --> RunWriter
//                                        each record streamed to timeseries.csv, summary, plots
//
// --frequency-response: instead of the scenario's run, the closed loop's frequency response by
// stepped sines (analysis/frequency_response.hpp, docs/analysis.md) into DIR.
//
// Exit codes: 0 ok, 2 bad input (scenario, arguments, a run too large), 1 runtime failure,
// 128 + signal after Ctrl-C / SIGTERM (the staged output folder is removed).
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "feeddrive/analysis/frequency_response.hpp"
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
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")->required();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--quiet,-q", quiet, "print only errors");
  bool frequency_response = false;
  feeddrive::analysis::FrequencyResponseOptions fr;
  app.add_flag("--frequency-response", frequency_response, "measure the closed loop's frequency response (docs/analysis.md)");
  app.add_option("--fr-frequencies", fr.frequencies, "frequencies [Hz] (default: --fr-points log-spaced)")->delimiter(',');
  app.add_option("--fr-from", fr.f_min, "lowest frequency [Hz]")->capture_default_str();
  app.add_option("--fr-to", fr.f_max, "highest frequency [Hz] (0: 0.4/control_period)")->capture_default_str();
  app.add_option("--fr-points", fr.points, "number of frequencies")->capture_default_str();
  app.add_option("--fr-amplitude", fr.reference_amplitude, "reference sine amplitude [m] (0: no reference run)")->capture_default_str();
  app.add_option("--fr-acceleration", fr.acceleration_limit, "reference acceleration limit [m/s^2] (0: a quarter of the force range / mass)")->capture_default_str();
  app.add_option("--fr-force", fr.force_amplitude, "disturbance force amplitude [N] (0: no disturbance run)")->capture_default_str();
  app.add_option("--fr-velocity", fr.feed_velocity, "constant feed velocity under the excitation [m/s]")->capture_default_str();
  app.add_option("--fr-settle", fr.settle_time, "least settling time dropped per frequency [s]")->capture_default_str();
  app.add_option("--jobs,-j", fr.jobs, "frequencies measured in parallel")->capture_default_str();
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
    scenario = feeddrive::sim::load_scenario(scenario_path);
    feeddrive::output::check_output_dir(out_dir);  // before any work
    if (frequency_response) fr.validate(scenario);
    else feeddrive::sim::check_run_size(scenario, out_dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  try {
    if (frequency_response) {
      const auto r = feeddrive::analysis::measure_frequency_response(scenario, fr);
      if (!quiet) std::fputs(feeddrive::analysis::frequency_response_table(scenario, r).c_str(), stdout);
      const std::string plot_error = feeddrive::analysis::write_frequency_response(out_dir, scenario, r, !no_plots);
      if (!plot_error.empty()) spdlog::warn("plots not drawn ({}); the data are in {}", plot_error, feeddrive::output::shown(out_dir));
      spdlog::info("{} frequencies in {:.1f} s -> {}", r.points.size(), r.wall_time_s, out_dir);
      return 0;
    }
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
    spdlog::info("{}, wall {:.3f} s -> {}", feeddrive::sim::summary_headline(feeddrive::sim::summary_json(summary, scenario)),
                 summary.wall_time_s, out_dir);
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

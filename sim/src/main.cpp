// feeddrive-sim: runs one scenario in-process and writes DIR/{timeseries.csv, summary.json, *.png}.
//
//   scenario.yaml --> load_scenario --> run (reference -> controller -> CVODE plant) --> RunWriter
//                                        each record streamed to timeseries.csv, summary, plots
//
// Exit codes: 0 ok, 2 bad input (scenario, arguments, a run too large), 1 runtime failure,
// 128 + signal after Ctrl-C / SIGTERM (the staged output folder is removed).
#include <spdlog/spdlog.h>

#include "feeddrive/output/folder.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/tool/main.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-sim: in-process simulation of a linear-motor feed drive", "feeddrive-sim"};
  std::string scenario_path, out_dir;
  bool no_plots = false, quiet = false;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")->required();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--quiet,-q", quiet, "print only errors");
  tool::Options opt{"feeddrive-sim", &quiet, [&] { return "; nothing written to " + output::shown(out_dir); }};
  return tool::run(app, argc, argv, opt, [&] {
    const sim::Scenario scenario = tool::input_step([&] {
      sim::Scenario s = sim::load_scenario(scenario_path);
      output::check_output_dir(out_dir);  // before any work
      sim::check_run_size(s, out_dir);
      return s;
    });
    spdlog::info("{}: {} steps of {} s", scenario.name, scenario.steps(), scenario.control_period);
    if (scenario.controller.type == sim::ControllerType::kCascade)
      spdlog::info("cascade gains: kp = {:.6g} 1/s, kv = {:.6g} 1/s, ki = {:.6g} 1/s^2", scenario.controller.cascade.kp,
                   scenario.controller.cascade.kv, scenario.controller.cascade.ki);
    // At run time: a model the keys make unintegrable (plant::IntegrationError) or a non-finite
    // value (check_finite_step: sim::ScenarioError), or a CSV that cannot fit (RunWriter's check
    // on its first rows: std::invalid_argument) is bad input, exit 2 (tool::report).
    sim::RunWriter out(out_dir, scenario, "feeddrive-sim");
    const auto stats = sim::run(scenario, [&](const sim::Record& r) { out.add(r); });
    const auto summary = out.summary(stats.wall_time_s, stats.integrator);
    out.finish(summary, !no_plots);
    if (!out.plot_error().empty())
      spdlog::warn("plots not drawn ({}); the data are in {}", out.plot_error(), output::shown(out_dir));
    else if (!no_plots)
      spdlog::info("plots drawn in {:.3f} s", out.plot_seconds());
    spdlog::info("max |e| = {:.4g} m, rms e = {:.4g} m, u in [{:.4g}, {:.4g}], wall {:.3f} s -> {}",
                 summary.position_error_max_abs_m, summary.position_error_rms_m, summary.control_min,
                 summary.control_max, summary.wall_time_s, out_dir);
    return kExitOk;
  });
}

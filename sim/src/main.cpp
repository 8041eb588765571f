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
#include <spdlog/spdlog.h>

#include <cstdio>

#include "feeddrive/analysis/frequency_response.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/tool/main.hpp"

namespace {

using namespace feeddrive;

// The --fr-* options of --frequency-response into `fr`.
void add_frequency_response_options(CLI::App& app, analysis::FrequencyResponseOptions& fr) {
  app.add_option("--fr-frequencies", fr.frequencies, "frequencies [Hz] (default: --fr-points log-spaced)")
      ->delimiter(',');
  app.add_option("--fr-from", fr.f_min, "lowest frequency [Hz]")->capture_default_str();
  app.add_option("--fr-to", fr.f_max, "highest frequency [Hz] (0: 0.4/control_period)")->capture_default_str();
  app.add_option("--fr-points", fr.points, "number of frequencies")->capture_default_str();
  app.add_option("--fr-amplitude", fr.reference_amplitude, "reference sine amplitude [m] (0: no reference run)")
      ->capture_default_str();
  app.add_option("--fr-acceleration", fr.acceleration_limit,
                 "reference acceleration limit [m/s^2] (0: a quarter of the force range / mass)")
      ->capture_default_str();
  app.add_option("--fr-force", fr.force_amplitude, "disturbance force amplitude [N] (0: no disturbance run)")
      ->capture_default_str();
  app.add_option("--fr-velocity", fr.feed_velocity, "constant feed velocity under the excitation [m/s]")
      ->capture_default_str();
  app.add_option("--fr-settle", fr.settle_time, "least settling time dropped per frequency [s]")->capture_default_str();
  app.add_option("--jobs,-j", fr.jobs, "frequencies measured in parallel")
      ->check(tool::within(1, 256, true))
      ->capture_default_str();
}

// --frequency-response: measures the closed loop's response, prints its table (unless quiet) and
// writes it to out_dir.
void run_frequency_response(const sim::Scenario& scenario, analysis::FrequencyResponseOptions fr,
                            const std::string& out_dir, bool plots, bool quiet) {
  fr.stop = tool::stop_token();
  const auto r = analysis::measure_frequency_response(scenario, fr);
  if (!quiet) std::fputs(analysis::frequency_response_table(scenario, r).c_str(), stdout);
  const analysis::FrequencyResponseWritten written =
      analysis::write_frequency_response(out_dir, scenario, r, plots, tool::stop_token());
  if (!written.plot_error.empty())
    spdlog::warn("plots not drawn ({}); the data are in {}", written.plot_error, output::shown(out_dir));
  for (const std::string& w : written.warnings) spdlog::warn("{}", w);
  // as after a run: the scenario's and the options' plausibility warnings (frequency_response.json too)
  for (const std::string& w : r.warnings) spdlog::warn("{}", w);
  spdlog::info("{} frequencies in {:.1f} s -> {}", r.points.size(), r.wall_time_s, out_dir);
}

// The scenario's run, streamed to out_dir (timeseries.csv, summary.json, plots), then its headline.
void run_scenario(const sim::Scenario& scenario, const std::string& out_dir, bool plots) {
  spdlog::info("{}: {} steps of {} s", scenario.name, scenario.steps(), scenario.control_period);
  if (scenario.controller.type == sim::ControllerType::kCascade)
    spdlog::info("cascade gains: kp = {:.6g} 1/s, kv = {:.6g} 1/s, ki = {:.6g} 1/s^2", scenario.controller.cascade.kp,
                 scenario.controller.cascade.kv, scenario.controller.cascade.ki);
  // At run time: a model the keys make unintegrable (plant::IntegrationError) or a non-finite
  // value (check_finite_step: sim::ScenarioError), or a CSV that cannot fit (RunWriter's check
  // on its first rows: std::invalid_argument) is bad input, exit 2 (tool::report).
  sim::RunWriter out(out_dir, scenario, "feeddrive-sim", tool::stop_token());
  const auto stats = sim::run(
      scenario, [&](const sim::Record& r) { out.add(r); }, tool::stop_token());
  const auto summary = out.summary(stats.wall_time_s, stats.integrator);
  out.finish(summary, plots);
  if (!out.plot_error().empty())
    spdlog::warn("plots not drawn ({}); the data are in {}", out.plot_error(), output::shown(out_dir));
  else if (plots) spdlog::info("plots drawn in {:.3f} s", out.plot_seconds());
  for (const std::string& w : out.warnings()) spdlog::warn("{}", w);
  // After the run (a run that then fails says only why, in one line): the values that load but
  // are implausible for a linear feed drive, and a move the run cut off (summary.json too).
  for (const std::string& w : scenario.warnings) spdlog::warn("{}", w);
  spdlog::info("{}, wall {:.3f} s -> {}", sim::summary_headline(summary, scenario), summary.wall_time_s, out_dir);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-sim: in-process simulation of a linear-motor feed drive", "feeddrive-sim"};
  std::string scenario_path, out_dir;
  bool no_plots = false, quiet = false;
  std::vector<std::string> sets;
  app.add_option("scenario", scenario_path, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")
      ->required();
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_option("--set", sets,
                 "KEY=VALUE: set a scenario key (dotted, e.g. plant.mass=110) as if the file said so; repeatable")
      ->type_name("KEY=VALUE");
  app.add_flag("--quiet,-q", quiet, "print only errors");
  bool frequency_response = false;
  analysis::FrequencyResponseOptions fr;
  app.add_flag("--frequency-response", frequency_response,
               "measure the closed loop's frequency response (docs/analysis.md)");
  add_frequency_response_options(app, fr);
  tool::Options opt{"feeddrive-sim", &quiet, [&] { return "; nothing written to " + output::shown(out_dir); }};
  return tool::run(app, argc, argv, opt, [&] {
    const sim::Scenario scenario = tool::input_step([&] {
      std::vector<sim::KeySetting> settings;
      for (const std::string& k : sets) settings.push_back(sim::parse_key_setting(k));
      sim::Scenario s = sim::load_scenario(scenario_path, settings);
      output::check_output_dir(out_dir);  // before any work
      if (frequency_response) fr.validate(s);
      else sim::check_run_size(s, out_dir);
      return s;
    });
    if (frequency_response) {
      run_frequency_response(scenario, fr, out_dir, !no_plots, quiet);
      return kExitOk;
    }
    run_scenario(scenario, out_dir, !no_plots);
    return kExitOk;
  });
}

// feeddrive-fit: finds where a model and measured data disagree, names the missing effect, adds
// it, and shows the gap shrink (docs/fit.md). Wiring only: load -> run_fit -> write_outputs.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "feeddrive/common/validate.hpp"
#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/report.hpp"
#include "feeddrive/fit/sanity.hpp"
#include "feeddrive/fit/workflow.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/tool/main.hpp"

namespace {
using namespace feeddrive;

// The command line.
struct Args {
  std::string scenario_path, data_path, out_dir, prefix = "FD";
  std::vector<std::string> sets, ask;
  std::string separator = ",", units;
  fit::FitOptions opt;
  fit::CsvOptions csv;
  bool no_plots = false, quiet = false;
};

// The model, the data and the output folder.
void add_input_options(CLI::App& app, Args& a) {
  app.add_option("--scenario,-s", a.scenario_path, "the model: a feeddrive scenario YAML")->required();
  app.add_option("--set", a.sets,
                 "KEY=VALUE: set a key of the model's scenario (dotted, e.g. plant.mass=110); repeatable")
      ->type_name("KEY=VALUE");
  app.add_option("--data,-d", a.data_path,
                 "measured data: CSV (t, x, u or force_N[, xd, v]) or an lcm-logger log (.lcm, .lcmlog, .log)")
      ->required();
  app.add_option("--out,-o", a.out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")
      ->required();
}

// The search (workflow.hpp) and the noise floor (verdict.hpp).
void add_search_options(CLI::App& app, fit::FitOptions& opt) {
  app.add_option("--max-effects", opt.max_effects, "most effects to add")
      ->capture_default_str()
      ->check(tool::within(0, 11, true));
  app.add_option("--score-threshold", opt.score_threshold, "least BIC score of a significant effect")
      ->capture_default_str()
      ->check(tool::within(0.0, 1e9, false, false));
  app.add_option("--min-gap-reduction", opt.min_gap_reduction,
                 "least fraction by which an effect must shrink the replay gap")
      ->capture_default_str()
      ->check(tool::within(0.0, 0.99, false, false));
  app.add_option("--replay-window", opt.replay_window,
                 "replay window W [s] (0: 0.1 s); shorter: the gap shows only larger forces (1/W^2), and an "
                 "all-clear is checked at the default")
      ->capture_default_str()
      ->check(tool::within(1e-3, 1e3, false, true));
  app.add_option("--filter-half-width", opt.record.filter_half_width,
                 "half-width L of the force filter [s] (0: max(10 ms, 10 periods)); shorter: a higher force floor, "
                 "and an all-clear is checked at the default")
      ->capture_default_str()
      ->check(tool::within(1e-5, 10.0, false, true));
  app.add_option(
         "--time-stamp-error", opt.stamp_error,
         "standard deviation of the record's time stamps [s], for the noise floor (0: not known, not in the floor)")
      ->capture_default_str()
      ->check(tool::within(1e-12, 1e-2, false, true));
}

// The record's layout: the channel prefix of a log, the columns, separator and units of a CSV.
void add_record_options(CLI::App& app, Args& a) {
  fit::CsvOptions& csv = a.csv;
  app.add_option("--prefix", a.prefix, "channel prefix of an LCM log (ignored for CSV)")->capture_default_str();
  app.add_option("--time-column", csv.time_column, "CSV column with the time [s]")->capture_default_str();
  app.add_option("--position-column", csv.position_column, "CSV column with the measured position [m]")
      ->capture_default_str();
  app.add_option("--command-column", csv.command_column, "CSV column with the command (thrust = Ka*Kf*u)")
      ->capture_default_str();
  app.add_option("--force-column", csv.force_column, "CSV column with the thrust [N] (if the command column is absent)")
      ->capture_default_str();
  app.add_option("--reference-column", csv.reference_column, "CSV column with the position reference [m] (optional)")
      ->capture_default_str();
  app.add_option("--separator", a.separator, "CSV column separator: ',', ';', 'tab' (or a tab character)")
      ->capture_default_str()
      ->check(CLI::IsMember({",", ";", "tab", "\t"}));
  app.add_flag("--decimal-comma", csv.decimal_comma,
               "numbers are written with a decimal comma (0,25); needs another --separator");
  app.add_option("--units", a.units,
                 "units of the columns, ROLE=UNIT[,...]: t=s|ms|us, x=m|mm|um|nm, xd=..., force=N|kN|mN, u=V|mV, or "
                 "ROLE=counts:SCALE (SI per count); e.g. t=ms,x=mm,force=kN");
}

// The vocabulary, the out-of-sample check, the model form and the output.
void add_other_options(CLI::App& app, Args& a) {
  app.add_option("--effects", a.ask,
                 "also consider these effects where the scenario does not describe them "
                 "(grinding_force: a grinding process)")
      ->delimiter(',')
      ->check(CLI::IsMember(plant::effect_names()));
  app.add_option("--cv-folds", a.opt.cv_folds, "blocks of time of the out-of-sample check")
      ->capture_default_str()
      ->check(tool::within(2, 50, true));
  app.add_flag(
      "--no-form-fit", [&a](std::int64_t) { a.opt.fit_form = false; }, "keep the model's Coulomb transition velocity");
  app.add_flag("--no-plots", a.no_plots, "skip the PNG plots");
  app.add_flag("--quiet,-q", a.quiet, "print only the result table and errors");
}

// The tool's work: load the model and the record, check them (fit/sanity.hpp: units, gaps and
// jumps), fit, write the outputs, print the result table; the exit code of the verdict.
int fit_record(Args& a) {
  a.csv.separator = a.separator == "tab" ? '\t' : a.separator[0];
  if (a.csv.decimal_comma && a.csv.separator == ',')
    throw BadInput("--decimal-comma needs another --separator (e.g. --separator ';'): the comma cannot be both");
  output::check_output_dir(a.out_dir);
  a.opt.stop = tool::stop_token();
  std::vector<sim::KeySetting> settings;
  for (const std::string& k : a.sets) settings.push_back(sim::parse_key_setting(k));
  const sim::Scenario scenario = sim::load_scenario(a.scenario_path, settings);
  a.opt.plausibility.grinding_process =
      scenario.grinding_process || std::find(a.ask.begin(), a.ask.end(), "grinding_force") != a.ask.end();
  if (!a.units.empty()) a.csv.units = fit::parse_units(a.units);
  fit::MeasuredData data = fit::load_data(a.data_path, a.prefix, a.csv, tool::stop_token());
  for (std::string& n : fit::check_record(data, scenario.plant, scenario.control_period)) data.notes.push_back(n);
  const fit::Record rec = fit::prepare(data, a.opt.record);
  fit::check_options(rec, a.opt);
  fit::check_force_scale(rec, scenario.plant);
  for (const std::string& n : data.notes) spdlog::warn("{}: {}", a.data_path, n);
  spdlog::info("{}: {} samples over {:.3g} s; model {}", a.data_path, data.size(), data.t.back() - data.t.front(),
               a.scenario_path);
  const fit::FitResult r =
      fit::run_fit(rec, scenario.plant, a.opt, [](const std::string& s) { spdlog::info("{}", s); });
  for (const std::string& w : fit::write_outputs(a.out_dir, a.scenario_path, rec, r, !a.no_plots, tool::stop_token()))
    spdlog::warn("{}", w);
  std::fputs(fit::result_table(r, a.out_dir).c_str(), stdout);
  // exit codes (docs/fit.md, "Verdicts"): 0 explained or no discrepancy, 3 unexplained, 2 bad input
  return fit::exit_code(r.verdict);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"feeddrive-fit: model-discrepancy workflow (docs/fit.md)", "feeddrive-fit"};
  Args a;
  add_input_options(app, a);
  add_search_options(app, a.opt);
  add_record_options(app, a);
  add_other_options(app, a);
  // Bad input (scenario, data, too short a record, an --out that must not be replaced, a model
  // that cannot be replayed on this record) is a BadInput or std::invalid_argument: exit 2 with one
  // line (tool::report), before any work is done. Ctrl-C in any phase: nothing written.
  return tool::run(app, argc, argv, {"feeddrive-fit", &a.quiet, {}}, [&]() -> int { return fit_record(a); });
}

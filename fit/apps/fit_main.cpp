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

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-fit: model-discrepancy workflow (docs/fit.md)", "feeddrive-fit"};
  std::string scenario_path, data_path, out_dir, prefix = "FD";
  fit::FitOptions opt;
  fit::CsvOptions csv;
  bool no_plots = false, quiet = false;
  app.add_option("--scenario,-s", scenario_path, "the model: a feeddrive scenario YAML")->required();
  std::vector<std::string> sets;
  app.add_option("--set", sets,
                 "KEY=VALUE: set a key of the model's scenario (dotted, e.g. plant.mass=110); repeatable")
      ->type_name("KEY=VALUE");
  app.add_option("--data,-d", data_path,
                 "measured data: CSV (t, x, u or force_N[, xd, v]) or an lcm-logger log (.lcm, .lcmlog, .log)")
      ->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")
      ->required();
  app.add_option("--max-effects", opt.max_effects, "most effects to add")
      ->capture_default_str()
      ->check(CLI::Range(0, 11));
  // A finite number in [lo, hi] (CLI::Range lets NaN through), or exactly 0 where `zero` says so.
  const auto within = [](double lo, double hi, bool zero) {
    return CLI::Validator(
        [=](std::string& s) -> std::string {
          char* end = nullptr;
          const double v = std::strtod(s.c_str(), &end);
          if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) return "'" + s + "' is not a finite number";
          if (zero && v == 0.0) return "";
          if (v < lo || v > hi)
            return "'" + s + "' is outside [" + validate::format_number(lo) + ", " + validate::format_number(hi) + "]" +
                   (zero ? " (or 0 for the default)" : "");
          return "";
        },
        "");
  };
  app.add_option("--score-threshold", opt.score_threshold, "least BIC score of a significant effect")
      ->capture_default_str()
      ->check(within(0.0, 1e9, false));
  app.add_option("--min-gap-reduction", opt.min_gap_reduction,
                 "least fraction by which an effect must shrink the replay gap")
      ->capture_default_str()
      ->check(within(0.0, 0.99, false));
  app.add_option("--replay-window", opt.replay_window, "replay window W [s] (0: 0.1 s)")
      ->capture_default_str()
      ->check(within(1e-3, 1e3, true));
  app.add_option("--filter-half-width", opt.record.filter_half_width,
                 "half-width L of the force filter [s] (0: max(10 ms, 10 periods))")
      ->capture_default_str()
      ->check(within(1e-5, 10.0, true));
  app.add_option(
         "--time-stamp-error", opt.stamp_error,
         "standard deviation of the record's time stamps [s], for the noise floor (0: not known, not in the floor)")
      ->capture_default_str()
      ->check(within(1e-12, 1e-2, true));
  app.add_option("--prefix", prefix, "channel prefix of an LCM log (ignored for CSV)")->capture_default_str();
  app.add_option("--time-column", csv.time_column, "CSV column with the time [s]")->capture_default_str();
  app.add_option("--position-column", csv.position_column, "CSV column with the measured position [m]")
      ->capture_default_str();
  app.add_option("--command-column", csv.command_column, "CSV column with the command (thrust = Ka*Kf*u)")
      ->capture_default_str();
  app.add_option("--force-column", csv.force_column, "CSV column with the thrust [N] (if the command column is absent)")
      ->capture_default_str();
  app.add_option("--reference-column", csv.reference_column, "CSV column with the position reference [m] (optional)")
      ->capture_default_str();
  std::string separator = ",", units;
  app.add_option("--separator", separator, "CSV column separator: ',', ';', 'tab' (or a tab character)")
      ->capture_default_str()
      ->check(CLI::IsMember({",", ";", "tab", "\t"}));
  app.add_flag("--decimal-comma", csv.decimal_comma,
               "numbers are written with a decimal comma (0,25); needs another --separator");
  app.add_option("--units", units,
                 "units of the columns, ROLE=UNIT[,...]: t=s|ms|us, x=m|mm|um|nm, xd=..., force=N|kN|mN, u=V|mV, or "
                 "ROLE=counts:SCALE (SI per count); e.g. t=ms,x=mm,force=kN");
  std::vector<std::string> ask;
  app.add_option("--effects", ask,
                 "also consider these effects where the scenario does not describe them "
                 "(grinding_force: a grinding process)")
      ->delimiter(',')
      ->check(CLI::IsMember(plant::effect_names()));
  app.add_option("--cv-folds", opt.cv_folds, "blocks of time of the out-of-sample check")
      ->capture_default_str()
      ->check(CLI::Range(2, 50));
  app.add_flag(
      "--no-form-fit", [&](std::int64_t) { opt.fit_form = false; }, "keep the model's Coulomb transition velocity");
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_flag("--quiet,-q", quiet, "print only the result table and errors");
  // Bad input (scenario, data, too short a record, an --out that must not be replaced, a model
  // that cannot be replayed on this record) is a BadInput or std::invalid_argument: exit 2 with one
  // line (tool::report), before any work is done. Ctrl-C in any phase: nothing written.
  return tool::run(app, argc, argv, {"feeddrive-fit", &quiet, {}}, [&]() -> int {
    csv.separator = separator == "tab" ? '\t' : separator[0];
    if (csv.decimal_comma && csv.separator == ',')
      throw BadInput("--decimal-comma needs another --separator (e.g. --separator ';'): the comma cannot be both");
    output::check_output_dir(out_dir);
    opt.stop = tool::stop_token();
    std::vector<sim::KeySetting> settings;
    for (const std::string& k : sets) settings.push_back(sim::parse_key_setting(k));
    const sim::Scenario scenario = sim::load_scenario(scenario_path, settings);
    opt.plausibility.grinding_process =
        scenario.grinding_process || std::find(ask.begin(), ask.end(), "grinding_force") != ask.end();
    if (!units.empty()) csv.units = fit::parse_units(units);
    const fit::MeasuredData data = fit::load_data(data_path, prefix, csv, tool::stop_token());
    // sanity before fitting: units, gaps and jumps (fit/sanity.hpp)
    fit::check_record(data, scenario.plant, scenario.control_period);
    const fit::Record rec = fit::prepare(data, opt.record);
    fit::check_options(rec, opt);
    fit::check_force_scale(rec, scenario.plant);
    for (const std::string& n : data.notes) spdlog::warn("{}: {}", data_path, n);
    spdlog::info("{}: {} samples over {:.3g} s; model {}", data_path, data.size(), data.t.back() - data.t.front(),
                 scenario_path);
    const fit::FitResult r =
        fit::run_fit(rec, scenario.plant, opt, [](const std::string& s) { spdlog::info("{}", s); });
    for (const std::string& w : fit::write_outputs(out_dir, scenario_path, rec, r, !no_plots, tool::stop_token()))
      spdlog::warn("{}", w);
    std::printf("%-4s %-24s %14s %18s\n", "step", "model", "gap [um]", "force RMS [N]");
    std::printf("%-4d %-24s %14.4g %18.4g\n", 0, "as given", r.replay_initial.gap * 1e6, r.force_rms_initial);
    int k = 0;
    for (const auto& st : r.steps)
      if (st.accepted)
        std::printf("%-4d %-24s %14.4g %18.4g%s\n", ++k, ("+ " + st.effect.name).c_str(), st.gap_after * 1e6,
                    st.force_rms_after, st.swap.empty() ? "" : ("   (swap: " + st.swap + ")").c_str());
    std::printf("%s\n", r.conclusion.c_str());
    for (const auto& [name, caveat] : r.tentative) std::printf("tentative %s: %s\n", name.c_str(), caveat.c_str());
    for (const std::string& t : r.ties) std::printf("tie: %s\n", t.c_str());
    for (const std::string& u : r.unexplained) std::printf("  %s\n", u.c_str());
    std::printf("results: %s/{findings.json,model.fitted.yaml,report.md}\n", out_dir.c_str());
    // exit codes (docs/fit.md, "Verdicts"): 0 explained or no discrepancy, 3 unexplained, 2 bad input
    return r.verdict == fit::Verdict::kUnexplained ? fit::kExitUnexplained : 0;
  });
}

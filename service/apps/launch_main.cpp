// feeddrive-launch: runs a scenario as four LCM processes (plant, controller, trajectory,
// monitor) in lockstep and collects the results in DIR. Wiring only: options -> launch().
#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "feeddrive/common/text_file.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/record/lcm_log.hpp"
#include "feeddrive/service/cli.hpp"
#include "feeddrive/service/integrity.hpp"
#include "feeddrive/service/launch.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace {

using namespace feeddrive;

// The inode of the monitor's marker in `out` (0: none): a successful run leaves a new file.
ino_t marker_id(const std::filesystem::path& out) {
  struct stat st {};
  return ::lstat((out / output::kMarkerFile).c_str(), &st) == 0 ? st.st_ino : ino_t{0};
}

// A failed run's lines: a refusal (bad input, exit 2) is the run's one line, printed once however
// many processes gave it (the others were stopped for it and say nothing); else each failure; and
// where a killed monitor's record went.
void report_failure(const service::LaunchResult& r) {
  for (const auto& line : r.refusals) std::fprintf(stderr, "%s\n", line.c_str());
  if (r.refusals.empty())
    for (const auto& f : r.failed) spdlog::error("failed: {}", f);
  if (!r.partial_record.empty())
    spdlog::error(
        "the monitor was killed: its record up to then (it goes to the file every second: the last "
        "second's rows may be missing; no summary.json) is in {}",
        r.partial_record);
}

// The headline of DIR/summary.json as feeddrive-sim prints it (sim/summary.hpp), then the lockstep figures.
void print_headline(const std::string& out_dir) {
  std::ifstream in(out_dir + "/summary.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.contains("lockstep")) return;
  const auto p50 = j["lockstep"]["latency_us"]["state_to_command"].value("p50", nlohmann::json());
  spdlog::info("{} steps, {}, resends {}, lost {}, state->command p50 {} us -> {}", j.value("steps", 0L),
               sim::summary_headline(text), j["lockstep"].value("resends", 0L), j["lockstep"].value("lost", 0L),
               p50.is_number() ? fmt::format("{:.4g}", p50.get<double>()) : std::string("n/a"), out_dir);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{
      "feeddrive-launch: runs SCENARIO as four lockstep LCM processes and writes DIR "
      "(timeseries.csv, summary.json, plots)",
      "feeddrive-launch"};
  service::LaunchOptions lo;
  service::NodeOptions opt;
  std::vector<std::string> external;
  bool no_plots = false;
  app.add_option("scenario", lo.scenario, "scenario YAML file (docs/scenario.md)")->required();
  app.add_option("--out,-o", lo.out_dir,
                 "output folder (written atomically by the monitor; replaces only an earlier feeddrive output)")
      ->required();
  app.add_option("--external", external, "leave ROLE (controller, plant or trajectory) to a process you start")
      ->type_name("ROLE");
  app.add_flag("--no-plots", no_plots, "skip the PNG plots");
  app.add_option("--lcm-log", lo.lcm_log,
                 "the monitor also writes every message of the run to FILE in the standard LCM log format "
                 "(instead of the stock lcm-logger, which halves a lockstep run's speed)");
  std::string cpus;
  app.add_option("--cpus", cpus,
                 "pin every process to these CPUs, e.g. 0 or 0,1 (a lockstep chain runs fastest on one core where "
                 "cross-core wake-ups are slow)")
      ->type_name("LIST");
  std::string off_path_cpus;
  app.add_option("--off-path-cpus", off_path_cpus,
                 "pin the monitor and the trajectory (off the step's critical path) to these CPUs instead; "
                 "with --realtime, keeps --cpus for the plant and controller (docs/lcm-contract.md, An isolated core)")
      ->type_name("LIST");
  service::add_node_options(app, opt);
  return service::run_process(app, argc, argv, opt, [&] {
    lo.external.insert(external.begin(), external.end());
    lo.plots = !no_plots;
    lo.auto_pace = app.count("--max-rate") == 0;
    if (!cpus.empty()) lo.cpus = service::parse_cpu_list(cpus);
    if (!off_path_cpus.empty()) lo.off_path_cpus = service::parse_cpu_list(off_path_cpus, "--off-path-cpus");
    // Read once, here: bad input fails before any process starts, and every process checks that
    // its copy hashes the same (one run, one scenario).
    const service::RunScenario rs = service::load_run_scenario(lo.scenario, opt);
    const sim::Scenario& s = rs.scenario;
    opt.scenario_hash = rs.sha256;                          // --scenario-hash, run_info_t.scenario_hash
    const auto out = output::check_output_dir(lo.out_dir);  // and these, before any process starts
    output::check_outside(lo.lcm_log, "--lcm-log", lo.out_dir);
    output::check_output_file(lo.lcm_log, "--lcm-log", record::kLcmLogMagic);
    if (!opt.key_file.empty()) service::read_key_file(opt.key_file);
    sim::check_run_size(s, lo.out_dir);
    spdlog::info("{}: {} steps of {} s on {} (prefix {})", s.name, s.steps(), s.control_period, opt.lcm_url,
                 opt.prefix);
    const ino_t before = marker_id(out);  // the monitor's marker before the run
    const service::LaunchResult r = service::launch(lo, opt);
    report_failure(r);
    // A failed run's record is where the monitor said (DIR, or DIR.incomplete-N beside an
    // earlier output): DIR's summary may be the earlier run's, so it is not shown as this one's.
    if (r.exit_code != 0) return r.exit_code;
    // Every process exited 0: the monitor's new results must be there.
    if (!output::is_feeddrive_output(out) || marker_id(out) == before) {
      spdlog::error("--out {}: the monitor wrote no results", output::shown(lo.out_dir));
      return 1;
    }
    for (const std::string& w : s.warnings) spdlog::warn("{}", w);  // after the run, as feeddrive-sim does
    print_headline(lo.out_dir);
    return 0;
  });
}

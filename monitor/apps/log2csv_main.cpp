// feeddrive-log2csv: turns an LCM log of a run (stock lcm-logger) into DIR/timeseries.csv and
// DIR/summary.json, the same files feeddrive-monitor writes. Wiring only: read_log -> RunWriter.
#include <spdlog/spdlog.h>

#include <cstdio>

#include "feeddrive/monitor/log_reader.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/service/cli.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/summary.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-log2csv: converts an lcm-logger log of a run into timeseries.csv and summary.json",
               "feeddrive-log2csv"};
  std::string log_path, scenario_path, out_dir;
  bool plots = false;
  service::NodeOptions opt;  // only --prefix and --quiet matter here
  app.add_option("log", log_path, "LCM log file written by lcm-logger")->required();
  app.add_option("--scenario,-s", scenario_path, "the run's scenario YAML (control period, name)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")->required();
  app.add_option("--prefix", opt.prefix, "channel prefix of the run")->capture_default_str();
  app.add_flag("--plots", plots, "also draw the PNG plots");
  app.add_flag("--quiet,-q", opt.quiet, "log only warnings and errors");
  return service::run_process(app, argc, argv, opt, [&] {
    const sim::Scenario s = sim::load_scenario(scenario_path);
    output::check_output_dir(out_dir);
    sim::check_run_size(s, out_dir);
    sim::RunWriter out(out_dir, s, "feeddrive-log2csv");  // rows streamed as the log is read
    const monitor::LogConversion c = monitor::read_log(log_path, opt.prefix, [&](const sim::Record& r) { out.add(r); });
    const monitor::Recorder& rec = c.recorder;
    const sim::Summary sum = out.summary(0.0, {});
    out.finish(sum, plots);
    const bool complete = rec.complete();
    spdlog::info("{}: {} events, {} rows{}, {} undecodable, {} on other channels -> {}", log_path, c.events,
                 rec.rows(), complete ? " (complete run)" : "", c.undecodable, c.foreign_events, out_dir);
    if (!complete) {
      std::string why = rec.end_seen() ? "" : "; the log has no end-of-run state";
      for (const auto& m : rec.missing()) why += "; no " + m.what + " " + std::to_string(m.seq) + " from the " + m.role;
      std::fprintf(stderr, "error: %s: incomplete run: rows stop at step %lld%s\n", log_path.c_str(),
                   static_cast<long long>(rec.next()), why.c_str());
      return 1;
    }
    return 0;
  });
}

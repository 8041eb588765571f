// feeddrive-log2csv: turns an LCM log of a run (stock lcm-logger) into DIR/timeseries.csv and
// DIR/summary.json, the same files feeddrive-monitor writes. Wiring only: read_log -> RunWriter.
// Every complete step is written, across gaps (the stock logger drops messages); the steps that
// are missing are reported in one warning line and in summary.json ("log": missing_steps, gaps).
// Exit 2 (one line) for a log that cannot be read, is corrupt (the event's byte offset), or holds
// no complete step.
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <limits>

#include "feeddrive/output/folder.hpp"
#include "feeddrive/record/log_reader.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/tool/main.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive;
  CLI::App app{"feeddrive-log2csv: converts an lcm-logger log of a run into timeseries.csv and summary.json",
               "feeddrive-log2csv"};
  std::string log_path, scenario_path, out_dir;
  std::string prefix = "FD";
  bool plots = false, quiet = false;
  app.add_option("log", log_path, "LCM log file written by lcm-logger")->required();
  app.add_option("--scenario,-s", scenario_path, "the run's scenario YAML (control period, name)")->required();
  app.add_option("--out,-o", out_dir, "output folder (written atomically; replaces only an earlier feeddrive output)")
      ->required();
  app.add_option("--prefix", prefix, "channel prefix of the run")->capture_default_str();
  app.add_flag("--plots", plots, "also draw the PNG plots");
  app.add_flag("--quiet,-q", quiet, "log only warnings and errors");
  return tool::run(app, argc, argv, {"feeddrive-log2csv", &quiet, {}}, [&] {
    const sim::Scenario s = sim::load_scenario(scenario_path);
    output::check_output_dir(out_dir);
    // A step of a log is at least a state and a command event, each over 40 bytes (the 28-byte
    // event header, the channel name, the message's 8-byte fingerprint): the log bounds its steps.
    std::error_code ec;
    const auto log_bytes = std::filesystem::file_size(log_path, ec);
    const double log_steps = ec ? std::numeric_limits<double>::infinity() : static_cast<double>(log_bytes) / 64.0;
    sim::check_run_size(s, out_dir, log_steps);
    sim::RunWriter out(out_dir, s, "feeddrive-log2csv", tool::stop_token());  // rows streamed as the log is read
    out.set_expected_steps(std::min(static_cast<double>(s.steps()), log_steps));
    const record::LogConversion c = record::read_log(
        log_path, prefix, [&](const sim::Record& r) { out.add(r); }, true, tool::stop_token());
    const record::Recorder& rec = c.recorder;
    if (out.steps() == 0)
      throw std::invalid_argument(log_path + ": no complete step on channels " + prefix + "_STATE/_REF/_CMD (" +
                                  std::to_string(c.events) + " events read; " +
                                  (c.cut_bytes > 0 ? record::describe_cut(c) : std::string("wrong --prefix?")) + ")");
    nlohmann::ordered_json j;
    auto& l = j["log"];
    l["events"] = c.events;
    l["steps_expected"] = rec.steps();
    l["missing_steps"] = rec.missing_steps();
    l["gaps"] = nlohmann::ordered_json::array();
    for (const auto& g : rec.gaps()) l["gaps"].push_back({{"first", g.first}, {"last", g.last}, {"why", g.why}});
    l["steps_without_command"] = rec.commandless_rows();
    l["end_of_run_seen"] = rec.end_seen();
    l["undecodable_events"] = c.undecodable;
    l["non_finite_messages"] = c.non_finite;
    l["foreign_events"] = c.foreign_events;
    l["cut_event_bytes"] = c.cut_bytes;
    out.finish(out.summary(0.0, {}), plots, j.dump());
    if (!out.plot_error().empty())
      spdlog::warn("plots not drawn ({}); the data are in {}", out.plot_error(), output::shown(out_dir));
    for (const std::string& w : out.warnings()) spdlog::warn("{}", w);
    spdlog::info(
        "{}: {} events, {} rows, {} without their command, {} undecodable, {} non-finite, {} on other channels -> {}",
        log_path, c.events, out.steps(), rec.commandless_rows(), c.undecodable, c.non_finite, c.foreign_events,
        out_dir);
    if (c.cut_bytes > 0) spdlog::warn("{}: {}", log_path, record::describe_cut(c));
    if (!rec.gaps().empty())
      spdlog::warn("{}: {} of {} steps; the {} complete steps are in {}", log_path, record::describe_gaps(rec.gaps()),
                   rec.steps(), out.steps(), out_dir);
    return 0;
  });
}

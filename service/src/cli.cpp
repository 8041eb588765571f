#include "feeddrive/service/cli.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <limits>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/tool/main.hpp"

namespace feeddrive::service {

void add_node_options(CLI::App& app, NodeOptions& opt) {
  opt.stop = tool::stop_token();  // the process's: every run process is a tool's main
  app.add_option("--set", opt.sets,
                 "KEY=VALUE: set a scenario key (dotted, e.g. plant.mass=110) as if the file said so; repeatable")
      ->type_name("KEY=VALUE");
  app.add_option("--lcm-url", opt.lcm_url, "LCM URL (default: multicast, ttl=0, 4 MB receive buffer)")
      ->capture_default_str();
  app.add_option("--prefix", opt.prefix, "channel prefix: <prefix>_STATE, _CMD, _REF, ...")->capture_default_str();
  app.add_option("--start-timeout", opt.start_timeout_s, "seconds to wait for the other roles to start")
      ->capture_default_str();
  app.add_option("--step-timeout", opt.step_timeout_s, "seconds without progress before failing")
      ->capture_default_str();
  app.add_option("--resend-interval", opt.resend_interval_s, "seconds before a pending message is re-published")
      ->capture_default_str();
  app.add_option("--monitor-window", opt.monitor_window,
                 "plant: max steps ahead of the monitor's acknowledgement (0: do not wait for a monitor)")
      ->capture_default_str();
  app.add_option("--linger", opt.linger_s, "seconds to keep answering resend requests after the end")
      ->capture_default_str();
  app.add_flag("--realtime", opt.realtime, "real-time mode: the plant is paced by the wall clock");
  app.add_option("--max-rate", opt.max_rate,
                 "lockstep: at most this many steps per second (0: unpaced); the stock lcm-logger records "
                 "without loss at 1000 (docs/lcm-contract.md)")
      ->capture_default_str()
      ->check(tool::within(0, 1e300));
  app.add_option("--max-bad-commands", opt.max_bad_commands,
                 "real time: missed or invalid commands in a row before the plant goes to zero thrust")
      ->capture_default_str();
  app.add_option("--spin-us", opt.realtime_spin_us,
                 "real time: busy-wait this many us before each period start (timer wake-up latency)")
      ->capture_default_str()
      ->check(tool::within(0, 1000));
  app.add_flag("--quiet,-q", opt.quiet, "log only warnings and errors");
  app.add_option("--run-id", opt.run_id,
                 "identity of the run (nonzero; docs/security.md); default: the plant draws one, the others join "
                 "the plant's")
      ->check(tool::within(1, 9.2e18, true));
  app.add_option("--scenario-hash", opt.scenario_hash,
                 "hex SHA-256 of the scenario file as the launcher read it (run_info_t.scenario_hash; feeddrive-launch "
                 "passes it)")
      ->type_name("HEX");
  app.add_option("--key", opt.key_file,
                 "authenticate every message with HMAC-SHA256 and this key file (mode 0600; docs/security.md)")
      ->type_name("FILE");
  app.add_option("--run-nonce", opt.run_nonce,
                 "with --key: the run's nonce, which binds the run id on the wire to this run (docs/security.md); "
                 "default: feeddrive-launch draws it, a plant started alone draws it, the others take the plant's")
      ->check(tool::within(1, 9.2e18, true));
  tool::add_enum_option(app, "--on-conflict", opt.on_conflict,
                        "a second, different message for a step: fail (default) or keep-first (count and log it)");
}

RunScenario load_run_scenario(const std::string& path, const NodeOptions& opt) {
  std::string text;
  std::vector<sim::KeySetting> sets;
  for (const std::string& k : opt.sets) sets.push_back(sim::parse_key_setting(k));
  RunScenario r{sim::load_scenario(path, sets, &text), ""};
  // The run's scenario is the file and the tables it names (waypoints, an open-loop force
  // table), as parsed here: a table swapped while the run starts changes the hash as the file
  // does. A scenario that names no file hashes as its text alone.
  const auto add_table = [&text](const std::string& what, const std::string& file, const std::vector<double>& a,
                                 const std::vector<double>& b) {
    if (file.empty()) return;
    text += "\n# feeddrive table " + what + "\n";  // its content, not its path (relative or not)
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double v[2] = {a[i], i < b.size() ? b[i] : 0.0};
      text.append(reinterpret_cast<const char*>(v), sizeof v);
    }
  };
  std::vector<double> wt, wx;
  for (const auto& w : r.scenario.reference.waypoints) {
    wt.push_back(w.t);
    wx.push_back(w.x);
  }
  if (r.scenario.reference.type == sim::ReferenceType::kWaypoints)
    add_table("waypoints", r.scenario.reference.waypoints_file, wt, wx);
  if (r.scenario.controller.open_loop.kind == controller::OpenLoopKind::kCsv)
    add_table("open_loop", r.scenario.controller.open_loop_file, r.scenario.controller.open_loop.table_t,
              r.scenario.controller.open_loop.table_value);
  r.sha256 = sha256_hex(text);
  if (!opt.scenario_hash.empty() && opt.scenario_hash != r.sha256)
    throw std::invalid_argument(
        path + ": not the scenario this run started with (sha256 " + r.sha256.substr(0, 12) +
        "..., the launcher read " + opt.scenario_hash.substr(0, 12) +
        "...): the file, or a table it names, changed while the run started; one run, one scenario: launch again");
  return r;
}

int run_process(CLI::App& app, int argc, char** argv, const NodeOptions& opt, const std::function<int()>& body) {
  // RunFailure is a std::runtime_error: exit 1; the mapping is tool::report's, as in every tool.
  return tool::run(app, argc, argv, {app.get_name(), &opt.quiet, {}}, body);
}

}  // namespace feeddrive::service

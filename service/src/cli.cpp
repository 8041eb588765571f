#include "feeddrive/service/cli.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <limits>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/plant/cvode_integrator.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::service {

void add_node_options(CLI::App& app, NodeOptions& opt) {
  app.add_option("--set", opt.sets, "KEY=VALUE: set a scenario key (dotted, e.g. plant.mass=110) as if the file said so; repeatable")
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
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-bad-commands", opt.max_bad_commands,
                 "real time: missed or invalid commands in a row before the plant goes to zero thrust")
      ->capture_default_str();
  app.add_option("--spin-us", opt.realtime_spin_us,
                 "real time: busy-wait this many us before each period start (timer wake-up latency)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  app.add_flag("--quiet,-q", opt.quiet, "log only warnings and errors");
  app.add_option("--run-id", opt.run_id,
                 "identity of the run (nonzero; docs/security.md); default: the plant draws one, the others join "
                 "the plant's")
      ->check(CLI::Range(std::int64_t{1}, std::numeric_limits<std::int64_t>::max()));
  app.add_option("--scenario-hash", opt.scenario_hash,
                 "hex SHA-256 of the scenario file as the launcher read it (run_info_t.scenario_hash; feeddrive-launch passes it)")
      ->type_name("HEX");
  app.add_option("--key", opt.key_file,
                 "authenticate every message with HMAC-SHA256 and this key file (mode 0600; docs/security.md)")
      ->type_name("FILE");
  app.add_option("--run-nonce", opt.run_nonce,
                 "with --key: the run's nonce, which binds the run id on the wire to this run (docs/security.md); "
                 "default: feeddrive-launch draws it, a plant started alone draws it, the others take the plant's")
      ->check(CLI::Range(std::int64_t{1}, std::numeric_limits<std::int64_t>::max()));
  app.add_option_function<std::string>(
         "--on-conflict", [&opt](const std::string& v) { opt.on_conflict = parse_conflict_policy(v); },
         "a second, different message for a step: fail (default) or keep-first (count and log it)")
      ->check(CLI::IsMember({"fail", "keep-first"}))
      ->type_name("fail|keep-first");
}

RunScenario load_run_scenario(const std::string& path, const NodeOptions& opt) {
  std::string text;
  std::vector<sim::KeySetting> sets;
  for (const std::string& k : opt.sets) sets.push_back(sim::parse_key_setting(k));
  RunScenario r{sim::load_scenario(path, sets, &text), ""};
  r.sha256 = sha256_hex(text);
  if (!opt.scenario_hash.empty() && opt.scenario_hash != r.sha256)
    throw std::invalid_argument(path + ": not the scenario this run started with (sha256 " + r.sha256.substr(0, 12) +
                                "..., the launcher read " + opt.scenario_hash.substr(0, 12) +
                                "...): the file changed while the run started; one run, one scenario: launch again");
  return r;
}

int run_process(CLI::App& app, int argc, char** argv, const NodeOptions& opt, const std::function<int()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  auto logger = spdlog::stderr_color_mt(app.get_name());
  logger->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(opt.quiet ? spdlog::level::warn : spdlog::level::info);
  install_signal_handlers();
  try {
    return body();
  } catch (const interrupt::Interrupted& e) {
    return interrupt::report(e);
  } catch (const plant::IntegrationError& e) {  // the scenario's keys make it unintegrable
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const sim::ScenarioError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const RunFailure& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}

}  // namespace feeddrive::service

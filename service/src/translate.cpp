#include "feeddrive/service/translate.hpp"

#include <stdexcept>

#include "feeddrive/plant/parameter_table.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/wire.hpp"

namespace feeddrive::service {

std::vector<parameter_t> to_parameters(const std::vector<fields::FlatValue>& table) {
  using Bounds = wire::Check<parameter_t>;
  if (table.size() > static_cast<std::size_t>(wire::Check<run_info_t>::kMax_plant_count))
    throw std::logic_error("run_info_t.plant: " + std::to_string(table.size()) + " parameters, above the contract's " +
                           std::to_string(wire::Check<run_info_t>::kMax_plant_count) +
                           " (raise the bound in lcmtypes/run_info_t.lcm: a new contract version)");
  std::vector<parameter_t> out;
  out.reserve(table.size());
  for (const fields::FlatValue& v : table) {
    // A key or name cut to its bound would name another parameter: refused, never cut.
    if (v.key.size() > Bounds::kMax_key || v.name.size() > Bounds::kMax_name)
      throw std::logic_error(
          "run_info_t.plant: " + v.key + " = '" + v.name +
          "' is longer than parameter_t's bounds (lcmtypes/parameter_t.lcm: a new contract version)");
    parameter_t p;
    p.key = v.key;
    p.value = v.number;
    p.name = v.name;
    out.push_back(std::move(p));
  }
  return out;
}

run_info_t to_run_info(const sim::Scenario& s, const NodeOptions& opt, const std::string& scenario_hash) {
  run_info_t m;
  m.run_id = 0;
  m.utime = 0;
  m.scenario = wire::fit(s.name, wire::Check<run_info_t>::kMax_scenario);
  m.mode = opt.realtime ? "realtime" : "lockstep";
  m.contract_version = kContractVersion;
  m.scenario_hash = scenario_hash;
  m.start_timeout = opt.start_timeout_s;
  m.step_timeout = opt.step_timeout_s;
  m.resend_interval = opt.resend_interval_s;
  m.monitor_window = opt.monitor_window;
  m.max_bad_commands = opt.max_bad_commands;
  m.max_rate = opt.max_rate;
  // "auto" resolved by the sensor's one rule: the true velocity only from an ideal sensor.
  m.sensor_velocity = s.plant.sensor.differenced_velocity() ? "difference" : "true";
  m.current_step = -1;
  m.control_period = s.control_period;
  m.steps = s.steps();
  m.plant = to_parameters(plant::parameter_table(s.plant));
  m.plant_count = static_cast<std::int16_t>(m.plant.size());
  const sim::OutputLimits limits = sim::controller_output_limits(s);
  m.u_min = limits.u_min;
  m.u_max = limits.u_max;
  return m;
}

}  // namespace feeddrive::service

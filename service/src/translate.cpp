#include "feeddrive/service/translate.hpp"
#include "feeddrive/wire.hpp"

#include <limits>

#include "feeddrive/service/contract.hpp"

namespace feeddrive::service {

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
  m.initial_position = s.plant.initial.position;
  m.initial_velocity = s.plant.initial.velocity;
  m.sensor_quantization = s.plant.sensor.quantization;
  m.sensor_noise_stddev = s.plant.sensor.noise_stddev;
  // "auto" resolved by the sensor's one rule: the true velocity only from an ideal sensor.
  m.sensor_velocity = s.plant.sensor.differenced_velocity() ? "difference" : "true";
  m.current_step = -1;
  m.control_period = s.control_period;
  m.steps = s.steps();
  const plant::PlantParams& p = s.plant;
  m.mass = p.mass;
  m.thrust_gain = p.thrust_gain();
  m.friction_model = plant::to_string(p.friction.model);
  m.static_force = p.friction.static_force;
  m.coulomb_force = p.friction.coulomb_force;
  m.stribeck_velocity = p.friction.stribeck_velocity;
  m.bristle_stiffness = p.friction.bristle_stiffness;
  m.bristle_damping = p.friction.bristle_damping;
  m.viscous = p.friction.viscous;
  m.ripple = p.ripple.enabled;
  m.ripple_pitch = p.ripple.pitch;
  m.cogging_amplitude = p.ripple.cogging_amplitude;
  m.reluctance_amplitude = p.ripple.reluctance_amplitude;
  m.input_limit = p.input_limit;
  switch (s.controller.type) {
    case sim::ControllerType::kSlidingMode:
      m.u_min = s.controller.sliding_mode.u_min;
      m.u_max = s.controller.sliding_mode.u_max;
      break;
    case sim::ControllerType::kCascade:
      m.u_min = s.controller.cascade.u_min;
      m.u_max = s.controller.cascade.u_max;
      break;
    case sim::ControllerType::kOpenLoop:
      m.u_min = s.controller.open_loop.u_min;
      m.u_max = s.controller.open_loop.u_max;
      break;
    case sim::ControllerType::kPlugin:
      m.u_min = s.controller.plugin.u_min;
      m.u_max = s.controller.plugin.u_max;
      break;
  }
  return m;
}

}  // namespace feeddrive::service

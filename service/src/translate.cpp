#include "feeddrive/wire.hpp"
#include "feeddrive/service/translate.hpp"

#include <limits>

#include "feeddrive/service/contract.hpp"

namespace feeddrive::service {

reference_t to_message(std::int64_t seq, double t, const trajectory::Sample& s) {
  reference_t m;
  m.seq = seq;
  m.t = t;
  m.position = s.position;
  m.velocity = s.velocity;
  m.acceleration = s.acceleration;
  m.jerk = s.jerk;
  return m;
}

trajectory::Sample to_sample(const reference_t& m) {
  return {m.position, m.velocity, m.acceleration, m.jerk};
}

control_command_t to_message(std::int64_t seq, double t, const controller::Command& c) {
  control_command_t m;
  m.seq = seq;
  m.t = t;
  m.u = c.u;
  m.u_unsaturated = c.u_unsaturated;
  m.sliding = c.sliding;
  m.z_estimate = c.z_estimate;
  return m;
}

plant::Measurement to_measurement(const drive_state_t& m) { return {m.t, m.x_measured, m.v_measured}; }

drive_truth_t to_truth_message(const plant::State& s) {
  drive_truth_t m;
  m.valid = true;
  m.x = s.x;
  m.v = s.v;
  m.z = s.z;
  m.fg = s.fg;
  m.i = s.i;
  return m;
}

controller::Truth to_truth(const drive_truth_t& m) { return {m.z, m.fg}; }

applied_t to_applied(std::int64_t seq, double u, const plant::Forces& f) {
  applied_t m;
  m.seq = seq;
  m.u = u;
  m.forces_valid = true;
  m.f_thrust = f.thrust;
  m.f_friction = f.friction;
  m.f_ripple = f.ripple;
  m.f_grinding = f.grinding;
  return m;
}

applied_t no_applied() {
  applied_t m;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.seq = -1;
  m.u = nan;
  m.forces_valid = false;
  m.f_thrust = m.f_friction = m.f_ripple = m.f_grinding = nan;
  return m;
}

sim::Record to_record(const drive_state_t& state, const reference_t& ref, const control_command_t& cmd,
                      const applied_t& applied) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool truth = state.truth.valid;
  const plant::State st = truth ? plant::State{state.truth.x, state.truth.v, state.truth.z, state.truth.fg, state.truth.i}
                                : plant::State{nan, nan, nan, nan, nan};
  controller::Command c;
  c.u = cmd.u;
  c.u_unsaturated = cmd.u_unsaturated;
  c.sliding = cmd.sliding;
  c.z_estimate = cmd.z_estimate;
  plant::Forces f{nan, nan, nan, nan, nan};
  if (applied.forces_valid) f = {applied.f_thrust, applied.f_friction, applied.f_ripple, applied.f_grinding, 0.0};
  return sim::make_record(state.t, to_sample(ref), st, to_measurement(state), c, applied.u, f);
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

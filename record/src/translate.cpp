#include "feeddrive/record/translate.hpp"

#include <limits>

namespace feeddrive::record {

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

trajectory::Sample to_sample(const reference_t& m) { return {m.position, m.velocity, m.acceleration, m.jerk}; }

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
  const plant::State st = truth
                              ? plant::State{state.truth.x, state.truth.v, state.truth.z, state.truth.fg, state.truth.i}
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

}  // namespace feeddrive::record

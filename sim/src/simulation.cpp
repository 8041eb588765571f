#include "feeddrive/sim/simulation.hpp"

#include <chrono>

#include "feeddrive/plant/command.hpp"
#include "feeddrive/plant/plant.hpp"

namespace feeddrive::sim {

const std::vector<std::string>& record_columns() {
  static const std::vector<std::string> kColumns = {
      "t", "xd", "vd", "ad", "jd", "x", "x_measured", "v", "v_measured", "z", "fg", "i", "u",
      "u_unsaturated", "f_thrust", "f_friction", "f_ripple", "f_grinding", "sliding", "z_estimate"};
  return kColumns;
}

std::vector<double> record_values(const Record& r) {
  return {r.t, r.xd, r.vd, r.ad, r.jd, r.x, r.x_measured, r.v, r.v_measured, r.z, r.fg, r.i, r.u,
          r.u_unsaturated, r.f_thrust, r.f_friction, r.f_ripple, r.f_grinding, r.sliding, r.z_estimate};
}

RunResult run(const Scenario& s, const std::function<void(long, long)>& progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  plant::Plant drive(s.drive(), s.control_period);
  const auto reference = make_reference(s);
  const auto controller = make_controller(s);
  const long n = s.steps();

  RunResult result;
  result.records.reserve(static_cast<std::size_t>(n));
  for (long k = 0; k < n; ++k) {
    const double t = s.time_of(k);
    const trajectory::Sample ref = reference->sample(t);
    const plant::Measurement meas = drive.measure();
    const plant::State st = drive.state();
    const controller::Truth truth{st.z, st.fg};
    const controller::Command cmd = controller->update(ref, meas, &truth);
    const double u = plant::admit_command(cmd.u, s.plant.input_limit).u;
    const plant::Forces f = drive.forces(u);

    Record r;
    r.t = t;
    r.xd = ref.position;
    r.vd = ref.velocity;
    r.ad = ref.acceleration;
    r.jd = ref.jerk;
    r.x = st.x;
    r.v = st.v;
    r.z = st.z;
    r.fg = st.fg;
    r.i = st.i;
    r.x_measured = meas.x;
    r.v_measured = meas.v;
    r.u = u;  // what the drive applied (plant/command.hpp)
    r.u_unsaturated = cmd.u_unsaturated;
    r.f_thrust = f.thrust;
    r.f_friction = f.friction;
    r.f_ripple = f.ripple;
    r.f_grinding = f.grinding;
    r.sliding = cmd.sliding;
    r.z_estimate = cmd.z_estimate;
    result.records.push_back(r);

    drive.advance(u, s.time_of(k + 1));
    if (progress && (k % 5000 == 0 || k + 1 == n)) progress(k + 1, n);
  }
  result.integrator = drive.integrator_stats();
  result.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace feeddrive::sim

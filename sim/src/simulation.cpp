#include "feeddrive/sim/simulation.hpp"

#include <chrono>
#include <cmath>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/plant/command.hpp"
#include "feeddrive/plant/plant.hpp"

namespace feeddrive::sim {

const std::vector<std::string>& record_columns() {
  static const std::vector<std::string> kColumns = [] {
    std::vector<std::string> c;
    Record r;
    visit_record_columns(
        r, [&](const char* name, const char*, const char*, ColumnSource, double&) { c.emplace_back(name); });
    return c;
  }();
  return kColumns;
}

void record_values(const Record& r, double* out) {
  std::size_t c = 0;
  visit_record_columns(r, [&](const char*, const char*, const char*, ColumnSource, const double& v) { out[c++] = v; });
}

std::vector<double> record_values(const Record& r) {
  std::vector<double> v(kRecordColumns);
  record_values(r, v.data());
  return v;
}

Record make_record(double t, const trajectory::Sample& ref, const plant::State& st, const plant::Measurement& meas,
                   const controller::Command& cmd, double u_applied, const plant::Forces& f) {
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
  r.u = u_applied;  // what the drive applied (plant/command.hpp)
  r.u_unsaturated = cmd.u_unsaturated;
  r.f_thrust = f.thrust;
  r.f_friction = f.friction;
  r.f_ripple = f.ripple;
  r.f_grinding = f.grinding;
  r.sliding = cmd.sliding;
  r.z_estimate = cmd.z_estimate;
  return r;
}

void check_finite_step(const Scenario& s, long k, const Record& r, double command) {
  // The sources are named only when a value fails: building their text (a number formatted, the
  // plant's time scales) every step cost ~5 % of a period (docs/performance.md).
  const auto source = [&](ColumnSource src) -> std::string {
    switch (src) {
      case ColumnSource::kController:
        return std::string("from the controller (controller.type = ") + fields::enum_name(s.controller.type) +
               "; its gains or model make it diverge)";
      case ColumnSource::kReference: return "from the reference (the reference section)";
      case ColumnSource::kSensor:
        return "from the sensor (plant.sensor.quantization = " + validate::format_number(s.plant.sensor.quantization) +
               ", noise_stddev = " + validate::format_number(s.plant.sensor.noise_stddev) + ")";
      case ColumnSource::kPlant: return "from the plant, driven to it (" + s.plant.fastest_time_scales(1) + ")";
      case ColumnSource::kTime: break;
    }
    return "";
  };
  const auto fail = [&](const std::string& what, double v, ColumnSource src) {
    throw ScenarioError("step " + std::to_string(k) + " (t = " + validate::format_number(r.t) + " s): " + what + " = " +
                        validate::format_number(v) + ": " + source(src));
  };
  if (!std::isfinite(command)) fail("the command u", command, ColumnSource::kController);
  // The record's columns by source (visit_record_columns), the reference's first, then the
  // sensor's, then the plant's; the controller's own columns may be NaN (sliding, z_estimate).
  for (const ColumnSource want : {ColumnSource::kReference, ColumnSource::kSensor, ColumnSource::kPlant})
    visit_record_columns(r, [&](const char* name, const char*, const char*, ColumnSource src, const double& v) {
      if (src == want && !std::isfinite(v)) fail(name, v, src);
    });
}

RunStats run(const Scenario& s, const RecordSink& sink, const interrupt::StopToken& stop) {
  Excitation none;
  none.stop = stop;
  return run(s, sink, none);
}

RunStats run(const Scenario& s, const RecordSink& sink, const Excitation& excitation) {
  const auto wall_start = std::chrono::steady_clock::now();
  plant::Plant drive(s.drive(), s.control_period);
  const auto own_reference = excitation.reference ? nullptr : make_reference(s);
  const trajectory::Trajectory* reference = excitation.reference ? excitation.reference : own_reference.get();
  const double thrust_gain = s.plant.thrust_gain();
  const auto controller = make_controller(s);
  const long n = s.steps();

  for (long k = 0; k < n; ++k) {
    if ((k & 1023) == 0) excitation.stop.check();
    const double t = s.time_of(k);
    const trajectory::Sample ref = reference->sample(t);
    const plant::Measurement meas = drive.measure();
    const plant::State st = drive.state();
    const controller::Truth truth{st.z, st.fg};
    const controller::Command cmd = controller->update(ref, meas, &truth);
    const double u = plant::admit_command(cmd.u, s.plant.input_limit).u;
    // the drive's input: the command plus the excitation's force at the amplifier input
    const double u_drive = excitation.input_force ? u + excitation.input_force(t) / thrust_gain : u;
    const plant::Forces f = drive.forces(u_drive);
    const Record r = make_record(t, ref, st, meas, cmd, u, f);
    check_finite_step(s, k, r, cmd.u);
    sink(r);
    drive.advance(u_drive, s.time_of(k + 1));
  }
  RunStats stats;
  stats.steps = n;
  stats.integrator = drive.integrator_stats();
  stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return stats;
}

RunResult run(const Scenario& s) {
  RunResult result;
  result.records.reserve(static_cast<std::size_t>(s.steps()));
  const RunStats st = run(s, [&](const Record& r) { result.records.push_back(r); });
  result.wall_time_s = st.wall_time_s;
  result.integrator = st.integrator;
  return result;
}

}  // namespace feeddrive::sim

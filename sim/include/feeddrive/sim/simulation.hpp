#pragma once
// The in-process lockstep loop: reference -> controller -> plant, one record per control step.
//
//   for k = 0 .. N-1,  t_k = k*T:
//     r_k = reference(t_k);  m_k = plant.measure();  c_k = controller(r_k, m_k, truth_k)
//     record(t_k, r_k, state_k, m_k, c_k, forces(state_k, u_k));  plant.advance(u_k, t_{k+1})
//
// The multi-process service runs the same components in the same order, so both produce the
// same records bit for bit; both assemble a row with make_record.
//
// Streaming: run(s, sink) hands each record to `sink` as it is made and keeps none, so its
// memory does not depend on the number of steps.

#include <functional>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/controller/controller.hpp"
#include "feeddrive/plant/cvode_integrator.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::sim {

/// One row of timeseries.csv (columns documented in docs/scenario.md, generated from
/// visit_record_columns).
struct Record {
  double t{0.0};
  double xd{0.0}, vd{0.0}, ad{0.0}, jd{0.0};                              ///< reference [m, m/s, m/s^2, m/s^3]
  double x{0.0}, v{0.0}, z{0.0}, fg{0.0}, i{0.0};                         ///< true state
  double x_measured{0.0}, v_measured{0.0};                                ///< sensor output
  double u{0.0}, u_unsaturated{0.0};                                      ///< command [V]
  double f_thrust{0.0}, f_friction{0.0}, f_ripple{0.0}, f_grinding{0.0};  ///< [N]
  double sliding{0.0}, z_estimate{0.0};                                   ///< controller diagnostics (NaN if none)
};

/// Where a column's value comes from: a non-finite value is named by its source
/// (check_finite_step: "from the reference", "from the sensor (...)", "from the plant").
enum class ColumnSource { kTime, kReference, kPlant, kSensor, kController };

/// The one list of the record's columns, in timeseries.csv's order: f(name, unit, meaning,
/// source, member) for each. The column names, the row's values, the non-finite checks of a step
/// and the column table of docs/scenario.md (feeddrive-keys, ctest docs.key_tables) all come
/// from it.
template <class R, class F>
constexpr void visit_record_columns(R& r, F&& f) {
  using S = ColumnSource;
  f("t", "s", "k·T", S::kTime, r.t);
  f("xd", "m", "reference position", S::kReference, r.xd);
  f("vd", "m/s", "reference velocity", S::kReference, r.vd);
  f("ad", "m/s²", "reference acceleration", S::kReference, r.ad);
  f("jd", "m/s³", "reference jerk", S::kReference, r.jd);
  f("x", "m", "true position", S::kPlant, r.x);
  f("x_measured", "m", "measured position: what the controller saw (sensor model)", S::kSensor, r.x_measured);
  f("v", "m/s", "true velocity", S::kPlant, r.v);
  f("v_measured", "m/s", "measured velocity: what the controller saw (sensor model)", S::kSensor, r.v_measured);
  f("z", "m", "LuGre bristle deflection", S::kPlant, r.z);
  f("fg", "N", "grinding-force state", S::kPlant, r.fg);
  f("i", "A", "armature current (electrical option; 0 otherwise)", S::kPlant, r.i);
  f("u", "V", "the command the drive applied (saturated, delayed)", S::kController, r.u);
  f("u_unsaturated", "V", "the controller's command before saturation", S::kController, r.u_unsaturated);
  f("f_thrust", "N", "Ka·Kf·u (or Kf·i)", S::kPlant, r.f_thrust);
  f("f_friction", "N", "friction force opposing the thrust", S::kPlant, r.f_friction);
  f("f_ripple", "N", "force ripple opposing the thrust", S::kPlant, r.f_ripple);
  f("f_grinding", "N", "grinding force opposing the thrust", S::kPlant, r.f_grinding);
  f("sliding", "m/s", "the SMC sliding variable S (NaN for other controllers)", S::kController, r.sliding);
  f("z_estimate", "m", "the z used by the SMC friction compensation (NaN if none)", S::kController, r.z_estimate);
}

/// Column names of timeseries.csv, in order.
const std::vector<std::string>& record_columns();
/// Number of columns, counted on the list.
constexpr std::size_t record_column_count() {
  Record r;
  std::size_t n = 0;
  visit_record_columns(r, [&n](const char*, const char*, const char*, ColumnSource, double&) { ++n; });
  return n;
}
inline constexpr std::size_t kRecordColumns = record_column_count();
/// The values of a record in the order of record_columns() (out[kRecordColumns]).
void record_values(const Record& r, double* out);
std::vector<double> record_values(const Record& r);

/// The one assembly of a row (the in-process loop and the monitor's translator): step time t,
/// reference, true state at t, measurement, the controller's command, the u the drive applied
/// and the forces under it.
Record make_record(double t, const trajectory::Sample& ref, const plant::State& state, const plant::Measurement& meas,
                   const controller::Command& cmd, double u_applied, const plant::Forces& forces);

using RecordSink = std::function<void(const Record&)>;

struct RunStats {
  long steps{0};
  double wall_time_s{0.0};
  plant::CvodeIntegrator::Stats integrator;
};

/// Runs a scenario in-process, handing every record to `sink` in step order. Polls `stop`
/// (feeddrive/common/interrupt.hpp) every 1024 steps and throws interrupt::Interrupted when it
/// asks to stop (Ctrl-C or SIGTERM in a tool; the default never stops).
RunStats run(const Scenario& s, const RecordSink& sink, const interrupt::StopToken& stop = {});

/// An excitation of the closed loop (the frequency response, analysis/frequency_response.hpp):
///  * reference: replaces the scenario's reference (nullptr: the scenario's);
///  * input_force: F_d(t_k) [N], added at the amplifier input as u + F_d/(Ka*Kf) and held over the
///    period like the command (a drive's set-point injection: without the electrical option a
///    force on the carriage; with it, the set-point of the current loop). The controller does not
///    see it; the record's u stays the controller's command, f_thrust includes F_d.
struct Excitation {
  const trajectory::Trajectory* reference{nullptr};
  std::function<double(double t)> input_force;
  interrupt::StopToken stop;  ///< polled as by run(s, sink, stop)
};
RunStats run(const Scenario& s, const RecordSink& sink, const Excitation& excitation);

/// All records in memory (tests, short runs).
struct RunResult {
  std::vector<Record> records;
  double wall_time_s{0.0};
  plant::CvodeIntegrator::Stats integrator;
};
RunResult run(const Scenario& s);

/// The run-time guard of issue 13, point 7 (what the load-time checks of scenario.cpp cannot
/// foresee because it depends on the motion): throws ScenarioError (exit 2) naming the step, the
/// value and the scenario section that produced it if the controller's command or a value of
/// step k's record is NaN or infinite. The diagnostic columns u_unsaturated, sliding and
/// z_estimate may be NaN (a controller without them).
void check_finite_step(const Scenario& s, long k, const Record& r, double command);

}  // namespace feeddrive::sim

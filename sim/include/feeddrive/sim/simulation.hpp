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

#include "feeddrive/controller/controller.hpp"
#include "feeddrive/plant/cvode_integrator.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"
#include "feeddrive/trajectory/trajectory.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim {

/// One row of timeseries.csv (columns documented in docs/scenario.md).
struct Record {
  double t{0.0};
  double xd{0.0}, vd{0.0}, ad{0.0}, jd{0.0};  ///< reference [m, m/s, m/s^2, m/s^3]
  double x{0.0}, v{0.0}, z{0.0}, fg{0.0}, i{0.0};  ///< true state
  double x_measured{0.0}, v_measured{0.0};   ///< sensor output
  double u{0.0}, u_unsaturated{0.0};         ///< command [V]
  double f_thrust{0.0}, f_friction{0.0}, f_ripple{0.0}, f_grinding{0.0};  ///< [N]
  double sliding{0.0}, z_estimate{0.0};      ///< controller diagnostics (NaN if none)
};

/// Column names of timeseries.csv, in order.
const std::vector<std::string>& record_columns();
/// Number of columns.
inline constexpr std::size_t kRecordColumns = 20;
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

/// Runs a scenario in-process, handing every record to `sink` in step order. Polls the
/// interrupt flag (feeddrive/common/interrupt.hpp) every 1024 steps and throws
/// interrupt::Interrupted after Ctrl-C or SIGTERM.
RunStats run(const Scenario& s, const RecordSink& sink);

/// An excitation of the closed loop (the frequency response, analysis/frequency_response.hpp):
///  * reference: replaces the scenario's reference (nullptr: the scenario's);
///  * input_force: F_d(t_k) [N], added at the amplifier input as u + F_d/(Ka*Kf) and held over the
///    period like the command (a drive's set-point injection: without the electrical option a
///    force on the carriage; with it, the set-point of the current loop). The controller does not
///    see it; the record's u stays the controller's command, f_thrust includes F_d.
struct Excitation {
  const trajectory::Trajectory* reference{nullptr};
  std::function<double(double t)> input_force;
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

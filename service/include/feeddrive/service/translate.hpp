#pragma once
// Translators between the LCM message contract (lcmtypes/) and the domain structs of the
// libraries. No logic beyond copying fields lives here.

#include "feeddrive/controller/controller.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/trajectory/trajectory.hpp"
#include "feeddrive/applied_t.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_t.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/service/node.hpp"

namespace feeddrive::service {

reference_t to_message(std::int64_t seq, double t, const trajectory::Sample& s);
trajectory::Sample to_sample(const reference_t& m);

control_command_t to_message(std::int64_t seq, double t, const controller::Command& c);

plant::Measurement to_measurement(const drive_state_t& m);
/// The truth fields a simulated plant sends (valid = true).
drive_truth_t to_truth_message(const plant::State& s);
/// What the controller may use of the truth (nullopt-like: valid == false -> no truth).
controller::Truth to_truth(const drive_truth_t& m);

applied_t to_applied(std::int64_t seq, double u, const plant::Forces& f);
applied_t no_applied();

/// Assembles one row of timeseries.csv from the messages of step k: its state, reference and
/// command, and what the plant applied during it (carried by the state of step k+1).
sim::Record to_record(const drive_state_t& state, const reference_t& ref, const control_command_t& cmd,
                      const applied_t& applied);

/// The run's self-description (run_info_t) from its scenario and the run's options: name, mode,
/// period, steps, the drive's nominal parameters, the command limits, the protocol's timeouts,
/// window and pace, the initial state, the sensor model, the contract version and the scenario's
/// hash (utime, run_id and current_step are the sender's: current_step -1 here).
run_info_t to_run_info(const sim::Scenario& s, const NodeOptions& opt, const std::string& scenario_hash);

}  // namespace feeddrive::service

#pragma once
// Translators between the LCM message contract (lcmtypes/) and the domain structs of the
// libraries, without transport: the nodes (service/translate.hpp adds the run's
// self-description) and the offline tools (the Recorder's rows) share them. No logic beyond
// copying fields lives here.

#include "feeddrive/applied_t.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/controller/controller.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"
#include "feeddrive/reference_t.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::record {

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

}  // namespace feeddrive::record

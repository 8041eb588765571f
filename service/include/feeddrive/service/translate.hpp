#pragma once
// Translators between the LCM message contract (lcmtypes/) and the service's structs: the run's
// self-description here; the field copies of the step's messages in feeddrive/record/translate.hpp.
// No logic beyond copying fields lives here.

#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/parameter_t.hpp"
#include "feeddrive/record/translate.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::service {

// The field copies between messages and domain structs need no transport: they live in
// feeddrive::record (feeddrive/record/translate.hpp), shared with the offline tools.
using record::no_applied;
using record::to_applied;
using record::to_measurement;
using record::to_message;
using record::to_record;
using record::to_sample;
using record::to_truth;
using record::to_truth_message;

/// A parameter table (plant::parameter_table) as run_info_t.plant. Throws std::logic_error when
/// it does not fit the contract's bounds (more entries, a longer key or name): never cut.
std::vector<parameter_t> to_parameters(const std::vector<fields::FlatValue>& table);

/// The run's self-description (run_info_t) from its scenario and the run's options: name, mode,
/// period, steps, the drive's nominal parameters (plant::parameter_table of the scenario's plant,
/// its one list walked), the command limits, the protocol's timeouts, window and pace, the
/// resolved velocity measurement, the contract version and the scenario's hash (utime, run_id and
/// current_step are the sender's: current_step -1 here).
run_info_t to_run_info(const sim::Scenario& s, const NodeOptions& opt, const std::string& scenario_hash);

}  // namespace feeddrive::service

#pragma once
// The plant process: the simulated drive (feeddrive::plant) behind the message contract.
//
// Lockstep mode: publish state k; wait for command k (re-publishing state k every resend
// interval); admit it (plant/command.hpp: NaN/inf rejected -> 0 V, out of range clipped, both
// counted); integrate [t_k, t_k+1]; publish state k+1 carrying what was applied during k.
// Never more than monitor_window steps ahead of the monitor's acknowledged step.
//
// Real-time mode: the wall clock paces the steps. State k goes out at t0 + k*T; at t0 + (k+1)*T
// the plant integrates step k with the latest admissible command it has (command k if it came in
// time, else the previous one, counted as a missed deadline). After max_bad_commands missed or
// invalid commands in a row it goes to the safe state (0 V) and says so, in its status and in
// every following state message, until a valid command arrives on time.

#include <cstdint>
#include <optional>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::service {

class PlantNode : public Node {
 public:
  PlantNode(const sim::Scenario& s, const NodeOptions& opt);
  /// Runs to the end; returns normally when the run completed, throws RunFailure otherwise.
  void run();

  std::int64_t rejected_commands() const { return rejected_; }
  std::int64_t missed_deadlines() const { return missed_; }

 private:
  void run_lockstep();
  void run_realtime();
  drive_state_t make_state(std::int64_t k);
  void publish_state(std::int64_t k);
  /// Applies u over step k and advances the drive.
  void apply(std::int64_t k, double u);
  void wait_for_monitor(std::int64_t k);

  sim::Scenario s_;
  std::int64_t steps_;
  plant::Plant drive_;
  Outbox<drive_state_t> states_;
  std::optional<control_command_t> command_;  ///< the newest command received, any seq
  StepLedger<control_command_t> command_ledger_;  ///< every command received, for conflicts
  applied_t previous_;
  std::int64_t rejected_{0};
  std::int64_t missed_{0};
  int bad_in_a_row_{0};
  bool safe_state_{false};
  double last_good_u_{0.0};
};

}  // namespace feeddrive::service

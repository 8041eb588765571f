#pragma once
// The plant process: the simulated drive (feeddrive::plant) behind the message contract.
//
// Lockstep mode: publish state k; wait for command k (re-publishing state k every resend
// interval); admit it (plant/command.hpp: NaN/inf rejected -> 0 V, out of range clipped, both
// counted); integrate [t_k, t_k+1]; publish state k+1 carrying what was applied during k.
// Never more than monitor_window steps ahead of the monitor's acknowledged step.
//
// Real-time mode: the wall clock paces the steps, and a command acts from when it arrives (a
// real drive's zero-order hold). State k goes out at w_k = t0 + k*T, first thing in the period
// (absolute clock_nanosleep to w_k - spin, then a short spin). The drive holds the newest
// admissible command; a command that arrives at wall time w_k + d switches the input at
// simulated time t_k + d: the plant integrates [t_k, t_k + d] with the old input and restarts
// CVODE there (a jump discontinuity). When command k has arrived, the plant integrates to
// t_{k+1} at once and prepares state k+1, so that at w_{k+1} it only publishes. Command k must
// arrive before w_{k+1} - guard (guard: the plant's own computation, realtime_guard()); one
// that arrives later is a missed deadline, and acts from its arrival in a later period. When
// the plant itself starts a period more than the guard late (an overrun: its own timer or a
// stalled CPU), it moves its clock on by that delay instead of catching up, and counts it apart.
// After max_bad_commands missed or invalid commands in a row it goes to the safe state (0 V)
// and says so, in its status and in every following state message, until a valid command
// arrives on time. Lockstep keeps the idealisation: command k acts over all of [t_k, t_{k+1}].

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::service {

class PlantNode : public Node {
 public:
  /// `shared_lcm`: see Node (in-process tests); nullptr in the process.
  PlantNode(const sim::Scenario& s, const NodeOptions& opt, lcm_t* shared_lcm = nullptr);
  /// Runs to the end; returns normally when the run completed, throws RunFailure otherwise.
  void run();

  std::int64_t rejected_commands() const { return rejected_; }
  std::int64_t missed_deadlines() const { return missed_; }
  std::int64_t overruns() const { return overruns_; }

 private:
  void run_lockstep();
  void run_realtime();
  drive_state_t make_state(std::int64_t k);
  void publish_state(std::int64_t k);
  /// Applies u over step k and advances the drive.
  void apply(std::int64_t k, double u);
  void wait_for_monitor(std::int64_t k);
  /// Lockstep with --max-rate: waits (serving the bus) until monotonic time due_us [us].
  void wait_for_pace(std::int64_t due_us);
  /// Real time: takes the commands received so far; each newer one switches the input at its
  /// arrival (simulated time clamped to [now, t_end]). Returns true if command k was among them.
  bool take_commands(std::int64_t k, double t_end);
  /// Real time: the simulated time [s] of monotonic time mono [us].
  double sim_time_of(std::int64_t mono) const;

  sim::Scenario s_;
  std::int64_t steps_;
  plant::Plant drive_;
  Outbox<drive_state_t> states_;
  std::optional<control_command_t> command_;                         ///< the newest command received, any seq
  StepLedger<control_command_t> command_ledger_;                     ///< every command received, for conflicts
  std::vector<std::pair<control_command_t, std::int64_t>> arrived_;  ///< real time: (command, recv_us) not yet taken
  std::int64_t newest_seq_{-1};                                      ///< real time: the newest command seq taken
  std::int64_t t0_us_{0};  ///< real time: the wall (monotonic) time of t = 0 [us]
  double u_now_{0.0};      ///< real time: the input the drive holds now [V]
  applied_t previous_;
  std::int64_t rejected_{0};
  std::int64_t missed_{0};
  std::int64_t overruns_{0};  ///< real time: periods the plant started more than the guard late
  int bad_in_a_row_{0};
  bool safe_state_{false};
  double last_good_u_{0.0};
};

}  // namespace feeddrive::service

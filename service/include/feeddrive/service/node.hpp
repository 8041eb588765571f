#pragma once
// What every process of the lockstep service shares: options, the bus and its channels, the
// heartbeat (process_status_t), resend requests, and the view of the other roles' status.
//
// Protocol (docs/lcm-contract.md): the plant publishes drive_state_t k and waits for
// control_command_t k; it re-publishes state k every resend interval until the command comes.
// The controller answers state k once it also has reference_t k, and answers a repeated state k
// with the same command. The trajectory keeps references 256 steps ahead of the newest state it
// has seen, and re-publishes k's block when it sees state k repeated. The monitor records every step and
// asks for what it missed on <prefix>_RESEND; the plant stays within a window of the monitor's
// acknowledged step, so nothing is lost. Every wait has a timeout that names the missing role.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/service/bus.hpp"

namespace feeddrive::service {

struct NodeOptions {
  std::string lcm_url{default_lcm_url()};
  std::string prefix{"FD"};
  double start_timeout_s{30.0};     ///< how long to wait for the other roles to show up (step 0)
  double step_timeout_s{5.0};       ///< no progress for this long: fail, naming the missing role
  double resend_interval_s{0.002};  ///< re-publish a pending message after this long
  long monitor_window{4096};        ///< plant: max steps ahead of the monitor's ack; 0: ignore the monitor
  double linger_s{10.0};            ///< after the end: keep answering resend requests until the monitor is done
  bool realtime{false};             ///< plant: paced by the wall clock, applies the latest command
  /// Lockstep: the plant publishes at most this many steps per second (each state at least
  /// 1/max_rate after the previous one, never catching up); 0: as fast as the chain answers. The
  /// pace at which the stock lcm-logger records without loss is loggers.hpp's kStockLoggerSteps.
  double max_rate{0.0};
  int max_bad_commands{10};  ///< real time: consecutive missed/invalid commands before the safe state
  /// Real time: busy-wait this long before a period start (after clock_nanosleep). 30 us: a timer
  /// wakes 20-40 us late on the development VM (measured: bench/realtime_bench.sh with 10 us
  /// gave a median 767 plant overruns and 75 misses of 15,000, with 30 us 156 and 56).
  std::int64_t realtime_spin_us{30};
  /// Real time: take SCHED_FIFO (enter_realtime) as well as the wall-clock protocol. The memq://
  /// protocol tests turn it off: the protocol without changing the test process's scheduling.
  bool realtime_scheduling{true};
  bool quiet{false};
  /// Polled by the protocol loops (Ctrl-C, SIGTERM): add_node_options sets the process's token
  /// (tool::stop_token()); the default never stops.
  interrupt::StopToken stop;
  /// The run's identity (docs/security.md); 0: not given. Then the plant draws one and every
  /// other process takes it from the plant's first fresh heartbeat.
  std::int64_t run_id{0};
  /// Hex SHA-256 of the scenario file as the launcher read it (run_info_t.scenario_hash); "":
  /// the monitor hashes the file it read.
  std::string scenario_hash;
  std::string key_file;  ///< --key: authenticate every message with this key; "": off
  /// --set key=value: scenario settings applied before the scenario is read (sim::load_scenario),
  /// the same in every process (the scenario hash covers them).
  std::vector<std::string> sets;
  /// --run-nonce, with --key: the run's nonce (feeddrive-launch draws it and gives it to every
  /// process it starts); 0: the plant draws one and the others take it from its fresh heartbeat.
  std::int64_t run_nonce{0};
  ConflictPolicy on_conflict{ConflictPolicy::kFail};
};

/// The roles of a run (plant, controller, trajectory, monitor): a failure of one stops the
/// others. Any other role on the status channel (an attached monitor, a tool) is an observer:
/// its status is heard, its failure never stops the run.
bool is_run_role(const std::string& role);
/// The role of feeddrive-monitor --attach on the status channel.
inline constexpr const char* kAttachedMonitorRole = "monitor-attached";

/// Thrown when a run cannot go on: another role failed or stopped answering.
struct RunFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Node {
 public:
  /// `receive`: kDirect for the roles on a step's critical path (plant, controller), kBatched
  /// for the others (monitor, trajectory): see bus.hpp. `shared_lcm`: the bus publishes and
  /// receives through this liblcm instance instead of opening opt.lcm_url (Bus: in-process
  /// tests over one memq:// instance); nullptr in the processes.
  Node(std::string role, const NodeOptions& opt, Receive receive = Receive::kDirect, lcm_t* shared_lcm = nullptr);
  /// Reports the LCM publish calls that failed during the process's life (a warning; none: silent).
  virtual ~Node();

  const std::string& role() const { return role_; }
  Bus& bus() { return bus_; }
  const Channels& channels() const { return ch_; }
  const NodeOptions& options() const { return opt_; }
  /// Under --key, the run's nonce (process_status_t.run_nonce); 0 without a key or before the run is known.
  std::int64_t run_nonce() const { return run_nonce_; }

  /// Publishes the heartbeat if due (every 100 ms) or when forced.
  void heartbeat(bool force = false);
  /// Publishes state "failed" with the message (several times: it must not get lost).
  void announce_failure(const std::string& message);
  void set_state(const std::string& state) {
    state_ = state;
    heartbeat(true);
  }
  void set_seq(std::int64_t seq) { seq_ = seq; }

  void request_resend(const std::string& channel, std::int64_t seq);
  /// Returns once this process knows its run (--run-id, or the plant's heartbeat); throws
  /// RunFailure after --start-timeout. A process that publishes before any message of the run
  /// reaches it (the trajectory's first block) calls this first.
  void wait_for_run();

  /// Checks the message `item` of step `seq` on `channel` against the one this node already has
  /// for that step. True: new or identical (the caller goes on as before: an identical one is a
  /// re-publication). A different one is a conflict: counted, logged naming channel, step and
  /// fields, then RunFailure (--on-conflict fail, the default) or false (keep-first: drop it).
  template <typename T>
  bool admit(StepLedger<T>& ledger, const std::string& channel, std::int64_t seq, const T& item) {
    std::string diff;
    if (ledger.admit(seq, item, &diff) != StepLedger<T>::Seen::kConflict) return true;
    return on_conflict(channel, seq, T::getTypeName(), diff);
  }

  /// Throws RunFailure if another role announced a failure.
  void check_peers() const;
  /// The latest status of a role, if any was seen.
  const process_status_t* peer(const std::string& role) const;
  /// True if `role` published a status that is not "failed" within the last `seconds`: it is
  /// alive and running its own timeouts, so a wait on it is not yet its fault to report.
  bool peer_alive(const std::string& role, double seconds) const;
  /// The same, judged at `at_us` (monotonic [us]) rather than now: e.g. at the receive time of
  /// the message being handled (Bus::current_recv_us), for a process reading a backlog.
  bool peer_alive_at(const std::string& role, double seconds, std::int64_t at_us) const;
  /// The run role whose heartbeats came from the UDP source "IP:PORT" (Bus::current_source), ""
  /// if none did: a participant sends its heartbeats and its messages from one socket. Recorded
  /// from every heartbeat heard, before this node joined the run too (at most 64 sources);
  /// only heartbeats of this run count. Under --key only signed heartbeats reach it.
  std::string role_of_source(const std::string& source) const;
  bool monitor_done() const;
  /// After the end: state "done", then keep answering resend requests and sending heartbeats
  /// until the monitor is done (and an attached monitor heard within the last second too) or
  /// --linger seconds have passed. `every_100ms` (if given) runs
  /// about every 100 ms meanwhile (the plant re-publishes its end-of-run state).
  void linger(const std::function<void()>& every_100ms = {});

  std::int64_t resends{0};
  std::int64_t duplicates{0};
  std::int64_t invalid_content{0};
  std::int64_t conflicts{0};
  std::int64_t acked_seq{-1};  ///< monitor only: every step below is recorded

 protected:
  /// Real time (and realtime_scheduling): enter_realtime(priority, lock_memory), the line it
  /// returns logged under this role (a warning when SCHED_FIFO was not granted). Else nothing.
  void enter_realtime_if_asked(int priority, bool lock_memory = true);
  /// Called for resend requests on `channel`; re-publish `seq` if this node owns the channel.
  std::function<void(const resend_request_t&)> on_resend_request;
  /// Called each time the heartbeat goes out (every 100 ms and on changes of state).
  std::function<void()> on_heartbeat;
  /// Called with every heartbeat of another process of this run.
  std::function<void(const process_status_t&)> on_peer_status;
  /// A heartbeat of this run that went back (ignored as a conflict): the monitor tells a
  /// restarted plant from a replay by it (docs/security.md, "Heartbeats").
  std::function<void(const process_status_t&)> on_peer_status_back;

 private:
  /// The run's identity from the options: the launcher's nonce, or (the plant under --key) a
  /// fresh one, or the plain --run-id; else the run is joined from the plant's heartbeat.
  void set_run_identity();
  /// A heartbeat on the status channel: joins the run (join_run), ignores other runs, its own
  /// and heartbeats that go back (goes_back), else records the peer and calls on_peer_status.
  void on_status(const process_status_t& m, std::int64_t recv_us);
  /// Before a run is known: joins the run of a fresh plant heartbeat (under --key bound to its
  /// nonce). Returns false when `m` does not make this node join.
  bool join_run(const process_status_t& m);
  /// True (and counted as a conflict, logged at most once a second) when `m` goes back: a run
  /// role's state, a monitor's acknowledgement, or (--key) a step within a state.
  bool goes_back(const process_status_t& m);
  /// run_info_t naming another scenario hash than this participant's: refused (scenario_mismatch_).
  void on_run_info(const run_info_t& m);
  bool on_conflict(const std::string& channel, std::int64_t seq, const char* type, const std::string& diff);
  process_status_t status_message(const std::string& state, const std::string& message) const;

  std::string role_;
  NodeOptions opt_;
  /// Under --key: the nonce of the run (the plant draws it; the others take it from the plant's
  /// fresh, signed heartbeat whose run id is keyed_run_id(--run-id, nonce)); 0 without a key.
  std::int64_t run_nonce_{0};
  bool warned_no_nonce_{false};
  Bus bus_;
  Channels ch_;
  std::string state_{"starting"};
  std::int64_t seq_{-1};
  std::int64_t last_heartbeat_us_{-1};
  std::int64_t last_conflict_log_us_{-1};
  std::string scenario_mismatch_;                ///< set when run_info_t names another scenario hash than ours
  std::int64_t attached_acked_{-2};              ///< the attached monitor's last acknowledgement
  std::int64_t attached_progress_us_{-1};        ///< when it last moved (mono_us)
  static constexpr double kAttachedHoldS = 2.0;  ///< longest an attached monitor holds the linger
  std::map<std::string, process_status_t> peers_;
  std::map<std::string, std::int64_t> peer_seen_us_;
  std::map<std::string, std::pair<std::int64_t, std::string>> status_sources_;  ///< source -> (run id, role)
};

/// Real-time setup of a process on a real-time run's critical path (plant, controller), as
/// real-time Linux practice has it: mlockall(MCL_CURRENT | MCL_FUTURE) (no page fault in a
/// period), SCHED_FIFO at `priority` where permitted, and a 1 ns timer slack (the default 50 us
/// would delay every timed wake-up). Returns one line saying what was granted, e.g.
/// "SCHED_FIFO 80, memory locked" or "normal scheduling (SCHED_FIFO not permitted: needs root,
/// CAP_SYS_NICE or an rtprio limit), memory locked"; the caller logs it. It also holds the CPU
/// wake-up latency at 0 (hold_cpu_latency_zero). lock_memory = false leaves out the mlockall, for
/// a process whose memory grows with the run (the monitor's record).
std::string enter_realtime(int priority, bool lock_memory = true);

/// Back to normal scheduling (SCHED_OTHER) after a real-time phase, e.g. the monitor once the
/// run's messages are recorded and its output (CSV, plots) is written at normal priority.
void leave_realtime();

/// Asks the kernel's PM QoS for a CPU wake-up latency of 0 us, as cyclictest does by default, by
/// writing a 32-bit 0 to /dev/cpu_dma_latency and keeping the descriptor open for the life of the
/// process (Linux, Documentation/power/pm_qos_interface.rst). The cpuidle governor then keeps idle
/// CPUs in states with 0 exit latency (polling): a CPU halted in a deeper state (on a KVM guest,
/// `haltpoll`'s HLT) takes 20-30 us to wake, measured on this project's VM (docs/lcm-contract.md,
/// "An isolated core"). Costs power: idle CPUs spin while any process holds it. Needs root (the
/// device is 0600); returns one line saying what was granted. FEEDDRIVE_CPU_LATENCY_HOLD=0 in the
/// environment leaves it off (bench/realtime_bench.sh alternates the two in one invocation).
std::string hold_cpu_latency_zero();

/// Sleeps until monotonic time `target_us` [us]: an absolute clock_nanosleep to spin_us before
/// it, then a busy wait (the wake-up latency of a timer is tens of us on a virtual machine).
void sleep_until(std::int64_t target_us, std::int64_t spin_us, const interrupt::StopToken& stop);

/// "2", "0.5", "30": a duration in seconds for messages (shortest exact form, %g).
std::string seconds_text(double s);

/// Seconds to microseconds.
inline std::int64_t us(double seconds) { return static_cast<std::int64_t>(seconds * 1e6); }

}  // namespace feeddrive::service

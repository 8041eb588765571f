#pragma once
// feeddrive-launch: starts the four processes of a run (plant, controller, trajectory,
// monitor) with the same scenario, LCM URL and channel prefix, forwards SIGINT/SIGTERM to them,
// waits, and reports. A role named in `external` is not started: a process the user runs
// (hardware driver, external controller) takes it.

#include <set>
#include <string>
#include <vector>

#include "feeddrive/service/node.hpp"

namespace feeddrive::service {

struct LaunchOptions {
  std::string scenario;
  std::string out_dir;
  std::set<std::string> external;  ///< roles left to the user: "controller", "plant", "trajectory"
  bool plots{true};
  std::string bin_dir;  ///< where the feeddrive-* executables are (default: next to the launcher)
  /// After one process fails, how long the others get to notice before they are terminated [s].
  double grace_s{10.0};
  /// nice() increment of the monitor and the trajectory, which are off the step's critical path:
  /// they yield to it. Measured on the shared 2-core VM (alternating, 5 rounds each, 24 November
  /// 2026), nice 0 made the lockstep run faster (34,200 against 30,900 steps/s on one core, 5 of
  /// 5 rounds), but then an attached monitor (--attach, which then never asked for resends) lost
  /// datagrams under load (tests/service/attach_test.sh failed 2 of 8 times), so it stays 10.
  int off_path_niceness{10};
  /// The same in real-time mode, where the plant, the controller and the trajectory run at
  /// SCHED_FIFO and nice only affects the monitor: 10, measured (alternating, 5 rounds each)
  /// 30 against 33 median deadline misses of 15,000 at nice 0, fewer in 4 of 5 rounds.
  int realtime_off_path_niceness{10};
  /// CPUs every started process is pinned to (sched_setaffinity); empty: no pinning. A lockstep
  /// run is a strict chain (state -> command -> state), so its processes never need to run at
  /// once, and on machines where waking a process on another core is slow (virtual machines)
  /// one core is fastest (bench/lockstep_bench.sh measures it).
  std::vector<int> cpus;
  /// CPUs for the processes off the step's critical path (monitor, trajectory); empty: `cpus`.
  /// A real-time run keeps its core for the plant and controller and sends these elsewhere
  /// (docs/lcm-contract.md, "An isolated core").
  std::vector<int> off_path_cpus;
  /// Before starting, listen this long for another run's plant on the group and prefix (its
  /// heartbeat comes every 100 ms); if one is there, refuse in one line (docs/security.md).
  /// 0: no check.
  double busy_check_s{0.3};
  /// If set: the monitor also writes the run's messages to this LCM log (feeddrive-monitor --lcm-log).
  std::string lcm_log;
  /// --max-rate not given: when a stock lcm-logger is on the bus at the start (loggers.hpp), a
  /// lockstep run is paced to what it records without loss (kStockLoggerSteps), and says so.
  bool auto_pace{true};
};

/// Parses a CPU list "0" or "0,2" (each an index this process may run on). Throws
/// std::invalid_argument naming the bad entry.
std::vector<int> parse_cpu_list(const std::string& text, const std::string& option = "--cpus");

struct LaunchResult {
  int exit_code{0};                 ///< 0 if every started process exited 0
  std::vector<std::string> failed;  ///< "role (exit n)" of each process that did not exit 0
  /// The monitor was killed (no unwinding, e.g. SIGKILL): where its record so far was moved
  /// (DIR.incomplete-N, output::rescue_staging); "" otherwise.
  std::string partial_record;
  /// The different one-line refusals of the processes that exited 2 (bad input), each once; the
  /// launcher prints these instead of a line per process (the others were stopped at once).
  std::vector<std::string> refusals;
};

/// Throws std::invalid_argument (one line: who holds it, how to choose another) if another
/// run's plant publishes on opt's URL and prefix within `listen_s` seconds.
void check_group_free(const NodeOptions& opt, double listen_s);

/// Validates roles (std::invalid_argument naming a bad one), starts, waits, reports. Draws the
/// run id (unless given, or the plant is external) and passes it to every process it starts.
LaunchResult launch(const LaunchOptions& lo, const NodeOptions& opt);

/// The directory of the running executable.
std::string executable_dir();

}  // namespace feeddrive::service

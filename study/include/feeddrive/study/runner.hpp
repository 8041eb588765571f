#pragma once
// Running cases: one case in-process (run_case), its record in the output folder (the case file,
// so a rerun skips it), and a pool of worker threads.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::study {

/// What one case gave: its summary.json metrics (the numbers, in summary.json's order, without
/// the wall-clock ones, which differ from run to run, and the true/false verdicts as 1/0:
/// sim::summary_flag_names), its loader warnings and whether its move finished, or the error
/// that stopped it.
struct Outcome {
  bool ok{false};
  std::string error;
  std::vector<std::pair<std::string, double>> metrics;
  /// The loader's warnings of the case's scenario (sim::Scenario::warnings: an implausible value
  /// with its likely unit, a move cut off by `duration`), as summary.json lists them.
  std::vector<std::string> warnings;
  /// summary.json's move_finished: nullopt if the reference is not a move (or the case failed).
  std::optional<bool> move_finished;
  double wall_s{0.0};       ///< time of this case (not a result: kept out of results.csv)
  bool interrupted{false};  ///< stopped by Ctrl-C or SIGTERM: not an outcome, never recorded
};

/// Runs a case's scenario in-process (sim::run, streamed into the online summary: no records
/// kept) and returns the summary.json metrics. Never throws: a failure is an Outcome with its
/// one-line error; a run stopped by Ctrl-C/SIGTERM is marked `interrupted`.
Outcome run_case(const sim::Scenario& s, const interrupt::StopToken& stop = {});

/// The format of a case file (its "format" key). 2 (issue 23) added warnings and move_finished;
/// a file of another format is not reused: its case runs again.
inline constexpr int kOutcomeFormat = 2;

/// The case file DIR/cases/<hash>.json: the outcome, keyed by the case's hash.
std::string outcome_json(const std::string& hash, const Outcome& o);
/// Parses a case file; nullopt if it is not a case file of this format for this hash (a stale,
/// foreign or damaged file is run again, never trusted).
std::optional<Outcome> parse_outcome(const std::string& text, const std::string& hash);

/// A fixed set of worker threads running work(task) for pushed tasks; results come back through
/// pop(). The work function must not throw (run_case does not).
class Pool {
 public:
  Pool(int threads, std::function<Outcome(std::size_t)> work);
  ~Pool();  ///< stops the threads after the tasks they are on
  Pool(const Pool&) = delete;
  Pool& operator=(const Pool&) = delete;

  void push(std::size_t task);
  /// Tasks pushed and not yet popped as results.
  std::size_t in_flight() const;
  /// Waits up to `wait` for a finished task.
  std::optional<std::pair<std::size_t, Outcome>> pop(std::chrono::milliseconds wait);
  int threads() const { return static_cast<int>(workers_.size()); }

 private:
  void loop();
  std::function<Outcome(std::size_t)> work_;
  mutable std::mutex mu_;
  std::condition_variable task_cv_, done_cv_;
  std::deque<std::size_t> tasks_;
  std::deque<std::pair<std::size_t, Outcome>> done_;
  std::size_t in_flight_{0};
  bool stop_{false};
  std::vector<std::thread> workers_;
};

}  // namespace feeddrive::study

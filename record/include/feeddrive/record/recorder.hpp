#pragma once
// Assembles the rows of timeseries.csv from the messages of a run, in any arrival order, with
// duplicates ignored. Row k needs drive_state_t k, reference_t k, control_command_t k and the
// drive_state_t k+1 that carries what was applied during step k (or the end-of-run marker).
// In real-time runs (drive_state_t.realtime) a step may have no command of its own (it came too
// late, the plant applied the previous one): the row is then written once state k+2 (or the end)
// is there, with the command's diagnostic fields NaN; the applied u always comes from the plant.
// Pure logic, no I/O: used by the live monitor and by the log converter alike. Complete rows are
// handed to a sink and not kept, and the latency statistics are bounded histograms
// (feeddrive/common/quantile.hpp): memory holds only the steps in flight, whatever the length
// of the run.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "feeddrive/common/quantile.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_t.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace feeddrive::record {

/// One message a row is waiting for.
struct Missing {
  std::string what;  ///< "state", "reference" or "command"
  std::string role;  ///< who publishes it: "plant", "trajectory", "controller"
  std::int64_t seq;
};

/// Steps first..last (inclusive) that have no row: `why` names the first message missing.
struct Gap {
  std::int64_t first{0};
  std::int64_t last{0};
  std::string why;
  std::int64_t steps() const { return last - first + 1; }
};

/// "12 steps missing: 3000 (no command 3000 from the controller), 3500-3510 (...)": the gaps
/// as one line, at most `max_listed` of them (then "and N more").
std::string describe_gaps(const std::vector<Gap>& gaps, std::size_t max_listed = 5);

class Recorder {
 public:
  /// attach = false: rows start at step 0 and a gap is never skipped. attach = true: rows start
  /// at the first step whose state and reference can both have been seen, max(first state,
  /// first reference) (joining a running system or a log mid-way).
  /// whole_log (attach only): the messages come from a recording (a log file, in the order its
  /// recorder received them, re-published ones late): the first row is chosen at the first
  /// flush() or flush_final() from the lowest state and reference steps seen so far, not from
  /// the first ones (read_log flushes every 4096 events).
  explicit Recorder(bool attach = false, bool whole_log = false) : attach_(attach), whole_log_(attach && whole_log) {}

  void on_state(const drive_state_t& m, std::int64_t recv_us);
  void on_reference(const reference_t& m, std::int64_t recv_us);
  void on_command(const control_command_t& m, std::int64_t recv_us);

  /// Hands every complete row, in order, to `sink`; returns how many.
  std::size_t flush(const sim::RecordSink& sink);

  /// The end of a recorded log: no message will come any more. Records every step that can be
  /// completed, skipping the ones that cannot (they go to gaps()): a step needs state k, state
  /// k+1 (the input applied during k) and, if need_reference, reference k; a missing command
  /// only costs the command's diagnostic fields (NaN; the applied u is in state k+1). With
  /// need_reference = false a missing reference gives NaN xd, vd, ad, jd. The end of the run
  /// is the step count most states carry (one corrupt message cannot move it); steps after the
  /// last message are a gap too. Returns the rows added.
  std::size_t flush_final(const sim::RecordSink& sink, bool need_reference = true);
  /// Live, attach mode: step next() will never be complete (its messages were lost and no one
  /// re-sends them any more) but later steps are in. Records it as flush_final() would (a
  /// missing command costs only its diagnostic fields), or skips it and the steps that cannot
  /// start to the next state received, as a gap; then flushes what follows. Returns the rows
  /// added. Nothing after it yet: nothing is skipped (the step is late, not lost).
  std::size_t skip_lost(const sim::RecordSink& sink);
  /// The steps flush_final() could not record, in order.
  const std::vector<Gap>& gaps() const { return gaps_; }
  /// Sum of gaps()' steps.
  std::int64_t missing_steps() const;

  std::int64_t next() const { return next_; }    ///< first step not recorded
  std::int64_t steps() const { return steps_; }  ///< steps of the run (-1 until known)
  std::int64_t highest_state() const { return highest_state_; }
  bool end_seen() const { return end_seen_; }
  bool complete() const { return end_seen_ && next_ >= steps_; }
  /// Attach mode: whether the first row's step is chosen (messages before it are dropped).
  bool started() const { return !attach_ || started_; }
  /// What row next() is waiting for.
  std::vector<Missing> missing() const;
  /// The messages that steps next()..upto still lack, oldest first, at most `per_kind` states,
  /// commands and references each, looking at most 4096 steps ahead: states up to `upto`,
  /// commands below it (real time: none, a step may run without one), and one reference per
  /// block of 16 (a publisher re-sends the whole block). What a monitor asks for again.
  std::vector<Missing> missing_until(std::int64_t upto, std::size_t per_kind) const;

  std::int64_t rows() const { return rows_; }  ///< rows handed out so far
  std::int64_t duplicates() const { return duplicates_; }
  /// Steps per second of the run between the first and the newest state received (0 if < 2).
  double steps_per_second() const;
  std::int64_t commandless_rows() const { return commandless_; }  ///< real time: steps without a command
  /// The latest counters the plant reported.
  std::int64_t rejected_commands() const { return rejected_; }
  std::int64_t missed_deadlines() const { return missed_; }
  /// Real time: periods the plant started more than its guard late (drive_state_t.overruns).
  std::int64_t plant_overruns() const { return overruns_; }
  bool safe_state() const { return safe_state_; }

  /// Per-hop latencies from receive times [us]: state k -> command k, command k -> state k+1.
  const stats::StreamingQuantile& latency_state_to_command() const { return lat_sc_; }
  const stats::StreamingQuantile& latency_command_to_state() const { return lat_cs_; }
  /// How long before state k its reference k arrived [us]: the trajectory's lead. Negative:
  /// the reference came after the state, and the step waited for it.
  const stats::StreamingQuantile& reference_lead() const { return lead_; }

 private:
  template <typename Msg>
  struct Seen {
    Msg msg;
    std::int64_t recv_us;
  };
  bool attach_;
  bool whole_log_;
  std::int64_t next_{0};
  bool started_{false};
  std::int64_t steps_{-1};
  std::int64_t highest_state_{-1};
  bool end_seen_{false};
  std::map<std::int64_t, Seen<drive_state_t>> states_;
  std::map<std::int64_t, Seen<reference_t>> refs_;
  std::map<std::int64_t, Seen<control_command_t>> cmds_;
  std::int64_t rows_{0};
  std::int64_t duplicates_{0};
  std::int64_t commandless_{0};
  std::vector<Gap> gaps_;
  std::map<std::int64_t, long> steps_votes_;  ///< how many states carried each step count
  /// What advance() did with step next_.
  enum class Advance { kRow, kGap, kWait, kEnd };
  /// Records step next_ if its states (and, if need_reference, its reference) are in; else
  /// skips to the next step that may start and records the gap. With nothing after it:
  /// ended = true skips to the end of the run (kEnd), ended = false leaves it (kWait).
  Advance advance(const sim::RecordSink& sink, bool need_reference, bool ended);
  void add_gap(std::int64_t first, std::int64_t last, const std::string& why);
  void add_row(const Seen<drive_state_t>& s, const reference_t* r, const control_command_t* c, const drive_state_t& s1,
               const sim::RecordSink& sink);
  std::int64_t first_state_seq_{-1}, first_state_us_{0}, last_state_us_{0};
  std::int64_t first_ref_seq_{-1};
  void maybe_start();
  std::int64_t rejected_{0};
  std::int64_t missed_{0};
  std::int64_t overruns_{0};
  bool safe_state_{false};
  stats::StreamingQuantile lat_sc_, lat_cs_, lead_;
};

}  // namespace feeddrive::record

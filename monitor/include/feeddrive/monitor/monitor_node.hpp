#pragma once
// The monitor process: subscribes to every channel of a run, records every step (asking for
// what it missed), acknowledges recorded steps (the plant's flow control), prints a live
// progress line, and writes DIR/timeseries.csv and DIR/summary.json in feeddrive-sim's format
// plus the lockstep statistics. Ends when the run ends, a role fails, or a role stops answering;
// in every case it writes what it recorded and says where the run stopped.
//
// attach = true joins a running system or a log played back by lcm-logplayer: it records from
// the first state it sees and asks for what it missed like the run's monitor, but it does not
// acknowledge (the plant's flow control stays with the run's own monitor) and it is an observer:
// its failure never stops the run (service::is_run_role). A step it cannot get any more (asked
// for kLostAfterRequests times over kLostAfter_s while later states come in: the publishers no
// longer keep it) is skipped and reported as a gap, as feeddrive-log2csv does; when nothing
// comes for --step-timeout (the run or the played-back log is over) it records what it can and
// ends.

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/monitor/histogram.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/record/lcm_log.hpp"
#include "feeddrive/record/recorder.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/run_summary_t.hpp"
#include "feeddrive/service/loggers.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/output.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::monitor {

struct MonitorOptions {
  std::string out_dir;
  bool plots{true};
  bool attach{false};
  double progress_interval_s{0.5};
  /// Where the progress line goes, every progress_interval_s (not with --quiet): `line` without
  /// a line end; `last` for the run's final one. The tool draws it (feeddrive-monitor: stderr,
  /// each line over the one before); unset: no progress line. This library prints nothing.
  std::function<void(const std::string& line, bool last)> progress;
  /// If set: every message of the run received on the bus (channels <prefix>_*, re-published
  /// ones included) also goes to this file, in the standard LCM log format (lcm_log.hpp), with
  /// the kernel's receive time: what lcm-logger writes, without another process on the group.
  std::string lcm_log;
};

class MonitorNode : public service::Node {
 public:
  /// Opens the output (staged folder, timeseries.csv) at once: rows are written as they complete.
  /// `shared_lcm`: see service::Node (in-process tests); nullptr in the process.
  MonitorNode(const sim::Scenario& s, const service::NodeOptions& opt, const MonitorOptions& mopt,
              lcm_t* shared_lcm = nullptr);
  /// Returns true if the run completed and its results were written; tries to write the
  /// results in every case.
  bool run();
  /// The run was stopped because its record cannot fit the disk (bad input: the tool exits 2).
  bool record_too_big() const { return too_big_; }
  const run_summary_t& summary() const { return summary_; }

 private:
  void request_missing();
  /// Attach mode, no row for a while: skips a step lost for good, or ends when nothing comes.
  /// Returns true when the recording is over.
  bool attached_stalled(std::int64_t now, double limit);
  void publish_info();
  /// Names the senders of what the bus drops (service::BusEvents), one line per sender and kind,
  /// and fails the run (failure_, checked in run()) when a run role cannot take part: an older
  /// contract, run id 0, unsigned in a keyed run, a restarted plant.
  void on_foreign(const std::string& channel, std::int64_t run_id, const std::string& role);
  void on_unauthenticated(const std::string& channel, const std::uint8_t* d, std::size_t n);
  void on_undecodable(const std::string& channel, const std::uint8_t* d, std::size_t n, const std::string& why);
  void check_peer_status(const process_status_t& m);
  void plant_went_back(const process_status_t& m);
  bool plant_step_implausible(std::int64_t seq) const;
  /// Fails the run with `why` when `role` is one of the run's (an observer is only named) and,
  /// with unless_role_alive, no admitted process of that role was heard within the last second.
  void fail_for(const std::string& role, const std::string& why, bool unless_role_alive = true);
  void on_state_timing(const drive_state_t& m, std::int64_t t);
  void on_command_timing(const control_command_t& m, std::int64_t t);
  void prune_timing(std::int64_t seq);
  void progress(bool force);
  /// Once a second: looks for stock loggers on the bus (service::stock_loggers_on) and measures
  /// the step rate of the last second (the peak is what a logger had to keep up with).
  void watch_rate_and_loggers(std::int64_t now);
  // --- construction: what the monitor listens to ---
  /// Subscribes to the run's state, reference and command channels (each through the conflict check).
  void subscribe_run_channels();
  /// A state of the run: admitted (service::Node::admit), what the plant applied, then recorded and timed.
  void on_state(const drive_state_t& m, std::int64_t t);
  /// A command of the run: its sender noted, admitted (a conflict keeps both commands and who
  /// sent them, then rethrows), then recorded and timed.
  void on_command(const control_command_t& m, std::int64_t t);
  /// The local process behind a source "IP:PORT" (its UDP port's owner in /proc), looked up
  /// once per source, at most 16, when the source is first heard: on a participant's first
  /// heartbeat, long before its commands (one socket sends both). A process that has exited by
  /// the time a conflict is judged can no longer be found (CI, stop 29: the controller whose
  /// command 0 met a forged one had exited before a loaded monitor read its backlog).
  void note_source(const std::string& source);
  static std::string process_on_source(const std::string& source);
  /// --lcm-log: opens the LCM log and taps the bus so that every message of the run goes to it.
  void open_lcm_log(const service::NodeOptions& opt);
  /// The run's self-description (run_info_t), published on heartbeats and on request; not when attached.
  void serve_run_info(const service::NodeOptions& opt);
  /// The bus events (foreign, unauthenticated, undecodable) and the peers' heartbeats, routed to their checks.
  void watch_bus_events();

  // --- the run ---
  /// The recorder's completed rows go to the output; returns how many.
  std::size_t flush_rows();
  /// The steps the run is expected to have (the plant's end-of-run count once known, else the scenario's).
  std::int64_t steps_expected() const;
  /// Records until the run is complete; throws service::RunFailure when it cannot go on.
  void record_until_end();
  /// record_until_end(), at SCHED_FIFO 78 for a real-time run's own monitor, normal again after.
  void record_in_real_time_if_asked();
  /// Heartbeat with the step recorded; the run's own monitor acknowledges it (the plant's flow control).
  void heartbeat_progress();
  /// No row for `limit`: waits for a role that still beats (it names the culprit), else throws
  /// service::RunFailure naming the silent roles and what they did not send.
  void check_step_timeout(std::int64_t now, double limit);
  /// After a failure: waits briefly for the state that settles a command conflict, then records
  /// what is still queued on the socket; returns `failure` with the applied command appended.
  std::string record_after_failure(std::string failure);
  /// Closes the LCM log after the run; returns `failure`, or the log's write error when there was none.
  std::string close_lcm_log(std::string failure);

  // --- the end ---
  /// What every process of the run counted (the monitor's own counts plus the peers' heartbeats).
  struct BusCounts {
    std::int64_t resends{0}, duplicates{0}, invalid{0}, foreign{0}, conflicts{0}, unauthenticated{0};
  };
  BusCounts bus_counts();
  /// The latency histograms recorded (period_start_lateness only in real time) and their names.
  struct LatencyHistograms {
    std::vector<std::string> names;
    std::vector<Histogram> h;
  };
  LatencyHistograms latency_histograms() const;
  /// Fills summary_ (run_summary_t, published at the end) from the run's summary and counts.
  void fill_summary(bool completed, const std::string& failure, const sim::Summary& sum, double wall_time_s,
                    const BusCounts& c);
  /// summary.json's "lockstep" object: the counts, the conflict, the rates and the latencies.
  nlohmann::ordered_json lockstep_json(bool completed, const std::string& failure, const sim::Summary& sum,
                                       double wall_time_s, const BusCounts& c, const LatencyHistograms& hists);
  /// The bytes of one step on the wire (state, command, a 16th of a reference block; with the mac if keyed).
  int bytes_per_step();
  /// "stock_loggers": the stock loggers seen and whether the steps went out faster than they record
  /// (warned about then).
  nlohmann::ordered_json stock_loggers_json(const sim::Summary& sum, double wall_time_s) const;
  /// "latency_us", "reference_lead_us" and "latency_histogram_us" into `l` (NaN quantiles as null).
  void add_latency_json(nlohmann::ordered_json& l, const LatencyHistograms& hists);
  /// Writes the output folder; on failure says why, returns false and marks the run not completed
  /// (`completed`, `why`, summary_). `where` becomes the folder the record went to.
  /// `write_error`: the writer could not write the rows (then nothing more is tried).
  bool write_results(const sim::Summary& sum, const std::string& write_error, const std::string& lockstep,
                     const LatencyHistograms& hists, bool& completed, std::string& why, std::string& where);
  /// Writes the results and announces the end; false if the results could not be written.
  bool finish(bool completed, const std::string& failure);
  /// latency_histogram.csv (and .png when `plot`; a gnuplot failure is a warning) into the
  /// staged output folder `dir`.
  void write_histograms(const output::StagedFolder& dir, const std::vector<std::string>& names,
                        const std::vector<Histogram>& h, bool plot) const;

  sim::Scenario s_;
  MonitorOptions mopt_;
  bool too_big_{false};
  record::Recorder rec_;
  std::unique_ptr<sim::RunWriter> out_;
  /// options().stop, renewed once the first interrupt is handled (the record is still written; a
  /// second signal stops that too).
  interrupt::StopToken stop_;
  run_summary_t summary_{};
  run_info_t info_;
  std::int64_t heartbeats_{0};
  std::string failure_;  ///< set by the bus events: the run cannot go on (run() throws it)

  /// When things last happened (mono_us).
  struct Clocks {
    std::int64_t start{0};
    std::int64_t last_row{0};         ///< a row was completed
    std::int64_t last_request{0};     ///< resends were asked for
    std::int64_t last_progress{0};    ///< the progress line was printed
    std::int64_t last_file_flush{0};  ///< the record went to its file
    std::int64_t last_state{0};       ///< attach mode: a state arrived
  } when_;

  /// Acknowledgements and resend requests.
  struct Asking {
    std::int64_t last_ack_sent{-1};
    std::int64_t lost{0};  ///< messages asked for again
    // Attach mode: the step whose messages are being asked for, since when and how often.
    std::int64_t seq{-1}, since_us{0}, requests{0};
  } asking_;
  static constexpr int kLostAfterRequests = 50;
  static constexpr double kLostAfter_s = 0.5;

  /// For conflicts (service::Node::admit).
  struct Ledgers {
    service::StepLedger<drive_state_t> state;
    service::StepLedger<reference_t> reference;
    service::StepLedger<control_command_t> command;
  } ledgers_;

  /// The first command of each recent step and who sent it ("IP:PORT"), to name the two sides of
  /// a command conflict (a ring indexed by step, like the ledger).
  struct SentCommand {
    std::int64_t seq{-1};
    double u{0.0};
    std::string sender;
  };
  /// A command conflict (two different commands for one step: a forged one raced the
  /// controller's): both, and the one the plant applied (its state k+1's previous.u), once known.
  struct CommandConflict {
    std::int64_t step{-1};
    SentCommand first, second;
    bool applied_known{false};
    double applied_u{0.0};
    /// Whether the plant applied the first command (the nearer one: the plant may clip it).
    bool applied_first() const { return std::abs(applied_u - first.u) <= std::abs(applied_u - second.u); }
  };
  /// "command_conflict": the step, both commands and their senders, and the one the plant applied.
  static nlohmann::ordered_json command_conflict_json(const CommandConflict& c);
  /// "the plant applied u = ... from ..." for the failure line and summary.json, or "".
  std::string applied_command_text() const;
  /// What is known of the commands, to judge a command conflict.
  struct Commands {
    std::vector<SentCommand> first = std::vector<SentCommand>(4096);
    std::optional<CommandConflict> conflict;
    /// What the plant applied over each recent step (its next state's `previous`), a ring by
    /// step: the state can come before the second command of a conflict does.
    std::vector<std::pair<std::int64_t, double>> applied =
        std::vector<std::pair<std::int64_t, double>>(4096, {-1, 0.0});
    std::map<std::string, std::string> source_process;  ///< source "IP:PORT" -> local process (note_source)
  } commands_;

  /// What the bus events named, to name each once and judge who fills a role.
  struct Named {
    std::map<std::string, std::int64_t> count;  ///< what was named already (one line per sender and kind) -> count
    std::map<std::string, std::int64_t> first_unauthenticated_us;  ///< per channel and role (mono_us)
    /// When each role's own (decoded, authenticated, admitted) message last came [mono us].
    std::map<std::string, std::int64_t> last_admitted_us;
    std::int64_t plant_seq_seen{-1};  ///< the highest step of the plant's heartbeats
  } named_;

  /// --lcm-log.
  struct LcmLog {
    std::unique_ptr<record::LcmLogWriter> writer;
    std::string error;  ///< the first write error of the LCM log (ends the run)
  } log_;

  /// The step rate and the stock loggers on the bus.
  struct RateWatch {
    std::vector<service::StockLogger> loggers;  ///< stock loggers seen on the bus during the run
    std::int64_t since_us{-1}, since_step{0};
    double peak{0.0};  ///< the most steps per second recorded in one window of >= 1 s
  } rate_;

  /// The latency histograms and the first receive times of the steps in flight.
  struct Timing {
    explicit Timing(double bin_us)
        : state_to_command(bin_us, 40), command_to_state(bin_us, 40), start_lateness(bin_us, 40) {}
    Histogram state_to_command, command_to_state, start_lateness;
    std::map<std::int64_t, std::int64_t> state_recv, command_recv;
    std::int64_t pruned{-1};  ///< steps <= this are no longer timed
  } timing_;
};

}  // namespace feeddrive::monitor

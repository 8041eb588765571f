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

#include <functional>
#include <map>
#include <memory>
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
  std::string open_error_;  // why out_ could not be opened
  std::int64_t start_us_{0};
  std::int64_t last_row_us_{0};
  std::int64_t last_request_us_{0};
  std::int64_t last_progress_us_{0};
  std::int64_t last_ack_sent_{-1};
  std::int64_t lost_{0};
  // Attach mode: the step whose messages are being asked for, since when and how often.
  static constexpr int kLostAfterRequests = 50;
  static constexpr double kLostAfter_s = 0.5;
  std::int64_t asking_seq_{-1}, asking_since_us_{0}, asking_requests_{0};
  std::int64_t last_state_us_{0};  ///< attach mode: when the last state arrived (mono_us)
  run_summary_t summary_{};
  service::StepLedger<drive_state_t> state_ledger_;  ///< for conflicts (service::Node::admit)
  service::StepLedger<reference_t> reference_ledger_;
  service::StepLedger<control_command_t> command_ledger_;
  /// The first command of each recent step and who sent it ("IP:PORT"), to name the two sides of
  /// a command conflict (a ring indexed by step, like the ledger).
  struct SentCommand {
    std::int64_t seq{-1};
    double u{0.0};
    std::string sender;
  };
  std::vector<SentCommand> first_commands_ = std::vector<SentCommand>(4096);
  /// A command conflict (two different commands for one step: a forged one raced the
  /// controller's): both, and the one the plant applied (its state k+1's previous.u), once known.
  struct CommandConflict {
    std::int64_t step{-1};
    SentCommand first, second;
    bool applied_known{false};
    double applied_u{0.0};
  };
  std::optional<CommandConflict> command_conflict_;
  /// What the plant applied over each recent step (its next state's `previous`), a ring by step:
  /// the state can come before the second command of a conflict does.
  std::vector<std::pair<std::int64_t, double>> applied_ = std::vector<std::pair<std::int64_t, double>>(4096, {-1, 0.0});
  /// When each role's own (decoded, authenticated, admitted) message last came [mono us].
  std::map<std::string, std::int64_t> last_admitted_us_;
  /// "the plant applied u = ... from ..." for the failure line and summary.json, or "".
  std::string applied_command_text() const;
  run_info_t info_;
  std::unique_ptr<record::LcmLogWriter> log_;
  std::string log_error_;  ///< the first write error of the LCM log (ends the run)
  std::int64_t heartbeats_{0};
  Histogram hist_sc_, hist_cs_, hist_late_;
  std::string failure_;                        ///< set by the bus events: the run cannot go on (run() throws it)
  std::map<std::string, std::int64_t> named_;  ///< what was named already (one line per sender and kind) -> count
  std::int64_t plant_seq_seen_{-1};            ///< the highest step of the plant's heartbeats
  std::map<std::string, std::string> source_process_;             ///< command source "IP:PORT" -> local process
  std::map<std::string, std::int64_t> first_unauthenticated_us_;  ///< per channel and role (mono_us)
  std::int64_t last_file_flush_us_{0};                            ///< when the record last went to its file (mono_us)
  std::vector<service::StockLogger> loggers_;                     ///< stock loggers seen on the bus during the run
  std::int64_t rate_since_us_{-1}, rate_since_step_{0};
  double peak_rate_{0.0};  ///< the most steps per second recorded in one window of >= 1 s
  std::map<std::int64_t, std::int64_t> state_recv_, cmd_recv_;  ///< first receive times of the steps in flight
  std::int64_t timing_pruned_{-1};                              ///< steps <= this are no longer timed
};

}  // namespace feeddrive::monitor

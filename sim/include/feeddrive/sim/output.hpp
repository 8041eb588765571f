#pragma once
// Writing a run's results as the run goes: DIR/timeseries.csv (streamed), DIR/summary.json and
// PNG plots (gnuplot). The folder is checked, staged and swapped into place by
// feeddrive::output::StagedFolder (output/folder.hpp): DIR is never half-written, and only an
// earlier feeddrive output (or an empty folder) is replaced. Check --out before the run with
// feeddrive::output::check_output_dir, and the run's size with check_run_size.
//
// Memory does not grow with the run: each record goes to the CSV (every output.every-th row,
// the output.columns), to the online summary (SummaryBuilder) and to the plot reduction
// (output::MinMaxReducer, kPlotBuckets min/max pairs per curve), and is dropped. feeddrive-sim
// and feeddrive-monitor both write through RunWriter, so the same records give the same bytes.
//
// Off the critical path: add() only copies the record into a block of kBlockRows; full blocks
// go, in order, to one writer thread that formats and writes them (at most kQueuedBlocks
// waiting, so memory stays bounded and a slow disk slows the run instead of filling memory).
// On a machine with a free core the output costs the simulation nothing but the copy.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "feeddrive/output/csv.hpp"
#include "feeddrive/output/folder.hpp"
#include "feeddrive/output/plot_reduce.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::sim {

/// Buckets of the plot reduction: two per pixel column of the 1000-pixel-wide plots.
inline constexpr std::size_t kPlotBuckets = 2000;

/// Throws std::invalid_argument (one line naming the keys and the figure; the tools exit 2) if
/// timeseries.csv cannot fit: rows x columns x 2 bytes (the least a value takes, a digit and a
/// separator) above the free space of the file system that will hold out_dir. Call after
/// output::check_output_dir, before any work. `max_steps`: a bound of the record's own where it
/// can be shorter than the scenario (a log holds what it holds). RunWriter checks again on the
/// first rows' real size.
void check_run_size(const Scenario& s, const std::string& out_dir,
                    double max_steps = std::numeric_limits<double>::infinity());

class RunWriter {
 public:
  /// Creates the staged folder (marked as written by `tool`) and starts timeseries.csv.
  /// Throws std::invalid_argument if out_dir must not be replaced, std::runtime_error if it
  /// cannot be written.
  /// `stop` ends the plots (interrupt::Interrupted, see keep_data_on_interrupt).
  RunWriter(const std::string& out_dir, const Scenario& s, const std::string& tool,
            const interrupt::StopToken& stop = {});
  ~RunWriter();

  static constexpr std::size_t kBlockRows = 4096;
  static constexpr std::size_t kQueuedBlocks = 4;

  /// One record, in step order. Rethrows a write error of the writer thread, and
  /// std::invalid_argument once the first kProjectAfterRows rows show that the run's CSV
  /// (expected_steps() rows, default the scenario's) cannot fit the free disk.
  void add(const Record& r);
  static constexpr std::uint64_t kProjectAfterRows = 1000;
  /// A record that cannot be made again (the monitor's): a Ctrl-C while the plots are drawn
  /// skips them and the data are still put in place (plot_error() says so; the interrupt flag
  /// stays set for the caller). Otherwise (feeddrive-sim) the interrupt ends finish() unwritten.
  void keep_data_on_interrupt(bool keep) { keep_on_interrupt_ = keep; }
  /// How many steps the record will have (a log's own bound where it is shorter than the scenario).
  void set_expected_steps(double steps) { expected_steps_ = steps; }
  /// Has every row added so far written to timeseries.csv's file now (not only when a block of
  /// kBlockRows fills): the monitor calls it every second, so a SIGKILL loses at most a second
  /// of its record (the launcher rescues the staged folder). Rethrows a write error.
  void flush();
  long steps() const { return added_; }
  /// The most recent record (undefined before the first add).
  const Record& last() const { return last_; }
  /// The summary of every record added so far (waits until the writer thread has them all).
  /// `integrator`: none ({}) where the plant ran in another process (its counts are then null).
  Summary summary(double wall_time_s, const std::optional<plant::CvodeIntegrator::Stats>& integrator);

  /// Closes timeseries.csv, writes summary.json (`sum` plus the keys of the JSON object
  /// extra_json) and the plots (when asked and there is at least one record), and swaps the
  /// folder into place. On failure the previous output is kept and the staged folder removed.
  /// `extra_files` (if given) writes the caller's own files into the staged folder first.
  /// `replace_earlier` false (an incomplete record): an earlier output in out_dir is kept and
  /// the record goes beside it, to "out_dir.incomplete-N" (StagedFolder::commit_keeping_earlier).
  /// Returns the folder the results went to.
  std::filesystem::path finish(const Summary& sum, bool plots, const std::string& extra_json = "",
                               const std::function<void(const output::StagedFolder&)>& extra_files = {},
                               bool replace_earlier = true);
  /// Wall time finish() spent on the plots [s] (0 without plots).
  double plot_seconds() const { return plot_seconds_; }
  /// Why the plots could not be drawn ("" if they were or were not asked for); the data were
  /// written all the same.
  const std::string& plot_error() const { return plot_error_; }
  /// What finish() could not do although the results are in place (the previous output not
  /// removed: StagedFolder::commit), one line each, for the caller to log; this library prints
  /// nothing.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  const Scenario& s_;
  output::StagedFolder folder_;
  std::unique_ptr<output::CsvWriter> csv_;
  std::vector<std::size_t> columns_;  // indices into record_columns()
  long every_;
  double expected_steps_;
  bool keep_on_interrupt_{false};
  std::vector<std::string> warnings_;
  interrupt::StopToken stop_token_;
  SummaryBuilder summary_;
  output::MinMaxReducer plot_;
  double plot_seconds_{0.0};
  std::string plot_error_;

  void check_projected_size() const;  // the writer thread, after kProjectAfterRows rows

  // the caller's side
  std::vector<Record> block_;
  long added_{0};
  Record last_;
  void submit();  // hands block_ to the writer thread
  void drain();   // submits block_ and waits until the writer thread has written everything

  // the writer thread: write() runs there, in order
  void work();
  void write(const Record& r);
  long written_{0};
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<std::vector<Record>> queue_;
  std::vector<std::vector<Record>> spare_;  // emptied blocks, reused
  bool busy_{false}, stop_{false}, flush_pending_{false};
  std::exception_ptr error_;
  std::thread worker_;
};

/// Plots position+error, velocity error, control and forces into the staged folder (position.png,
/// velocity_error.png, control.png, forces.png, plots.gp) from its reduced plot data plot.csv.
/// `title` is any text (it goes through output::gnuplot_string). Throws on failure.
void write_plots(const output::StagedFolder& dir, const output::MinMaxReducer& reduced, const std::string& title,
                 const interrupt::StopToken& stop);

}  // namespace feeddrive::sim

#pragma once
// One run of feeddrive-study: load and resolve the study, reuse the finished cases of the output
// folder, run the rest on all cores (and all MPI ranks), write results.csv, report.md and plots.
//
// The output folder (feeddrive::output rules): --out DIR is checked before any work; a DIR that
// is absent, empty or the output of another feeddrive tool becomes a new, marked feeddrive-study
// folder; a feeddrive-study folder is reused: DIR/cases/<hash>.json holds each finished case,
// keyed by the SHA-256 of its resolved scenario (cases.hpp), so a rerun skips exactly the cases
// whose scenario is unchanged. Every file is written atomically (a temporary file renamed into
// place), so an interrupted run loses at most the cases that were running.

#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/study/transport.hpp"

namespace feeddrive::study {

struct Options {
  std::string study;                ///< the study file, or with `sweeps` the scenario file
  std::vector<std::string> sets;    ///< --set KEY=VALUE: every case, after the study's own set
  std::vector<std::string> sweeps;  ///< --sweep: the grid of a study without a study file (spec.hpp parse_sweep)
  std::string out;
  int jobs{0};  ///< worker threads of this process; 0: every core it may use (per MPI rank: shared)
  bool quiet{false};
  bool plots{true};
  bool retry_failed{false};   ///< run again the cases that failed in an earlier run
  bool list{false};           ///< only resolve and print the cases
  std::string command;        ///< the command line, for report.md
  interrupt::StopToken stop;  ///< polled by the study and its cases (Ctrl-C in the tool; the default never stops)
};

/// The cores this process may run on (sched_getaffinity), at least 1.
int available_cores();

/// What run_study tells while it runs; the tool prints it (the library never prints).
class Reporter {
 public:
  virtual ~Reporter() = default;
  /// --list: the number of cases, then one line per case ("INDEX HASH CONTROLLER FAMILY KEY=VALUE...").
  virtual void listed(const std::string& line) = 0;
  /// The run starts: "NAME: N cases on J threads x R ranks -> DIR".
  virtual void started(const std::string& line) = 0;
  /// The cases are about to run: total, of which none done yet.
  virtual void progress_start(std::size_t total) = 0;
  /// A case got its row: reused from an earlier run, or run here (failed or not).
  virtual void progress_step(bool reused, bool failed) = 0;
  virtual void progress_end() = 0;
  /// Something went wrong that does not fail the study (the plots not drawn).
  virtual void warning(const std::string& line) = 0;
};

/// What a finished study did (the tool's last line).
struct StudyResult {
  std::string name;
  std::size_t total{0}, ran{0}, reused{0}, failed{0};
  std::string dir;  ///< empty after --list
  /// The loader's warnings, once each with the number of cases that have it (warning_lines),
  /// and the cases with a move, of which moves_unfinished were cut off by duration.
  std::vector<std::string> warnings;
  std::size_t moves{0}, moves_unfinished{0};
};

/// Runs the study as the only process, or as rank 0 of an MPI job. Throws, after telling the
/// other ranks (Transport::broadcast / abort with the same exit code): BadInput (a bad study,
/// option or output folder: exit 2), std::runtime_error (a failure of the machine, e.g. writing
/// the folder: 1), interrupt::Interrupted with what was kept (128 + signal). Failed cases are not
/// errors: they are in results.csv and StudyResult::failed.
StudyResult run_study(const Options& o, Transport* t, Reporter& reporter);

/// The other ranks of an MPI job: run the cases rank 0 hands out until it has none. Returns the
/// exit code rank 0 broadcast (2 when the study was bad).
int serve(Transport& t, int jobs, const interrupt::StopToken& stop);

}  // namespace feeddrive::study

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

#include "feeddrive/study/transport.hpp"

namespace feeddrive::study {

struct Options {
  std::string study;  ///< the study file, or with `sweeps` the scenario file
  std::vector<std::string> sets;    ///< --set KEY=VALUE: every case, after the study's own set
  std::vector<std::string> sweeps;  ///< --sweep: the grid of a study without a study file (spec.hpp parse_sweep)
  std::string out;
  int jobs{0};  ///< worker threads of this process; 0: every core it may use (per MPI rank: shared)
  bool quiet{false};
  bool plots{true};
  bool retry_failed{false};  ///< run again the cases that failed in an earlier run
  bool list{false};          ///< only resolve and print the cases
  std::string command;       ///< the command line, for report.md
};

/// The cores this process may run on (sched_getaffinity), at least 1.
int available_cores();

/// Runs the study as the only process, or as rank 0 of an MPI job. Returns the exit code:
/// 0 (done; failed cases are in results.csv), 2 (bad study, option or output folder), 1 (a
/// failure of the machine: writing the folder).
int run_study(const Options& o, Transport* t);

/// The other ranks of an MPI job: run the cases rank 0 hands out until it has none. Returns the
/// exit code rank 0 broadcast (2 when the study was bad).
int serve(Transport& t, int jobs);

}  // namespace feeddrive::study

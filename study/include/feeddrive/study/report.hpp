#pragma once
// A study's results: results.csv (one row per case: its parameters and every summary.json
// metric), report.md (tables) and the plots (gnuplot, through feeddrive::output's one escaping
// rule: no text from the study reaches a script unescaped, data files have fixed names).
//
// results.csv is a pure function of the study and the outcomes' metrics: numbers in their
// shortest round-trip form, nothing measured on the clock, so the same study gives the same bytes
// for any -j, any number of MPI ranks and a rerun that reuses finished cases.

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/runner.hpp"
#include "feeddrive/study/spec.hpp"

namespace feeddrive::study {

struct CaseRecord {
  CaseSpec spec;
  ResolvedCase resolved;  ///< hash empty if the case could not be resolved (its outcome says why)
  Outcome outcome;
  bool cached{false};  ///< reused from an earlier run into the same folder
};

/// results.csv, one row at a time in study order: case,controller,family,point,draw,hash,
/// <varied keys>,ok,error,move_finished,warnings,<every numeric summary.json metric but the
/// wall-clock ones>. move_finished is true/false, empty where the reference is not a move or the
/// case failed; warnings the case's loader warnings joined by "; ". The rows go
/// to DIR/results.csv.partial as the cases finish; finish() renames it into place. Nothing of a
/// case is kept after its row (a study has up to 10^6 cases).
class ResultsWriter {
 public:
  ResultsWriter(const Study& s, const std::filesystem::path& dir);
  ~ResultsWriter();  ///< removes the partial file unless finish() ran
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;
  void add(std::size_t index, const CaseRecord& c);
  void finish();

 private:
  const Study& s_;
  std::filesystem::path partial_, final_;
  std::vector<std::string> params_, metrics_;
  std::ofstream out_;
  bool done_{false};
};

/// `value` as a CSV field (quoted when it holds a comma, quote or line break).
std::string csv_field(const std::string& value);

/// What report.md and the plots need of the cases, gathered one case at a time in study order:
/// per case a few numbers (its controller, the report metric, each varied key as a float for the
/// plots and as a category index, for a key with values that are not numbers such as switching:
/// sgn, tanh: about 20 + 6 x keys bytes), the worst case of each controller with its parameters,
/// the first kListedFailures failed cases, and the distinct loader warnings with their case
/// counts. Not the cases' scenarios or metrics.
struct ReportData {
  static constexpr std::size_t kListedFailures = 100;
  /// Distinct warnings kept with their counts; the cases with others are only counted.
  static constexpr std::size_t kListedWarnings = 50;
  /// Categories kept per key (in order of first appearance); a key with more is a distribution.
  static constexpr std::size_t kMaxCategories = 50;
  struct Cell {
    std::vector<double> values;
    long failed{0};    ///< cases that failed (ok = false)
    long no_value{0};  ///< cases that ran but have no value of the metric (e.g. a settled metric of a run shorter than
                       ///< settled_after)
    long total{0};
    long passed{0};          ///< cases that pass (case_passes)
    long verdict_failed{0};  ///< cases that ran with a required verdict false or missing
  };
  struct Worst {
    bool any{false};
    std::size_t index{0}, family{0};
    double value{0.0};
    std::map<std::string, std::string> parameters;
  };
  struct Failure {
    std::size_t index, controller, family;
    std::string error;
  };
  /// The four control-signal figures of docs/scenario.md ("Control-signal quality").
  static constexpr std::array<const char*, 4> kSignalFigures{"control_step_rms_V", "control_direction_changes_per_s",
                                                             "force_hf_rms_N", "control_saturated_fraction"};
  /// Per controller: the worst (largest) of each signal figure over its cases, the cases without
  /// a value of it (failed, or not measurable), and the cases whose control_signal_within_limits
  /// is true, false or absent (a failed case: absent).
  struct Signal {
    std::array<double, 4> worst{NAN, NAN, NAN, NAN};
    std::array<long, 4> no_value{0, 0, 0, 0};
    long within{0}, outside{0}, unknown{0};
  };

  explicit ReportData(const Study& s);
  void add(std::size_t index, const CaseRecord& c);

  const Study& s;
  std::vector<std::string> params;        ///< varied_keys(s)
  std::vector<std::vector<Cell>> table;   ///< [family][controller]
  std::vector<std::uint32_t> controller;  ///< per case
  std::vector<double> shown;              ///< per case: the report metric x scale, NaN without one
  std::vector<float> x;           ///< per case, params.size() each: the varied keys' values (NaN if not a number)
  std::vector<Worst> worst;       ///< per controller
  std::vector<Signal> signal;     ///< per controller
  std::vector<Failure> failures;  ///< the first kListedFailures
  std::size_t cases{0}, failed{0}, cached{0};
  /// Per varied key: its values in order of first appearance (at most kMaxCategories; `more`
  /// set when there were more), and whether any of them is not a number.
  struct Categories {
    std::vector<std::string> values;
    bool more{false}, text{false};
  };
  std::vector<Categories> categories;  ///< per varied key
  std::vector<std::int16_t> category;  ///< per case, params.size() each: index in categories[p].values, -1 beyond
  std::map<std::string, std::size_t>
      warnings;                              ///< distinct loader warning -> cases with it (the first kListedWarnings)
  std::size_t cases_with_other_warnings{0};  ///< cases with a warning beyond those kept
  std::size_t moves{0};                      ///< cases that ran a move (move_finished true or false)
  std::size_t moves_unfinished{0};           ///< of those, cases whose move `duration` cut off
};

/// The report metric's name as a label: without its SI suffix (_m, _s, _mps, _N, _V, _Hz ...),
/// with the unit shown: "position_error_max_abs [um]".
std::string metric_label(const std::string& metric, const std::string& unit);

/// Whether the plot of key `key` has a logarithmic x-axis: its values were given log-spaced
/// (--sweep KEY=log:...), or they are all > 0 and span more than two decades.
bool log_axis(const Study& s, const std::string& key, const std::vector<double>& values);

/// The warnings of a study, one line each with its count ("<warning> (N of M cases)"), as
/// feeddrive-study prints them on stderr; empty if there are none.
std::vector<std::string> warning_lines(const ReportData& d);

/// The report's pass criterion (report.limit and report.require): the case ran, its shown metric
/// `shown` is a number and <= limit (when a limit is given), and every required verdict is 1
/// (true) in its metrics (a verdict the case lacks fails: an outcome of an older version).
bool case_passes(const Study& s, const Outcome& o, double shown);
/// Whether every verdict report.require names is 1 in the case's metrics.
bool verdicts_hold(const Study& s, const Outcome& o);

/// Writes the plots into `dir` (box.png, param_<i>.png, with their .dat files and plots.gp);
/// returns the markdown that shows them (paths relative to the study folder, under `prefix`).
std::string write_plots(const std::filesystem::path& dir, const std::string& prefix, const ReportData& d,
                        const interrupt::StopToken& stop = {});

/// report.md: counts, the verdict against report.limit, worst and median per family and
/// controller, the worst case of each controller with its parameters, the failed cases, and the
/// plots' markdown.
std::string report_md(const ReportData& d, const std::string& command, const std::string& plots_markdown);

}  // namespace feeddrive::study

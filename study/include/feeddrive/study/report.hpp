#pragma once
// A study's results: results.csv (one row per case: its parameters and every summary.json
// metric), report.md (tables) and the plots (gnuplot, through feeddrive::output's one escaping
// rule: no text from the study reaches a script unescaped, data files have fixed names).
//
// results.csv is a pure function of the study and the outcomes' metrics: numbers in their
// shortest round-trip form, nothing measured on the clock, so the same study gives the same bytes
// for any -j, any number of MPI ranks and a rerun that reuses finished cases.

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
/// <varied keys>,ok,error,<every numeric summary.json metric but the wall-clock ones>. The rows go
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
/// plots: about 20 + 4 x keys bytes), the worst case of each controller with its parameters, and the
/// first kListedFailures failed cases. Not the cases' scenarios or metrics.
struct ReportData {
  static constexpr std::size_t kListedFailures = 100;
  struct Cell {
    std::vector<double> values;
    long failed{0};    ///< cases that failed (ok = false)
    long no_value{0};  ///< cases that ran but have no value of the metric (e.g. a settled metric of a run shorter than settled_after)
    long total{0};
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

  explicit ReportData(const Study& s);
  void add(std::size_t index, const CaseRecord& c);

  const Study& s;
  std::vector<std::string> params;              ///< varied_keys(s)
  std::vector<std::vector<Cell>> table;         ///< [family][controller]
  std::vector<std::uint32_t> controller;        ///< per case
  std::vector<double> shown;                    ///< per case: the report metric x scale, NaN without one
  std::vector<float> x;                         ///< per case, params.size() each: the varied keys' values (NaN if not a number)
  std::vector<Worst> worst;                     ///< per controller
  std::vector<Failure> failures;                ///< the first kListedFailures
  std::size_t cases{0}, failed{0}, cached{0};
};

/// Writes the plots into `dir` (box.png, param_<i>.png, with their .dat files and plots.gp);
/// returns the markdown that shows them (paths relative to the study folder, under `prefix`).
std::string write_plots(const std::filesystem::path& dir, const std::string& prefix, const ReportData& d,
                        const interrupt::StopToken& stop = {});

/// report.md: counts, the verdict against report.limit, worst and median per family and
/// controller, the worst case of each controller with its parameters, the failed cases, and the
/// plots' markdown.
std::string report_md(const ReportData& d, const std::string& command, const std::string& plots_markdown);

}  // namespace feeddrive::study

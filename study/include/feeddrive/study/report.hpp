#pragma once
// A study's results: results.csv (one row per case: its parameters and every summary.json
// metric), report.md (tables) and the plots (gnuplot, through feeddrive::output's one escaping
// rule: no text from the study reaches a script unescaped, data files have fixed names).
//
// results.csv is a pure function of the study and the outcomes' metrics: numbers in their
// shortest round-trip form, nothing measured on the clock, so the same study gives the same bytes
// for any -j, any number of MPI ranks and a rerun that reuses finished cases.

#include <filesystem>
#include <string>
#include <vector>

#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/runner.hpp"
#include "feeddrive/study/spec.hpp"

namespace feeddrive::study {

struct CaseRecord {
  CaseSpec spec;
  ResolvedCase resolved;
  Outcome outcome;
  bool cached{false};  ///< reused from an earlier run into the same folder
};

/// results.csv: case,controller,family,point,draw,hash,<varied keys>,ok,error,<metrics>.
std::string results_csv(const Study& s, const std::vector<CaseRecord>& cases);

/// `value` as a CSV field (quoted when it holds a comma, quote or line break).
std::string csv_field(const std::string& value);

/// Writes the plots into `dir` (box.png, param_<i>.png, with their .dat files and plots.gp);
/// returns the markdown that shows them (paths relative to the study folder, under `prefix`).
std::string write_plots(const std::filesystem::path& dir, const std::string& prefix, const Study& s,
                        const std::vector<CaseRecord>& cases);

/// report.md: counts, the verdict against report.limit, worst and median per family and
/// controller, the worst case of each controller with its parameters, the failed cases, and the
/// plots' markdown.
std::string report_md(const Study& s, const std::vector<CaseRecord>& cases, const std::string& command,
                      const std::string& plots_markdown);

}  // namespace feeddrive::study

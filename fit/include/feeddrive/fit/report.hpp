#pragma once
// Writing feeddrive-fit's results into DIR, atomically (a sibling temporary folder swapped into
// place when complete): findings.json, model.fitted.yaml, report.md and its PNG plots (gnuplot).

#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/fit/workflow.hpp"

namespace feeddrive::fit {

/// The scenario file at scenario_path with every effect of `fitted` written under
/// plant.effects (relative file names made absolute, so it loads from anywhere).
std::string fitted_scenario_yaml(const std::string& scenario_path, const plant::PlantParams& fitted);

/// findings.json: {"gap_initial", "gap_final", "effects": [{name, parameters, score, gap_before,
/// gap_after}], "data": {source, samples, time_offset_s, notes}, ...}.
std::string findings_json(const FitResult& r, const MeasuredData* data = nullptr);

/// Writes the results into out_dir through output::StagedFolder (feeddrive/output/folder.hpp:
/// check --out before the work with output::check_output_dir). Throws std::invalid_argument if
/// out_dir must not be replaced, std::runtime_error if writing fails; a previous output is kept.
/// Returns the warnings of putting the folder in place (StagedFolder::commit), for the tool to log.
[[nodiscard]] std::vector<std::string> write_outputs(const std::string& out_dir, const std::string& scenario_path,
                                                     const Record& rec, const FitResult& r, bool plots,
                                                     const interrupt::StopToken& stop = {});

/// The tool's result table: the gap and force residual RMS of the model as given and after each
/// addition, the conclusion, the tentative effects, the ties, the unexplained rest and where the
/// results are (one item a line).
std::string result_table(const FitResult& r, const std::string& out_dir);

}  // namespace feeddrive::fit

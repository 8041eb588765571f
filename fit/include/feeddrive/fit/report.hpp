#pragma once
// Writing feeddrive-fit's results into DIR, atomically (a sibling temporary folder renamed when
// complete): findings.json, model.fitted.yaml, report.md and its PNG plots (gnuplot).

#include <string>

#include "feeddrive/fit/workflow.hpp"

namespace feeddrive::fit {

/// The scenario file at scenario_path with every effect of `fitted` written under
/// plant.effects (relative file names made absolute, so it loads from anywhere).
std::string fitted_scenario_yaml(const std::string& scenario_path, const plant::PlantParams& fitted);

/// findings.json: {"gap_initial", "gap_final", "effects": [{name, parameters, score, gap_before,
/// gap_after}], ...}.
std::string findings_json(const FitResult& r);

/// Throws std::invalid_argument unless out_dir is absent, empty, or an earlier feeddrive-fit
/// output (holds findings.json): an unrelated folder is never replaced.
void check_output_dir(const std::string& out_dir);

void write_outputs(const std::string& out_dir, const std::string& scenario_path, const Record& rec,
                   const FitResult& r, bool plots);

}  // namespace feeddrive::fit

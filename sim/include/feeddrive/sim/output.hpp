#pragma once
// Writing a run's results: DIR/timeseries.csv, DIR/summary.json and PNG plots (gnuplot).
// All files go to a sibling temporary folder that is renamed to DIR only when complete, so DIR
// is never half-written.

#include <string>

#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::sim {

/// timeseries.csv: header of record_columns(), one row per record, %.17g (round-trips exactly).
void write_timeseries_csv(const std::string& path, const std::vector<Record>& records);

/// Plots position+error, velocity error, control and forces with gnuplot into dir
/// (position.png, velocity_error.png, control.png, forces.png). Throws on failure.
void write_plots(const std::string& dir, const std::string& title);

/// Throws std::invalid_argument unless out_dir is absent, empty, or a previous feeddrive output
/// (holds summary.json): an unrelated folder is never replaced.
void check_output_dir(const std::string& out_dir);

/// Writes timeseries.csv, summary.json (with the keys of extra_json appended) and the plots into
/// out_dir atomically.
void write_results(const std::string& out_dir, const RunResult& r, const Summary& sum, const Scenario& s,
                   bool plots = true, const std::string& extra_json = "");

}  // namespace feeddrive::sim

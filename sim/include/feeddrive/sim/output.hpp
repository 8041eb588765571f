#pragma once
// Writing a run's results: DIR/timeseries.csv, DIR/summary.json and PNG plots (gnuplot).
// The folder is checked, staged and swapped into place by feeddrive::output (output/folder.hpp):
// DIR is never half-written, and only an earlier feeddrive output (or an empty folder) is
// replaced. Check --out before the run with feeddrive::output::check_output_dir.

#include <functional>
#include <string>

#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::sim {

/// timeseries.csv: header of record_columns(), one row per record, %.17g (round-trips exactly).
void write_timeseries_csv(const std::string& path, const std::vector<Record>& records);

/// Plots position+error, velocity error, control and forces with gnuplot into dir
/// (position.png, velocity_error.png, control.png, forces.png, plots.gp), from dir/timeseries.csv.
/// `title` is any text (it goes through output::gnuplot_string). Throws on failure.
void write_plots(const std::string& dir, const std::string& title);

/// Writes timeseries.csv, summary.json (with the keys of extra_json appended) and the plots into
/// out_dir atomically (output::StagedFolder, marked as written by `tool`). Throws
/// std::invalid_argument if out_dir must not be replaced, std::runtime_error if writing fails;
/// a previous output is kept in both cases. `extra_files` (if given) writes the caller's own
/// files into the staged folder (its path) before it is swapped into place.
void write_results(const std::string& out_dir, const RunResult& r, const Summary& sum, const Scenario& s,
                   bool plots = true, const std::string& extra_json = "", const std::string& tool = "feeddrive-sim",
                   const std::function<void(const std::string&)>& extra_files = {});

}  // namespace feeddrive::sim

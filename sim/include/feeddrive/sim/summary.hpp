#pragma once
// Run metrics (summary.json). Errors are true-state errors: e = xd - x, e_v = vd - v.
// "settled" metrics are over t >= analysis.settled_after. A metric over an empty window has no
// value (std::nullopt; null in summary.json), never 0: the settled metrics when no step reaches
// settled_after, the after-first metric with fewer than two steps, and every error, control and
// position metric of a run without steps.

#include <optional>
#include <string>
#include <vector>

#include "feeddrive/sim/simulation.hpp"

namespace feeddrive::sim {

struct Summary {
  long steps{0};
  double sim_time_s{0.0};
  double wall_time_s{0.0};
  double position_error_max_abs_m{0.0};
  double position_error_rms_m{0.0};
  double position_error_p95_abs_m{0.0};
  double velocity_error_max_abs_mps{0.0};
  std::optional<double> velocity_error_max_abs_after_first_mps;  ///< excludes the first sample
  double velocity_error_rms_mps{0.0};
  double settled_after_s{0.0};
  long settled_steps{0};  ///< steps with t >= settled_after
  std::optional<double> position_error_max_abs_settled_m;
  std::optional<double> position_error_rms_settled_m;
  std::optional<double> velocity_error_max_abs_settled_mps;
  double control_min{0.0};
  double control_max{0.0};
  double control_total_variation{0.0};  ///< sum |u_k - u_{k-1}| [V]
  long control_saturated_steps{0};
  double final_position_m{0.0};
  double final_velocity_mps{0.0};
  double final_bristle_m{0.0};
  double final_friction_N{0.0};
  double max_position_m{0.0};
  double min_position_m{0.0};
  long integrator_steps{0};
  long integrator_rhs_evals{0};
  long integrator_jac_evals{0};
  long integrator_error_test_fails{0};
};

Summary summarize(const RunResult& r, const Scenario& s);
/// The summary as a JSON document (also carries the scenario name and path). `extra`, if not
/// empty, is a JSON object whose keys are appended (the monitor's lockstep statistics).
std::string summary_json(const Summary& sum, const Scenario& s, const std::string& extra = "");

}  // namespace feeddrive::sim

#pragma once
// Run metrics (summary.json). position_error_* and velocity_error_* are true-state errors:
// e = xd - x, e_v = vd - v (null without a true state: a hardware plant). measured_position_error_*
// are against the measured position, e_m = xd - x_measured (the encoder's, what a controller and a
// hardware-in-the-loop user have), in every run: max |e_m|, RMS, p95 |e_m| in the same form.
// error_source names which the headline figure (launcher line, plots) uses: "true_state" or
// "measured".
// "settled" metrics are over t >= analysis.settled_after. A metric over an empty window has no
// value: summary_json writes null, never 0, for the settled metrics when no step reaches
// settled_after (settled_steps == 0), for the after-first metric with fewer than two steps, and
// for every error, control and position metric of a run without steps.
//
// Computed online (SummaryBuilder::add, one record at a time, memory independent of the number
// of steps): maxima, minima, sums of squares (RMS), the total variation and the end state are
// exact; position_error_p95_abs_m is the rank-floor(0.95 n) order statistic of |e| from a
// bounded histogram (feeddrive/common/quantile.hpp), within 2^-11 (0.05 %) of the exact value.

#include <string>
#include <vector>

#include "feeddrive/common/quantile.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace feeddrive::sim {

struct Summary {
  long steps{0};
  double sim_time_s{0.0};
  double wall_time_s{0.0};
  double position_error_max_abs_m{0.0};
  double position_error_rms_m{0.0};
  double position_error_p95_abs_m{0.0};
  double measured_position_error_max_abs_m{0.0};  ///< max |xd - x_measured| [m]
  double measured_position_error_rms_m{0.0};
  double measured_position_error_p95_abs_m{0.0};
  double velocity_error_max_abs_mps{0.0};
  double velocity_error_max_abs_after_first_mps{0.0};  ///< excludes the first sample
  double velocity_error_rms_mps{0.0};
  double settled_after_s{0.0};
  long settled_steps{0};  ///< steps with t >= settled_after (0: the settled metrics have no value)
  double position_error_max_abs_settled_m{0.0};
  double position_error_rms_settled_m{0.0};
  double velocity_error_max_abs_settled_mps{0.0};
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

/// The metrics of a stream of records.
class SummaryBuilder {
 public:
  explicit SummaryBuilder(const Scenario& s);
  void add(const Record& q);
  long steps() const { return n_; }
  const Record& last() const { return last_; }
  /// The summary of every record added so far.
  Summary summary(double wall_time_s, const plant::CvodeIntegrator::Stats& integrator) const;

 private:
  double settled_after_, control_period_;
  Summary m_;
  long n_{0}, n_settled_{0};
  // steps with a finite position / velocity error (all, settled, after the first)
  long n_e_{0}, n_em_{0}, n_e_settled_{0}, n_ev_{0}, n_ev_settled_{0}, n_ev_after_first_{0};
  // Sums of squares and the control's total variation in long double (x86-64: 64-bit mantissa,
  // exponent to 1e4932): no finite record can overflow them, so a run that recorded a finite but
  // absurd value (a corrupt logged state at 1e220 m) still gets finite metrics, never inf/null.
  long double se_{0.0L}, sem_{0.0L}, sev_{0.0L}, se_settled_{0.0L}, total_variation_{0.0L};
  Record last_;
  stats::StreamingQuantile abs_e_, abs_em_;
};

/// All records in memory at once (SummaryBuilder over r.records).
Summary summarize(const RunResult& r, const Scenario& s);
/// The summary as a JSON document (also carries the scenario name and path). `extra`, if not
/// empty, is a JSON object whose keys are appended (the monitor's lockstep statistics).
std::string summary_json(const Summary& sum, const Scenario& s, const std::string& extra = "");

/// summary.json keys that measure the computer, not the drive (wall_time_s, realtime_factor).
bool is_wall_clock_metric(const std::string& key);
/// The drive's metrics: the keys summary_json writes as numbers for a run with steps (nulls of
/// an empty window included), except the wall-clock ones, in the order written. What a study
/// records per case and what its report.metric may name.
std::vector<std::string> summary_metric_names();

}  // namespace feeddrive::sim

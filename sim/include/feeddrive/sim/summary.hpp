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
//
// Move metrics (docs/scenario.md, "Move and step metrics"): for a reference that is a rest-to-rest
// move (step, accel_limited, scurve, waypoints: a finite end_time() t_e within the run), with
// x0 = xd(0), target xT = xd(t_e), distance D = xT - x0, the position y = x (x_measured in a run
// without a true state), the move start t_s = the first step whose xd differs from x0:
//   rise time      t(y first >= x0 + 0.9 D) - t(y first >= x0 + 0.1 D)   (in the direction of D;
//                  MATLAB stepinfo's RiseTimeLimits [0.1 0.9])
//   overshoot      max over t >= t_s of sgn(D)*(y - xT)  (>= 0), also in % of |D|
//   band b         analysis.settling_band, or 2 % of |D| when 0 (stepinfo's default)
//   settling time  t_in - t_s, t_in = the step after the last t >= t_s with |y - xT| > b
//                  (t_s if none); null if |y - xT| > b at the last step (not settled)
//   settle after the move  max(0, t_in - t_e): the in-position time after the reference stopped
//   error during / after the move  max |xd - y| over t_s <= t <= t_e / over t > t_e (RMS during)
// A reference that is not a move (sine, ramp, none), a move with D = 0 (rise, overshoot; and the
// band unless settling_band is given) or a move that ends after the run has null for what does
// not apply.
//
// Chatter: a reversal is a step k where du_k = u_k - u_{k-1} and du_{k-1} have opposite signs and
// both |du| >= delta = 1 % of the controller's output range (u_max - u_min; 0.2 V for +-10 V).
// control_reversals_per_s = reversals / sim_time; the control chatters (control_chattering) when
// that rate is at least 5 % of the control rate (0.05/T: 500 /s at T = 0.1 ms). A sgn switching
// law in a band reverses every period (rate 1/T); a smooth law tracking a smooth reference never.
//
// Control-signal quality (docs/scenario.md, "Control-signal quality"; issue 24 item 3), with
// delta = the chatter threshold above and F = Ka*Kf*u the commanded force (the plant's Ka*Kf):
//   control_step_rms_V        sqrt(mean over k >= 1 of (u_k - u_{k-1})^2)
//   control_direction_changes_per_s  turning points of u with hysteresis h = 0.1 % of the output
//                             range (control_direction_band_V; 0.02 V for +-10 V, 4 LSB of a 12-bit
//                             +-10 V DAC): u changes direction when it falls h below its last
//                             maximum (or rises h above its last minimum); per simulated second.
//                             A sine of amplitude > h/2 at f Hz: 2f; a square wave: one per edge.
//   control_saturated_fraction  control_saturated_steps / steps
//   force_hf_rms_N            RMS of F after a 2nd-order Butterworth high-pass at f_c = 1 kHz
//                             (bilinear transform with the corner pre-warped, started at rest on
//                             the first F: a constant gives 0); null when f_c >= 1/(2T)
//                             (no content above f_c is representable at that rate).
//   control_signal_within_limits  all four within kSignalLimits (below; sources in the docs).

#include <limits>
#include <optional>
#include <string>
#include <utility>
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
  /// The integrator ran in this process (false: a monitor's record of a separate plant, or a
  /// log; summary_json writes its counts as null).
  bool integrator_known{false};
  long integrator_steps{0};
  long integrator_rhs_evals{0};
  long integrator_jac_evals{0};
  long integrator_error_test_fails{0};
  // Move metrics (above); NaN = does not apply (written as null).
  double move_start_s{kNaN}, move_end_s{kNaN}, move_distance_m{kNaN};
  double rise_time_s{kNaN}, overshoot_m{kNaN}, overshoot_percent{kNaN};
  double settling_band_m{kNaN}, settling_time_s{kNaN}, settle_after_move_s{kNaN};
  double position_error_max_abs_during_move_m{kNaN}, position_error_rms_during_move_m{kNaN};
  double position_error_max_abs_after_move_m{kNaN};
  // Chatter (above)
  double control_chatter_threshold_V{0.0};
  double control_reversals_per_s{0.0};
  bool control_chattering{false};
  // Control-signal quality (above); NaN = no value (null)
  double control_step_rms_V{kNaN};
  double control_direction_band_V{0.0};
  double control_direction_changes_per_s{0.0};
  double control_saturated_fraction{0.0};
  double force_hf_corner_Hz{0.0};
  double force_hf_rms_N{kNaN};
  double force_hf_limit_N{0.0};  ///< Ka*Kf*delta: the limit on force_hf_rms_N
  bool control_signal_within_limits{false};

  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
};

/// The limits a command must keep to pass (docs/scenario.md, "Control-signal quality": current-
/// loop bandwidth of servo amplifiers, thermal limit of a linear motor). In units of delta (the
/// chatter threshold, 1 % of the output range) where they scale with the command range.
struct SignalLimits {
  double step_rms_deltas{1.0};             ///< control_step_rms_V <= 1 delta
  double direction_changes_per_s{2000.0};  ///< 2 per period of a 1 kHz current loop
  double saturated_fraction{0.01};         ///< 1 % of the run at the amplifier's peak
  double force_hf_rms_deltas{1.0};         ///< force_hf_rms_N <= Ka*Kf*delta
  double hf_corner_hz{1000.0};             ///< f_c of force_hf_rms_N
};
inline constexpr SignalLimits kSignalLimits{};

/// The scenario controller's output limits [V], of whichever type it is (its u_min, u_max).
struct OutputLimits {
  double u_min{0.0}, u_max{0.0};
};
OutputLimits controller_output_limits(const Scenario& s);
/// The controller's output range u_max - u_min [V] of a scenario (chatter threshold).
double controller_output_range(const Scenario& s);
/// summary.json's controller_model: "plant" (the controller's model is the plant's own
/// parameters: no controller.model key), "plant_without_effects" (the same, the plant having
/// effects the model lacks), "own" (controller.model given), "" (open_loop: no model).
std::string controller_model_source(const Scenario& s);
/// The headline of a run for a tool's final line, from summary.json's text: "max |e| = 1.367e-06
/// m, rms e = ..., u in [..., ...] V" (the measured error where the run has no true state), and
/// ", CONTROL CHATTERS (n reversals/s)" when control_chattering, ", CONTROL SIGNAL OUTSIDE LIMITS
/// (...)" when control_signal_within_limits is false. feeddrive-sim and -launch print it.
std::string summary_headline(const std::string& summary_json_text);
/// The same headline from the run's summary itself, without a JSON text (feeddrive-sim).
std::string summary_headline(const Summary& m, const Scenario& s);

/// The metrics of a stream of records.
class SummaryBuilder {
 public:
  explicit SummaryBuilder(const Scenario& s);
  void add(const Record& q);
  long steps() const { return n_; }
  const Record& last() const { return last_; }
  /// The summary of every record added so far.
  /// `integrator`: the CVODE counts of the plant run in this process; none (`{}`) where the
  /// plant ran elsewhere (the monitor, a log): the counts are then null.
  Summary summary(double wall_time_s, const std::optional<plant::CvodeIntegrator::Stats>& integrator) const;

 private:
  void add_move(const Record& q);
  void finish_move(Summary& m) const;
  void add_signal(double u);
  void finish_signal(Summary& m) const;
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
  // move metrics
  bool is_move_{false};
  double x0_{0.0}, target_{0.0}, distance_{0.0}, move_end_{0.0}, band_{0.0};
  double move_start_{Summary::kNaN}, t10_{Summary::kNaN}, t90_{Summary::kNaN}, overshoot_{0.0};
  double t_in_{Summary::kNaN};  // first step after the last out-of-band one (NaN: none out yet)
  bool last_out_{false};
  long n_during_{0};
  long double se_during_{0.0L};
  double max_during_{0.0}, max_after_{0.0};
  long n_after_{0};
  // chatter
  double chatter_delta_{0.0};
  double du_prev_{0.0};
  long reversals_{0};
  // control-signal quality
  long double sdu_{0.0L};  // sum of (u_k - u_{k-1})^2
  double direction_band_{0.0}, extreme_{0.0};
  int direction_{0};  // +1 rising, -1 falling, 0 not yet moved by the band
  long direction_changes_{0};
  double thrust_gain_{0.0};
  bool hf_defined_{false};
  double hb0_{0.0}, ha1_{0.0}, ha2_{0.0};  // high-pass: b = hb0*(1, -2, 1), a = (1, ha1, ha2)
  long double hx1_{0.0L}, hx2_{0.0L}, hy1_{0.0L}, hy2_{0.0L};
  long double shf_{0.0L};  // sum of squares of the high-passed force
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
/// The drive's metrics of a run, by name, as summary_json writes them as numbers (its nulls and
/// the wall-clock figures left out), and its verdicts (summary_flag_names) as 1/0: what a study
/// records per case, without a JSON text.
std::vector<std::pair<std::string, double>> summary_metrics(const Summary& sum, const Scenario& s);
/// summary.json's move_finished: whether the reference's move ends within `duration`
/// (move_end_s <= duration); nullopt when the reference is not a move.
std::optional<bool> move_finished(const Scenario& s);
/// The drive's verdicts: the keys summary_json writes as true/false for a run with steps
/// (control_chattering, control_signal_within_limits), in the order written; move_finished, also
/// true/false, is recorded by a study in a column of its own. A study records
/// them per case as 1 (true) or 0 (false) and report.require may name them.
std::vector<std::string> summary_flag_names();

}  // namespace feeddrive::sim

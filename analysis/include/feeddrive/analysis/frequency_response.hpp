#pragma once
// Frequency response of the full nonlinear drive in closed loop, by stepped sines
// (feeddrive-sim SCENARIO --frequency-response; docs/analysis.md).
//
// For each frequency f the scenario runs twice, from its initial state, with the plant, sensor,
// controller and period it gives (every nonlinearity included):
//   reference run    xd(t) = x0 + v_feed*t + A(f)*sin(w t)   (analytic derivatives: the
//                    controller's feedforward sees them), A(f) = min(A, a_lim/w^2);
//   disturbance run  xd(t) = x0 + v_feed*t, and a force F_d(t) = F*sin(w t) added at the
//                    amplifier input (sim::Excitation: u + F_d/(Ka*Kf), held over the period, as a
//                    drive's commissioning software injects at the force set-point).
// w = 2 pi f. The first S samples (max(settle_cycles/f, settle_time)) are dropped; then two
// blocks of N samples each hold exactly M whole cycles (f is moved to M/(N T), stated in the
// output), over which the phasor of each signal is its DFT at f,
//   Y = (2/N) sum_k y_k exp(-j w t_k),
// exact for a sinusoid of that frequency and blind to a constant and to every other harmonic of
// f. With e = xd - x (true position) the phasors give
//   T(jw)  = X/R = 1 - E/R                        reference -> position (closed loop)
//   G_d    = X/F_d = -E/F_d  [m/N]                dynamic compliance; |1/G_d| = dynamic stiffness
//   S_i    = (F_c + F_d)/F_d                      input sensitivity (F_c = Ka*Kf*u, the controller's
//                                                 force)
//   L      = -F_c/(F_c + F_d)                     the open loop broken at the force set-point
// (L and S_i are the loop as the injection sees it: any controller, linear or not). Per point:
//   drift         |H_1 - H_2|/|H| of the two blocks (a transient left, or a response that wanders)
//   nonfundamental sqrt(P_other/(P_fund + P_other)) of the position: the share of the response at
//                 other frequencies (harmonics from friction, stick-slip, chatter, noise)
// A point where nonfundamental > 1/sqrt(2) (more of the power elsewhere than at f) or drift > 0.1
// is named as doubtful in the table and in frequency_response.json (doubtful_frequencies_hz): its
// ratio is not a frequency response, so it supplies no summary figure (compute_figures leaves it
// out, and the outputs say so).
// Friction makes the result depend on the amplitude: A(f), F and v_feed are in every output.
//
// Summary figures (FrequencyResponse), from the points that are not doubtful: closed-loop
// bandwidth (the first -3 dB crossing of |T|, interpolated in log f between the two measured
// points around it, which are kept), resonance peak of |T| (a peak only when the largest |T| is
// inside the measured range, not at its edge), peak sensitivity Ms = max |S_i|, phase margin at
// the first downward crossing of |L| = 1, gain margin at the first downward -180 deg crossing of
// arg L above it, and (MATLAB allmargin) the lower gain margin at a -180 deg crossing below it (a
// conditionally stable loop: lowering the gain by that much makes it unstable), least dynamic
// stiffness and where; NaN where the measured range holds no such point.
//
// Bounds (validate): every frequency as measured (moved to whole cycles) below Nyquist 1/(2T); the
// whole measurement's steps (runs x (settle + 2 blocks)) at most sim::kMaxSteps, as a scenario's
// run; --fr-velocity as reference.max_velocity (the same hard bound, the same plausibility
// warning); a controller with a feedback loop (not open_loop).

#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::analysis {

struct FrequencyResponseOptions {
  std::vector<double> frequencies;  ///< [Hz]; empty: `points` log-spaced over [f_min, f_max]
  double f_min{5.0};                ///< [Hz]
  double f_max{0.0};                ///< [Hz]; 0: 0.4/T (4 kHz at T = 0.1 ms), below Nyquist 0.5/T
  int points{20};
  double reference_amplitude{1e-5};  ///< A [m]; 0: no reference run
  double acceleration_limit{0.0};    ///< a_lim [m/s^2]; 0: a quarter of the controller's force range / mass
  double force_amplitude{100.0};     ///< F [N]; 0: no disturbance run
  double feed_velocity{0.0};         ///< v_feed [m/s]: the excitation rides on this constant motion
  double settle_cycles{3.0};
  double settle_time{0.1};    ///< [s]
  int block_cycles{2};        ///< at least this many cycles per block
  double block_time{0.05};    ///< [s] at least this long per block
  int jobs{1};                ///< frequencies measured in parallel (threads)
  interrupt::StopToken stop;  ///< polled by every run (Ctrl-C in the tool; the default never stops)
  /// Throws std::invalid_argument naming the option and its value (the tool exits 2).
  void validate(const sim::Scenario& s) const;
  /// The frequencies asked for [Hz], ascending (before they are moved to whole cycles).
  std::vector<double> requested(const sim::Scenario& s) const;
  /// Plant steps of the whole measurement (every run's settling and two blocks), in double:
  /// inf or above sim::kMaxSteps for an option that cannot be meant.
  double total_steps(const sim::Scenario& s) const;
  /// The options' plausibility warnings ("--fr-velocity: 50 m/s is above any linear drive (10 m/s); mm/s?").
  std::vector<std::string> warnings() const;
};

/// Above this share of the power at other frequencies, or this drift, a point is doubtful.
inline constexpr double kDoubtfulNonfundamental = 0.70710678118654752;  // 1/sqrt(2)
inline constexpr double kDoubtfulDrift = 0.1;

struct FrequencyPoint {
  double frequency_hz{0.0};           ///< as measured (moved to whole cycles in a block)
  double reference_amplitude_m{0.0};  ///< A(f)
  std::complex<double> closed_loop{}, compliance{}, sensitivity{}, loop{};  ///< T, G_d [m/N], S_i, L
  double closed_loop_drift{0.0}, closed_loop_nonfundamental{0.0};
  double disturbance_drift{0.0}, disturbance_nonfundamental{0.0};
  long saturated_steps{0};  ///< measured samples with the controller's output saturated (both runs)
  bool has_reference{false}, has_disturbance{false};
  double stiffness_N_per_um() const { return 1e-6 / std::abs(compliance); }
  bool reference_doubtful() const {
    return has_reference &&
           (closed_loop_nonfundamental > kDoubtfulNonfundamental || closed_loop_drift > kDoubtfulDrift);
  }
  bool disturbance_doubtful() const {
    return has_disturbance &&
           (disturbance_nonfundamental > kDoubtfulNonfundamental || disturbance_drift > kDoubtfulDrift);
  }
  bool doubtful() const { return reference_doubtful() || disturbance_doubtful(); }
};

struct FrequencyResponse {
  FrequencyResponseOptions options;
  double acceleration_limit{0.0};      ///< a_lim used [m/s^2]
  std::vector<FrequencyPoint> points;  ///< in frequency order
  std::vector<std::string> warnings;   ///< the scenario's plausibility warnings and the options'
  double bandwidth_hz{kNaN};
  double bandwidth_between_hz[2]{kNaN, kNaN};  ///< the measured points the bandwidth is interpolated between
  /// Where no -3 dB crossing was found: -1 |T| below -3 dB at the lowest (non-doubtful) point, +1 above throughout.
  int bandwidth_outside{0};
  double peak_db{kNaN}, peak_hz{kNaN};  ///< the largest |T| measured, and where
  bool peak_inside{false};              ///< not at the lowest or highest frequency: a resonance peak
  double lower_gain_margin_db{kNaN}, lower_phase_crossover_hz{kNaN};  ///< -180 deg below the crossover
  double sensitivity_peak{kNaN}, sensitivity_peak_hz{kNaN};           ///< Ms (linear), at
  double phase_margin_deg{kNaN}, crossover_hz{kNaN};
  double gain_margin_db{kNaN}, phase_crossover_hz{kNaN};
  double min_stiffness_N_per_um{kNaN}, min_stiffness_hz{kNaN};
  double wall_time_s{0.0};
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
};

/// Measures the frequency response of scenario `s` (see the top of this file). Throws what
/// sim::run throws (a run that diverges: ScenarioError), interrupt::Interrupted.
FrequencyResponse measure_frequency_response(const sim::Scenario& s, const FrequencyResponseOptions& o);
/// The summary figures from the points (measure_frequency_response calls it).
void compute_figures(FrequencyResponse& r);
/// The phases of h [deg], unwrapped (no step of more than 180 deg between neighbours), the first
/// in (-180, 180], or in (-360, 0] with `negative_start` (an open loop's phase).
std::vector<double> unwrapped_phase_deg(const std::vector<std::complex<double>>& h, bool negative_start = false);

/// The table printed by the tool (one row per frequency, the amplitudes and the summary figures).
std::string frequency_response_table(const sim::Scenario& s, const FrequencyResponse& r);
/// Writes DIR/frequency_response.csv, frequency_response.json and (plots) bode_reference.png,
/// bode_compliance.png, bode_loop.png through an output::StagedFolder.
struct FrequencyResponseWritten {
  std::string plot_error;             ///< why the plots were not drawn ("" ok); the data are in place
  std::vector<std::string> warnings;  ///< StagedFolder::commit's, one line each, for the tool to log
};
[[nodiscard]] FrequencyResponseWritten write_frequency_response(const std::string& out_dir, const sim::Scenario& s,
                                                                const FrequencyResponse& r, bool plots,
                                                                const interrupt::StopToken& stop = {});

}  // namespace feeddrive::analysis

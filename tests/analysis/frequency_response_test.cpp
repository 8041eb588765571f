// The stepped-sine frequency response (analysis/frequency_response.hpp) of a linear drive against
// the analytic linearised loop: a rigid mass with viscous friction only, the cascade controller
// (feedforward off, so that reference -> position is the feedback loop's), an ideal sensor, no
// delay. The loop is then linear and sampled, and its frequency response at the sample instants
// is exact in the z-domain (z = exp(j w T)):
//   plant, force F held over [t_k, t_k+1) (zero-order hold), a = c/m, alpha = exp(-a T):
//     v_{k+1} = alpha v_k + (1 - alpha)/c F_k
//     x_{k+1} = x_k + (1 - alpha)/a v_k + (T - (1 - alpha)/a)/c F_k
//   =>  V = Pv F,  Pv = ((1 - alpha)/c)/(z - alpha);   X = Px F,  Px = ((1 - alpha)/a Pv + (T - (1 - alpha)/a)/c)/(z -
//   1) cascade (controller/cascade.cpp): e_v = kp (r - x) - v, F = m (kv e_v + ki I), I_{k+1} = I_k + T e_v
//   =>  F = m C(z) e_v,  C = kv + ki T/(z - 1)
//   loop at the force set-point L = m C (kp Px + Pv),  S = 1/(1 + L),
//   T = m C kp Px/(1 + L),  compliance G_d = X/F_d = Px/(1 + L).
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <complex>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "feeddrive/analysis/frequency_response.hpp"

namespace feeddrive::analysis {
namespace {

using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

struct Analytic {
  cd closed_loop, compliance, loop, sensitivity;
};

Analytic analytic(const sim::Scenario& s, double f) {
  const double T = s.control_period, m = s.plant.mass, c = s.plant.effects.viscous_friction.viscous;
  const auto& k = s.controller.cascade;
  const double a = c / m, alpha = std::exp(-a * T);
  const cd z = std::polar(1.0, 2.0 * kPi * f * T);
  const cd pv = ((1.0 - alpha) / c) / (z - alpha);
  const cd px = ((1.0 - alpha) / a * pv + (T - (1.0 - alpha) / a) / c) / (z - 1.0);
  const cd C = k.kv + k.ki * T / (z - 1.0);
  const cd L = k.mass * C * (k.kp * px + pv);
  return {k.mass * C * k.kp * px / (1.0 + L), px / (1.0 + L), L, 1.0 / (1.0 + L)};
}

sim::Scenario linear_drive() {
  return sim::parse_scenario(
      "name: linear\nduration: 1.0\ncontrol_period: 1.0e-4\n"
      "plant:\n  friction: {model: none}\n  effects: {viscous_friction: {viscous: 400.0}}\n"
      "controller: {type: cascade, tuning: rule, velocity_feedforward: 0.0, acceleration_feedforward: 0.0}\n",
      ".", "linear");
}

TEST(FrequencyResponse, MatchesTheAnalyticLinearisedLoop) {
  const sim::Scenario s = linear_drive();
  FrequencyResponseOptions o;
  o.f_min = 5.0;
  o.f_max = 2000.0;
  o.points = 12;
  o.jobs = 2;
  const FrequencyResponse r = measure_frequency_response(s, o);
  ASSERT_EQ(r.points.size(), 12u);
  double worst = 0.0;
  for (const FrequencyPoint& p : r.points) {
    const Analytic a = analytic(s, p.frequency_hz);
    // Tolerance. The loop is linear and the comparison is at the same (moved) frequency, so what
    // separates the two is (1) CVODE's error (rtol 1e-8, atol 1e-12 m, on responses of at least
    // ~2e-8 m here: 100 N against >= 4000 N/um; 0.04 um of reference at 2 kHz); (2) the transient
    // of the start from rest left after the dropped settling (>= 0.1 s, >= 3 cycles), which the
    // drift between the two blocks bounds below (< 1e-5); (3) rounding in the DFT sums (~1e-12).
    // Measured: 6.4e-8 at worst. 1e-5 relative (1e-4 dB, 6e-4 deg) leaves a factor of 100 for
    // other compilers and CPUs, and is far below any error a wrong formula (a sample of delay is
    // 2 pi f T: 0.3 % at 5 Hz) or a wrong sign would make.
    const double tol = 1e-5;
    for (double d : {std::abs(p.closed_loop / a.closed_loop - 1.0), std::abs(p.compliance / a.compliance - 1.0),
                     std::abs(p.loop / a.loop - 1.0), std::abs(p.sensitivity / a.sensitivity - 1.0)})
      worst = std::max(worst, d);
    EXPECT_NEAR(std::abs(p.closed_loop / a.closed_loop - 1.0), 0.0, tol) << p.frequency_hz << " Hz: T";
    EXPECT_NEAR(std::abs(p.compliance / a.compliance - 1.0), 0.0, tol) << p.frequency_hz << " Hz: G_d";
    EXPECT_NEAR(std::abs(p.loop / a.loop - 1.0), 0.0, tol) << p.frequency_hz << " Hz: L";
    EXPECT_NEAR(std::abs(p.sensitivity / a.sensitivity - 1.0), 0.0, tol) << p.frequency_hz << " Hz: S";
    // a linear loop: no power at other frequencies (the DFT window holds whole cycles), no drift
    EXPECT_LT(p.closed_loop_nonfundamental, 1e-3) << p.frequency_hz;
    EXPECT_LT(p.disturbance_nonfundamental, 1e-3) << p.frequency_hz;
    EXPECT_LT(std::max(p.closed_loop_drift, p.disturbance_drift), 1e-5) << p.frequency_hz;
    EXPECT_EQ(p.saturated_steps, 0);
  }
  std::printf("largest relative difference from the analytic loop: %.2e\n", worst);
  // The summary figures are interpolated between the points (log f, dB): from the analytic values
  // at the same frequencies they come out the same, within the points' tolerance.
  FrequencyResponse ra = r;
  for (FrequencyPoint& p : ra.points) {
    const Analytic a = analytic(s, p.frequency_hz);
    p.closed_loop = a.closed_loop, p.compliance = a.compliance, p.loop = a.loop, p.sensitivity = a.sensitivity;
  }
  compute_figures(ra);
  ASSERT_FALSE(std::isnan(r.bandwidth_hz));
  EXPECT_NEAR(r.bandwidth_hz / ra.bandwidth_hz, 1.0, 1e-3);
  EXPECT_NEAR(r.phase_margin_deg, ra.phase_margin_deg, 0.05);
  EXPECT_NEAR(r.sensitivity_peak / ra.sensitivity_peak, 1.0, 1e-3);
  // On a grid of 2 % steps around it the bandwidth is the analytic -3 dB crossing (bisection)
  // within 1 %: the interpolation error of a 2 % step (the coarse grid above is 11 % off: near the
  // resonance peak |T| in dB is far from linear in log f over a factor 1.67).
  double lo = 5.0, hi = 2000.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = std::sqrt(lo * hi);
    (20.0 * std::log10(std::abs(analytic(s, mid).closed_loop)) > -3.0103 ? lo : hi) = mid;
  }
  FrequencyResponseOptions fine = o;
  fine.force_amplitude = 0.0;
  for (double f = 0.9 * lo; f < 1.1 * lo; f *= 1.02) fine.frequencies.push_back(f);
  EXPECT_NEAR(measure_frequency_response(s, fine).bandwidth_hz / lo, 1.0, 0.01) << "analytic " << lo << " Hz";
  // The phase margin of the rule is 45 deg for the velocity loop alone (docs/controllers.md); the
  // position loop inside and the sampled plant take some: between 25 and 50 deg.
  EXPECT_GT(r.phase_margin_deg, 25.0);
  EXPECT_LT(r.phase_margin_deg, 50.0);
}

TEST(FrequencyResponse, BadOptionsNameTheOptionAndValue) {
  const sim::Scenario s = linear_drive();
  FrequencyResponseOptions o;
  o.frequencies = {6000.0};  // above Nyquist 5 kHz
  try {
    o.validate(s);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--fr-frequencies 6000: must be > 0 and below Nyquist 5000 Hz");
  }
  o = {};
  o.reference_amplitude = 0.0;
  o.force_amplitude = 0.0;
  EXPECT_THROW(o.validate(s), std::invalid_argument);
}

TEST(FrequencyResponse, FrictionMakesItAmplitudeDependent) {
  // The paper's LuGre friction (Fc = 80 N): a 20 N force stays in presliding (the bristles'
  // 2e6 N/m add to the servo's stiffness), 2000 N breaks away. The stiffness at 20 Hz must differ,
  // and the table must say at which amplitude it was measured.
  sim::Scenario s = sim::parse_scenario(
      "name: lugre\nduration: 1.0\ncontrol_period: 1.0e-4\nplant: {friction: {model: lugre}}\n"
      "controller: {type: cascade, kp: 50, kv: 300, ki: 10000}\n",
      ".", "lugre");
  FrequencyResponseOptions o;
  o.frequencies = {20.0};
  o.reference_amplitude = 0.0;
  double k[2];
  int i = 0;
  for (double force : {20.0, 2000.0}) {
    o.force_amplitude = force;
    const FrequencyResponse r = measure_frequency_response(s, o);
    k[i++] = r.points[0].stiffness_N_per_um();
    EXPECT_NE(frequency_response_table(s, r).find("force " + std::to_string(static_cast<int>(force)) + " N"),
              std::string::npos);
  }
  // presliding stiffer than sliding by more than 10 %
  EXPECT_GT(k[0], 1.1 * k[1]) << k[0] << " vs " << k[1];
}

// --- the bounds, the summary figures and the texts (issue 23 review F7-F13, F20) ---------------

// A response from given values at given frequencies: compute_figures and the table without a run.
FrequencyResponse synthetic(const std::vector<double>& fs, const std::function<cd(double)>& t,
                            const std::function<cd(double)>& l) {
  FrequencyResponse r;
  for (double f : fs) {
    FrequencyPoint p;
    p.frequency_hz = f;
    p.has_reference = p.has_disturbance = true;
    p.closed_loop = t(f);
    p.loop = l(f);
    p.sensitivity = 1.0 / (1.0 + p.loop);
    p.compliance = 1e-9 * p.sensitivity;  // 1000 N/um times |1 + L|
    r.points.push_back(p);
  }
  compute_figures(r);
  return r;
}

std::vector<double> log_grid(double lo, double hi, double step) {
  std::vector<double> fs;
  for (double f = lo; f < hi; f *= step) fs.push_back(f);
  return fs;
}

std::string error_of(const FrequencyResponseOptions& o, const sim::Scenario& s) {
  try {
    o.validate(s);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(FrequencyResponse, AFrequencyMovedOntoNyquistIsRefused) {
  // F7: 4999.9 Hz at T = 0.1 ms: M = 250 cycles in N = round(250/(4999.9 T)) = 500 samples is
  // 5000 Hz exactly, where sin(pi k) = 0 at every sample: refused, naming the option and the value.
  const sim::Scenario s = linear_drive();
  FrequencyResponseOptions o;
  o.frequencies = {4999.9, 4990.0, 4900.0};
  EXPECT_EQ(error_of(o, s),
            "--fr-frequencies 4999.9: is measured as 250 cycles in 500 samples, i.e. at 5000 Hz: must be below Nyquist "
            "5000 Hz");
  o.frequencies = {4990.0, 4900.0};  // 250 cycles in 501 samples: 4990.0 Hz
  EXPECT_EQ(error_of(o, s), "");
  o = {};
  o.f_max = 4999.9;  // the log grid's top is moved the same way
  EXPECT_NE(error_of(o, s).find("--fr-to 4999.9: is measured as"), std::string::npos) << error_of(o, s);
}

TEST(FrequencyResponse, DoubtfulPointsSupplyNoSummaryFigure) {
  // F7: a doubtful point (nonfund > 0.71) with the least stiffness, the largest |T| and the only
  // -3 dB crossing must not supply any of them; the table says they are left out.
  const std::vector<double> fs = {10, 100, 1000, 4000};
  FrequencyResponse r = synthetic(
      fs, [](double f) { return cd(f < 2000 ? 1.0 : 0.1); }, [](double f) { return cd(10.0 / f); });
  r.points[3].closed_loop = cd(30.0);  // +29.5 dB: a bogus peak
  r.points[3].compliance = cd(1.0);    // 1e-6 N/um: a bogus least stiffness
  r.points[3].closed_loop_nonfundamental = r.points[3].disturbance_nonfundamental = 0.99;
  compute_figures(r);
  EXPECT_TRUE(std::isnan(r.bandwidth_hz));  // the only crossing was to the doubtful point
  EXPECT_EQ(r.bandwidth_outside, 1);
  EXPECT_NEAR(r.peak_db, 0.0, 1e-12);
  EXPECT_GT(r.min_stiffness_N_per_um, 100.0);
  EXPECT_LT(r.min_stiffness_hz, 2000.0);
  const std::string t = frequency_response_table(linear_drive(), r);
  EXPECT_NE(t.find("WARNING: at 4000 Hz"), std::string::npos) << t;
  EXPECT_NE(t.find("left out of every summary figure"), std::string::npos) << t;
  EXPECT_EQ(t.find("29.5"), t.find("29.54")) << t;  // the bogus value only in its own row
}

TEST(FrequencyResponse, ARunNotMadeSaysNotMeasured) {
  // F8: --fr-force 0 (no L measured) and --fr-amplitude 0 (no T measured): "not measured", never
  // "none found" or "n/a dB" (which would read as a measured absence).
  const sim::Scenario s = linear_drive();
  FrequencyResponse r;
  FrequencyPoint p;
  p.frequency_hz = 100;
  p.has_reference = true;
  p.closed_loop = 1.0;
  r.points = {p};
  r.options.force_amplitude = 0.0;
  compute_figures(r);
  std::string t = frequency_response_table(s, r);
  EXPECT_NE(t.find("phase and gain margins, dynamic stiffness: not measured (--fr-force 0)"), std::string::npos) << t;
  EXPECT_EQ(t.find("none found"), std::string::npos) << t;
  EXPECT_EQ(t.find("least dynamic stiffness"), std::string::npos) << t;
  p.has_reference = false;
  p.has_disturbance = true;
  p.loop = 2.0, p.sensitivity = 1.0 / 3.0, p.compliance = 1e-9;
  r.points = {p};
  r.options.force_amplitude = 100.0;
  r.options.reference_amplitude = 0.0;
  compute_figures(r);
  t = frequency_response_table(s, r);
  EXPECT_NE(
      t.find(
          "closed-loop bandwidth (-3 dB): not measured (--fr-amplitude 0); peak |T|: not measured (--fr-amplitude 0)"),
      std::string::npos)
      << t;
  EXPECT_EQ(t.find("n/a dB"), std::string::npos) << t;
}

TEST(FrequencyResponse, ScenarioAndOptionWarningsAreKeptAndWritten) {
  // F9: the scenario's plausibility warnings (a 5e4 kg carriage) go into the result and into
  // frequency_response.json, as into a run's summary.json; F11: --fr-velocity 0.5 is plausible,
  // 50 m/s gets reference.max_velocity's warning (mm/s?), beyond its 1000 m/s bound exit 2.
  sim::Scenario s = sim::parse_scenario(
      "name: heavy\nduration: 1.0\ncontrol_period: 1.0e-4\nplant:\n  mass: 5.0e4\n  friction: {model: none}\n"
      "  effects: {viscous_friction: {viscous: 400.0}}\ncontroller: {type: cascade, tuning: rule}\n",
      ".", "heavy");
  ASSERT_FALSE(s.warnings.empty());
  FrequencyResponseOptions o;
  o.frequencies = {50.0};
  o.reference_amplitude = 0.0;
  const FrequencyResponse r = measure_frequency_response(s, o);
  ASSERT_EQ(r.warnings, s.warnings);
  EXPECT_NE(r.warnings.front().find("above"), std::string::npos) << r.warnings.front();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fd_fr_warn_" + std::to_string(::getpid()));
  EXPECT_TRUE(write_frequency_response(dir.string(), s, r, false).warnings.empty());
  std::ifstream in(dir / "frequency_response.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["warnings"], nlohmann::json(s.warnings));
  std::filesystem::remove_all(dir);

  const sim::Scenario lin = linear_drive();
  o = {};
  o.feed_velocity = 0.5;
  EXPECT_TRUE(o.warnings().empty());
  o.feed_velocity = -50.0;
  ASSERT_EQ(o.warnings().size(), 1u);
  EXPECT_EQ(o.warnings()[0], "--fr-velocity: 50 m/s is above any linear drive (10 m/s); mm/s?");
  EXPECT_EQ(error_of(o, lin), "");
  o.feed_velocity = 2000.0;
  EXPECT_EQ(error_of(o, lin), "--fr-velocity 2000: must be within +-1000 m/s, as reference.max_velocity (mm/s?)");
}

TEST(FrequencyResponse, OpenLoopControllerIsRefused) {
  // F10: an open_loop controller has no feedback loop: nothing to measure, exit 2.
  const sim::Scenario s = sim::parse_scenario(
      "name: ol\nduration: 1.0\ncontrol_period: 1.0e-4\nplant: {friction: {model: lugre}}\n"
      "controller: {type: open_loop, kind: step, amplitude: 12.0}\nreference: {type: none}\n",
      ".", "ol");
  EXPECT_EQ(error_of(FrequencyResponseOptions{}, s),
            "controller.type open_loop: no feedback loop to measure (the frequency response needs a closed loop: "
            "sliding_mode, "
            "cascade or plugin)");
}

TEST(FrequencyResponse, TheWholeMeasurementIsBoundedAsARun) {
  // F11: the steps are counted before any run: 20 frequencies x 2 runs x (1e9 s / 1e-4 s) = 4e14,
  // and 1e-6 Hz alone is 2 cycles in 2e10 samples per block; both beyond 1e10 steps.
  const sim::Scenario s = linear_drive();
  FrequencyResponseOptions o;
  EXPECT_GT(o.total_steps(s), 20 * 2 * 2000.0);  // >= 0.1 s settling and 2 x 0.05 s blocks each
  EXPECT_LT(o.total_steps(s), 20 * 2 * 8000.0);  // 3 cycles at 5 Hz = 0.6 s settling, 2 x 0.4 s blocks at most
  o.settle_time = 1e9;
  EXPECT_NEAR(o.total_steps(s), 20 * 2 * 1e13, 20 * 2 * 1e13 * 1e-6);
  EXPECT_EQ(error_of(o, s).rfind("frequency response: 4e+14 steps (20 frequencies from 5 Hz, --fr-settle 1e+09 s); a "
                                 "run has at most 1e+10 steps",
                                 0),
            0u)
      << error_of(o, s);
  o = {};
  o.frequencies = {1e-6};
  EXPECT_NE(error_of(o, s).find("steps (1 frequencies from 1e-06 Hz"), std::string::npos) << error_of(o, s);
  o.frequencies = {1e-300};  // counted in double: no overflow of a long on the way, refused
  EXPECT_NE(error_of(o, s).find("1.4e+305 steps"), std::string::npos) << error_of(o, s);
}

TEST(FrequencyResponse, PeakOnlyInsideTheRangeAndLowerGainMargin) {
  // F12. (a) A first-order |T| = 1/|1 + j f/100| falls monotonically: its largest value is at the
  // lowest frequency, which is no resonance peak.
  const auto lowpass = [](double f) { return 1.0 / cd(1.0, f / 100.0); };
  // (b) A conditionally stable loop, L = K (1 + s/w1)^2 / (s^3 (1 + s/w2)^2), w1 = 10, w2 = 1000 rad/s:
  // arg L = -270 + 2 atan(w/w1) - 2 atan(w/w2) starts below -180, crosses it upward at ~10 rad/s
  // (|L| > 1 there), peaks near 100 rad/s where |L| = 1 (K chosen so), and crosses -180 down again
  // at ~1000 rad/s. MATLAB's allmargin gives both gain margins; here from the analytic L by bisection.
  const double w1 = 10.0, w2 = 1000.0;
  const auto shape = [&](double f) {
    const cd s(0.0, 2.0 * kPi * f);
    return (1.0 + s / w1) * (1.0 + s / w1) / (s * s * s * (1.0 + s / w2) * (1.0 + s / w2));
  };
  const double K = 1.0 / std::abs(shape(100.0 / (2.0 * kPi)));
  const auto loop = [&](double f) { return K * shape(f); };
  const auto phase = [&](double f) {
    return -270.0 + 2.0 * (std::atan(2 * kPi * f / w1) - std::atan(2 * kPi * f / w2)) * 180.0 / kPi;
  };
  const auto bisect = [&](double lo, double hi, bool rising) {
    for (int i = 0; i < 100; ++i) {
      const double mid = std::sqrt(lo * hi);
      ((phase(mid) < -180.0) == rising ? lo : hi) = mid;
    }
    return lo;
  };
  const double f_low = bisect(0.1, 100.0 / (2 * kPi), true), f_high = bisect(100.0 / (2 * kPi), 1e4, false);
  const FrequencyResponse r = synthetic(log_grid(0.5, 2000.0, 1.01), lowpass, loop);
  EXPECT_FALSE(r.peak_inside);
  EXPECT_NEAR(r.peak_hz, 0.5, 1e-12);
  const std::string t = frequency_response_table(linear_drive(), r);
  EXPECT_NE(t.find("no peak inside the measured range (|T| largest at the lowest frequency"), std::string::npos) << t;
  // Tolerance: the figures are interpolated linearly (dB, degrees over log f) between points 1 %
  // apart; the curvature of atan and of |L| in dB over one step is far below 0.5 % in f, 0.05 dB.
  EXPECT_NEAR(r.crossover_hz / (100.0 / (2 * kPi)), 1.0, 5e-3);
  ASSERT_FALSE(std::isnan(r.lower_gain_margin_db));
  EXPECT_NEAR(r.lower_phase_crossover_hz / f_low, 1.0, 5e-3);
  EXPECT_NEAR(r.lower_gain_margin_db, -20.0 * std::log10(std::abs(loop(f_low))), 0.05);
  EXPECT_LT(r.lower_gain_margin_db, 0.0);  // |L| > 1 below the crossover
  EXPECT_NEAR(r.phase_crossover_hz / f_high, 1.0, 5e-3);
  EXPECT_NEAR(r.gain_margin_db, -20.0 * std::log10(std::abs(loop(f_high))), 0.05);
  EXPECT_NE(t.find("lower gain margin"), std::string::npos) << t;
  // a peak inside the range is one: |T| of a resonance at 100 Hz, zeta 0.2
  const FrequencyResponse rr = synthetic(
      log_grid(5, 2000, 1.05), [](double f) { return 1.0 / cd(1.0 - f * f / 1e4, 0.4 * f / 100.0); }, loop);
  EXPECT_TRUE(rr.peak_inside);
  EXPECT_NEAR(rr.peak_hz, 100.0 * std::sqrt(1 - 2 * 0.04), 5.0);
}

TEST(FrequencyResponse, BandwidthNamesItsGridAndTheTableUnwrapsThePhase) {
  // F13: the bandwidth says which two measured points it is interpolated between. F20: the table
  // prints the phase unwrapped along f, as the CSV and the plots do: T = 1/(1 + j f/100)^3 goes
  // to -270 deg, which wrapped would read +90.
  const auto t3 = [](double f) {
    const cd a(1.0, f / 100.0);
    return 1.0 / (a * a * a);
  };
  const std::vector<double> fs = {10, 50, 100, 300, 1000};
  const FrequencyResponse r = synthetic(fs, t3, [](double f) { return cd(100.0 / f); });
  ASSERT_FALSE(std::isnan(r.bandwidth_hz));
  EXPECT_EQ(r.bandwidth_between_hz[0], 50.0);
  EXPECT_EQ(r.bandwidth_between_hz[1], 100.0);
  const std::string t = frequency_response_table(linear_drive(), r);
  EXPECT_NE(t.find("(interpolated in log f between the measured points 50 and 100 Hz)"), std::string::npos) << t;
  char unwrapped[32];
  std::snprintf(unwrapped, sizeof unwrapped, "%.2f", -3.0 * std::atan(10.0) * 180.0 / kPi);  // -253.14 at 1 kHz
  EXPECT_NE(t.find(unwrapped), std::string::npos) << t;
  EXPECT_EQ(t.find("106.86"), std::string::npos) << t;  // the wrapped value
}

}  // namespace
}  // namespace feeddrive::analysis

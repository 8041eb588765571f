// The online summary (sim/summary.hpp) of records that are finite but absurd, as a corrupt
// logged state or a hostile external plant can deliver (issue 13, point 7: nothing non-finite
// passes). A 1e220 m position once made the sum of squared errors overflow: rms = inf, written
// as null by the JSON writer, with exit 0 (found by fuzz.lcm_log).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::sim {
namespace {

Scenario scenario() {
  Scenario s;
  s.control_period = 1e-4;
  s.analysis.settled_after = 0.0;  // every record is in the settled window
  return s;
}

Record at(long k, double x, double u) {
  Record r;
  r.t = static_cast<double>(k) * 1e-4;
  r.x = x;
  r.u = r.u_unsaturated = u;
  return r;
}

TEST(Summary, FiniteButHugeRecordsGiveFiniteMetrics) {
  const Scenario s = scenario();
  SummaryBuilder b(s);
  // Three ordinary steps and one position of 1e220 m; commands alternating at +-1e308 V, whose
  // differences (2e308) overflow a double.
  b.add(at(0, 0.0, 1e308));
  b.add(at(1, 0.0, -1e308));
  b.add(at(2, -1e220, 1e308));
  b.add(at(3, 0.0, -1e308));
  const Summary m = b.summary(1.0, {});
  // rms of (0, 0, 1e220, 0) = 1e220 / sqrt(4) = 5e219 (relative rounding of long double sums)
  EXPECT_NEAR(m.position_error_rms_m / 5e219, 1.0, 1e-12);
  EXPECT_NEAR(m.position_error_rms_settled_m / 5e219, 1.0, 1e-12);
  EXPECT_EQ(m.position_error_max_abs_m, 1e220);
  // |u| differences of 2e308 and their sum exceed the largest double: saturated there, finite.
  EXPECT_EQ(m.control_total_variation, std::numeric_limits<double>::max());
  // The error of xd = 1e308 against x = -1e308 (2e308) saturates too.
  SummaryBuilder c(s);
  Record r = at(0, -1e308, 0.0);
  r.xd = 1e308;
  c.add(r);
  const Summary mc = c.summary(1.0, {});
  EXPECT_EQ(mc.position_error_max_abs_m, std::numeric_limits<double>::max());
  EXPECT_EQ(mc.position_error_rms_m, std::numeric_limits<double>::max());
  EXPECT_TRUE(std::isfinite(mc.position_error_p95_abs_m));
  const auto j = nlohmann::json::parse(summary_json(m, s));
  EXPECT_TRUE(j["position_error_rms_m"].is_number()) << j.dump();
  EXPECT_TRUE(j["position_error_rms_settled_m"].is_number()) << j.dump();
  EXPECT_TRUE(j["control_total_variation"].is_number()) << j.dump();
}

}  // namespace
}  // namespace feeddrive::sim

namespace feeddrive::sim {
namespace {

TEST(Summary, ACascadeReportsTheGainsItRunsWith) {
  // tuning: rule chooses kp, kv, ki (docs/controllers.md): summary.json says which.
  const Scenario c = parse_scenario(
      "name: c\nduration: 0.1\ncontrol_period: 1.0e-4\ncontroller: {type: cascade, tuning: rule}\n", ".", "c");
  Summary m;
  m.steps = 1;
  const auto j = nlohmann::json::parse(summary_json(m, c));
  ASSERT_TRUE(j.contains("cascade_gains"));
  EXPECT_EQ(j["cascade_gains"]["kv"].get<double>(), c.controller.cascade.kv);
  EXPECT_EQ(j["cascade_gains"]["kp"].get<double>(), c.controller.cascade.kp);
  EXPECT_EQ(j["cascade_gains"]["ki"].get<double>(), c.controller.cascade.ki);
  // Ideal sensor, T = 100 us: tau = T/2, crossover ~10,800 rad/s, kv ~10,490 1/s (docs/controllers.md,
  // "Cascade tuning rule"); 1 % covers the rounding of the documented figure.
  EXPECT_NEAR(c.controller.cascade.kv, 10490.0, 105.0);
  const Scenario smc =
      parse_scenario("name: s\nduration: 0.1\ncontrol_period: 1.0e-4\ncontroller: {type: sliding_mode}\n", ".", "s");
  EXPECT_FALSE(nlohmann::json::parse(summary_json(m, smc)).contains("cascade_gains"));
}

}  // namespace
}  // namespace feeddrive::sim

namespace feeddrive::sim {
namespace {

TEST(Summary, ARecordWithoutTrueStateHasNoErrorMetricsNotZero) {
  // Hardware reports no true state (truth.valid = 0: x, v NaN). Its error metrics once read 0
  // (max of nothing), i.e. perfect tracking, and a study would rank such a run best.
  Scenario s;
  s.control_period = 1e-4;
  s.analysis.settled_after = 0.0;
  SummaryBuilder b(s);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (long k = 0; k < 10; ++k) {
    Record r;
    r.t = k * 1e-4;
    r.xd = 1e-3;
    r.x = r.v = nan;
    b.add(r);
  }
  const auto j = nlohmann::json::parse(summary_json(b.summary(0.0, {}), s));
  for (const char* key :
       {"position_error_max_abs_m", "position_error_rms_m", "position_error_p95_abs_m", "velocity_error_max_abs_mps",
        "velocity_error_max_abs_after_first_mps", "velocity_error_rms_mps", "position_error_max_abs_settled_m",
        "position_error_rms_settled_m", "velocity_error_max_abs_settled_mps"})
    EXPECT_TRUE(j[key].is_null()) << key << " = " << j[key];
  EXPECT_EQ(j["steps"], 10);
  // Truth on some steps only: the metrics are over those (here e = 1e-3 - 0 on two steps).
  SummaryBuilder c(s);
  for (long k = 0; k < 10; ++k) {
    Record r;
    r.t = k * 1e-4;
    r.xd = 1e-3;
    r.x = (k == 3 || k == 7) ? 0.0 : nan;
    c.add(r);
  }
  const Summary m = c.summary(0.0, {});
  EXPECT_DOUBLE_EQ(m.position_error_max_abs_m, 1e-3);
  EXPECT_NEAR(m.position_error_rms_m, 1e-3, 1e-18);  // rms of two equal errors
}

TEST(Summary, MeasuredErrorMetricsInEveryRunAndWhichIsWhich) {
  // Without a true state the run's tracking error is xd - x_measured: max, RMS and p95 in the
  // same form. Ten steps with x_measured = xd - e_k, e_k = k * 1 um (k = 0..9): max 9 um,
  // RMS sqrt(sum k^2 / 10) um = sqrt(28.5) um, p95 = the value of rank floor(0.95 * 10) = 9 of
  // the sorted |e| (9 um; the histogram keeps it within 2^-11).
  Scenario s;
  s.control_period = 1e-4;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const bool truth : {false, true}) {
    SummaryBuilder b(s);
    for (long k = 0; k < 10; ++k) {
      Record r;
      r.t = k * 1e-4;
      r.xd = 1e-3;
      r.x_measured = 1e-3 - k * 1e-6;
      r.x = truth ? r.x_measured : nan;
      r.v = truth ? 0.0 : nan;
      b.add(r);
    }
    const auto j = nlohmann::json::parse(summary_json(b.summary(0.0, {}), s));
    EXPECT_NEAR(j["measured_position_error_max_abs_m"].get<double>(), 9e-6, 1e-15);
    EXPECT_NEAR(j["measured_position_error_rms_m"].get<double>(), std::sqrt(28.5) * 1e-6, 1e-15);
    EXPECT_NEAR(j["measured_position_error_p95_abs_m"].get<double>(), 9e-6, 9e-6 * std::ldexp(1.0, -11));
    EXPECT_EQ(j["error_source"], truth ? "true_state" : "measured");
    if (truth) {  // an ideal sensor: both the same
      EXPECT_EQ(j["position_error_max_abs_m"], j["measured_position_error_max_abs_m"]);
      EXPECT_EQ(j["position_error_rms_m"], j["measured_position_error_rms_m"]);
    } else {
      EXPECT_TRUE(j["position_error_max_abs_m"].is_null());
    }
  }
}

}  // namespace
}  // namespace feeddrive::sim

namespace feeddrive::sim {
namespace {

// Step and move metrics (summary.hpp, "Move metrics") on records of a known response: a step of
// D = 1 mm at t0 = 0.1 s followed by the underdamped second-order response
//   y(t') = D (1 - e^{-zeta wn t'} (cos wd t' + zeta/sqrt(1 - zeta^2) sin wd t')),  t' = t - t0,
// whose overshoot is exp(-pi zeta/sqrt(1 - zeta^2)) of D (at t' = pi/wd) and whose 10-90 % rise
// time and settling time to a 2 % band have no closed form: they are found here by bisection on
// the continuous y and compared with the sampled metrics within one sample period T (the
// summary sees y only at the steps; a crossing is reported at the first step past it).
TEST(Summary, StepMetricsOfASecondOrderResponse) {
  Scenario s;
  s.control_period = 1e-4;
  s.duration = 1.0;
  s.reference.type = ReferenceType::kStep;
  s.reference.step = {1e-3, 0.1, 0.0};
  const double D = 1e-3, t0 = 0.1, zeta = 0.3, wn = 60.0, wd = wn * std::sqrt(1 - zeta * zeta), T = 1e-4;
  const auto y = [&](double tp) {
    return tp < 0 ? 0.0
                  : D * (1 - std::exp(-zeta * wn * tp) *
                                 (std::cos(wd * tp) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * tp)));
  };
  SummaryBuilder b(s);
  for (long k = 0; k < 10000; ++k) {
    Record r;
    r.t = k * T;
    r.xd = r.t >= t0 ? D : 0.0;
    r.x = r.x_measured = y(r.t - t0);
    r.u = (k % 2) ? 1.0 : -1.0;  // a +-1 V command reversing every period: chatter
    b.add(r);
  }
  const Summary m = b.summary(1.0, plant::CvodeIntegrator::Stats{});
  // first t' with y(t') >= level, by bisection on [0, first peak] where y is increasing
  const auto first_at = [&](double level) {
    double lo = 0.0, hi = M_PI / wd;
    for (int i = 0; i < 200; ++i) ((y(0.5 * (lo + hi)) >= level) ? hi : lo) = 0.5 * (lo + hi);
    return hi;
  };
  EXPECT_NEAR(m.move_start_s, t0, 1e-12);
  EXPECT_NEAR(m.rise_time_s, first_at(0.9 * D) - first_at(0.1 * D), T);
  EXPECT_NEAR(m.overshoot_percent, 100.0 * std::exp(-M_PI * zeta / std::sqrt(1 - zeta * zeta)), 1e-3);
  EXPECT_DOUBLE_EQ(m.settling_band_m, 0.02 * D);
  // settling: the last t' where |y - D| > 2 % D, scanned finely (the envelope decays monotonically)
  double last_out = 0.0;
  for (double tp = 0.0; tp < 0.9; tp += 1e-6)
    if (std::abs(y(tp) - D) > 0.02 * D) last_out = tp;
  EXPECT_NEAR(m.settling_time_s, last_out, T);
  EXPECT_NEAR(m.settle_after_move_s, m.settling_time_s, 1e-12);   // a step ends where it starts
  EXPECT_NEAR(m.position_error_max_abs_during_move_m, D, 1e-15);  // the jump itself
  // after the move: the largest |D - y| after t0, the first undershoot below D: at t' = 0+ ~ D
  EXPECT_LE(m.position_error_max_abs_after_move_m, D);
  // +-1 V every period: every step of 2 V reverses the previous one (9998 reversals in 1 s)
  EXPECT_NEAR(m.control_reversals_per_s, 9998.0, 1e-9);
  EXPECT_TRUE(m.control_chattering);
  const auto j = nlohmann::json::parse(summary_json(m, s));
  EXPECT_TRUE(j["integrator_steps"].is_number());
  EXPECT_EQ(j["controller_model"], "plant");  // no controller.model: the plant's own parameters
  // The plant ran elsewhere (a monitor's record): its integrator counts are unknown, null.
  const auto jm = nlohmann::json::parse(summary_json(b.summary(1.0, {}), s));
  for (const char* key :
       {"integrator_steps", "integrator_rhs_evals", "integrator_jac_evals", "integrator_error_test_fails"})
    EXPECT_TRUE(jm[key].is_null()) << key;
}

TEST(Summary, MoveMetricsApplyOnlyToMoves) {
  // A sine reference is no move: every move metric null. A smooth command never chatters.
  Scenario s;
  s.control_period = 1e-4;
  s.reference.type = ReferenceType::kSine;
  SummaryBuilder b(s);
  for (long k = 0; k < 1000; ++k) {
    Record r;
    r.t = k * 1e-4;
    r.xd = std::sin(r.t);
    r.x = r.x_measured = r.xd;
    r.u = std::sin(10 * r.t);
    b.add(r);
  }
  const auto j = nlohmann::json::parse(summary_json(b.summary(0.1, {}), s));
  for (const char* key :
       {"move_start_s", "move_end_s", "rise_time_s", "overshoot_m", "settling_time_s", "settling_band_m",
        "position_error_max_abs_during_move_m", "position_error_max_abs_after_move_m"})
    EXPECT_TRUE(j[key].is_null()) << key;
  EXPECT_EQ(j["control_reversals_per_s"], 0.0);
  EXPECT_EQ(j["control_chattering"], false);
}

// A move the run cuts off has no overshoot: null, never 0 (issue 23 review: 0.0 read as "none").
TEST(Summary, AMoveCutOffHasNoOvershoot) {
  Scenario s;
  s.control_period = 1e-4;
  s.reference.type = ReferenceType::kAccelLimited;  // default move: ends well after 0.05 s
  const auto ref = make_reference(s);
  ASSERT_GT(ref->end_time(), 0.1);
  SummaryBuilder b(s);
  for (long k = 0; k < 500; ++k) {  // 0.05 s of it
    Record r;
    r.t = k * 1e-4;
    r.xd = ref->sample(r.t).position;
    r.x = r.x_measured = r.xd;
    b.add(r);
  }
  const auto j = nlohmann::json::parse(summary_json(b.summary(0.1, {}), s));
  EXPECT_TRUE(j["move_start_s"].is_number());
  for (const char* key : {"overshoot_m", "overshoot_percent", "rise_time_s", "settling_time_s"})
    EXPECT_TRUE(j[key].is_null()) << key;
}

// Control-signal quality (summary.hpp, docs/scenario.md "Control-signal quality") on commands
// whose figures are known in closed form. Scenario{}: T = 1e-4 s, u in [-10, 10] V (delta = 0.2 V,
// h = 0.02 V), Ka*Kf = 260 N/V.
Summary signal_summary(
    double period, long n, const std::function<double(long)>& u,
    const std::function<bool(long)>& saturated = [](long) { return false; }) {
  Scenario s;
  s.control_period = period;
  SummaryBuilder b(s);
  for (long k = 0; k < n; ++k) {
    Record r;
    r.t = static_cast<double>(k) * period;
    r.u = u(k);
    r.u_unsaturated = saturated(k) ? 2.0 * r.u : r.u;
    b.add(r);
  }
  return b.summary(0.0, {});
}

TEST(Summary, SignalQualityOfASquareWave) {
  // +-1 V, toggling every 50 steps (a 100 Hz square wave) for 10,000 steps (1 s): 199 edges of
  // 2 V each among 9,999 differences; every edge after the first reverses the direction (198);
  // the first 250 steps marked saturated: 2.5 %.
  const Summary m = signal_summary(
      1e-4, 10000, [](long k) { return (k / 50) % 2 == 0 ? 1.0 : -1.0; }, [](long k) { return k < 250; });
  EXPECT_NEAR(m.control_step_rms_V, std::sqrt(199.0 * 4.0 / 9999.0), 1e-12);  // rounding only
  EXPECT_NEAR(m.control_direction_changes_per_s, 198.0, 1e-9);                // sim_time = 1 s
  EXPECT_NEAR(m.control_saturated_fraction, 0.025, 1e-15);
  EXPECT_DOUBLE_EQ(m.control_direction_band_V, 0.02);
  EXPECT_DOUBLE_EQ(m.force_hf_limit_N, 260.0 * 0.2);
  // 0.28 V RMS from step to step exceeds delta = 0.2 V; so does 2.5 % saturation: fails
  EXPECT_FALSE(m.control_signal_within_limits);
}

// |H| of the pre-warped bilinear 2nd-order Butterworth high-pass at f: w^2/sqrt(1 + w^4),
// w = tan(pi f T)/tan(pi f_c T) (the analog prototype at the warped frequency).
double highpass_gain(double f, double fc, double period) {
  const double w = std::tan(M_PI * f * period) / std::tan(M_PI * fc * period);
  return w * w / std::sqrt(1.0 + w * w * w * w);
}

TEST(Summary, SignalQualityOfSines) {
  const double T = 1e-4, A = 1.0;
  for (const double f : {2000.0, 100.0}) {
    // A cosine, so the high-pass (at rest on the first sample) starts without a jump in slope:
    // its start transient decays within ~0.2 ms (1/(sqrt2 pi f_c)) and carries < 1e-4 of the
    // energy of the 1 s run, hence the relative tolerance 1e-3 on the RMS.
    const Summary m = signal_summary(T, 10000, [&](long k) { return A * std::cos(2.0 * M_PI * f * k * T); });
    // du_k = -2A sin(w T/2) sin(w (k - 1/2) T): RMS sqrt2 A sin(w T/2) over whole periods
    EXPECT_NEAR(m.control_step_rms_V / (std::sqrt(2.0) * A * std::sin(M_PI * f * T)), 1.0, 1e-3) << f;
    // two turning points a period, the first direction taken without a count: 2f - 1 or 2f
    EXPECT_NEAR(m.control_direction_changes_per_s, 2.0 * f, 1.0) << f;
    EXPECT_NEAR(m.force_hf_rms_N / (260.0 * A / std::sqrt(2.0) * highpass_gain(f, 1000.0, T)), 1.0, 1e-3) << f;
    EXPECT_EQ(m.control_saturated_fraction, 0.0);
  }
  // 2 kHz at 1 V: 0.98 of 184 N RMS above 1 kHz, 4,000 changes/s: out of limits. 100 Hz at
  // 0.1 V: 0.0044 V step RMS, 200 changes/s, 0.17 N above 1 kHz: within.
  EXPECT_FALSE(signal_summary(T, 10000, [&](long k) {
                 return std::cos(2.0 * M_PI * 2000.0 * k * T);
               }).control_signal_within_limits);
  EXPECT_TRUE(signal_summary(T, 10000, [&](long k) {
                return 0.1 * std::cos(2.0 * M_PI * 100.0 * k * T);
              }).control_signal_within_limits);
}

TEST(Summary, SignalQualityOfAConstantAndOfASlowRate) {
  // A constant command: no change, no turning point, nothing above 1 kHz (exactly: the filter
  // starts at rest on the first sample and its numerator sums to 0).
  const Summary c = signal_summary(1e-4, 1000, [](long) { return 3.0; });
  EXPECT_EQ(c.control_step_rms_V, 0.0);
  EXPECT_EQ(c.control_direction_changes_per_s, 0.0);
  EXPECT_EQ(c.force_hf_rms_N, 0.0);
  EXPECT_TRUE(c.control_signal_within_limits);
  // Noise smaller than the band h = 0.02 V (+-0.009 V every step) is no change of direction.
  EXPECT_EQ(signal_summary(1e-4, 1000, [](long k) { return k % 2 ? 0.009 : -0.009; }).control_direction_changes_per_s,
            0.0);
  // At T = 1 ms nothing above 1 kHz is representable (Nyquist 500 Hz): null, never 0.
  Scenario s;
  s.control_period = 1e-3;
  SummaryBuilder b(s);
  for (long k = 0; k < 10; ++k) {
    Record r;
    r.t = k * 1e-3;
    r.u = r.u_unsaturated = (k % 2) ? 1.0 : -1.0;
    b.add(r);
  }
  const auto j = nlohmann::json::parse(summary_json(b.summary(0.0, {}), s));
  EXPECT_TRUE(j["force_hf_rms_N"].is_null());
  EXPECT_TRUE(j["control_step_rms_V"].is_number());
  EXPECT_EQ(j["control_signal_within_limits"], false);  // 2 V steps
  // One step has no step-to-step change: null.
  SummaryBuilder one(s);
  one.add(Record{});
  EXPECT_TRUE(nlohmann::json::parse(summary_json(one.summary(0.0, {}), s))["control_step_rms_V"].is_null());
}

// Every control-signal figure is a study metric (summary_metric_names(): what a study records
// per case and what report.metric may name), the null-able ones included.
TEST(Summary, SignalFiguresAreStudyMetrics) {
  const std::vector<std::string> names = summary_metric_names();
  for (const char* key : {"control_step_rms_V", "control_direction_changes_per_s", "control_saturated_fraction",
                          "force_hf_rms_N", "force_hf_limit_N"})
    EXPECT_NE(std::find(names.begin(), names.end(), key), names.end()) << key;
}

// The true/false verdicts are what a study's report.require may name (summary_flag_names), and
// none of them is a metric (a number).
TEST(Summary, VerdictsAreStudyFlagsNotMetrics) {
  const std::vector<std::string> flags = summary_flag_names();
  EXPECT_EQ(flags, (std::vector<std::string>{"control_chattering", "control_signal_within_limits"}));
  const std::vector<std::string> names = summary_metric_names();
  for (const std::string& f : flags) EXPECT_EQ(std::find(names.begin(), names.end(), f), names.end()) << f;
}

// The final line names a command outside the signal limits with its figures, and says nothing
// of a command within them.
TEST(Summary, HeadlineFlagsASignalOutsideTheLimits) {
  Scenario s;
  s.control_period = 1e-4;
  const auto line = [&](double amplitude) {
    SummaryBuilder b(s);
    for (long k = 0; k < 1000; ++k) {
      Record r;
      r.t = k * 1e-4;
      r.u = r.u_unsaturated = (k % 2) ? amplitude : -amplitude;
      b.add(r);
    }
    return summary_headline(summary_json(b.summary(0.0, {}), s));
  };
  // +-1 V every period over 0.1 s: 2 V steps, 998 direction changes (the first direction is not
  // one), 9,980 /s: outside
  EXPECT_NE(line(1.0).find("CONTROL SIGNAL OUTSIDE LIMITS (step rms 2 V, 9980 direction changes/s"), std::string::npos)
      << line(1.0);
  // +-0.005 V: under the band h and the limits: no flag
  EXPECT_EQ(line(0.005).find("OUTSIDE"), std::string::npos) << line(0.005);
}

}  // namespace
}  // namespace feeddrive::sim

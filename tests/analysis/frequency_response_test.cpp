// The stepped-sine frequency response (analysis/frequency_response.hpp) of a linear drive against
// the analytic linearised loop: a rigid mass with viscous friction only, the cascade controller
// (feedforward off, so that reference -> position is the feedback loop's), an ideal sensor, no
// delay. The loop is then linear and sampled, and its frequency response at the sample instants
// is exact in the z-domain (z = exp(j w T)):
//   plant, force F held over [t_k, t_k+1) (zero-order hold), a = c/m, alpha = exp(-a T):
//     v_{k+1} = alpha v_k + (1 - alpha)/c F_k
//     x_{k+1} = x_k + (1 - alpha)/a v_k + (T - (1 - alpha)/a)/c F_k
//   =>  V = Pv F,  Pv = ((1 - alpha)/c)/(z - alpha);   X = Px F,  Px = ((1 - alpha)/a Pv + (T - (1 - alpha)/a)/c)/(z - 1)
//   cascade (controller/cascade.cpp): e_v = kp (r - x) - v, F = m (kv e_v + ki I), I_{k+1} = I_k + T e_v
//   =>  F = m C(z) e_v,  C = kv + ki T/(z - 1)
//   loop at the force set-point L = m C (kp Px + Pv),  S = 1/(1 + L),
//   T = m C kp Px/(1 + L),  compliance G_d = X/F_d = Px/(1 + L).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <complex>

#include "feeddrive/analysis/frequency_response.hpp"

namespace feeddrive::analysis {
namespace {

using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

struct Analytic {
  cd closed_loop, compliance, loop, sensitivity;
};

Analytic analytic(const sim::Scenario& s, double f) {
  const double T = s.control_period, m = s.plant.mass, c = s.plant.effects.viscous_friction.viscous_Ns_per_m;
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
      "plant:\n  friction: {model: none}\n  effects: {viscous_friction: {viscous_Ns_per_m: 400.0}}\n"
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
    EXPECT_NE(frequency_response_table(s, r).find("force " + std::to_string(static_cast<int>(force)) + " N"), std::string::npos);
  }
  // presliding stiffer than sliding by more than 10 %
  EXPECT_GT(k[0], 1.1 * k[1]) << k[0] << " vs " << k[1];
}

}  // namespace
}  // namespace feeddrive::analysis

// Xie & Liang Sec. 5 (sliding-mode control) against the paper's figures and the independent
// check values of docs/paper-analysis.md Sec. 3. Three controller families:
//   smc_*       the paper's law with hard sgn at 20 us and the true z (Figs. 18-22);
//   smc_bl_*    sat(S/phi) with a near-deadbeat boundary layer at 10 kHz, true z;
//   beyond_*    the beyond-the-paper configuration: 10 kHz, bristle observer, 50 nm encoder,
//               model-based x/v/disturbance observer.
// The sub-um claims are inequalities (the paper is not self-consistent, notes Sec. 3.4).
#include <gtest/gtest.h>

#include <cmath>

#include "paper_util.hpp"

namespace feeddrive::paper {
namespace {

// Fraction of the samples with t in [t0, t1] where |e| <= bound.
double fraction_within(const PaperRun& r, double bound, double t0, double t1) {
  long in = 0, n = 0;
  for (const auto& q : r.r.records)
    if (q.t >= t0 && q.t <= t1) {
      ++n;
      if (std::abs(q.xd - q.x) <= bound) ++in;
    }
  return n > 0 ? static_cast<double>(in) / static_cast<double>(n) : 0.0;
}

constexpr double kJerkMoveEnd = 1.1006;  // s, the S-curve's duration (docs/trajectories.md)

// Fig. 18: 100 mm, 1 Hz sinusoid from rest. The ideal reaching dynamics dS/dt = -eta sgn S - kS,
// de/dt = S - lambda e from S0 = 0.2 pi m/s give max|e| = 6.84 mm (notes Sec. 3.3; a 1e-4 s ZOH
// gives 6.82 mm). 1 % band: covers the ZOH/continuous difference (0.3 %) and the um-level
// chatter of hard sgn; a wrong unit of eta (5 mm/s^2) gives 8.40 mm, far outside.
TEST(PaperClosedLoop, SineMaxErrorNearStartThenZero) {
  const PaperRun r = simulate("smc_sine");
  const double peak = r.max_abs_error(0.0, 0.1);
  EXPECT_NEAR(peak, 6.84e-3, 6.84e-3 * 0.01);
  EXPECT_DOUBLE_EQ(peak, r.sum.position_error_max_abs_m);  // the maximum is near the start
  // "Then -> 0": after the reaching phase (S reaches 0 at ~0.1 s, e decays with lambda = 50/s)
  // only the hard-sgn chatter is left, < 1 um (ours 0.41 um), i.e. < 1.5e-4 of the peak.
  EXPECT_LT(r.max_abs_error(0.5, 2.0), 1e-6);
}

// Fig. 19: 100 mm step at 1 s, qualitative only (notes Sec. 3.2). With exact cancellation the
// continuous-time response is monotonic (S0 = 5 m/s reaches 0 after ln(11)/10 = 0.24 s), so we
// check what the paper shows qualitatively: a huge control effort, a large speed error and a
// large friction transient, then convergence; and that our response does not overshoot (the
// paper's 135 mm overshoot comes from how it differentiated the step, see the doc).
TEST(PaperClosedLoop, StepQualitative) {
  const PaperRun r = simulate("smc_step");
  const double chatter = r.s.plant.mass * 5.0 / r.s.plant.thrust_gain();                   // m*eta/(Ka*Kf) = 1.96 V
  EXPECT_GT(r.sum.control_max, 5 * chatter);                                               // ours 23 V
  EXPECT_GT(r.sum.velocity_error_max_abs_mps, 0.5);                                        // ours 0.73 m/s
  EXPECT_GT(r.max_of([](const sim::Record& q) { return q.f_friction; }, 1.0, 2.0), 79.0);  // slides: F_f ~ Fc..Fs
  EXPECT_LT(r.max_of([](const sim::Record& q) { return std::abs(q.f_friction); }, 0.0, 0.99),
            10.0);                                        // presliding before
  EXPECT_LT(r.sum.max_position_m, 0.1 + 1e-6);            // no overshoot beyond chatter
  EXPECT_LT(std::abs(r.r.records.back().x - 0.1), 1e-6);  // converged
}

// Figs. 21-22, hard sgn at 20 us: max|e| <= 0.8 um, "mostly within +-0.2 um" (we require >= 75 %
// of the samples during the move; ours 89 %), u within (-2, 4), and fast switching (the chatter
// term +-m*eta flips S's sign at a fraction of the sample rate; we require > 5,000 flips/s).
TEST(PaperClosedLoop, HardSgnJerkLimitedMeetsTheJerkClaims) {
  const PaperRun r = simulate("smc_jerk_limited");
  EXPECT_LE(r.sum.position_error_max_abs_m, 0.8e-6);
  EXPECT_GE(fraction_within(r, 0.2e-6, 0.0, kJerkMoveEnd), 0.75);
  EXPECT_GT(r.sum.control_min, -2.0);
  EXPECT_LT(r.sum.control_max, 4.0);
  long flips = 0;
  for (std::size_t k = 1; k < r.r.records.size(); ++k)
    if (r.r.records[k].sliding * r.r.records[k - 1].sliding < 0) ++flips;
  EXPECT_GT(static_cast<double>(flips) / r.sum.sim_time_s, 5000.0);
}

// Fig. 20 under hard sgn: max|e| <= 4.4 um holds, but the paper's "accel-limited error > jerk-
// limited error" does not: the chatter (+-m*eta*T) dominates both (notes Sec. 3.4, ours 0.51 vs
// 0.62 um). Kept as a test so a change that alters this finding is noticed; the boundary-layer
// families below reproduce the ordering.
TEST(PaperClosedLoop, HardSgnCannotOrderAccelAboveJerk) {
  const double accel = simulate("smc_accel_limited").sum.position_error_max_abs_m;
  const double jerk = simulate("smc_jerk_limited").sum.position_error_max_abs_m;
  EXPECT_LE(accel, 4.4e-6);
  EXPECT_LT(accel, jerk);
}

// Fig. 23, hard sgn: the ramp's velocity error is the chatter, ~1e-4 m/s, far above 150 nm/s.
TEST(PaperClosedLoop, HardSgnCannotMeetTheRampVelocityClaims) {
  const PaperRun r = simulate("smc_ramp_all_forces");
  EXPECT_GT(r.sum.velocity_error_max_abs_settled_mps, 150e-9);
}

// Every sub-um claim at once, for one controller configuration.
void expect_all_sub_um_claims(const std::string& prefix) {
  SCOPED_TRACE(prefix);
  const PaperRun jerk = simulate(prefix + "jerk_limited");
  const PaperRun accel = simulate(prefix + "accel_limited");
  const PaperRun ramp = simulate(prefix + "ramp_all_forces");
  expect_sub_um_claims(jerk, accel, ramp);
  // Jerk-limited (Figs. 21-22): within 0.2 um for at least 75 % of the move.
  EXPECT_GE(fraction_within(jerk, 0.2e-6, 0.0, kJerkMoveEnd), 0.75);
}

TEST(PaperClosedLoop, BoundaryLayerMeetsEverySubMicronClaim) { expect_all_sub_um_claims("smc_bl_"); }

TEST(PaperClosedLoop, BeyondThePaperMeetsEverySubMicronClaim) { expect_all_sub_um_claims("beyond_"); }

// The beyond configuration is what the issue asks for: >= 1e-4 s period, the bristle observer
// (not the true z), 50 nm quantization, and >= 10x less chattering (control total variation)
// than the paper's hard sgn on the same move, both at the paper's 20 us and at the same 10 kHz.
TEST(PaperClosedLoop, BeyondConfigurationIsRealisticAndChattersTenTimesLess) {
  const PaperRun beyond = simulate("beyond_jerk_limited");
  const auto& c = beyond.s.controller.sliding_mode;
  EXPECT_GE(beyond.s.control_period, 1e-4);
  EXPECT_EQ(c.friction_state, controller::StateSource::kObserver);
  EXPECT_EQ(beyond.s.plant.sensor.quantization, 50e-9);
  EXPECT_FALSE(beyond.s.plant.sensor.ideal());
  // The controller never saw the true z: needs_truth() is false.
  EXPECT_FALSE(sim::make_controller(beyond.s)->needs_truth());

  const double tv_sgn_20us = simulate("smc_jerk_limited").sum.control_total_variation;
  sim::Scenario s10k = scenario("smc_jerk_limited");
  s10k.control_period = 1e-4;
  s10k.controller.sliding_mode.period = 1e-4;
  const double tv_sgn_10k = simulate(s10k).sum.control_total_variation;
  EXPECT_LE(beyond.sum.control_total_variation * 10, tv_sgn_20us);
  EXPECT_LE(beyond.sum.control_total_variation * 10, tv_sgn_10k);
}

// Fig. 23's force panels (notes Sec. 3.5): in presliding friction ~ sigma0*x + sigma1*v grows
// like 2.0 N/s * t (5 % band: z lags x by the creep term); ripple barely changes over 1 um
// (expected ~6e-4 N, we require < 5e-3 N); grinding exceeds friction (early slope ke*v = 20 N/s,
// 10x friction's).
TEST(PaperClosedLoop, RampForcesFrictionGrowsRippleFlatGrindingDominates) {
  const PaperRun r = simulate("smc_bl_ramp_all_forces");
  const double slope = (r.at(1.0).f_friction - r.at(0.5).f_friction) / 0.5;
  EXPECT_NEAR(slope, 2.0, 0.1);
  EXPECT_LT(std::abs(r.at(1.0).f_ripple - r.at(0.01).f_ripple), 5e-3);
  for (double t : {0.1, 0.5, 1.0}) EXPECT_GT(r.at(t).f_grinding, r.at(t).f_friction) << t;
}

}  // namespace
}  // namespace feeddrive::paper

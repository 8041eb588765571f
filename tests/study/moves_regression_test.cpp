// Regression bounds of the robustness study on every move (studies/robustness_moves.yaml, issue 24
// item 7; docs/robustness.md, "Every move, wider mismatch"): robust_smc's worst case of each move
// and its control-signal figures at those corners, and the recommended controller's
// (cascade_recommended, docs/controllers.md "Which controller, and where it holds") worst passing
// cases and the cases where it does not hold, run from the study file
// itself (the same resolved scenario as the study's case: same plant, encoder seed, delay and
// nominal model), so a change to a controller, the plant or the study shows here first.
//
// Tolerances. Every case is deterministic (seeded encoder noise, CVODE at fixed tolerances, a
// fixed control period): on this machine a rerun gives the same bits. The bounds are the figure
// measured by the study plus 10 %: room for another compiler or libm moving CVODE's adaptive
// steps (the error is a maximum over noise-driven samples, so it moves by a fraction of itself,
// not by rounding), small enough that a real regression of the size the docs would have to
// report (a tenth of the worst case) fails; and at least half of it (check()). The signal limits are checked as the
// verdict itself (control_signal_within_limits) and, where the controller is known to miss one, as a bound on its
// measured figure with the same 10 %: it must not get worse while the docs say how far over the limit it is.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "feeddrive/study/cases.hpp"
#include "feeddrive/study/runner.hpp"
#include "feeddrive/study/spec.hpp"

namespace feeddrive::study {
namespace {

const std::string kStudy = std::string(FEEDDRIVE_SOURCE_DIR) + "/studies/robustness_moves.yaml";

double metric(const Outcome& o, const std::string& key) {
  for (const auto& [k, v] : o.metrics)
    if (k == key) return v;
  ADD_FAILURE() << "no metric " << key;
  return NAN;
}

// A case of the study: controller and family by name, then the variation values it must have
// ("plant.mass" -> factor 0.7, "controller.computation_delay" -> "5.0e-4", ...).
struct Want {
  std::string key;
  double factor_or_value;
};

Outcome run(const Study& s, const std::string& controller, const std::string& family, const std::vector<Want>& want,
            long draw = -1) {
  Resolver resolver(s);
  for (const CaseSpec& c : expand(s)) {
    if (s.controllers[c.controller].name != controller || s.families[c.family].name != family || c.draw != draw)
      continue;
    bool match = true;
    for (const Want& w : want) {
      bool found = false;
      for (const Variation& v : c.variations)
        if (v.key == w.key) found = std::abs((v.scale ? v.factor : std::stod(v.value)) - w.factor_or_value) < 1e-12;
      match = match && found;
    }
    if (!match) continue;
    const Outcome o = run_case(*resolver.resolve(c).scenario);
    EXPECT_TRUE(o.ok) << o.error;
    return o;
  }
  ADD_FAILURE() << "no case " << controller << " / " << family;
  return {};
}

std::vector<Want> corner(double mass, double friction, double bristle, double delay) {
  return {{"plant.mass", mass},
          {"plant.friction.static_force", friction},
          {"plant.friction.bristle_stiffness", bristle},
          {"controller.computation_delay", delay}};
}

struct Expect {
  double max_um;             // measured max |e| [um]
  double step_rms_V;         // measured control_step_rms_V
  double direction_changes;  // measured control_direction_changes_per_s
  double force_hf_N;         // measured force_hf_rms_N
};

// The bounds: 10 % over each measured figure (header), the verdict exactly, and the step and
// force figures within their limits (robust_smc meets those two everywhere in the study).
void check(const Outcome& o, const Expect& e) {
  EXPECT_LE(metric(o, "position_error_max_abs_m") * 1e6, 1.1 * e.max_um);
  // And not far below it: half the measured figure means the case no longer is the study's
  // worst case (a variation that stopped reaching the plant, a changed move) or the controller
  // improved; either way the docs' figure is stale.
  EXPECT_GE(metric(o, "position_error_max_abs_m") * 1e6, 0.5 * e.max_um);
  EXPECT_LE(metric(o, "control_step_rms_V"), 1.1 * e.step_rms_V);
  EXPECT_LE(metric(o, "control_direction_changes_per_s"), 1.1 * e.direction_changes);
  EXPECT_LE(metric(o, "force_hf_rms_N"), 1.1 * e.force_hf_N);
  EXPECT_LE(metric(o, "control_step_rms_V"), metric(o, "control_chatter_threshold_V")) << "step RMS within its limit";
  EXPECT_LE(metric(o, "force_hf_rms_N"), metric(o, "force_hf_limit_N")) << "force above 1 kHz within its limit";
  EXPECT_EQ(metric(o, "control_saturated_fraction"), 0.0);
  // The direction-change limit (2,000 /s) is what robust_smc misses on every move: the verdict
  // stays false until a change fixes that (then this test and the docs change together).
  EXPECT_GT(metric(o, "control_direction_changes_per_s"), 2000.0);
  EXPECT_EQ(metric(o, "control_signal_within_limits"), 0.0);
}

// robust_smc (the most accurate law, docs/robustness.md, not the recommended controller: it misses the
// direction-change limit everywhere): its worst case of each move's 24 corners (a 100 nm encoder
// with 40 nm noise, seed 1; 500 us of delay in every one), and a Monte Carlo draw on two moves
// with encoder-noise seeds 3 and 2.
// Measured by `feeddrive-study studies/robustness_moves.yaml` (the figures of the docs' table).
// The robustness study, loaded once per test suite (each suite below names its fixture).
class MovesStudy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { study_ = new Study(load_study(kStudy)); }
  static void TearDownTestSuite() {
    delete study_;
    study_ = nullptr;
  }
  static Study* study_;
};
Study* MovesStudy::study_ = nullptr;
using RobustSmcWorstCase = MovesStudy;

TEST_F(RobustSmcWorstCase, JerkLimited) {  // mass -30 %, Fs/Fc -50 %, sigma0/sigma1 +50 %
  check(run(*study_, "robust_smc", "jerk_limited_corners", corner(0.7, 0.5, 1.5, 5e-4)), {0.269, 0.148, 4215, 23.7});
}
TEST_F(RobustSmcWorstCase, AccelLimited) {  // mass +50 %, Fs/Fc -50 %, sigma0/sigma1 +50 %
  check(run(*study_, "robust_smc", "accel_limited_corners", corner(1.5, 0.5, 1.5, 5e-4)), {0.692, 0.139, 3832, 22.4});
}
// The sine misses 0.8 um: the reversal (docs/controllers.md, "Velocity reversals"). The bound
// keeps it from getting worse; the docs state the 5.18 um.
TEST_F(RobustSmcWorstCase, SineWithReversals) {  // mass +50 %, Fs/Fc -50 %, sigma0/sigma1 +50 %
  check(run(*study_, "robust_smc", "sine_corners", corner(1.5, 0.5, 1.5, 5e-4)), {5.18, 0.149, 4427, 24.1});
}
TEST_F(RobustSmcWorstCase, FastScurve) {  // mass +50 %, Fs/Fc +50 %, sigma0/sigma1 -50 %: 1.13 um, over 0.8
  check(run(*study_, "robust_smc", "scurve_fast_corners", corner(1.5, 1.5, 0.5, 5e-4)), {1.13, 0.146, 4077, 23.5});
}
TEST_F(RobustSmcWorstCase, GrindingRamp) {  // mass -30 %, Fs/Fc -50 %, sigma0/sigma1 -50 %
  check(run(*study_, "robust_smc", "grinding_ramp_corners", corner(0.7, 0.5, 0.5, 5e-4)), {0.202, 0.142, 3542, 22.9});
}
TEST_F(RobustSmcWorstCase, GrindingInfeed) {  // mass -30 %, Fs/Fc +50 %, sigma0/sigma1 -50 %
  check(run(*study_, "robust_smc", "grinding_infeed_corners", corner(0.7, 1.5, 0.5, 5e-4)), {0.178, 0.138, 3665, 22.3});
}
// Other encoder-noise sequences: draw 1 (mass +21 %, Fs/Fc +43 %, 280 us of delay) with seed 3
// on the acceleration-limited move and seed 2 on the fast S-curve (the worst of draws 0 and 1).
TEST_F(RobustSmcWorstCase, MonteCarloOtherNoiseSeeds) {
  check(run(*study_, "robust_smc", "accel_limited_mc", {{"plant.sensor.seed", 3}}, 1), {0.323, 0.118, 3717, 18.9});
  check(run(*study_, "robust_smc", "scurve_fast_mc", {{"plant.sensor.seed", 2}}, 1), {0.669, 0.120, 3853, 19.3});
}

// The cascade on the observer with the Smith predictor and the 1 kHz velocity filter: the one
// configuration whose command meets every signal limit where it is stable. Within the limits and
// 0.8 um on its worst stable corner of the jerk-limited move; and the corner that breaks it
// (the plant 30 % lighter than the model with 500 us of delay: the predictor's model mass is
// wrong by 1/0.7 and the loop, tuned as if the delay were gone, limit-cycles in saturation),
// bounded so that a fix shows and the docs' statement is kept true.
TEST(CascadeObserverFiltered, WithinTheSignalLimitsWhereStableAndTheCornerThatBreaksIt) {
  const Study s = load_study(kStudy);
  const Outcome ok = run(s, "cascade_observer_vf", "jerk_limited_corners", corner(0.7, 1.5, 0.5, 0.0));
  EXPECT_LE(metric(ok, "position_error_max_abs_m") * 1e6, 1.1 * 0.372);  // measured 0.372 um
  EXPECT_EQ(metric(ok, "control_signal_within_limits"), 1.0);            // 0.049 V, 1,063 /s, 9.6 N
  EXPECT_LE(metric(ok, "control_direction_changes_per_s"), 1.1 * 1063);
  const Outcome broken = run(s, "cascade_observer_vf", "jerk_limited_corners", corner(0.7, 1.5, 1.5, 5e-4));
  // Measured 14.8 um with 46 % of the run in saturation: anything over 0.8 um and 1 % says "still
  // broken"; a fix (lower gains for a mass error, or a robust predictor) fails this on purpose.
  EXPECT_GT(metric(broken, "position_error_max_abs_m") * 1e6, 0.8);
  EXPECT_GT(metric(broken, "control_saturated_fraction"), 0.01);
  EXPECT_EQ(metric(broken, "control_signal_within_limits"), 0.0);
}

}  // namespace
}  // namespace feeddrive::study

namespace feeddrive::study {
namespace {

// The recommended controller (docs/controllers.md, "Which controller, and where it holds"): the
// cascade on the observer with the Smith predictor, a 2 kHz velocity filter and the rule's
// bandwidth x 0.6, chosen by the tuning procedure (docs/tuning.md) on a design set this study
// does not contain. Its worst passing case of a few families (within 0.8 um and every signal
// limit), and the cases where it does not hold, each run from studies/robustness_moves.yaml.
// Tolerances: the measured figure + 10 % as a bound on the error (the header: room for another
// libm or compiler moving CVODE's steps, a regression of a tenth fails); the verdicts exactly;
// the 0.8 um goal itself where the measured figure is within 10 % of it (0.721 um: the bound is
// then 0.793 um, so "passes" stays true); a failing case bounded from below (more than 0.8 um,
// or saturated), so that a fix shows here and the docs change with it.
//
// The four control-signal figures of each case (docs/scenario.md, "Control-signal quality"), as
// measured by the tuning test run (docs/tuning.md, the same cases): step RMS of du, direction
// changes per second, the force above 1 kHz and the saturated fraction. Each is bounded by the
// measured figure + 10 % (the same reason as the error: another libm or compiler moves CVODE's
// steps and the noise-driven samples by a fraction of the figure; a command that got noisier by
// a tenth fails) and from below by half of it (the figure stopped measuring this case: a metric
// that no longer counts, a filter or variation that stopped reaching the command). A saturated
// fraction measured 0 must stay exactly 0 (a passing case never touches the +-10 V rails; one
// saturated sample is a change in kind, not noise).
struct Signal {
  double step_rms_V;         // control_step_rms_V
  double direction_changes;  // control_direction_changes_per_s
  double force_hf_N;         // force_hf_rms_N
  double saturated;          // control_saturated_fraction
};

void expect_signal(const Outcome& o, const Signal& m) {
  const auto bounded = [&](const char* key, double measured) {
    EXPECT_LE(metric(o, key), 1.1 * measured) << key;
    EXPECT_GE(metric(o, key), 0.5 * measured) << key;
  };
  bounded("control_step_rms_V", m.step_rms_V);
  bounded("control_direction_changes_per_s", m.direction_changes);
  bounded("force_hf_rms_N", m.force_hf_N);
  if (m.saturated == 0.0) EXPECT_EQ(metric(o, "control_saturated_fraction"), 0.0);
  else bounded("control_saturated_fraction", m.saturated);
}

void expect_passes(const Outcome& o, double measured_um, const Signal& signal) {
  const double e_um = metric(o, "position_error_max_abs_m") * 1e6;
  EXPECT_LE(e_um, std::min(1.1 * measured_um, 0.8));
  EXPECT_GE(e_um, 0.5 * measured_um);  // half of it: no longer the family's worst passing case
  EXPECT_EQ(metric(o, "control_signal_within_limits"), 1.0);
  expect_signal(o, signal);
}

using RecommendedCascade = MovesStudy;

// The worst passing corner of the jerk-limited move (mass -30 %, Fs/Fc +50 %, sigma +50 %,
// 200 us: 0.561 um, 0.085 V, 1,274 /s, 15.4 N) and of the fast S-curve (mass -30 %, Fs/Fc and
// sigma -50 %, 200 us: 0.721 um), a move the tuner never saw.
// (0.077 V, 1,364 /s, 14.1 N).
TEST_F(RecommendedCascade, WorstPassingCorners) {
  expect_passes(run(*study_, "cascade_recommended", "jerk_limited_corners", corner(0.7, 1.5, 1.5, 2e-4)), 0.561,
                {0.0853, 1274, 15.40, 0.0});
  expect_passes(run(*study_, "cascade_recommended", "scurve_fast_corners", corner(0.7, 0.5, 0.5, 2e-4)), 0.721,
                {0.0768, 1364, 14.12, 0.0});
}

// The acceleration-limited move (a move the tuner never saw; the paper's 0.1 m at 0.4 m/s^2, a
// triangle to 0.2 m/s): its worst passing corner (mass +50 %, Fs/Fc -50 %, sigma -50 %, 500 us: 0.573 um,
// 0.047 V, 1,601 /s, 10.1 N), and its worst draw (draw 2: mass x0.77, Fs/Fc x0.58, 442 us, noise
// seed 2), which misses 0.8 um (0.932 um) with a command within every limit (0.138 V, 1,405 /s,
// 22.5 N): bounded from below by 0.8 um so that a fix shows here and the docs change with it.
TEST_F(RecommendedCascade, AccelLimited) {
  expect_passes(run(*study_, "cascade_recommended", "accel_limited_corners", corner(1.5, 0.5, 0.5, 5e-4)), 0.573,
                {0.0470, 1601, 10.10, 0.0});
  const Outcome draw = run(*study_, "cascade_recommended", "accel_limited_mc", {{"plant.sensor.seed", 2}}, 2);
  const double e_um = metric(draw, "position_error_max_abs_m") * 1e6;
  EXPECT_GT(e_um, 0.8);
  EXPECT_LE(e_um, 1.1 * 0.932);
  EXPECT_EQ(metric(draw, "control_signal_within_limits"), 1.0);
  expect_signal(draw, {0.1380, 1405, 22.47, 0.0});
}

// Both grinding moves pass in every case; their worst draw (mass x0.77, Fs/Fc x0.58, 442 us)
// with noise seeds 3 and 2: 0.667 and 0.648 um, step RMS 0.142 and 0.135 V (limit 0.2 V).
TEST_F(RecommendedCascade, GrindingMonteCarloWorstDraw) {
  expect_passes(run(*study_, "cascade_recommended", "grinding_ramp_mc", {{"plant.sensor.seed", 3}}, 2), 0.667,
                {0.1424, 1297, 24.22, 0.0});
  expect_passes(run(*study_, "cascade_recommended", "grinding_infeed_mc", {{"plant.sensor.seed", 2}}, 2), 0.648,
                {0.1352, 1325, 23.06, 0.0});
}

// Where it does not hold. (1) The plant 30 % lighter than the model with 500 us of delay: the
// Smith predictor runs on the model's mass and the loop limit-cycles in saturation (measured
// 11.4 um, 19.5 % of the run saturated, 1.51 V step RMS, 789 /s, 235 N on the jerk-limited move;
// its signal figures bounded like the others: a worse limit cycle fails, so does one that stops).
// (2) The sine: its worst corner (mass +50 %, Fs/Fc -50 %, sigma +50 %, 500 us) 3.39 um within
// every signal limit (0.050 V, 1,735 /s, 10.5 N): the start's acceleration step and the
// reversals (docs/controllers.md).
TEST_F(RecommendedCascade, WhereItDoesNotHold) {
  const Outcome light = run(*study_, "cascade_recommended", "jerk_limited_corners", corner(0.7, 1.5, 1.5, 5e-4));
  EXPECT_GT(metric(light, "position_error_max_abs_m") * 1e6, 0.8);
  EXPECT_GT(metric(light, "control_saturated_fraction"), 0.01);
  EXPECT_EQ(metric(light, "control_signal_within_limits"), 0.0);
  expect_signal(light, {1.514, 789.3, 235.2, 0.1951});
  const Outcome sine = run(*study_, "cascade_recommended", "sine_corners", corner(1.5, 0.5, 1.5, 5e-4));
  const double e_um = metric(sine, "position_error_max_abs_m") * 1e6;
  EXPECT_GT(e_um, 0.8);
  EXPECT_LE(e_um, 1.1 * 3.394);
  EXPECT_EQ(metric(sine, "control_signal_within_limits"), 1.0);
  expect_signal(sine, {0.04975, 1735, 10.48, 0.0});
}

}  // namespace
}  // namespace feeddrive::study

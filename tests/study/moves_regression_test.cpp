// Regression bounds of the robustness study on every move (studies/robustness_moves.yaml, issue 24
// item 7; docs/robustness.md, "Every move, wider mismatch"): robust_smc's worst case of each move
// and its control-signal figures at those corners; and the recommended controller's
// (cascade_recommended, docs/controllers.md "Which controller, and where it holds") worst passing
// cases and the cases where it does not hold on its blind test set (studies/tuning_test.yaml).
// Each runs from the study file itself (the same resolved scenario as the study's case: same
// plant, encoder seed, delay and nominal model), so a change to a controller, the plant or the
// study shows here first.
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
        if (v.key == w.key) {
          // A factor or a listed value; relative, since a value is a product (102.04 * 0.7)
          const double x = v.scale ? v.factor : std::stod(v.value);
          found = std::abs(x - w.factor_or_value) <= 1e-9 * std::max(1.0, std::abs(w.factor_or_value));
        }
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
// entry cascade_recommended of studies/robustness_moves.yaml (the one place that names it): the
// cascade on the x,v,d observer (1,000 rad/s) with the Smith predictor, a 2 kHz velocity filter,
// the rule's bandwidth x 0.6 and the friction level and inertia of its feedforward adapted online
// (gamma = 50 1/s), the family cascade_adaptive's choice of the tuning procedure (docs/tuning.md).
// Run on cases of its blind test set, studies/tuning_test.yaml (corner noise seed 31, Monte Carlo
// seed 2431 with noise seeds 41-43): the same resolved scenarios as the tuning test run, whose
// figures (docs/tuning/test_cases.csv) are the measured values below. The error is the tuning
// objective's: max |e| after the analysis window, t >= 0.1 s (position_error_max_abs_settled_m).
//
// Tolerances: the measured figure + 10 % as a bound on the error (the header: room for another
// libm or compiler moving CVODE's steps, a regression of a tenth fails), and at least half of it
// (the case stopped being the one the docs name); the verdicts exactly; the 0.8 um goal itself
// where the measured figure is within 10 % of it (0.781 um: the bound is then 0.8 um, so "passes"
// stays true); a failing case bounded from below by 0.8 um, so that a fix shows here and the
// docs change with it.
//
// The four control-signal figures of each case (docs/scenario.md, "Control-signal quality"), as
// measured by the tuning test run: step RMS of du, direction changes per second, the force above
// 1 kHz and the saturated fraction. Each is bounded by the measured figure + 10 % (the same
// reason as the error: another libm or compiler moves CVODE's steps and the noise-driven samples
// by a fraction of the figure; a command that got noisier by a tenth fails) and from below by
// half of it (the figure stopped measuring this case: a metric that no longer counts, a filter or
// variation that stopped reaching the command). A saturated fraction measured 0 must stay exactly
// 0 (none of these cases touches the +-10 V rails; one saturated sample is a change in kind, not
// noise).
const std::string kTestStudy = std::string(FEEDDRIVE_SOURCE_DIR) + "/studies/tuning_test.yaml";
const char* const kWindowed = "position_error_max_abs_settled_m";

struct Signal {
  double step_rms_V;         // control_step_rms_V
  double direction_changes;  // control_direction_changes_per_s
  double force_hf_N;         // force_hf_rms_N
};

void expect_signal(const Outcome& o, const Signal& m) {
  const auto bounded = [&](const char* key, double measured) {
    EXPECT_LE(metric(o, key), 1.1 * measured) << key;
    EXPECT_GE(metric(o, key), 0.5 * measured) << key;
  };
  bounded("control_step_rms_V", m.step_rms_V);
  bounded("control_direction_changes_per_s", m.direction_changes);
  bounded("force_hf_rms_N", m.force_hf_N);
  EXPECT_EQ(metric(o, "control_saturated_fraction"), 0.0);
  EXPECT_EQ(metric(o, "control_signal_within_limits"), 1.0);  // every case here: within every limit
}

void expect_passes(const Outcome& o, double measured_um, const Signal& signal) {
  const double e_um = metric(o, kWindowed) * 1e6;
  EXPECT_LE(e_um, std::min(1.1 * measured_um, 0.8));
  EXPECT_GE(e_um, 0.5 * measured_um);  // half of it: no longer the family's worst passing case
  expect_signal(o, signal);
}

// Where it does not hold: over 0.8 um (the docs say so, with this figure), within the signal limits.
void expect_misses(const Outcome& o, double measured_um, const Signal& signal) {
  const double e_um = metric(o, kWindowed) * 1e6;
  EXPECT_GT(e_um, 0.8);
  EXPECT_LE(e_um, 1.1 * measured_um);
  expect_signal(o, signal);
}

// A corner of the test set by its factors on the nominal drive (102.04 kg, Fs 120 N, sigma0
// 2e6 N/m; Fc and sigma1 move with them) and its delay [s]: the values its grid lists.
std::vector<Want> test_corner(double mass, double friction, double bristle, double delay) {
  return {{"plant.mass", 102.04 * mass},
          {"plant.friction.static_force", 120.0 * friction},
          {"plant.friction.bristle_stiffness", 2.0e6 * bristle},
          {"controller.computation_delay", delay}};
}

// The test set with the recommended controller as its one controller.
class RecommendedCascade : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Study moves = load_study(kStudy);
    study_ = new Study(load_study(kTestStudy));
    const auto it = std::find_if(moves.controllers.begin(), moves.controllers.end(),
                                 [](const ControllerEntry& c) { return c.name == "cascade_recommended"; });
    ASSERT_NE(it, moves.controllers.end()) << "studies/robustness_moves.yaml names no cascade_recommended";
    study_->controllers = {*it};
  }
  static void TearDownTestSuite() {
    delete study_;
    study_ = nullptr;
  }
  static Outcome test_case(const std::string& family, const std::vector<Want>& want, long draw = -1) {
    return run(*study_, "cascade_recommended", family, want, draw);
  }
  static Study* study_;
};
Study* RecommendedCascade::study_ = nullptr;

// The worst passing corner of the jerk-limited move (a design move, at a corner of the other
// fraction), and of the acceleration-limited move and the fast S-curve (moves the tuner never
// saw): the plant 30 % lighter with 500 us of delay, where the previous recommendation
// limit-cycled in saturation.
TEST_F(RecommendedCascade, WorstPassingCorners) {
  expect_passes(test_case("jerk_limited_corners", test_corner(0.7, 0.5, 0.5, 5e-4)), 0.6900, {0.02510, 877.3, 4.014});
  expect_passes(test_case("accel_limited_corners", test_corner(0.7, 0.5, 0.5, 5e-4)), 0.7811, {0.03107, 862.7, 4.741});
  expect_passes(test_case("scurve_fast_corners", test_corner(0.7, 1.5, 1.5, 5e-4)), 0.6907, {0.02320, 884.0, 3.836});
}

// Both grinding moves pass at every corner; their worst (light plant, Fs/Fc and sigma x0.5,
// 500 us): 0.770 and 0.763 um.
TEST_F(RecommendedCascade, GrindingWorstCorners) {
  expect_passes(test_case("grinding_ramp_corners", test_corner(0.7, 0.5, 0.5, 5e-4)), 0.7699, {0.05541, 733.3, 7.589});
  expect_passes(test_case("grinding_infeed_corners", test_corner(0.7, 0.5, 0.5, 5e-4)), 0.7631,
                {0.04928, 767.3, 6.881});
}

// Other encoder-noise sequences: the worst draw of the acceleration-limited Monte Carlo (draw 3:
// mass x1.43, Fs/Fc x0.74, 252 us; noise seed 42) and of the jerk-limited one (the same draw, seed 43).
TEST_F(RecommendedCascade, MonteCarloOtherNoiseSeeds) {
  expect_passes(test_case("accel_limited_mc", {{"plant.sensor.seed", 42}}, 3), 0.7038, {0.01154, 902.0, 2.403});
  expect_passes(test_case("jerk_limited_mc", {{"plant.sensor.seed", 43}}, 3), 0.1703, {0.01015, 930.0, 2.132});
}

// Where it does not hold (within every signal limit in each): the jerk-limited move at the light
// plant with Fs/Fc and sigma x1.5 and 500 us (1.003 um); the acceleration-limited move at the heavy
// plant, Fs/Fc x0.5, sigma x1.5, 500 us (1.068 um); the sine's worst corner (heavy, Fs/Fc x1.5,
// sigma x0.5, 500 us: 5.75 um, the reversals) and its worst draw (draw 1, noise seed 42: 1.81 um).
TEST_F(RecommendedCascade, WhereItDoesNotHold) {
  expect_misses(test_case("jerk_limited_corners", test_corner(0.7, 1.5, 1.5, 5e-4)), 1.0027, {0.03666, 832.0, 5.135});
  expect_misses(test_case("accel_limited_corners", test_corner(1.5, 0.5, 1.5, 5e-4)), 1.0683, {0.01390, 1012.7, 2.857});
  expect_misses(test_case("sine_corners", test_corner(1.5, 1.5, 0.5, 5e-4)), 5.7498, {0.01521, 1053.3, 2.943});
  expect_misses(test_case("sine_mc", {{"plant.sensor.seed", 42}}, 1), 1.8082, {0.01129, 903.3, 2.173});
}

}  // namespace
}  // namespace feeddrive::study

// Regression bounds of the robustness study on every move (studies/robustness_moves.yaml, issue 24
// item 7; docs/robustness.md, "Every move, wider mismatch"): robust_smc's worst case of each move
// and its control-signal figures at those corners; and the recommended controller's
// (`recommended`, scenarios/robustness/recommended.yaml; docs/controllers.md "Which controller,
// and where it holds") worst cases per move family on its blind test set (studies/tuning_test.yaml),
// passing or documented misses.
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
// entry `recommended` of studies/robustness_moves.yaml, i.e. scenarios/robustness/recommended.yaml
// (the one source of its settings): the robust SMC on the x,v,d observer (2,000 rad/s) with
// state prediction over the delay, phi = 8 mm/s and its friction level and inertia adapted online
// (gamma = 50 1/s), the tuning procedure's choice across families (docs/tuning.md, round 2).
// Run on cases of its blind test set, studies/tuning_test.yaml (corner noise seed 5119, Monte
// Carlo seed 7243 with noise seeds 6113-6115): the same resolved scenarios as the tuning test
// run, whose figures (docs/tuning/test_cases.csv) are the measured values below. Per move family
// (jerk-limited, acceleration-limited, sine, fast S-curve, grinding ramp, grinding infeed): the
// worst corner and the worst Monte Carlo draw by the objective's error (max |e| after t = 0.1 s),
// and the worst case over the whole run where it is another case; each checks BOTH errors (the
// windowed one and the whole run's) and the four signal figures.
//
// Tolerances, each figure (the header's reason): at most the measured figure + 10 % (another
// libm or compiler moves CVODE's steps and the noise-driven samples by a fraction of the figure;
// a regression of a tenth fails) and at least half of it (the case stopped being the one the docs
// name: a variation that no longer reaches the plant, a changed move). On top, the verdicts
// exactly as measured: an error measured within 0.8 um must stay within 0.8 um (the docs say it
// passes), one measured over 0.8 um must stay over it (a documented miss: a fix shows here and the
// docs change with it); control_signal_within_limits as measured (true or false); a saturated
// fraction measured 0 stays exactly 0 (one saturated sample is a change in kind, not noise).
const std::string kTestStudy = std::string(FEEDDRIVE_SOURCE_DIR) + "/studies/tuning_test.yaml";

struct Measured {
  double windowed_um;        // position_error_max_abs_settled_m [um] (t >= 0.1 s)
  double full_um;            // position_error_max_abs_m [um] (the whole run)
  double step_rms_V;         // control_step_rms_V
  double direction_changes;  // control_direction_changes_per_s
  double force_hf_N;         // force_hf_rms_N
  bool within_limits;        // control_signal_within_limits
};

void expect_figure(const Outcome& o, const char* key, double measured, double scale = 1.0) {
  EXPECT_LE(metric(o, key) * scale, 1.1 * measured) << key;
  EXPECT_GE(metric(o, key) * scale, 0.5 * measured) << key;
}

// An error [um] and its verdict against the 0.8 um goal, as measured.
void expect_error(const Outcome& o, const char* key, double measured_um) {
  expect_figure(o, key, measured_um, 1e6);
  if (measured_um <= 0.8) EXPECT_LE(metric(o, key) * 1e6, 0.8) << key << ": measured " << measured_um << " um, a pass";
  else EXPECT_GT(metric(o, key) * 1e6, 0.8) << key << ": measured " << measured_um << " um, a documented miss";
}

void expect_measured(const Outcome& o, const Measured& m) {
  expect_error(o, "position_error_max_abs_settled_m", m.windowed_um);
  expect_error(o, "position_error_max_abs_m", m.full_um);
  expect_figure(o, "control_step_rms_V", m.step_rms_V);
  expect_figure(o, "control_direction_changes_per_s", m.direction_changes);
  expect_figure(o, "force_hf_rms_N", m.force_hf_N);
  EXPECT_EQ(metric(o, "control_saturated_fraction"), 0.0);
  EXPECT_EQ(metric(o, "control_signal_within_limits"), m.within_limits ? 1.0 : 0.0);
}

// A corner of the test set by its plant values (mass [kg], Fs [N], sigma0 [N/m]; Fc and sigma1
// move with them in the grid's rows) and its delay [s]: the values its grid lists.
std::vector<Want> test_corner(double mass, double static_force, double bristle_stiffness, double delay) {
  return {{"plant.mass", mass},
          {"plant.friction.static_force", static_force},
          {"plant.friction.bristle_stiffness", bristle_stiffness},
          {"controller.computation_delay", delay}};
}

// The test set with the recommended controller as its one controller.
class RecommendedController : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Study moves = load_study(kStudy);
    study_ = new Study(load_study(kTestStudy));
    const auto it = std::find_if(moves.controllers.begin(), moves.controllers.end(),
                                 [](const ControllerEntry& c) { return c.name == "recommended"; });
    ASSERT_NE(it, moves.controllers.end()) << "studies/robustness_moves.yaml names no recommended";
    study_->controllers = {*it};
  }
  static void TearDownTestSuite() {
    delete study_;
    study_ = nullptr;
  }
  static Outcome test_case(const std::string& family, const std::vector<Want>& want, long draw = -1) {
    return run(*study_, "recommended", family, want, draw);
  }
  static Study* study_;
};
Study* RecommendedController::study_ = nullptr;

// The jerk-limited move (a design move, at new cases): its worst corner and worst draw, both passing.
// Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1 kHz; within the
// signal limits):
//   case 363: mass x0.7, Fs/Fc x1.5, sigma0 x1.5 / sigma1 x1.5, 500 us
//   case 376: draw 4, noise seed 6113: mass x0.816, Fs/Fc x0.675, sigma0 x0.672 / sigma1 x0.563, 230 us
TEST_F(RecommendedController, JerkLimited) {
  expect_measured(test_case("jerk_limited_corners", test_corner(71.428, 180.0, 3000000.0, 0.0005)),
                  {0.735, 0.735, 0.07712, 1734, 12.37, true});
  expect_measured(test_case("jerk_limited_mc", {{"plant.sensor.seed", 6113}}, 4),
                  {0.1945, 0.1945, 0.03203, 1355, 6.154, true});
}

// The acceleration-limited move (never seen by the tuner): the worst corner, a documented miss, and the worst draw.
// Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1 kHz; within the
// signal limits):
//   case 425: mass x1.5, Fs/Fc x0.5, sigma0 x1.5 / sigma1 x1.5, 500 us
//   case 435: draw 3, noise seed 6113: mass x1.43, Fs/Fc x0.523, sigma0 x1.11 / sigma1 x0.997, 317 us
TEST_F(RecommendedController, AccelLimited) {
  expect_measured(test_case("accel_limited_corners", test_corner(153.06, 60.0, 3000000.0, 0.0005)),
                  {1.097, 1.097, 0.03237, 1441, 6.4, true});
  expect_measured(test_case("accel_limited_mc", {{"plant.sensor.seed", 6113}}, 3),
                  {0.7709, 0.7709, 0.02939, 1377, 5.844, true});
}

// The sine's reversals, where it misses: the worst corner after the window and over the whole run, the worst draw after
// the window and over the whole run. Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1
// kHz; within the signal limits):
//   case 396: mass x1.5, Fs/Fc x1.5, sigma0 x0.5 / sigma1 x0.5, 500 us
//   case 395: mass x1.5, Fs/Fc x0.5, sigma0 x1.5 / sigma1 x1.5, 500 us
//   case 410: draw 2, noise seed 6114: mass x1.21, Fs/Fc x1.16, sigma0 x1.09 / sigma1 x0.59, 457 us
//   case 417: draw 3, noise seed 6115: mass x1.43, Fs/Fc x0.523, sigma0 x1.11 / sigma1 x0.997, 317 us
TEST_F(RecommendedController, SineWithReversals) {
  expect_measured(test_case("sine_corners", test_corner(153.06, 180.0, 1000000.0, 0.0005)),
                  {4.052, 4.052, 0.03435, 1627, 6.716, true});
  expect_measured(test_case("sine_corners", test_corner(153.06, 60.0, 3000000.0, 0.0005)),
                  {2.368, 4.92, 0.03493, 1579, 6.775, true});
  expect_measured(test_case("sine_mc", {{"plant.sensor.seed", 6114}}, 2), {2.395, 2.395, 0.03359, 1611, 6.611, true});
  expect_measured(test_case("sine_mc", {{"plant.sensor.seed", 6115}}, 3), {0.7834, 3.038, 0.03003, 1543, 5.846, true});
}

// The case nearest a signal limit (review, 27 November): the sine at mass x0.7, Fs/Fc x1.5,
// sigma0 x1.5 / sigma1 x1.5, 500 us (case 393), 1,945 direction changes/s against the limit of
// 2,000 (2.7 % below). The same case with encoder-noise seed 17 gives 2,008 /s (over the limit:
// docs/tuning.md), so this bound's upper side (x1.1 as for every figure) is looser than the limit;
// the exact verdict (within the limits, as measured) is what keeps the margin from being lost.
TEST_F(RecommendedController, NearestTheSignalLimit) {
  expect_measured(test_case("sine_corners", test_corner(71.428, 180.0, 3000000.0, 0.0005)),
                  {2.519, 2.519, 0.0765, 1945, 12.62, true});
}

// The fast S-curve: the worst corner after the window (a documented miss), the worst corner over the whole run (a
// documented miss: its acceleration phase, which the window mostly leaves out), the worst draw after the window and
// over the whole run. Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1 kHz; within the
// signal limits):
//   case 450: mass x0.7, Fs/Fc x0.5, sigma0 x0.5 / sigma1 x0.5, 500 us
//   case 456: mass x1.5, Fs/Fc x1.5, sigma0 x0.5 / sigma1 x0.5, 500 us
//   case 465: draw 3, noise seed 6113: mass x1.43, Fs/Fc x0.523, sigma0 x1.11 / sigma1 x0.997, 317 us
//   case 477: draw 3, noise seed 6115: mass x1.43, Fs/Fc x0.523, sigma0 x1.11 / sigma1 x0.997, 317 us
TEST_F(RecommendedController, FastScurve) {
  expect_measured(test_case("scurve_fast_corners", test_corner(71.428, 60.0, 1000000.0, 0.0005)),
                  {0.8413, 0.8522, 0.08039, 1671, 12.67, true});
  expect_measured(test_case("scurve_fast_corners", test_corner(153.06, 180.0, 1000000.0, 0.0005)),
                  {0.1879, 1.465, 0.03168, 1298, 6.348, true});
  expect_measured(test_case("scurve_fast_mc", {{"plant.sensor.seed", 6113}}, 3),
                  {0.3209, 0.5494, 0.02877, 1106, 5.717, true});
  expect_measured(test_case("scurve_fast_mc", {{"plant.sensor.seed", 6115}}, 3),
                  {0.2764, 0.5769, 0.02912, 1109, 5.833, true});
}

// The grinding ramp: the worst corner and the worst draw, both passing.
// Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1 kHz; within the
// signal limits):
//   case 480: mass x0.7, Fs/Fc x0.5, sigma0 x0.5 / sigma1 x0.5, 500 us
//   case 502: draw 4, noise seed 6114: mass x0.816, Fs/Fc x0.675, sigma0 x0.672 / sigma1 x0.563, 230 us
TEST_F(RecommendedController, GrindingRamp) {
  expect_measured(test_case("grinding_ramp_corners", test_corner(71.428, 60.0, 1000000.0, 0.0005)),
                  {0.2892, 0.2892, 0.03929, 1691, 7.351, true});
  expect_measured(test_case("grinding_ramp_mc", {{"plant.sensor.seed", 6114}}, 4),
                  {0.1879, 0.1879, 0.02909, 1121, 5.715, true});
}

// The grinding infeed: the worst corner and the worst draw, both passing.
// Measured (after 0.1 s, whole run; step RMS, direction changes/s, force above 1 kHz; within the
// signal limits):
//   case 510: mass x0.7, Fs/Fc x0.5, sigma0 x0.5 / sigma1 x0.5, 500 us
//   case 532: draw 4, noise seed 6114: mass x0.816, Fs/Fc x0.675, sigma0 x0.672 / sigma1 x0.563, 230 us
TEST_F(RecommendedController, GrindingInfeed) {
  expect_measured(test_case("grinding_infeed_corners", test_corner(71.428, 60.0, 1000000.0, 0.0005)),
                  {0.2941, 0.2941, 0.03906, 1713, 7.328, true});
  expect_measured(test_case("grinding_infeed_mc", {{"plant.sensor.seed", 6114}}, 4),
                  {0.1592, 0.1592, 0.02923, 1103, 5.773, true});
}

}  // namespace
}  // namespace feeddrive::study

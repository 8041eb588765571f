// Issue 10, points 3 and 6: the scenario's realism knobs (computation delay, honest encoder
// velocity, the cascade tuning rule) and the project's robust configuration
// (scenarios/robustness/robust_smc.yaml) on the hardest cases of the robustness study.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"
#include "scenario_error.hpp"

namespace feeddrive::sim {
namespace {

const std::string kRobust = std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/robustness/";

// computation_delay is applied by the drive as an input delay, added to a plant input_delay.
TEST(ComputationDelay, TheDriveAppliesItAsAnInputDelay) {
  const Scenario s = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
plant: {effects: {input_delay: {delay: 2.0e-4}}}
controller: {type: cascade, computation_delay: 1.5e-4}
)");
  EXPECT_EQ(s.controller.computation_delay, 1.5e-4);
  EXPECT_EQ(s.controller.cascade.computation_delay, 1.5e-4);
  const plant::PlantParams d = s.drive();
  EXPECT_TRUE(d.effects.input_delay.enabled);
  EXPECT_DOUBLE_EQ(d.effects.input_delay.delay, 3.5e-4);
  EXPECT_EQ(s.plant.effects.input_delay.delay, 2.0e-4) << "the plant as given is unchanged";
  // Without a plant delay the drive gets the computation delay alone; without either, none.
  const Scenario t =
      parse_scenario("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, computation_delay: 1e-3}\n");
  EXPECT_TRUE(t.drive().effects.input_delay.enabled);
  EXPECT_EQ(t.drive().effects.input_delay.delay, 1e-3);
  EXPECT_FALSE(parse_scenario("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade}\n")
                   .drive()
                   .effects.input_delay.enabled);
}

TEST(ComputationDelay, BadValuesAreOneLineErrors) {
  EXPECT_EQ(
      test::error_of("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, computation_delay: -1e-4}\n"),
      "s.yaml: controller.computation_delay = -1e-04: must be >= 0");
  EXPECT_EQ(test::error_of(
                "duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: sliding_mode, compensate_delay: true}\n"),
            "s.yaml: controller.compensate_delay = true: needs motion_state: observer (the model predictor)");
}

// An encoder measures position only: the true velocity is refused with quantization or noise.
TEST(SensorHonesty, AnEncoderHasNoTrueVelocity) {
  EXPECT_EQ(
      test::error_of("duration: 0.01\ncontrol_period: 1e-4\nplant: {sensor: {quantization: 5e-8, velocity: 'true'}}\n"
                     "controller: {type: cascade}\n"),
      "s.yaml: plant.sensor.velocity = 'true': an encoder with quantization or noise measures position only; "
      "use difference (or auto)");
  EXPECT_NO_THROW(parse_scenario(
      "duration: 0.01\ncontrol_period: 1e-4\nplant: {sensor: {velocity: 'true'}}\ncontroller: {type: cascade}\n"));
}

// tuning: rule sets kp, kv, ki from the period, the delay and the sensor (cascade_tuning());
// giving a gain as well is an error.
TEST(CascadeTuningKeys, RuleSetsTheGains) {
  const Scenario s = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
plant: {sensor: {quantization: 5e-8}}
controller: {type: cascade, tuning: rule, bandwidth_scale: 0.5, computation_delay: 1e-3}
)");
  const controller::CascadeGains g = controller::cascade_tuning(1e-4, 1e-3, true, 0.5);
  EXPECT_EQ(s.controller.cascade.kv, g.kv);
  EXPECT_EQ(s.controller.cascade.kp, g.kp);
  EXPECT_EQ(s.controller.cascade.ki, g.ki);
  EXPECT_EQ(
      test::error_of("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, tuning: rule, kv: 3000}\n"),
      "s.yaml: controller.kv: set by tuning: rule (remove it, or use tuning: manual)");
  // The observer's v^ is no difference (no T/2), the Smith predictor takes the delay out of the
  // loop (observer with compensate_delay), a velocity filter adds its time constant 1/(2 pi f_v).
  const Scenario o = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
plant: {sensor: {quantization: 5e-8}}
controller: {type: cascade, tuning: rule, computation_delay: 1e-3, motion_state: observer, compensate_delay: true,
             disturbance_observer_bandwidth: 2000, velocity_filter_cutoff: 2000}
)");
  const controller::CascadeGains go = controller::cascade_tuning(1e-4, 0.0, false, 1.0, 1.0 / (2.0 * M_PI * 2000.0));
  EXPECT_EQ(o.controller.cascade.kv, go.kv);
  EXPECT_EQ(o.controller.cascade.ki, go.ki);
  EXPECT_EQ(o.controller.cascade.motion_state, controller::MotionSource::kObserver);
  EXPECT_EQ(o.controller.cascade.velocity_filter_cutoff, 2000.0);
  // Without the observer the delay stays in tau; the filter's lag is added.
  const Scenario f = parse_scenario(
      "duration: 0.01\ncontrol_period: 1e-4\nplant: {sensor: {quantization: 5e-8}}\n"
      "controller: {type: cascade, tuning: rule, computation_delay: 1e-3, velocity_filter_cutoff: 1000}\n");
  EXPECT_EQ(f.controller.cascade.kv, controller::cascade_tuning(1e-4, 1e-3, true, 1.0, 1.0 / (2.0 * M_PI * 1000.0)).kv);
  EXPECT_EQ(
      test::error_of("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, motion_state: observer}\n"),
      "s.yaml: controller.motion_state = observer: needs disturbance_observer_bandwidth > 0 (the observer)");
  EXPECT_EQ(test::error_of("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, motion_state: guess}\n"),
            "s.yaml: controller.motion_state = 'guess': expected one of measured, observer");
  EXPECT_EQ(test::error_of("duration: 0.01\ncontrol_period: 1e-4\ncontroller: {type: cascade, tuning: fast}\n"),
            "s.yaml: controller.tuning = 'fast': expected one of manual, rule");
}

// max |xd - x| over the run [um].
double max_error_um(const RunResult& r) {
  double e = 0.0;
  for (const Record& rec : r.records) e = std::max(e, std::abs(rec.xd - rec.x));
  return e * 1e6;
}

// One corner of the robustness study's combination family: the 50 nm encoder with 20 nm noise,
// 1 ms of computation delay, and the plant's mass, Fs/Fc and sigma0/sigma1 scaled; the controller
// keeps the nominal model (pinned in both files) and knows its encoder (the study's rule).
Scenario corner(const std::string& file, double mass, double friction, double bristle) {
  Scenario s = load_scenario(kRobust + file);
  s.plant.sensor.quantization = 5e-8;
  s.plant.sensor.noise_stddev = 2e-8;
  s.plant.mass *= mass;
  s.plant.friction.static_force *= friction;
  s.plant.friction.coulomb_force *= friction;
  s.plant.friction.bristle_stiffness *= bristle;
  s.plant.friction.bristle_damping *= bristle;
  s.controller.computation_delay = 1e-3;
  s.controller.sliding_mode.computation_delay = 1e-3;
  s.controller.sliding_mode.model.sensor = s.plant.sensor;  // the observer's dead zone: one count
  return s;
}

// The issue-10 study's worst corner (docs/robustness.md, "Verdict"): 1 ms of computation delay
// with the 50 nm encoder and 20 nm noise, mass -20 %, Fs/Fc +30 %, sigma0/sigma1 -30 %. The ERROR
// claim holds: the robust SMC keeps 0.8 um (0.226 um) and is below the tuned cascade's 0.312 um,
// and so does its other opposite corner (Fs/Fc -30 %, sigma +30 %: 0.211 um). But NEITHER command
// is within the signal limits (docs/scenario.md, "Control-signal quality": 2,000 direction
// changes/s): the robust SMC changes direction 4,022 times a second, the cascade 5,836 (its
// differenced encoder velocity through kv). So neither passes: the test asserts both halves, so a
// report of "0.8 um in every case" as a pass fails here. The cascade's 0.312 is checked to
// 0.001 um (the study's rounding: the same, seeded scenario). The direction-change counts are
// bounded 10 % either side of the measured figures (deterministic runs; room for another libm
// moving CVODE's steps, not for a change that would move the verdict: both stay far over 2,000).
TEST(RobustConfiguration, WorstCornerKeepsTheErrorButBreaksTheSignalLimits) {
  Scenario c = corner("cascade_tuned.yaml", 0.8, 1.3, 0.7);
  c.controller.cascade.computation_delay = 1e-3;
  // The rule's gains for this delay and sensor (read_cascade sets them at load time, delay 0).
  const controller::CascadeGains g = controller::cascade_tuning(1e-4, 1e-3, true, 1.0);
  c.controller.cascade.kp = g.kp;
  c.controller.cascade.kv = g.kv;
  c.controller.cascade.ki = g.ki;
  c.controller.cascade.quantization = 5e-8;
  const RunResult rc = run(c);
  const double cascade = max_error_um(rc);
  EXPECT_NEAR(cascade, 0.312, 0.001) << "the study's number for this corner (the same scenario)";
  const Summary mc = summarize(rc, c);
  EXPECT_FALSE(mc.control_signal_within_limits) << "the tuned cascade's command breaks the limits here";
  EXPECT_NEAR(mc.control_direction_changes_per_s, 5836.0, 584.0);
  struct Corner {
    double friction, changes;  // Fs/Fc factor (sigma the opposite), measured direction changes/s
  };
  for (const Corner k : {Corner{0.7, NAN}, Corner{1.3, 4022.0}}) {
    const Scenario s = corner("robust_smc.yaml", 0.8, k.friction, 2.0 - k.friction);
    EXPECT_EQ(s.controller.sliding_mode.model.mass, 102.04) << "the model stays nominal";
    const RunResult r = run(s);
    const double e = max_error_um(r);
    SCOPED_TRACE("Fs,Fc x" + std::to_string(k.friction));
    EXPECT_LE(e, 0.8);
    EXPECT_LT(e, cascade) << "the tuned cascade's worst corner: " << cascade << " um";
    const Summary m = summarize(r, s);
    EXPECT_FALSE(m.control_signal_within_limits) << "the robust SMC's command breaks the limits: not a pass";
    EXPECT_GT(m.control_direction_changes_per_s, 2000.0);
    if (!std::isnan(k.changes)) {
      EXPECT_NEAR(m.control_direction_changes_per_s, k.changes, 0.1 * k.changes);
    }
  }
}

}  // namespace
}  // namespace feeddrive::sim

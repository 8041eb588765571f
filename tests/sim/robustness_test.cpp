// Issue 10, points 3 and 6: the scenario's realism knobs (computation delay, honest encoder
// velocity, the cascade tuning rule) and the project's robust configuration
// (scenarios/robustness/robust_smc.yaml) on the hardest cases of the robustness study.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
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
      "s.yaml: controller.computation_delay = -1e-4: must be >= 0");
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

double max_error_um(const Scenario& s) {
  const RunResult r = run(s);
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

// The robust configuration keeps the paper's 0.8 um on the jerk-limited move in the hardest
// corners of the robustness study (docs/controllers.md, "The robust configuration"): 1 ms of
// computation delay with the 50 nm encoder and 20 nm noise, mass -20 %, and Fs/Fc, sigma0/sigma1
// 30 % off in opposite directions, and it beats the tuned cascade's worst corner of the study
// (mass -20 %, Fs/Fc +30 %, sigma0/sigma1 -30 %: 0.312 um, docs/robustness.md). Measured: the
// robust SMC 0.211 um (Fs/Fc -30 %) and 0.226 um (Fs/Fc +30 %, the same corner as the cascade's
// worst). The bound is the cascade's own error in its worst corner, run here (the noise is seeded:
// both runs are deterministic, and the cascade's 0.312 is checked to 0.001 um, the rounding of the
// study's figure, so the test reproduces the study's case), so the test fails if either
// controller moves the other way.
TEST(RobustConfiguration, KeepsTheClaimAndBeatsTheTunedCascadesWorstCorner) {
  Scenario c = corner("cascade_tuned.yaml", 0.8, 1.3, 0.7);
  c.controller.cascade.computation_delay = 1e-3;
  // The rule's gains for this delay and sensor (read_cascade sets them at load time, delay 0).
  const controller::CascadeGains g = controller::cascade_tuning(1e-4, 1e-3, true, 1.0);
  c.controller.cascade.kp = g.kp;
  c.controller.cascade.kv = g.kv;
  c.controller.cascade.ki = g.ki;
  c.controller.cascade.quantization = 5e-8;
  const double cascade = max_error_um(c);
  EXPECT_NEAR(cascade, 0.312, 0.001) << "the study's number for this corner (the same scenario)";
  for (const double friction : {0.7, 1.3}) {
    const Scenario s = corner("robust_smc.yaml", 0.8, friction, 2.0 - friction);
    EXPECT_EQ(s.controller.sliding_mode.model.mass, 102.04) << "the model stays nominal";
    const double e = max_error_um(s);
    SCOPED_TRACE("Fs,Fc x" + std::to_string(friction));
    EXPECT_LE(e, 0.8);
    EXPECT_LT(e, cascade) << "the tuned cascade's worst corner: " << cascade << " um";
  }
}

}  // namespace
}  // namespace feeddrive::sim

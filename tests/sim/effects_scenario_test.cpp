// plant.effects in the scenario YAML: a map from effect name to its parameters; every bad input
// is one line naming the key (and the value).
#include <gtest/gtest.h>

#include <cmath>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "scenario_error.hpp"

namespace feeddrive::sim {
namespace {

std::string scenario_with_effects(const std::string& effects) {
  return R"(
duration: 0.01
control_period: 1e-4
plant:
  effects:
)" + effects +
         R"(
controller: {type: sliding_mode}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)";
}

using test::error_of;

TEST(ScenarioEffects, NoneByDefault) {
  const Scenario s = parse_scenario(scenario_with_effects("    {}"));
  EXPECT_FALSE(s.plant.effects.any());
}

TEST(ScenarioEffects, EveryEffectIsReadAndEnabledByBeingListed) {
  const Scenario s = parse_scenario(scenario_with_effects(R"(
    constant_force: {force_N: -3.5}
    coulomb_friction: {coulomb_N: 12}
    viscous_friction: {viscous_Ns_per_m: 40}
    stribeck_friction: {static_N: 30, coulomb_N: 20, stribeck_velocity_mps: 0.005}
    presliding: {bristle_stiffness_N_per_m: 1.5e6, bristle_damping_Ns_per_m: 900}
    cogging_ripple: {pitch_m: 0.024, amplitude_N: 2.0, phase_rad: 0.3, third_harmonic_N: 0.5, third_phase_rad: 0.1}
    reluctance_ripple: {pitch_m: 0.025, relative_amplitude: 0.02, phase_rad: 1.2}
    grinding_force: {gain_Ns_per_m: 5e6, stiffness_N_per_m: 3e7, contact_position_m: 0.001}
    spring_force: {stiffness_N_per_m: 250, rest_position_m: -0.02}
    mass_error: {mass_kg: 110}
    input_delay: {delay_s: 0.002})"));
  const plant::EffectsParams& e = s.plant.effects;
  EXPECT_TRUE(e.constant_force.enabled);
  EXPECT_EQ(e.constant_force.force_N, -3.5);
  EXPECT_TRUE(e.coulomb_friction.enabled);
  EXPECT_EQ(e.coulomb_friction.coulomb_N, 12.0);
  EXPECT_TRUE(e.viscous_friction.enabled);
  EXPECT_EQ(e.viscous_friction.viscous_Ns_per_m, 40.0);
  EXPECT_TRUE(e.stribeck_friction.enabled);
  EXPECT_EQ(e.stribeck_friction.static_N, 30.0);
  EXPECT_EQ(e.stribeck_friction.coulomb_N, 20.0);
  EXPECT_EQ(e.stribeck_friction.stribeck_velocity_mps, 0.005);
  EXPECT_TRUE(e.presliding.enabled);
  EXPECT_EQ(e.presliding.bristle_stiffness_N_per_m, 1.5e6);
  EXPECT_EQ(e.presliding.bristle_damping_Ns_per_m, 900.0);
  EXPECT_TRUE(e.cogging_ripple.enabled);
  EXPECT_EQ(e.cogging_ripple.pitch_m, 0.024);
  EXPECT_EQ(e.cogging_ripple.amplitude_N, 2.0);
  EXPECT_EQ(e.cogging_ripple.phase_rad, 0.3);
  EXPECT_EQ(e.cogging_ripple.third_harmonic_N, 0.5);
  EXPECT_EQ(e.cogging_ripple.third_phase_rad, 0.1);
  EXPECT_TRUE(e.reluctance_ripple.enabled);
  EXPECT_EQ(e.reluctance_ripple.pitch_m, 0.025);
  EXPECT_EQ(e.reluctance_ripple.relative_amplitude, 0.02);
  EXPECT_EQ(e.reluctance_ripple.phase_rad, 1.2);
  EXPECT_TRUE(e.grinding_force.enabled);
  EXPECT_EQ(e.grinding_force.gain_Ns_per_m, 5e6);
  EXPECT_EQ(e.grinding_force.stiffness_N_per_m, 3e7);
  EXPECT_EQ(e.grinding_force.contact_position_m, 0.001);
  EXPECT_TRUE(e.spring_force.enabled);
  EXPECT_EQ(e.spring_force.stiffness_N_per_m, 250.0);
  EXPECT_EQ(e.spring_force.rest_position_m, -0.02);
  EXPECT_TRUE(e.mass_error.enabled);
  EXPECT_EQ(e.mass_error.mass_kg, 110.0);
  EXPECT_TRUE(e.input_delay.enabled);
  EXPECT_EQ(e.input_delay.delay_s, 0.002);
  // The effects are the plant's discrepancy from the controller's model: the model has none.
  EXPECT_FALSE(s.controller.sliding_mode.model.effects.any());
  EXPECT_EQ(s.controller.sliding_mode.model.mass, s.plant.mass);
}

TEST(ScenarioEffects, OmittedParametersKeepTheDefaultsAndEnabledFalseSwitchesOff) {
  const Scenario s = parse_scenario(scenario_with_effects(R"(
    cogging_ripple: {amplitude_N: 4.0}
    mass_error:
    input_delay: {enabled: false, delay_s: 0.001})"));
  const plant::EffectsParams& e = s.plant.effects;
  EXPECT_TRUE(e.cogging_ripple.enabled);
  EXPECT_EQ(e.cogging_ripple.amplitude_N, 4.0);
  EXPECT_EQ(e.cogging_ripple.pitch_m, plant::CoggingRippleEffect{}.pitch_m);
  EXPECT_TRUE(e.mass_error.enabled);  // listed with no parameters: on, at the defaults
  EXPECT_EQ(e.mass_error.mass_kg, plant::MassErrorEffect{}.mass_kg);
  EXPECT_FALSE(e.input_delay.enabled);
  EXPECT_FALSE(e.constant_force.enabled);
}

TEST(ScenarioEffects, UnknownNamesAndKeysAreOneLineErrorsWithAHint) {
  EXPECT_EQ(error_of(scenario_with_effects("    coging_ripple: {pitch_m: 0.02}")),
            "s.yaml: plant.effects.coging_ripple: unknown key (did you mean 'cogging_ripple'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    backlash: {gap_m: 1e-6}")),
            "s.yaml: plant.effects.backlash: unknown key");
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {pitch: 0.02}")),
            "s.yaml: plant.effects.cogging_ripple.pitch: unknown key (did you mean 'pitch_m'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: {delay: 0.002}")),
            "s.yaml: plant.effects.input_delay.delay: unknown key (did you mean 'delay_s'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: 0.002")),
            "s.yaml: plant.effects.input_delay = '0.002': expected a map of keys");
  EXPECT_EQ(error_of(scenario_with_effects("    spring_force: {stiffness_N_per_m: abc}")),
            "s.yaml: plant.effects.spring_force.stiffness_N_per_m = 'abc': not a number");
  EXPECT_EQ(error_of(scenario_with_effects("    mass_error: {enabled: maybe}")),
            "s.yaml: plant.effects.mass_error.enabled = 'maybe': expected true or false");
}

TEST(ScenarioEffects, ValidationNamesKeyAndValue) {
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {pitch_m: -1}")),
            "s.yaml: plant.effects.cogging_ripple.pitch_m = -1: must be > 0");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: {delay_s: -0.5}")),
            "s.yaml: plant.effects.input_delay.delay_s = -0.5: must be >= 0");
  EXPECT_EQ(error_of(scenario_with_effects("    stribeck_friction: {static_N: 5, coulomb_N: 8}")),
            "s.yaml: plant.effects.stribeck_friction.static_N = 5: must be >= coulomb_N");
  EXPECT_EQ(error_of(scenario_with_effects("    mass_error: {mass_kg: 0}")),
            "s.yaml: plant.effects.mass_error.mass_kg = 0: must be > 0");
}

// The sliding-mode controller's model takes effects (a fitted model, docs/fit.md): they are read
// into the model, not the plant. The cascade's model does not (it uses mass and friction only).
TEST(ScenarioEffects, OnlyTheSlidingModeModelTakesEffects) {
  const Scenario s = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
controller: {type: sliding_mode, model: {effects: {constant_force: {force_N: 3}}}}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)",
                                    ".", "s.yaml");
  EXPECT_TRUE(s.controller.sliding_mode.model.effects.constant_force.enabled);
  EXPECT_EQ(s.controller.sliding_mode.model.effects.constant_force.force_N, 3.0);
  EXPECT_FALSE(s.plant.effects.any());
  const std::string yaml = R"(
duration: 0.01
control_period: 1e-4
controller: {type: cascade, model: {effects: {constant_force: {force_N: 3}}}}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)";
  EXPECT_EQ(error_of(yaml),
            "s.yaml: controller.model.effects: only the sliding_mode controller's model takes effects "
            "(e.g. those feeddrive-fit found); the cascade uses the model's mass and friction only");
}

// A closed-loop run with effects of every kind (additive, folded, delayed) completes with finite
// records, and the recorded thrust is the delayed one: 0 until the first command acts at t = d.
TEST(ScenarioEffects, ClosedLoopRunWithEffects) {
  const Scenario s = parse_scenario(scenario_with_effects(R"(
    constant_force: {force_N: 5}
    cogging_ripple: {amplitude_N: 2}
    presliding: {bristle_damping_Ns_per_m: 1e4}
    mass_error: {mass_kg: 95}
    input_delay: {delay_s: 2.5e-4})"));
  const RunResult r = run(s);
  ASSERT_EQ(r.records.size(), 100u);
  EXPECT_EQ(r.records[0].f_thrust, 0.0);
  EXPECT_EQ(r.records[2].f_thrust, 0.0);  // t = 2e-4 < d
  EXPECT_NE(r.records[3].f_thrust, 0.0);  // t = 3e-4: u_0 acts since 2.5e-4
  for (const Record& rec : r.records) {
    ASSERT_TRUE(std::isfinite(rec.x) && std::isfinite(rec.f_thrust)) << "t=" << rec.t;
  }
}

}  // namespace
}  // namespace feeddrive::sim

// plant.effects in the scenario YAML: a map from effect name to its parameters; every bad input
// is one line naming the key (and the value).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "feeddrive/sim/key_tables.hpp"
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

// Every effect with every parameter, in the plant's vocabulary (kNewSpelling) and in the spelling
// with unit suffixes it replaced (kOldSpelling, the fields' aliases): the same values.
const char* const kNewSpelling = R"(
    constant_force: {force: -3.5}
    coulomb_friction: {coulomb_force: 12}
    viscous_friction: {viscous: 40}
    stribeck_friction: {static_force: 30, coulomb_force: 20, stribeck_velocity: 0.005}
    presliding: {bristle_stiffness: 1.5e6, bristle_damping: 900}
    cogging_ripple: {pitch: 0.024, cogging_amplitude: 2.0, cogging_phase: 0.3, cogging_third: 0.5, cogging_third_phase: 0.1}
    reluctance_ripple: {pitch: 0.025, reluctance_amplitude: 0.02, reluctance_phase: 1.2}
    grinding_force: {damping: 5e6, stiffness: 3e7, contact_position: 0.001}
    spring_force: {stiffness: 250, rest_position: -0.02}
    mass_error: {mass: 110}
    input_delay: {delay: 0.002})";
const char* const kOldSpelling = R"(
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
    input_delay: {delay_s: 0.002})";

void expect_every_effect(const plant::EffectsParams& e) {
  EXPECT_TRUE(e.constant_force.enabled);
  EXPECT_EQ(e.constant_force.force, -3.5);
  EXPECT_TRUE(e.coulomb_friction.enabled);
  EXPECT_EQ(e.coulomb_friction.coulomb_force, 12.0);
  EXPECT_TRUE(e.viscous_friction.enabled);
  EXPECT_EQ(e.viscous_friction.viscous, 40.0);
  EXPECT_TRUE(e.stribeck_friction.enabled);
  EXPECT_EQ(e.stribeck_friction.static_force, 30.0);
  EXPECT_EQ(e.stribeck_friction.coulomb_force, 20.0);
  EXPECT_EQ(e.stribeck_friction.stribeck_velocity, 0.005);
  EXPECT_TRUE(e.presliding.enabled);
  EXPECT_EQ(e.presliding.bristle_stiffness, 1.5e6);
  EXPECT_EQ(e.presliding.bristle_damping, 900.0);
  EXPECT_TRUE(e.cogging_ripple.enabled);
  EXPECT_EQ(e.cogging_ripple.pitch, 0.024);
  EXPECT_EQ(e.cogging_ripple.cogging_amplitude, 2.0);
  EXPECT_EQ(e.cogging_ripple.cogging_phase, 0.3);
  EXPECT_EQ(e.cogging_ripple.cogging_third, 0.5);
  EXPECT_EQ(e.cogging_ripple.cogging_third_phase, 0.1);
  EXPECT_TRUE(e.reluctance_ripple.enabled);
  EXPECT_EQ(e.reluctance_ripple.pitch, 0.025);
  EXPECT_EQ(e.reluctance_ripple.reluctance_amplitude, 0.02);
  EXPECT_EQ(e.reluctance_ripple.reluctance_phase, 1.2);
  EXPECT_TRUE(e.grinding_force.enabled);
  EXPECT_EQ(e.grinding_force.damping, 5e6);
  EXPECT_EQ(e.grinding_force.stiffness, 3e7);
  EXPECT_EQ(e.grinding_force.contact_position, 0.001);
  EXPECT_TRUE(e.spring_force.enabled);
  EXPECT_EQ(e.spring_force.stiffness, 250.0);
  EXPECT_EQ(e.spring_force.rest_position, -0.02);
  EXPECT_TRUE(e.mass_error.enabled);
  EXPECT_EQ(e.mass_error.mass, 110.0);
  EXPECT_TRUE(e.input_delay.enabled);
  EXPECT_EQ(e.input_delay.delay, 0.002);
}

TEST(ScenarioEffects, EveryEffectIsReadAndEnabledByBeingListed) {
  const Scenario s = parse_scenario(scenario_with_effects(kNewSpelling));
  expect_every_effect(s.plant.effects);
  EXPECT_TRUE(s.renamed_keys.empty());
  for (const std::string& w : s.warnings) EXPECT_EQ(w.find("old spelling"), std::string::npos) << w;
  // The effects are the plant's discrepancy from the controller's model: the model has none.
  EXPECT_FALSE(s.controller.sliding_mode.model.effects.any());
  EXPECT_EQ(s.controller.sliding_mode.model.mass, s.plant.mass);
}

TEST(ScenarioEffects, OmittedParametersKeepTheDefaultsAndEnabledFalseSwitchesOff) {
  const Scenario s = parse_scenario(scenario_with_effects(R"(
    cogging_ripple: {cogging_amplitude: 4.0}
    mass_error:
    input_delay: {enabled: false, delay: 0.001})"));
  const plant::EffectsParams& e = s.plant.effects;
  EXPECT_TRUE(e.cogging_ripple.enabled);
  EXPECT_EQ(e.cogging_ripple.cogging_amplitude, 4.0);
  EXPECT_EQ(e.cogging_ripple.pitch, plant::CoggingRippleEffect{}.pitch);
  EXPECT_TRUE(e.mass_error.enabled);  // listed with no parameters: on, at the defaults
  EXPECT_EQ(e.mass_error.mass, plant::MassErrorEffect{}.mass);
  EXPECT_FALSE(e.input_delay.enabled);
  EXPECT_FALSE(e.constant_force.enabled);
}

TEST(ScenarioEffects, UnknownNamesAndKeysAreOneLineErrorsWithAHint) {
  EXPECT_EQ(error_of(scenario_with_effects("    coging_ripple: {pitch: 0.02}")),
            "s.yaml: plant.effects.coging_ripple: unknown key (did you mean 'cogging_ripple'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    backlash: {gap_m: 1e-6}")),
            "s.yaml: plant.effects.backlash: unknown key");
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {pich: 0.02}")),
            "s.yaml: plant.effects.cogging_ripple.pich: unknown key (did you mean 'pitch'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: {delays: 0.002}")),
            "s.yaml: plant.effects.input_delay.delays: unknown key (did you mean 'delay'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: 0.002")),
            "s.yaml: plant.effects.input_delay = '0.002': expected a map of keys");
  EXPECT_EQ(error_of(scenario_with_effects("    spring_force: {stiffness: abc}")),
            "s.yaml: plant.effects.spring_force.stiffness = 'abc': not a number");
  // An old spelling's value errors name the key as written.
  EXPECT_EQ(error_of(scenario_with_effects("    spring_force: {stiffness_N_per_m: abc}")),
            "s.yaml: plant.effects.spring_force.stiffness_N_per_m = 'abc': not a number");
  EXPECT_EQ(error_of(scenario_with_effects("    mass_error: {enabled: maybe}")),
            "s.yaml: plant.effects.mass_error.enabled = 'maybe': expected true or false");
}

TEST(ScenarioEffects, ValidationNamesKeyAndValue) {
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {pitch: -1}")),
            "s.yaml: plant.effects.cogging_ripple.pitch = -1: must be > 0");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: {delay: -0.5}")),
            "s.yaml: plant.effects.input_delay.delay = -0.5: must be >= 0");
  EXPECT_EQ(error_of(scenario_with_effects("    stribeck_friction: {static_force: 5, coulomb_force: 8}")),
            "s.yaml: plant.effects.stribeck_friction.static_force = 5: must be >= coulomb_force");
  EXPECT_EQ(error_of(scenario_with_effects("    mass_error: {mass: 0}")),
            "s.yaml: plant.effects.mass_error.mass = 0: must be > 0");
  // The effect's pitch is the ripple's (one declaration): the same hard bound.
  EXPECT_EQ(error_of(scenario_with_effects("    reluctance_ripple: {pitch: 30}")),
            "s.yaml: plant.effects.reluctance_ripple.pitch = 30: must be <= 10 m (mm?)");
}

// The sliding-mode controller's model takes effects (a fitted model, docs/fit.md): they are read
// into the model, not the plant. The cascade's model does not (it uses mass and friction only).
TEST(ScenarioEffects, OnlyTheSlidingModeModelTakesEffects) {
  const Scenario s = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
controller: {type: sliding_mode, model: {effects: {constant_force: {force: 3}}}}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)",
                                    ".", "s.yaml");
  EXPECT_TRUE(s.controller.sliding_mode.model.effects.constant_force.enabled);
  EXPECT_EQ(s.controller.sliding_mode.model.effects.constant_force.force, 3.0);
  EXPECT_FALSE(s.plant.effects.any());
  const std::string yaml = R"(
duration: 0.01
control_period: 1e-4
controller: {type: cascade, model: {effects: {constant_force: {force: 3}}}}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)";
  EXPECT_EQ(error_of(yaml),
            "s.yaml: controller.model.effects: only the sliding_mode controller's model takes effects "
            "(e.g. those feeddrive-fit found); the cascade uses the model's mass and friction only");
}

// The spellings with unit suffixes the effects had before they took the plant's names are the
// fields' aliases: read as the new keys, each one used a warning naming the old and the new key,
// and given under the new key (the presence facts speak one vocabulary).
TEST(ScenarioEffects, OldSpellingsAreReadWithOneWarningEach) {
  const Scenario s = parse_scenario(scenario_with_effects(kOldSpelling), ".", "s.yaml");
  expect_every_effect(s.plant.effects);
  ASSERT_EQ(s.renamed_keys.size(), 23u);  // every parameter of kOldSpelling, once
  EXPECT_EQ(s.renamed_keys.front(),
            "plant.effects.constant_force.force_N: old spelling of plant.effects.constant_force.force (deprecated: "
            "rename the key)");
  const auto warned = [&](const std::string& old, const std::string& now) {
    const std::string line = old + ": old spelling of " + now + " (deprecated: rename the key)";
    return std::count(s.warnings.begin(), s.warnings.end(), line) == 1;
  };
  EXPECT_TRUE(warned("plant.effects.cogging_ripple.amplitude_N", "plant.effects.cogging_ripple.cogging_amplitude"));
  EXPECT_TRUE(warned("plant.effects.cogging_ripple.phase_rad", "plant.effects.cogging_ripple.cogging_phase"));
  EXPECT_TRUE(warned("plant.effects.reluctance_ripple.phase_rad", "plant.effects.reluctance_ripple.reluctance_phase"));
  EXPECT_TRUE(warned("plant.effects.grinding_force.gain_Ns_per_m", "plant.effects.grinding_force.damping"));
  EXPECT_TRUE(warned("plant.effects.input_delay.delay_s", "plant.effects.input_delay.delay"));
  EXPECT_TRUE(s.given_keys.count("plant.effects.cogging_ripple.cogging_amplitude"));
  EXPECT_FALSE(s.given_keys.count("plant.effects.cogging_ripple.amplitude_N"));
  // The run's description (what feeddrive-study keys its cases by) is the same as with the new keys.
  ResolvedKeys old_keys, new_keys;
  parse_scenario(scenario_with_effects(kOldSpelling), ".", "s.yaml", &old_keys);
  parse_scenario(scenario_with_effects(kNewSpelling), ".", "s.yaml", &new_keys);
  EXPECT_EQ(old_keys, new_keys);
  // The sliding-mode controller's model reads them too.
  const Scenario m = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
controller: {type: sliding_mode, model: {effects: {cogging_ripple: {amplitude_N: 3}}}}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)");
  EXPECT_EQ(m.controller.sliding_mode.model.effects.cogging_ripple.cogging_amplitude, 3.0);
  EXPECT_EQ(m.renamed_keys,
            std::vector<std::string>{"controller.model.effects.cogging_ripple.amplitude_N: old spelling of "
                                     "controller.model.effects.cogging_ripple.cogging_amplitude (deprecated: rename "
                                     "the key)"});
}

TEST(ScenarioEffects, BothSpellingsOfOneKeyAreAOneLineError) {
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {amplitude_N: 2, cogging_amplitude: 3}")),
            "s.yaml: plant.effects.cogging_ripple.amplitude_N: old spelling of cogging_amplitude, which is given "
            "too: give cogging_amplitude only");
  EXPECT_EQ(error_of(scenario_with_effects("    input_delay: {delay: 1e-3, delay_s: 1e-3}")),
            "s.yaml: plant.effects.input_delay.delay_s: old spelling of delay, which is given too: give delay only");
}

// A near-miss of an old spelling is hinted at the key it became.
TEST(ScenarioEffects, DidYouMeanKnowsTheOldSpellings) {
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {amplitude_n: 2}")),
            "s.yaml: plant.effects.cogging_ripple.amplitude_n: unknown key (did you mean 'cogging_amplitude', "
            "formerly 'amplitude_N'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    mass_error: {mass_kgs: 90}")),
            "s.yaml: plant.effects.mass_error.mass_kgs: unknown key (did you mean 'mass', formerly 'mass_kg'?)");
  EXPECT_EQ(error_of(scenario_with_effects("    cogging_ripple: {cogging_amplitud: 2}")),
            "s.yaml: plant.effects.cogging_ripple.cogging_amplitud: unknown key (did you mean 'cogging_amplitude'?)");
}

// --set and feeddrive-study's cases (set_read_key) take an old spelling as its key, with the warning;
// a map that gives both spellings is refused as the file's is.
TEST(ScenarioEffects, SettingsTakeTheOldSpellings) {
  EXPECT_EQ(canonical_key("plant.effects.cogging_ripple.amplitude_N"),
            "plant.effects.cogging_ripple.cogging_amplitude");
  EXPECT_EQ(canonical_key("controller.model.effects.input_delay.delay_s"),
            "controller.model.effects.input_delay.delay");
  EXPECT_EQ(canonical_key("plant.ripple.cogging_amplitude"), "plant.ripple.cogging_amplitude");
  EXPECT_EQ(canonical_key("plant.effects.cogging_ripple.nonsense"), "plant.effects.cogging_ripple.nonsense");
  std::string note;
  canonical_key("plant.effects.mass_error.mass_kg", &note);
  EXPECT_EQ(note,
            "plant.effects.mass_error.mass_kg: old spelling of plant.effects.mass_error.mass (deprecated: "
            "rename the key)");

  Scenario s = read_scenario(scenario_with_effects("    {}"));
  set_read_keys(
      s, {{"plant.effects.cogging_ripple.amplitude_N", "2.5"}, {"plant.effects.input_delay", "{delay_s: 1e-3}"}});
  complete_read(s);
  EXPECT_TRUE(s.plant.effects.cogging_ripple.enabled);
  EXPECT_EQ(s.plant.effects.cogging_ripple.cogging_amplitude, 2.5);
  EXPECT_EQ(s.plant.effects.input_delay.delay, 1e-3);
  EXPECT_TRUE(s.given_keys.count("plant.effects.cogging_ripple.cogging_amplitude"));
  EXPECT_EQ(std::count_if(s.warnings.begin(), s.warnings.end(),
                          [](const std::string& w) { return w.find("old spelling") != std::string::npos; }),
            2);

  Scenario t = read_scenario(scenario_with_effects("    {}"));
  try {
    set_read_key(t, "plant.effects.cogging_ripple", "{amplitude_N: 1, cogging_amplitude: 2}");
    ADD_FAILURE() << "both spellings accepted";
  } catch (const ScenarioError& e) {
    EXPECT_STREQ(e.what(),
                 "plant.effects.cogging_ripple.amplitude_N: old spelling of "
                 "plant.effects.cogging_ripple.cogging_amplitude, which is given too: give "
                 "plant.effects.cogging_ripple.cogging_amplitude only");
  }
}

// The generated key table (docs/scenario.md) names each old spelling with its key.
TEST(ScenarioEffects, TheKeyTableListsTheOldSpellings) {
  std::string effects;
  for (const auto& [name, text] : key_tables())
    if (name == "plant.effects") effects = text;
  EXPECT_NE(
      effects.find("| `cogging_ripple.cogging_amplitude` | N | 0 | finite | -2000 … 2000 | ac, cogging amplitude; "
                   "formerly `amplitude_N` (still read, with a warning) |"),
      std::string::npos)
      << effects;
  // Each quantity the effect shares with a plant section has that section's unit, rule and range.
  EXPECT_NE(effects.find("| `presliding.bristle_stiffness` | N/m | 2e+06 | > 0 | 1000 … 1e+10 | sigma0, LuGre bristle "
                         "stiffness;"),
            std::string::npos);
}

// A closed-loop run with effects of every kind (additive, folded, delayed) completes with finite
// records, and the recorded thrust is the delayed one: 0 until the first command acts at t = d.
TEST(ScenarioEffects, ClosedLoopRunWithEffects) {
  const Scenario s = parse_scenario(scenario_with_effects(R"(
    constant_force: {force: 5}
    cogging_ripple: {cogging_amplitude: 2}
    presliding: {bristle_damping: 1e4}
    mass_error: {mass: 95}
    input_delay: {delay: 2.5e-4})"));
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

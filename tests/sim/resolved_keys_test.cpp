// The loader's resolved keys (feeddrive/sim/yaml_reader.hpp, scenario.hpp): every key a scenario
// run depends on, with its effective value, written back as YAML that loads to the same run.
// feeddrive-study keys its cases by this text, so it must be complete and stable.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "../support/scratch.hpp"
#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim {
namespace {

namespace fs = std::filesystem;

using feeddrive::test_support::slurp;

TEST(ResolvedKeys, DefaultsAreRecordedWithTheirValues) {
  ResolvedKeys keys;
  parse_scenario(R"(
duration: 0.01
control_period: 1e-4
controller: {type: sliding_mode, switching: sat}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
plant: {effects: {input_delay: {delay_s: 2.0e-4}}}
)",
                 ".", "s.yaml", &keys);
  // Given values, in shortest round-trip form.
  EXPECT_EQ(keys.at("control_period").text, "1e-04");
  EXPECT_EQ(keys.at("controller.switching").text, "sat");
  EXPECT_TRUE(keys.at("controller.switching").is_string);
  // Defaults the file never wrote (plant.mass 102.04 kg, docs/parameters.md), in both the plant
  // and the controller's model.
  EXPECT_EQ(keys.at("plant.mass").text, "102.04");
  EXPECT_EQ(keys.at("controller.model.mass").text, "102.04");
  EXPECT_EQ(keys.at("plant.grinding.contact_position").text, "-.inf");
  // A listed effect: switched on, with its parameter; an unlisted one leaves no key.
  EXPECT_EQ(keys.at("plant.effects.input_delay.enabled").text, "true");
  EXPECT_EQ(keys.at("plant.effects.input_delay.delay_s").text, "2e-04");
  for (const auto& [k, v] : keys) EXPECT_EQ(k.find("effects.spring"), std::string::npos) << k;
  // Only the keys of the chosen reference type.
  EXPECT_EQ(keys.count("reference.frequency"), 1u);
  EXPECT_EQ(keys.count("reference.max_jerk"), 0u);
}

// Every scenario of the repository: the resolved YAML loads back to the same keys, and writing
// those again gives the same bytes (the study's case hash is stable).
TEST(ResolvedKeys, EveryRepositoryScenarioRoundTrips) {
  int n = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(FEEDDRIVE_SOURCE_DIR) / "scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string text = slurp(entry.path());
    ResolvedKeys first;
    Scenario a;
    try {
      a = parse_scenario(text, entry.path().parent_path().string(), entry.path().string(), &first);
    } catch (const ScenarioError&) {
      continue;  // not a scenario (a fit model or a study)
    }
    const std::string yaml = resolved_yaml(first);
    ResolvedKeys second;
    const Scenario b = parse_scenario(yaml, "/nonexistent", "resolved", &second);
    EXPECT_EQ(first, second) << entry.path();
    EXPECT_EQ(yaml, resolved_yaml(second)) << entry.path();
    // Spot checks of the struct itself.
    EXPECT_EQ(a.steps(), b.steps());
    EXPECT_EQ(a.plant.mass, b.plant.mass);
    EXPECT_EQ(a.plant.friction.static_force, b.plant.friction.static_force);
    EXPECT_EQ(a.controller.type, b.controller.type);
    EXPECT_EQ(a.controller.sliding_mode.model.friction.coulomb_force,
              b.controller.sliding_mode.model.friction.coulomb_force);
    EXPECT_EQ(a.controller.cascade.kv, b.controller.cascade.kv);
    EXPECT_EQ(a.reference.type, b.reference.type);
    ++n;
  }
  EXPECT_GT(n, 20);
}

TEST(ResolvedKeys, StringsThatLookLikeOtherThingsSurvive) {
  ResolvedKeys keys;
  parse_scenario(R"(
name: "a: b, #c 'd'"
duration: 0.01
control_period: 1e-4
controller: {type: sliding_mode}
reference: {type: sine, amplitude: 0.1, frequency: 1.0}
)",
                 ".", "s.yaml", &keys);
  ResolvedKeys back;
  parse_scenario(resolved_yaml(keys), ".", "r.yaml", &back);
  EXPECT_EQ(back.at("name").text, "a: b, #c 'd'");
  EXPECT_EQ(keys, back);
}

// The keys are written from the struct (resolved_keys): what the YAML alone tells is kept as a
// fact of the struct (a listed effect, even switched off), and the keys a rule sets are left out.
TEST(ResolvedKeys, ComeFromTheStructAndItsFacts) {
  ResolvedKeys keys;
  const Scenario s = parse_scenario(R"(
duration: 0.01
control_period: 1e-4
plant: {ripple: paper, effects: {constant_force: {enabled: false}}}
controller: {type: cascade, tuning: rule, model: {mass: 90}}
reference: {type: step, amplitude: 1.0e-3}
)",
                                    ".", "s.yaml", &keys);
  EXPECT_EQ(keys, resolved_keys(s));
  // Listed but off: its keys describe the run; an effect not listed has none.
  EXPECT_EQ(s.listed_effects, std::set<std::string>{"plant.effects.constant_force"});
  EXPECT_EQ(keys.at("plant.effects.constant_force.enabled").text, "false");
  EXPECT_EQ(keys.count("plant.effects.spring_force.enabled"), 0u);
  // `ripple: paper` is the preset with its values (RippleParams::paper(): ac = 3 N).
  EXPECT_EQ(keys.at("plant.ripple.preset").text, "paper");
  EXPECT_EQ(keys.at("plant.ripple.cogging_amplitude").text, "3");
  // The tuning rule sets the gains: they are not keys of the run, its bandwidth_scale is.
  EXPECT_EQ(keys.count("controller.kp"), 0u);
  EXPECT_EQ(keys.count("controller.bandwidth_scale"), 1u);
  // The model: the given mass, the plant's values elsewhere, never the plant's effects.
  EXPECT_EQ(keys.at("controller.model.mass").text, "90");
  EXPECT_EQ(keys.at("controller.model.friction.static_force").text, keys.at("plant.friction.static_force").text);
  EXPECT_EQ(keys.count("controller.model.effects.constant_force.enabled"), 0u);
}

}  // namespace
}  // namespace feeddrive::sim

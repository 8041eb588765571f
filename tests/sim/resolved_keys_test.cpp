// The loader's resolved keys (feeddrive/sim/yaml_reader.hpp, scenario.hpp): every key a scenario
// run depends on, with its effective value, written back as YAML that loads to the same run.
// feeddrive-study keys its cases by this text, so it must be complete and stable.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

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

// feeddrive-study builds a case as a struct: the nominal scenario as read (parse_scenario's
// as_read), each setting set in it (set_read_key), derived and checked (complete_read). Where it
// sets a key, the keys must be those of the YAML with the same setting (set_key, then the
// loader), and the YAML must load; where it declines or fails, the study reads the YAML.
ResolvedKeys yaml_with(const std::string& text, const std::string& dir, const std::string& key,
                       const std::string& value) {
  YAML::Node root = load_yaml_strict(text);
  set_key(root, key, value);
  YAML::Emitter em;
  em << root;
  ResolvedKeys keys;
  parse_scenario(em.c_str(), dir, "s.yaml", &keys);
  return keys;
}

// Sets key = value both ways; true if the struct took it (and then the two agree).
bool struct_as_yaml(const std::string& text, const std::string& dir, const std::string& key, const std::string& value) {
  Scenario s;
  parse_scenario(text, dir, "s.yaml", nullptr, &s);
  try {
    if (!set_read_key(s, key, value)) return false;
    complete_read(s);
  } catch (const std::exception&) {
    EXPECT_THROW(yaml_with(text, dir, key, value), ScenarioError) << key << " = " << value;
    return false;
  }
  ResolvedKeys yaml;
  EXPECT_NO_THROW(yaml = yaml_with(text, dir, key, value)) << key << " = " << value;
  EXPECT_EQ(resolved_keys(s), yaml) << key << " = " << value;
  return true;
}

// Another value of a key of the same type: a number times 1.25 (an integer plus 1), a flag
// flipped, a name as it is.
std::string other_value(const ResolvedValue& v) {
  if (v.is_string) return v.text;
  if (v.text == "true") return "false";
  if (v.text == "false") return "true";
  if (v.text.find_first_of(".e") == std::string::npos && v.text.find("inf") == std::string::npos)
    return std::to_string(std::stol(v.text) + 1);
  if (v.text.find("inf") != std::string::npos) return "1.5";
  return std::to_string(std::strtod(v.text.c_str(), nullptr) * 1.25);
}

TEST(ResolvedKeys, ACaseSetAsAStructHasTheKeysOfItsYaml) {
  const fs::path dir = fs::path(FEEDDRIVE_SOURCE_DIR) / "scenarios";
  int by_struct = 0;
  int keys_tried = 0;
  for (const char* file : {"paper/smc_bl_jerk_limited.yaml", "fit/truth_cogging.yaml",
                           "analysis/cascade_tuned_feedback_only.yaml", "paper/open_loop_ripple_sine_130N.yaml"}) {
    const fs::path path = dir / file;
    const std::string text = slurp(path);
    ResolvedKeys keys;
    parse_scenario(text, path.parent_path().string(), file, &keys);
    for (const auto& [k, v] : keys) {
      ++keys_tried;
      if (struct_as_yaml(text, path.parent_path().string(), k, other_value(v))) ++by_struct;
    }
  }
  // Most keys of a run are plain values of the lists (the rest: types, presets, files, the
  // timing keys read_timing checks): the struct must take them, not leave every case to YAML.
  EXPECT_GT(by_struct, keys_tried / 2) << by_struct << " of " << keys_tried;
}

TEST(ResolvedKeys, ASetStructKeyFollowsTheReadersRules) {
  const std::string base = R"(
duration: 0.01
control_period: 1e-4
plant: {ripple: paper, effects: {constant_force: {force_N: 2}}}
controller: {type: sliding_mode, model: {friction: {static_force: 150}}}
reference: {type: step, amplitude: 1.0e-3}
)";
  // A plant value the model does not give follows into the model; one it gives does not.
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.mass", "90"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.friction.static_force", "130"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.model.mass", "80"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.effects.constant_force.force_N", "3"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.ripple.cogging_amplitude", "4"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.computation_delay", "2e-4"));
  // What only the YAML reader decides: declined (the study then reads the YAML).
  for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
           {"plant.ripple.preset", "none"},                // a preset sets the whole section
           {"plant.effects.spring_force.stiffness", "1"},  // listing an effect enables it
           {"controller.type", "cascade"},                 // another type's keys
           {"reference.frequency", "2"},                   // not a key of a step
           {"controller.computation_delay", "-1"},         // refused, quoting the value as written
           {"duration", "0.02"},                           // read_timing's rules
           {"plant.mass", "~"},                            // null in YAML
           {"plant.mass", "[1, 2]"},                       // a flow list
           {"plant.mas", "90"}}) {                         // unknown (did-you-mean comes from YAML)
    Scenario s;
    parse_scenario(base, ".", "s.yaml", nullptr, &s);
    EXPECT_FALSE(set_read_key(s, k, v)) << k << " = " << v;
  }
  // A value its accessor refuses: the reader's own error.
  Scenario s;
  parse_scenario(base, ".", "s.yaml", nullptr, &s);
  EXPECT_THROW(set_read_key(s, "plant.mass", "abc"), ScenarioError);
}

}  // namespace
}  // namespace feeddrive::sim

// The loader's resolved keys (feeddrive/sim/yaml_reader.hpp, scenario.hpp): every key a scenario
// run depends on, with its effective value, written back as YAML that loads to the same run.
// feeddrive-study keys its cases by this text, so it must be complete and stable.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/common/text.hpp"
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
plant: {effects: {input_delay: {delay: 2.0e-4}}}
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
  EXPECT_EQ(keys.at("plant.effects.input_delay.delay").text, "2e-04");
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

// The oracle: the YAML with the setting written into it, as the file would say it (a flow list or
// map read as YAML; a part set on `ripple: paper` keeps the preset), loaded by the reader. A case
// and --set build the scenario as a struct instead (read_scenario, set_read_key, complete_read);
// the two must give the same keys, or both refuse.
void yaml_set(YAML::Node& root, const std::string& key, const std::string& value) {
  const std::vector<std::string> parts = text::split(key, '.');
  YAML::Node cur = root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = cur[parts[i]];
    if (!next.IsDefined() || next.IsNull()) {
      cur[parts[i]] = YAML::Node(YAML::NodeType::Map);
    } else if (next.IsScalar() && parts[i] == "ripple") {
      YAML::Node m(YAML::NodeType::Map);
      m["preset"] = next.Scalar();
      cur[parts[i]] = m;
    } else if (!next.IsMap()) {
      throw ScenarioError(key + ": a single value, not a map of keys");
    }
    cur.reset(cur[parts[i]]);
  }
  cur[parts.back()] = value.find_first_of("[{") == 0 ? load_yaml_strict(value) : YAML::Node(value);
}

ResolvedKeys yaml_with(const std::string& text, const std::string& dir,
                       const std::vector<std::pair<std::string, std::string>>& sets) {
  YAML::Node root = load_yaml_strict(text);
  for (const auto& [key, value] : sets) yaml_set(root, key, value);
  YAML::Emitter em;
  em << root;
  ResolvedKeys keys;
  parse_scenario(em.c_str(), dir, "s.yaml", &keys);
  return keys;
}

// Sets the keys both ways; true if the struct took them (and then the two agree), false if both
// refuse (the struct with a one-line error naming the key).
bool struct_as_yaml(const std::string& text, const std::string& dir,
                    const std::vector<std::pair<std::string, std::string>>& sets) {
  Scenario s = read_scenario(text, dir, "s.yaml");
  std::vector<KeySetting> ks;
  for (const auto& [k, v] : sets) ks.push_back({k, v});
  const std::string what = sets.front().first + " = " + sets.front().second;
  try {
    set_read_keys(s, ks);
    complete_read(s);
  } catch (const ScenarioError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    EXPECT_THROW(yaml_with(text, dir, sets), ScenarioError) << what << ": the struct said " << e.what();
    return false;
  }
  ResolvedKeys yaml;
  EXPECT_NO_THROW(yaml = yaml_with(text, dir, sets)) << what;
  EXPECT_EQ(resolved_keys(s), yaml) << what;
  return true;
}
bool struct_as_yaml(const std::string& text, const std::string& dir, const std::string& key, const std::string& value) {
  return struct_as_yaml(text, dir, {{key, value}});
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
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", std::strtod(v.text.c_str(), nullptr) * 1.25);
  return buf;
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
  // Every key of a run is set through the struct (types, presets and files included), never
  // left to YAML; a few values refuse both ways (a tuning rule's gain, a type's required file).
  EXPECT_GT(by_struct, keys_tried * 9 / 10) << by_struct << " of " << keys_tried;
}

TEST(ResolvedKeys, ASetStructKeyFollowsTheReadersRules) {
  const std::string base = R"(
duration: 0.01
control_period: 1e-4
plant: {ripple: paper, effects: {constant_force: {force: 2}}}
controller: {type: sliding_mode, model: {friction: {static_force: 150}}}
reference: {type: step, amplitude: 1.0e-3}
)";
  // A plant value the model does not give follows into the model; one it gives does not.
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.mass", "90"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.friction.static_force", "130"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.model.mass", "80"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.effects.constant_force.force", "3"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.ripple.cogging_amplitude", "4"));
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.computation_delay", "2e-4"));
  // What the YAML reader decided alone before: now set in the struct, the same keys.
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.ripple.preset", "none"));                // a preset: the whole section
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.ripple", "none"));                       // its short form replaces it
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.effects.spring_force.stiffness", "1"));  // listed: on
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.effects.spring_force", "{}"));           // listed with its defaults
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.type", "cascade"));                 // another type's keys
  EXPECT_TRUE(struct_as_yaml(base, ".", {{"controller.kp", "50"}, {"controller.type", "cascade"}}));  // any order
  EXPECT_TRUE(struct_as_yaml(base, ".", {{"reference.type", "sine"}, {"reference.frequency", "2"}}));
  EXPECT_TRUE(struct_as_yaml(base, ".", "duration", "0.02"));                 // read_timing's rules
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.friction", "{model: none}"));  // a flow map replaces the part
  EXPECT_TRUE(struct_as_yaml(base, ".", "controller.model.friction", "{}"));  // an empty map: the part at the plant's
  EXPECT_TRUE(struct_as_yaml(base, ".", "output.columns", "[t, x, u]"));      // a flow list
  EXPECT_TRUE(struct_as_yaml(base, ".", "plant.grinding.enabled", "true"));   // a section made present
  EXPECT_TRUE(struct_as_yaml(base, ".", {{"controller.type", "cascade"}, {"controller.tuning", "rule"}}));
  // Refused both ways, one line naming the key: the struct never falls back to YAML.
  for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
           {"reference.frequency", "2"},            // not a key of a step
           {"controller.computation_delay", "-1"},  // refused, quoting the value as written
           {"plant.mass", "~"},                     // null in YAML
           {"plant.mass", "[1, 2]"},                // a flow list
           {"plant.mas", "90"},                     // unknown, with did-you-mean
           {"plant.ripple", "pape"},                // not a preset
           {"reference.type", "waypoints"},         // needs its file
           {"controller.type", "open_loop"}}) {     // the model given is not an open loop's key
    EXPECT_FALSE(struct_as_yaml(base, ".", k, v)) << k << " = " << v;
  }
  const auto error_of = [&](const std::string& k, const std::string& v) {
    Scenario s = read_scenario(base, ".", "s.yaml");
    try {
      set_read_key(s, k, v);
      complete_read(s);
    } catch (const ScenarioError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error_of("plant.mas", "90"), "plant.mas: unknown key (did you mean 'mass'?)");
  EXPECT_EQ(error_of("plant.mass", "abc"), "plant.mass = 'abc': not a number");
  EXPECT_EQ(error_of("plant.friction.model.x", "1"),
            "plant.friction.model.x: plant.friction.model is a single value in the scenario, not a map of keys");
  EXPECT_EQ(error_of("controller.type", "open_loop"),
            "controller.type = open_loop: controller.model is given and is not a key of open_loop");
  EXPECT_EQ(error_of("plant", "{mass: 90}"),
            "plant = {mass: 90}: a whole section is not set at once: set its keys (e.g. plant.mass=110)");
}

// The keys of each scenario shipped, set all at once through the struct to other values, give
// the keys of the YAML with the same settings.
TEST(ResolvedKeys, AllKeysOfAScenarioSetAtOnceAgreeWithItsYaml) {
  const fs::path dir = fs::path(FEEDDRIVE_SOURCE_DIR) / "scenarios";
  for (const char* file : {"paper/smc_bl_jerk_limited.yaml", "analysis/cascade_tuned_feedback_only.yaml"}) {
    const fs::path path = dir / file;
    const std::string text = slurp(path);
    ResolvedKeys keys;
    parse_scenario(text, path.parent_path().string(), file, &keys);
    std::vector<std::pair<std::string, std::string>> sets;
    for (const auto& [k, v] : keys)
      // (the reluctance parts x1.25 would break |af| + |bf| < 1)
      if (!v.is_string && k.rfind("plant.", 0) == 0 && k.find("reluctance") == std::string::npos)
        sets.emplace_back(k, other_value(v));
    EXPECT_TRUE(struct_as_yaml(text, path.parent_path().string(), sets)) << file;
  }
}

}  // namespace
}  // namespace feeddrive::sim

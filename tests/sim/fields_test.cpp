// The one list per params struct (common/fields.hpp): the reader, validate()'s ranges, the
// plausibility warnings and the docs' key tables all come from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <set>
#include <string>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/sim/key_tables.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "scenario_error.hpp"

namespace feeddrive::sim {
namespace {

using test::error_of;

std::string scenario(const std::string& controller, const std::string& reference, const std::string& plant = "{}") {
  return "duration: 0.01\ncontrol_period: 1e-4\nplant: " + plant + "\ncontroller: " + controller +
         "\nreference: " + reference + "\n";
}

// Every key a list declares is read by the loader (it appears among the resolved keys of a
// scenario of its controller and reference type), and every plant key the loader reads is listed:
// no key is spelled outside its list.
TEST(Fields, EveryListedKeyIsReadAndEveryReadKeyIsListed) {
  std::set<std::string> read;
  const std::pair<const char*, const char*> runs[] = {
      {"{type: sliding_mode}", "{type: sine}"},
      {"{type: cascade}", "{type: step}"},
      {"{type: cascade, tuning: rule}", "{type: accel_limited}"},
      {"{type: open_loop}", "{type: scurve}"},
      {"{type: sliding_mode}", "{type: ramp}"},
  };
  const std::string effects =
      "{effects: {constant_force: {}, coulomb_friction: {}, viscous_friction: {}, stribeck_friction: {}, presliding: "
      "{},"
      " cogging_ripple: {}, reluctance_ripple: {}, grinding_force: {}, spring_force: {}, mass_error: {}, input_delay: "
      "{}}}";
  for (const auto& [c, r] : runs) {
    ResolvedKeys keys;
    parse_scenario(scenario(c, r, effects), ".", "s.yaml", &keys);
    for (const auto& [k, v] : keys) read.insert(k);
  }
  {  // a plugin controller (a plugin that does nothing wrong) and the top level's sections
    ResolvedKeys keys;
    parse_scenario(scenario(std::string("{type: plugin, library: ") + FEEDDRIVE_TEST_PLUGIN + "}", "{type: none}") +
                       "analysis: {settled_after: 0.1}\noutput: {every: 2}\n",
                   ".", "s.yaml", &keys);
    for (const auto& [k, v] : keys) read.insert(k);
  }
  const std::vector<std::string> listed = listed_keys();
  // The map rows of the tables (a nested section's own row, "plant.friction", "analysis") are no
  // keys, their fields are; output.columns is a list, not a value of the run's description.
  const std::set<std::string> maps = {"analysis", "output", "output.columns"};
  for (const std::string& k : listed) {
    if (maps.count(k)) continue;
    if (k == "plant.effects" || k.rfind("plant.effects.", 0) == 0) {
      if (std::count(k.begin(), k.end(), '.') == 2) continue;  // plant.effects.<name>
    }
    EXPECT_TRUE(read.count(k)) << k << " is listed but the loader never reads it";
  }
  // Every key the loader reads is in a list, but for the rules of their own (docs/contributing.md):
  // a file name resolved against the scenario's folder and the plugin's own parameter names.
  // A controller's model is the plant's list (controller.model.mass is plant.mass).
  for (std::string k : read) {
    if (k == "controller.file" || k == "reference.file" || k.rfind("controller.parameters.", 0) == 0) continue;
    if (k.rfind("controller.model.", 0) == 0) k = "plant." + k.substr(17);
    EXPECT_NE(std::find(listed.begin(), listed.end(), k), listed.end()) << k << " is read but not in a list";
  }
  // The top level's and every type's keys among them (issue 22's review: they were spelled by hand).
  for (const char* k : {"name", "duration", "control_period", "analysis.settled_after", "analysis.settling_band",
                        "output.every", "controller.type", "controller.computation_delay", "controller.library",
                        "controller.u_min", "controller.u_max", "reference.type"})
    EXPECT_NE(std::find(listed.begin(), listed.end(), k), listed.end()) << k;
}

// Every old spelling of every list is respelled to its key by canonical_key (--set and
// feeddrive-study read it so), the registry of lists (sim/src/lists.hpp) being the key tables' one.
TEST(Fields, EveryOldSpellingOfEveryListIsItsKey) {
  const auto old = listed_old_spellings();
  ASSERT_FALSE(old.empty());
  for (const auto& [was, key] : old) {
    std::string note;
    EXPECT_EQ(canonical_key(was, &note), key) << was;
    EXPECT_NE(note.find("old spelling of " + key), std::string::npos) << note;
    EXPECT_EQ(canonical_key(key), key);
  }
  // The controller's model is the plant's list under another prefix.
  EXPECT_EQ(canonical_key("controller.model.effects.cogging_ripple.amplitude_N"),
            "controller.model.effects.cogging_ripple.cogging_amplitude");
}

// The one-line message of what f throws ("" and a failure if it does not throw).
template <typename F>
std::string thrown(F f) {
  try {
    f();
  } catch (const ScenarioError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ScenarioError";
  return "";
}

// The cascade's tuning keys: one rule (scenario_rules.hpp) for the file and --set, the list's
// range for bandwidth_scale (its .positive()) checked before the rule divides by it.
TEST(Fields, CascadeTuningKeysAreOneRule) {
  EXPECT_EQ(error_of(scenario("{type: cascade, tuning: rule, kp: 10}", "{type: none}")),
            "s.yaml: controller.kp: set by tuning: rule (remove it, or use tuning: manual)");
  EXPECT_EQ(error_of(scenario("{type: cascade, bandwidth_scale: 2}", "{type: none}")),
            "s.yaml: controller.bandwidth_scale: only with tuning: rule");
  EXPECT_EQ(error_of(scenario("{type: cascade, tuning: rule, bandwidth_scale: 0}", "{type: none}")),
            "s.yaml: controller.bandwidth_scale = 0: must be > 0");
  Scenario s = read_scenario(scenario("{type: cascade, tuning: rule}", "{type: none}"));
  EXPECT_EQ(thrown([&] { set_read_key(s, "controller.kv", "5"); }),
            "controller.kv: set by tuning: rule (remove it, or use tuning: manual)");
  EXPECT_EQ(thrown([&] { set_read_key(s, "controller.bandwidth_scale", "-1"); }),
            "controller.bandwidth_scale = -1: must be > 0");
  s = read_scenario(scenario("{type: cascade, kp: 100}", "{type: none}"));
  EXPECT_EQ(thrown([&] { set_read_key(s, "controller.tuning", "rule"); }),
            "controller.kp: set by tuning: rule (remove it, or use tuning: manual)");
}

// The top level's keys come from Scenario's list: the reader's required keys and ranges, the
// setter's did-you-mean, the units (feeddrive-study's axes) and the docs' Default cell.
TEST(Fields, TopLevelKeysComeFromTheList) {
  EXPECT_EQ(key_unit("duration"), "s");
  EXPECT_EQ(key_unit("control_period"), "s");
  EXPECT_EQ(key_unit("analysis.settled_after"), "s");
  EXPECT_EQ(key_unit("analysis.settling_band"), "m");
  EXPECT_EQ(key_unit("controller.computation_delay"), "s");
  EXPECT_EQ(key_unit("controller.u_max"), "V");
  const std::string good = scenario("{type: sliding_mode}", "{type: none}");
  EXPECT_EQ(error_of("control_period: 1e-4\ncontroller: {type: cascade}\n"), "s.yaml: duration: missing (required)");
  EXPECT_EQ(error_of("duration: 1\ncontrol_period: 1e-4\ncontroller: {}\n"),
            "s.yaml: controller.type: missing (required)");
  // A misspelt required key is named (the review of issue 22: it was reported as missing only).
  EXPECT_EQ(error_of("duration: 1\ncontrl_period: 1e-4\ncontroller: {type: cascade}\n"),
            "s.yaml: control_period: missing (required); 'contrl_period' is given: a misspelling of it?");
  EXPECT_EQ(error_of("duration: 1\ncontrol_period: 1e-4\ncontroller: {typ: cascade}\n"),
            "s.yaml: controller.type: missing (required); 'controller.typ' is given: a misspelling of it?");
  EXPECT_EQ(error_of(scenario("{type: open_loop, kind: csv, fiel: u.csv}", "{type: none}")),
            "s.yaml: controller.file = '': kind = csv needs a file; 'controller.fiel' is given: a misspelling of it?");
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: waypoints, fle: w.csv}")),
            "s.yaml: reference.file: missing (required); 'reference.fle' is given: a misspelling of it?");
  EXPECT_EQ(error_of(good + "analysis: {setled_after: 0.1}\n"),
            "s.yaml: analysis.setled_after: unknown key (did you mean 'settled_after'?)");
  EXPECT_EQ(error_of(good + "analysis: {settled_after: -1}\n"), "s.yaml: analysis.settled_after = -1: must be >= 0");
  Scenario s = read_scenario(good);
  EXPECT_EQ(thrown([&] { set_read_key(s, "duraton", "2"); }), "duraton: unknown key (did you mean 'duration'?)");
  EXPECT_EQ(thrown([&] { set_read_key(s, "analysis.settling_band", "-1"); }),
            "analysis.settling_band = -1: must be >= 0");
  EXPECT_EQ(thrown([&] { set_read_key(s, "output", "{every: 2}"); }),
            "output = {every: 2}: a whole section is not set at once: set its keys (e.g. output.every=10)");
  // --set's unknown keys get the hint of every key the section takes, as the file's reader gives.
  EXPECT_EQ(thrown([&] { set_read_key(s, "controller.computation_dely", "1e-4"); }),
            "controller.computation_dely: unknown key (did you mean 'computation_delay'?)");
  EXPECT_EQ(thrown([&] { set_read_key(s, "reference.tpye", "sine"); }),
            "reference.tpye: unknown key (did you mean 'type'?)");
  // One key in both spellings, in two settings, is refused as in a file.
  EXPECT_NE(thrown([&] {
              set_read_keys(s, {{"plant.effects.cogging_ripple.amplitude_N", "3"},
                                {"plant.effects.cogging_ripple.cogging_amplitude", "2"}});
            }).find("cogging_amplitude"),
            std::string::npos);
  s = read_scenario(good);  // a failed setting leaves its value: the caller stops (exit 2)
  set_read_key(s, "output.every", "5");
  set_read_key(s, "analysis.settled_after", "0.1");
  set_read_key(s, "controller.computation_delay", "2e-4");
  EXPECT_EQ(s.output.every, 5);
  EXPECT_DOUBLE_EQ(s.analysis.settled_after, 0.1);
  EXPECT_DOUBLE_EQ(s.controller.computation_delay, 2e-4);
  const auto tables = key_tables();
  ASSERT_EQ(tables.front().first, "scenario");
  EXPECT_NE(tables.front().second.find("| `duration` | s | required | required; > 0 |"), std::string::npos)
      << tables.front().second;
}

TEST(Fields, ValidateRangesComeFromTheList) {
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: sine}", "{mass: -1}")),
            "s.yaml: plant.mass = -1: must be > 0");
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: sine}", "{sensor: {quantization: 50}}")),
            "s.yaml: plant.sensor.quantization = 50: must be <= 1 m (um?)");
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: scurve, max_velocity: 1500}")),
            "s.yaml: reference.max_velocity = 1500: must be <= 1000 m/s (mm/s?)");
  EXPECT_EQ(error_of(scenario("{type: cascade, kv: -3}", "{type: sine}")), "s.yaml: controller.kv = -3: must be >= 0");
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: accel_limited, max_velocity: 0}")),
            "s.yaml: reference.max_velocity = 0: must be > 0");
}

TEST(Fields, EnumsAreReadByTheirNames) {
  const Scenario s =
      parse_scenario(scenario("{type: sliding_mode}", "{type: sine}", "{sensor: {velocity: difference}}"));
  EXPECT_EQ(s.plant.sensor.velocity, plant::VelocityMeasurement::kDifference);
  EXPECT_TRUE(s.plant.sensor.differenced_velocity());
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: sine}", "{sensor: {velocity: tacho}}")),
            "s.yaml: plant.sensor.velocity = 'tacho': expected one of auto, true, difference");
  EXPECT_EQ(error_of(scenario("{type: sliding_mode, switching: sign}", "{type: sine}")),
            "s.yaml: controller.switching = 'sign': expected one of sgn, sat, tanh");
}

// The cascade's tuning rule is applied after reading (controller::apply_tuning), from the
// model's sensor: differenced velocity halves... the loop delay grows by T/2 (cascade.hpp).
TEST(Fields, CascadeTuningRuleIsAppliedAfterReading) {
  const Scenario ideal = parse_scenario(scenario("{type: cascade, tuning: rule}", "{type: sine}"));
  const Scenario encoder =
      parse_scenario(scenario("{type: cascade, tuning: rule}", "{type: sine}", "{sensor: {quantization: 1e-7}}"));
  const controller::CascadeGains g = controller::cascade_tuning(1e-4, 0.0, false);
  EXPECT_DOUBLE_EQ(ideal.controller.cascade.kv, g.kv);
  EXPECT_DOUBLE_EQ(encoder.controller.cascade.kv, controller::cascade_tuning(1e-4, 0.0, true).kv);
  EXPECT_EQ(error_of(scenario("{type: cascade, tuning: rule, kp: 3}", "{type: sine}")),
            "s.yaml: controller.kp: set by tuning: rule (remove it, or use tuning: manual)");
}

// Issue 23: the ripple's parts are 0 unless the paper's ripple is named.
TEST(Fields, RippleIsZeroUnlessThePaperIsNamed) {
  const Scenario own = parse_scenario(
      scenario("{type: sliding_mode}", "{type: sine}", "{ripple: {enabled: true, cogging_amplitude: 6}}"));
  EXPECT_DOUBLE_EQ(own.plant.ripple.cogging_amplitude, 6.0);
  EXPECT_DOUBLE_EQ(own.plant.ripple.cogging_third, 0.0);
  EXPECT_DOUBLE_EQ(own.plant.ripple.reluctance_amplitude, 0.0);
  const Scenario paper = parse_scenario(scenario("{type: sliding_mode}", "{type: sine}", "{ripple: paper}"));
  EXPECT_TRUE(paper.plant.ripple.enabled);
  EXPECT_DOUBLE_EQ(paper.plant.ripple.cogging_amplitude, 3.0);
  EXPECT_DOUBLE_EQ(paper.plant.ripple.cogging_third, 1.0);
  EXPECT_DOUBLE_EQ(paper.plant.ripple.reluctance_amplitude, 0.03);
  EXPECT_DOUBLE_EQ(paper.plant.ripple.reluctance_third, 0.01);
  const Scenario paper6 = parse_scenario(
      scenario("{type: sliding_mode}", "{type: sine}", "{ripple: {preset: paper, cogging_amplitude: 6}}"));
  EXPECT_DOUBLE_EQ(paper6.plant.ripple.cogging_amplitude, 6.0);
  EXPECT_DOUBLE_EQ(paper6.plant.ripple.cogging_third, 1.0);
  // The resolved keys read back to the same ripple (feeddrive-study's cases).
  ResolvedKeys keys;
  parse_scenario(scenario("{type: sliding_mode}", "{type: sine}", "{ripple: paper}"), ".", "s.yaml", &keys);
  const Scenario back = parse_scenario(resolved_yaml(keys));
  EXPECT_DOUBLE_EQ(back.plant.ripple.cogging_third, 1.0);
  EXPECT_EQ(error_of(scenario("{type: sliding_mode}", "{type: sine}", "{ripple: papers}")),
            "s.yaml: plant.ripple = 'papers': expected a map of keys, or one of none, paper");
}

// flatten walks a list to (dotted key, value), nested structs, flags, integers and enums
// included, leaving out the keys it is told; unflatten sets a struct from such a table through
// the same list: the round trip is the same struct (fields::same), every field set once.
TEST(Fields, FlattenAndUnflattenRoundTripThroughTheList) {
  plant::PlantParams p;
  p.mass = 91.25;
  p.friction.model = plant::FrictionModel::kStatic;
  p.friction.stribeck_exponent = 1.3;
  p.friction.static_smoothing_shape = 0.75;
  p.ripple.enabled = true;
  p.sensor.seed = 123456789;
  p.sensor.velocity = plant::VelocityMeasurement::kDifference;
  p.integrator.max_steps = 777;
  p.grinding.contact_position = -std::numeric_limits<double>::infinity();
  const std::vector<fields::FlatValue> t = fields::flatten(p);
  const auto find = [&](const std::string& key) -> const fields::FlatValue* {
    for (const fields::FlatValue& v : t)
      if (v.key == key) return &v;
    return nullptr;
  };
  ASSERT_NE(find("friction.stribeck_exponent"), nullptr);
  EXPECT_EQ(find("friction.stribeck_exponent")->number, 1.3);
  EXPECT_EQ(find("friction.model")->name, "static");
  EXPECT_TRUE(find("friction.model")->is_name);
  EXPECT_EQ(find("ripple.enabled")->number, 1.0);
  EXPECT_EQ(find("integrator.max_steps")->number, 777.0);
  EXPECT_EQ(find("effects.constant_force.force")->number, 0.0);
  plant::PlantParams q;
  EXPECT_FALSE(fields::same(p, q));
  EXPECT_EQ(fields::unflatten(q, find), t.size());
  EXPECT_TRUE(fields::same(p, q));
  // Left out: a key and a whole section; the fields a table lacks keep their values.
  const std::vector<fields::FlatValue> part = fields::flatten(p, {"mass", "effects"});
  EXPECT_EQ(
      std::count_if(part.begin(), part.end(),
                    [](const fields::FlatValue& v) { return v.key == "mass" || v.key.rfind("effects.", 0) == 0; }),
      0);
  plant::PlantParams r;
  r.mass = 50.0;
  fields::unflatten(r, [&](const std::string& key) -> const fields::FlatValue* {
    for (const fields::FlatValue& v : part)
      if (v.key == key) return &v;
    return nullptr;
  });
  EXPECT_EQ(r.mass, 50.0);
  EXPECT_EQ(r.friction.stribeck_exponent, 1.3);
  // An enum's name it does not know: one line naming the key.
  fields::FlatValue bad{"friction.model", 0.0, "lugr", true};
  try {
    fields::unflatten(r, [&](const std::string& key) { return key == "friction.model" ? &bad : nullptr; });
    ADD_FAILURE() << "an unknown friction law was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "friction.model = 'lugr': expected one of lugre, static, none");
  }
}

TEST(Fields, KeyTablesListEverySection) {
  const auto tables = key_tables();
  ASSERT_FALSE(tables.empty());
  ASSERT_GT(tables.size(), 1u);
  EXPECT_EQ(tables[1].first, "plant");
  EXPECT_NE(tables[1].second.find("| `mass` | kg | 102.04 | > 0 | 0.5 … 5000 |"), std::string::npos);
  // A document with every table marked, each holding stale text.
  auto marked = [&](const std::string& skip) {
    std::string doc = "a\n";
    auto names = tables;
    names.emplace_back("columns", "");
    for (const auto& [name, text] : names)
      if (name != skip) doc += "<!-- keys: " + name + " (x) -->\nSTALE-TABLE\n<!-- /keys -->\n";
    return doc + "b\n";
  };
  const std::string out = with_key_tables(marked(""));
  EXPECT_EQ(out.find("STALE-TABLE"), std::string::npos);
  EXPECT_NE(out.find("| `velocity` | m/s |"), std::string::npos);
  EXPECT_EQ(with_key_tables(out), out);
}

// A table deleted with its marker is drift, not a smaller document (the review of issue 22).
TEST(Fields, KeyTablesMissingTableIsAnError) {
  std::string doc = "a\n";
  for (const auto& [name, text] : key_tables())
    if (name != "reference.step") doc += "<!-- keys: " + name + " (x) -->\nold\n<!-- /keys -->\n";
  try {
    with_key_tables(doc);
    FAIL() << "no error for the missing tables";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("key table(s) reference.step, columns: no marker"), std::string::npos)
        << e.what();
  }
  const std::string twice = doc + "<!-- keys: reference.ramp (x) -->\n<!-- /keys -->\n";
  EXPECT_THROW(with_key_tables(twice), std::invalid_argument);
}

}  // namespace
}  // namespace feeddrive::sim

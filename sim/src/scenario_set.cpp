// A scenario built as a struct: the file read once (read_scenario), each setting (--set, a study
// case's layers and variations) set in the struct through the sections' lists (set_read_key), then
// derived and checked (complete_read). No scenario goes through YAML text twice.

#include <algorithm>
#include <filesystem>
#include <map>

#include "feeddrive/common/text_file.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/yaml_archive.hpp"
#include "feeddrive/sim/yaml_reader.hpp"
#include "lists.hpp"
#include "scenario_rules.hpp"

namespace feeddrive::sim {
namespace {

namespace fs = std::filesystem;
using detail::gives;

// The value of a setting as the file would read it: a flow list or map (`[t, x]`, `{model:
// none}`) parsed as YAML, anything else the scalar as written; both through the emitter and the
// loader as a file's value is (so `~` and `null` are null).
YAML::Node value_node(const std::string& key, const std::string& value) {
  YAML::Node map(YAML::NodeType::Map);
  const std::size_t first = value.find_first_not_of(" \t");
  if (first != std::string::npos && (value[first] == '[' || value[first] == '{')) {
    try {
      map["v"] = load_yaml_strict(value);
    } catch (const std::exception& e) {
      throw ScenarioError(key + " = " + value + ": not a YAML list or map (" + e.what() + ")");
    }
  } else {
    map["v"] = value;
  }
  YAML::Emitter em;
  em << map;
  return load_yaml_strict(em.c_str())["v"];
}

// A value for a message: the scalar, or the list or map in flow style.
std::string shown(const YAML::Node& v) {
  if (v.IsScalar()) return v.Scalar();
  if (v.IsNull() || !v.IsDefined()) return "null";
  YAML::Emitter em;
  em << YAML::Flow << v;
  return em.c_str();
}

[[noreturn]] void refuse(const std::string& key, const YAML::Node& v, const std::string& why) {
  throw ScenarioError(key + " = " + shown(v) + ": " + why);
}

[[noreturn]] void unknown(const std::string& parent, const std::string& name, const std::vector<std::string>& names,
                          const std::map<std::string, std::string>& aliases = {}) {
  throw ScenarioError(detail::dotted(parent, name) + ": unknown key" + did_you_mean(name, names, aliases));
}

// A list's validate() (std::invalid_argument "KEY = VALUE: why") as the scenario's error.
template <typename F>
void checked(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
}

// A map of the one key `key` = v, for the reader's accessors.
YAML::Node one_key(const std::string& key, const YAML::Node& v) {
  YAML::Node map(YAML::NodeType::Map);
  map[key] = v;
  return map;
}

// The key and its maps are given (Scenario::given_keys).
void give(Scenario& s, const std::string& key) {
  for (std::size_t dot = key.find('.'); dot != std::string::npos; dot = key.find('.', dot + 1))
    s.given_keys.insert(key.substr(0, dot));
  s.given_keys.insert(key);
}

// Erases the keys below `prefix` from a set of dotted keys (given, listed).
void erase_below(std::set<std::string>& keys, const std::string& prefix) {
  for (auto it = keys.lower_bound(prefix + "."); it != keys.end() && it->rfind(prefix + ".", 0) == 0;)
    it = keys.erase(it);
}

// The keys given directly below `section` ("controller" -> "lambda", "model", ...).
std::vector<std::string> given_children(const Scenario& s, const std::string& section) {
  std::vector<std::string> out;
  for (auto it = s.given_keys.lower_bound(section + "."); it != s.given_keys.end(); ++it) {
    if (it->rfind(section + ".", 0) != 0) break;
    const std::string rest = it->substr(section.size() + 1);
    if (rest.find('.') == std::string::npos) out.push_back(rest);
  }
  return out;
}

// What a dotted path names in a struct's list.
enum class Found { kNone, kValue, kMap, kBelowValue };

// Finds the dotted path `rest` in a struct's list. A value field is set from `value`, read by the
// reader's own accessor (YamlReadArchive) from a map of that one key: the same value, or the same
// one-line error, as the key written in the file. A nested struct is only found (kMap).
class FieldSetArchive {
 public:
  FieldSetArchive(std::string parent, std::string rest, const YAML::Node& value)
      : parent_(std::move(parent)), rest_(std::move(rest)), value_(value) {}
  Found found() const { return found_; }
  // The one-line error of a path that names no value (kNone, kBelowValue).
  [[noreturn]] void fail() const {
    if (!error_.empty()) throw ScenarioError(error_);
    if (found_ == Found::kBelowValue)
      throw ScenarioError(detail::dotted(parent_, rest_) + ": " + below_ +
                          " is a single value in the scenario, not a map of keys");
    unknown(parent_, rest_.substr(0, rest_.find('.')), names_, aliases_);
  }

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const std::size_t dot = rest_.find('.');
    const std::string head = rest_.substr(0, dot);
    names_.push_back(f.meta.name);
    if (*f.meta.alias) aliases_[f.meta.alias] = f.meta.name;  // for the hint only: set_node respelled the key
    if (found_ != Found::kNone || head != f.meta.name) return;
    if constexpr (fields::is_serializable<T>::value) {
      if (dot == std::string::npos) {
        found_ = Found::kMap;
        return;
      }
      FieldSetArchive a(detail::dotted(parent_, head), rest_.substr(dot + 1), value_);
      f.value->Serialize(&a);
      found_ = a.found_;
      if (found_ == Found::kNone || found_ == Found::kBelowValue) {
        try {
          a.fail();
        } catch (const ScenarioError& e) {
          error_ = e.what();
        }
      }
    } else if (dot != std::string::npos) {
      found_ = Found::kBelowValue;
      below_ = detail::dotted(parent_, head);
    } else {
      MapReader r(one_key(head, value_), parent_);
      YamlReadArchive a(r);
      a.Visit(f);
      found_ = Found::kValue;
    }
  }

 private:
  std::string parent_, rest_, below_, error_;
  const YAML::Node& value_;
  std::vector<std::string> names_;
  std::map<std::string, std::string> aliases_;
  Found found_{Found::kNone};
};

template <typename S>
Found set_field(S& obj, const std::string& parent, const std::string& rest, const YAML::Node& v) {
  FieldSetArchive a(parent, rest, v);
  obj.Serialize(&a);
  if (a.found() == Found::kNone || a.found() == Found::kBelowValue) a.fail();
  return a.found();
}

// A value of a list that has no nested struct at `rest` (a controller's, a reference's).
template <typename S>
void set_value(S& obj, const std::string& parent, const std::string& rest, const YAML::Node& v) {
  if (set_field(obj, parent, rest, v) == Found::kMap) refuse(parent + "." + rest, v, "expected a single value");
}

struct NamesArchive {
  std::vector<std::string> names;
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    names.push_back(f.meta.name);
  }
};
template <typename S>
std::vector<std::string> names_of(const S& obj, std::vector<std::string> more = {}) {
  NamesArchive a;
  const_cast<S&>(obj).Serialize(&a);  // the archive only reads
  a.names.insert(a.names.end(), more.begin(), more.end());
  return a.names;
}

// The order a file's keys act in, whatever their order: a type first, then a tuning rule or a
// preset, then the keys they make valid.
int rank(const std::string& key) {
  if (key == "controller.type" || key == "reference.type") return 0;
  if (key == "controller.tuning" || key == "plant.ripple.preset" || key == "controller.model.ripple.preset") return 1;
  return 2;
}

void set_node(Scenario& s, const std::string& key, const YAML::Node& v);

// A map replaces what it is set at: `reset` puts the defaults back, then its keys are set.
template <typename Reset>
void set_map(Scenario& s, const std::string& key, const YAML::Node& v, Reset reset) {
  if (!v.IsMap() && !v.IsNull()) refuse(key, v, "expected a map of keys");
  erase_below(s.given_keys, key);
  reset();
  std::vector<std::pair<std::string, YAML::Node>> entries;
  std::map<std::string, std::string> spelled;  // key -> as written: one key in both spellings is refused
  if (v.IsMap())
    for (const auto& kv : v) {
      entries.emplace_back(key + "." + kv.first.Scalar(), kv.second);
      const std::string& written = entries.back().first;
      const auto [it, fresh] = spelled.emplace(canonical_key(written), written);
      if (!fresh) throw ScenarioError(both_spellings_error(it->first == written ? it->second : written, it->first));
    }
  std::stable_sort(entries.begin(), entries.end(),
                   [](const auto& a, const auto& b) { return rank(a.first) < rank(b.first); });
  for (const auto& [k, ev] : entries) set_node(s, k, ev);
}

// A value of the plant the controller's model does not give follows into the model (the reader:
// the model starts as the plant); a model that gives its own ripple preset keeps its ripple.
void follow(Scenario& s, const std::string& rest, const YAML::Node& v) {
  if (gives(s, "controller.model." + rest)) return;
  if (rest.rfind("ripple.", 0) == 0 && gives(s, "controller.model.ripple.preset")) return;
  set_field(s.controller.model, "controller.model", rest, v);
}

// `section` (plant.ripple, controller.model.ripple) from a preset, the keys given below it kept;
// `short_form`: the preset's name set at the section itself, which replaces it.
void preset(Scenario& s, const std::string& section, const YAML::Node& v, bool short_form) {
  const bool plant = section == "plant.ripple";
  plant::RippleParams& r = plant ? s.plant.ripple : s.controller.model.ripple;
  if (short_form) erase_below(s.given_keys, section);
  plant::RipplePreset p{};
  try {
    if (!v.IsScalar()) throw std::invalid_argument("not a name");
    p = fields::enum_from_name<plant::RipplePreset>(v.Scalar());
  } catch (const std::invalid_argument&) {
    refuse(short_form ? section : section + ".preset", v,
           std::string(short_form ? "expected a map of keys, or one of " : "expected one of ") +
               fields::enum_choices<plant::RipplePreset>());
  }
  ResolvedKeys kept;
  record_fields(r, "", kept);
  r = plant::RippleParams::of(p);
  for (const auto& [k, val] : kept)
    if (k != "preset" && gives(s, section + "." + k)) set_field(r, section, k, YAML::Node(val.text));
  give(s, section + ".preset");
  if (!plant) return;
  ResolvedKeys now;
  record_fields(r, "ripple", now);
  for (const auto& [k, val] : now) follow(s, k, YAML::Node(val.text));
}

// plant.effects.<name>[.<key>], controller.model.effects...: listing an effect enables it (its keys
// not given at their defaults); a listed one keeps its keys.
class EffectSetArchive {
 public:
  EffectSetArchive(Scenario& s, std::string prefix, std::string name, std::string rest, const YAML::Node& v)
      : s_(s), prefix_(std::move(prefix)), name_(std::move(name)), rest_(std::move(rest)), v_(v) {}
  bool found() const { return found_; }
  const std::vector<std::string>& names() const { return names_; }

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    names_.push_back(f.meta.name);
    if (name_ != f.meta.name) return;
    found_ = true;
    const std::string key = prefix_ + "." + name_;
    T& effect = *f.value;
    const auto list = [&] {
      effect = T{};
      effect.enabled = true;
      s_.listed_effects.insert(key);
    };
    if (key == "plant.effects.grinding_force") s_.grinding_process = true;
    if (rest_.empty()) return set_map(s_, key, v_, list);
    if (!s_.listed_effects.count(key)) list();
    set_value(effect, key, rest_, v_);
  }

 private:
  Scenario& s_;
  std::string prefix_, name_, rest_;
  const YAML::Node& v_;
  std::vector<std::string> names_;
  bool found_{false};
};

void effects_key(Scenario& s, plant::EffectsParams& e, const std::string& prefix, const std::string& sub,
                 const YAML::Node& v) {
  if (sub.empty()) {  // the whole list: the effects it names, no others
    return set_map(s, prefix, v, [&] {
      e = {};
      erase_below(s.listed_effects, prefix);
    });
  }
  const std::size_t dot = sub.find('.');
  EffectSetArchive a(s, prefix, sub.substr(0, dot), dot == std::string::npos ? "" : sub.substr(dot + 1), v);
  e.Serialize(&a);
  if (!a.found()) unknown(prefix, sub.substr(0, dot), a.names());
}

// The plant's sub-section `rest` at its defaults (a map set at it), each value followed into the model.
void reset_plant_part(Scenario& s, const std::string& rest) {
  ResolvedKeys defaults;
  record_fields(plant::PlantParams{}, "", defaults, {"effects"});
  for (const auto& [k, val] : defaults) {
    if (k.rfind(rest + ".", 0) != 0) continue;
    set_field(s.plant, "plant", k, YAML::Node(val.text));
    follow(s, k, YAML::Node(val.text));
  }
}

void plant_key(Scenario& s, const std::string& rest, const YAML::Node& v) {
  const std::string head = rest.substr(0, rest.find('.'));
  if (head == "effects")
    return effects_key(s, s.plant.effects, "plant.effects", rest.size() > 8 ? rest.substr(8) : "", v);
  if (head == "grinding") s.grinding_process = true;                                // the section made present
  if (rest == "ripple" && v.IsScalar()) return preset(s, "plant.ripple", v, true);  // the short form
  if (rest == "ripple.preset") return preset(s, "plant.ripple", v, false);
  if (set_field(s.plant, "plant", rest, v) == Found::kValue) return follow(s, rest, v);
  set_map(s, "plant." + rest, v, [&] { reset_plant_part(s, rest); });
}

// controller.model.<sub>: the model's list; its values not given follow the plant.
void model_key(Scenario& s, const std::string& sub, const YAML::Node& v) {
  ControllerConfig& cc = s.controller;
  cc.model_given = true;
  const std::string head = sub.substr(0, sub.find('.'));
  if (sub.empty()) {
    return set_map(s, "controller.model", v, [&] {
      cc.model = detail::model_of_plant(s.plant);
      erase_below(s.listed_effects, "controller.model");
    });
  }
  if (head == "effects") {
    if (cc.type != ControllerType::kSlidingMode)
      throw ScenarioError("controller.model.effects: only the sliding_mode controller's model takes effects");
    return effects_key(s, cc.model.effects, "controller.model.effects", sub.size() > 8 ? sub.substr(8) : "", v);
  }
  if (sub == "ripple" && v.IsScalar()) return preset(s, "controller.model.ripple", v, true);
  if (sub == "ripple.preset") return preset(s, "controller.model.ripple", v, false);
  if (set_field(cc.model, "controller.model", sub, v) == Found::kValue) return;
  set_map(s, "controller.model." + sub, v, [&] {
    ResolvedKeys plant;
    record_fields(s.plant, "", plant, {"effects"});
    for (const auto& [k, val] : plant)
      if (k.rfind(sub + ".", 0) == 0) set_field(cc.model, "controller.model", k, YAML::Node(val.text));
  });
}

// The keys a controller type reads (beside type and computation_delay).
std::vector<std::string> controller_names(const ControllerConfig& cc, ControllerType t) {
  switch (t) {
    case ControllerType::kSlidingMode: return names_of(cc.sliding_mode, {"model"});
    case ControllerType::kCascade: return names_of(cc.cascade, {"model"});
    case ControllerType::kOpenLoop: return names_of(cc.open_loop, {"file"});
    case ControllerType::kPlugin: return names_of(cc.plugin, {"parameters", "model"});
  }
  return {};
}

// Under the cascade's tuning rule the gains are not keys; bandwidth_scale is only with the rule.
// `just_set`: a key being set now (not yet among the given keys).
void check_tuning(const Scenario& s, const std::string& just_set = "") {
  if (s.controller.type != ControllerType::kCascade) return;
  detail::check_cascade_tuning(s.controller.cascade.tuning,
                               [&](const std::string& k) { return k == just_set || gives(s, "controller." + k); });
}

// A type switch: the keys the scenario gives for the old type must be keys of the new one, where
// they keep their values (`old`: the old type's keys, recorded from its struct); `set` sets one.
// `common`: the section's keys of every type (its list: type, computation_delay), which stay.
template <typename Set>
void switch_keys(const Scenario& s, const std::string& section, const YAML::Node& v,
                 const std::vector<std::string>& common, const std::vector<std::string>& names, const ResolvedKeys& old,
                 Set set) {
  for (const std::string& k : given_children(s, section)) {
    if (std::find(common.begin(), common.end(), k) != common.end()) continue;
    if (std::find(names.begin(), names.end(), k) != names.end()) {
      if (const auto it = old.find(k); it != old.end()) set(k, YAML::Node(it->second.text));
      continue;
    }
    refuse(section + ".type", v, section + "." + k + " is given and is not a key of " + v.Scalar());
  }
}

template <typename E>
E read_enum(const std::string& parent, const std::string& key, const YAML::Node& v) {
  MapReader r(one_key(key, v), parent);
  std::string name;
  r.string(key, name);
  try {
    return fields::enum_from_name<E>(name);
  } catch (const std::invalid_argument& e) {
    r.fail(key, " = '" + name + "': " + e.what());
  }
}

// A controller type's own keys as its struct has them (plugin: its limits).
ResolvedKeys controller_values(const ControllerConfig& cc, ControllerType t) {
  ResolvedKeys keys;
  detail::with_controller_params(cc, t, [&](const auto& p) { record_fields(p, "", keys); });
  return keys;
}

void controller_key(Scenario& s, const std::string& rest, const YAML::Node& v);

void controller_type(Scenario& s, const YAML::Node& v) {
  ControllerConfig& cc = s.controller;
  const ControllerType t = read_enum<ControllerType>("controller", "type", v);
  if (t == cc.type) return;
  if (t != ControllerType::kSlidingMode && gives(s, "controller.model.effects"))
    refuse("controller.type", v,
           "controller.model.effects is given: only the sliding_mode controller's model takes effects");
  const ResolvedKeys old = controller_values(cc, cc.type);
  cc.type = t;
  switch_keys(s, "controller", v, names_of(cc), controller_names(cc, t), old,
              [&](const std::string& k, const YAML::Node& value) { controller_key(s, k, value); });
  check_tuning(s);
}

void plugin_key(Scenario& s, const std::string& rest, const YAML::Node& v) {
  controller::PluginParams& p = s.controller.plugin;
  const std::vector<std::string> listed = names_of(p);  // library, u_min, u_max
  if (std::find(listed.begin(), listed.end(), rest) != listed.end()) {
    set_value(p, "controller", rest, v);
    if (rest == "library") p.library = detail::plugin_library(s.base_dir, p.library);
  } else if (rest == "parameters") {
    set_map(s, "controller.parameters", v, [&] { p.parameters.clear(); });
  } else if (rest.rfind("parameters.", 0) == 0) {
    const std::string name = rest.substr(11);
    MapReader pr(one_key(name, v), "controller.parameters");
    if (!detail::parameter_name(name)) pr.fail(name, ": a parameter name is letters, digits and _ only");
    std::string value;
    pr.number_or_string(name, value);
    const auto it =
        std::find_if(p.parameters.begin(), p.parameters.end(), [&](const auto& kv) { return kv.first == name; });
    if (it != p.parameters.end()) it->second = value;
    else p.parameters.emplace_back(name, value);
  } else {
    unknown("controller", rest.substr(0, rest.find('.')), controller_names(s.controller, ControllerType::kPlugin));
  }
}

void controller_key(Scenario& s, const std::string& rest, const YAML::Node& v) {
  ControllerConfig& cc = s.controller;
  if (rest == "type") return controller_type(s, v);
  if (const std::vector<std::string> every_type = names_of(cc);  // the keys of every type
      std::find(every_type.begin(), every_type.end(), rest) != every_type.end()) {
    set_value(cc, "controller", rest, v);
    return checked([&] { cc.validate("controller"); });
  }
  if (rest.rfind("model", 0) == 0 && (rest.size() == 5 || rest[5] == '.') && cc.type != ControllerType::kOpenLoop)
    return model_key(s, rest.size() > 5 ? rest.substr(6) : "", v);
  // An unknown key gets the hint of every key the section takes for its type (as the file's reader).
  if (std::vector<std::string> names = controller_names(cc, cc.type);
      std::find(names.begin(), names.end(), rest.substr(0, rest.find('.'))) == names.end()) {
    for (const std::string& n : names_of(cc)) names.push_back(n);
    unknown("controller", rest.substr(0, rest.find('.')), names);
  }
  switch (cc.type) {
    case ControllerType::kSlidingMode: return set_value(cc.sliding_mode, "controller", rest, v);
    case ControllerType::kCascade:
      if (rest != "tuning") check_tuning(s, rest);  // a gain under the rule, a rule's factor under manual
      set_value(cc.cascade, "controller", rest, v);
      if (rest == "tuning") check_tuning(s);
      return checked([&] { fields::check_fields(cc.cascade, "controller"); });
    case ControllerType::kOpenLoop:
      if (rest != "file") return set_value(cc.open_loop, "controller", rest, v);
      MapReader(one_key(rest, v), "controller").string(rest, cc.open_loop_file);
      if (!cc.open_loop_file.empty()) cc.open_loop_file = detail::resolved_file(s.base_dir, cc.open_loop_file);
      return;
    case ControllerType::kPlugin: return plugin_key(s, rest, v);
  }
}

std::vector<std::string> reference_names(ReferenceConfig& c, ReferenceType t) {
  std::vector<std::string> names;
  detail::with_reference_params(c, t, [&](auto& p) { names = names_of(p); });
  if (t == ReferenceType::kWaypoints) names.push_back("file");
  return names;
}

void reference_key(Scenario& s, const std::string& rest, const YAML::Node& v) {
  ReferenceConfig& c = s.reference;
  if (rest == "type") {
    const ReferenceType t = read_enum<ReferenceType>("reference", "type", v);
    if (t == c.type) return;
    ResolvedKeys old;
    detail::with_reference_params(c, c.type, [&](const auto& p) { record_fields(p, "", old); });
    c.type = t;
    return switch_keys(s, "reference", v, names_of(c), reference_names(c, t), old,
                       [&](const std::string& k, const YAML::Node& value) { reference_key(s, k, value); });
  }
  if (c.type == ReferenceType::kWaypoints && rest == "file") {
    MapReader(one_key(rest, v), "reference").string(rest, c.waypoints_file);
    c.waypoints_file = detail::resolved_file(s.base_dir, c.waypoints_file);
    return;
  }
  // An unknown key gets the hint of every key the section takes for its type (as the file's reader).
  if (std::vector<std::string> names = reference_names(c, c.type);
      std::find(names.begin(), names.end(), rest.substr(0, rest.find('.'))) == names.end()) {
    for (const std::string& n : names_of(c)) names.push_back(n);
    unknown("reference", rest.substr(0, rest.find('.')), names);
  }
  detail::with_reference_params(c, c.type, [&](auto& p) { set_value(p, "reference", rest, v); });
}

// The sections read by rules of their own (set_node); every other top-level key is the list's
// (Scenario::Serialize: name, duration, control_period, analysis.*, output.*).
const std::vector<std::string>& sections() {
  static const std::vector<std::string> names = {"plant", "controller", "reference"};
  return names;
}

void top_key(Scenario& s, const std::string& key, const YAML::Node& v) {
  const std::string head = key.substr(0, key.find('.'));
  const std::vector<std::string> names = names_of(s, sections());
  if (std::find(names.begin(), names.end(), head) == names.end()) unknown("", head, names);
  if (head == key && std::find(sections().begin(), sections().end(), key) != sections().end())
    refuse(key, v, "a whole section is not set at once: set its keys (e.g. plant.mass=110)");
  if (set_field(s, "", key, v) == Found::kMap)
    refuse(key, v, "a whole section is not set at once: set its keys (e.g. output.every=10)");
  if (key == "name") detail::check_name(s.name, "name");
  checked([&] { s.validate(); });
}

void set_node(Scenario& s, const std::string& written, const YAML::Node& v) {
  std::string note;
  const std::string key = canonical_key(written, &note);  // an old spelling is set as its key
  auto& renamed = s.renamed_keys;
  if (!note.empty() && std::find(renamed.begin(), renamed.end(), note) == renamed.end()) renamed.push_back(note);
  const std::size_t dot = key.find('.');
  const std::string section = key.substr(0, dot);
  const std::string rest = dot == std::string::npos ? "" : key.substr(dot + 1);
  if (rest.empty()) {
    top_key(s, key, v);
  } else if (section == "plant") {
    plant_key(s, rest, v);
  } else if (section == "controller") {
    controller_key(s, rest, v);
  } else if (section == "reference") {
    reference_key(s, rest, v);
  } else {
    top_key(s, key, v);  // analysis.*, output.*, or unknown with its hint
  }
  give(s, key);
}

// What only a whole scenario tells: a file its types need.
void check_required(const Scenario& s) {
  if (s.controller.type == ControllerType::kPlugin && s.controller.plugin.library.empty())
    throw ScenarioError("controller.library: missing (required)");
  if (s.reference.type == ReferenceType::kWaypoints && s.reference.waypoints_file.empty())
    throw ScenarioError("reference.file: missing (required)");
  if (s.controller.type == ControllerType::kOpenLoop && s.controller.open_loop.kind == controller::OpenLoopKind::kCsv &&
      s.controller.open_loop_file.empty())
    throw ScenarioError("controller.file = '': kind = csv needs a file");
}

// Walks the dotted path `rest` through a struct's list, each old spelling (fields::Meta::alias)
// replaced by its key; a path the list does not have is left as it is (its setter refuses it).
class SpellingArchive {
 public:
  explicit SpellingArchive(std::string rest) : rest_(std::move(rest)), path_(rest_) {}
  const std::string& path() const { return path_; }
  bool renamed() const { return renamed_; }

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const std::size_t dot = rest_.find('.');
    const std::string head = rest_.substr(0, dot);
    const bool old = *f.meta.alias && head == f.meta.alias;
    if (found_ || (head != f.meta.name && !old)) return;
    found_ = true;
    renamed_ = old;
    path_ = f.meta.name;
    if (dot == std::string::npos) return;
    SpellingArchive below(rest_.substr(dot + 1));
    if constexpr (fields::is_serializable<T>::value) f.value->Serialize(&below);
    renamed_ = renamed_ || below.renamed_;
    path_ += "." + below.path_;
  }

 private:
  std::string rest_, path_;
  bool found_{false}, renamed_{false};
};

// `key` below `prefix` ("" the top level) respelled through `list` (SpellingArchive), if it renames.
template <typename S>
bool respell(const std::string& prefix, S list, const std::string& key, std::string& out) {
  if (!prefix.empty() && key.rfind(prefix + ".", 0) != 0) return false;
  SpellingArchive a(prefix.empty() ? key : key.substr(prefix.size() + 1));
  list.Serialize(&a);
  if (a.renamed()) out = detail::dotted(prefix, a.path());
  return a.renamed();
}

}  // namespace

// Every list of the scenario (detail::for_each_list), the plant's under each of its prefixes.
std::string canonical_key(const std::string& key, std::string* note) {
  std::string out;
  bool renamed = false;
  detail::for_each_list(
      [&](const char*, const char* prefix, auto list) { renamed = renamed || respell(prefix, list, key, out); });
  for (const char* prefix : detail::kPlantPrefixes)
    renamed = renamed || respell(prefix, plant::PlantParams{}, key, out);
  if (!renamed) return key;
  if (note != nullptr) *note = renamed_key_note(key, out);
  return out;
}

void set_read_key(Scenario& s, const std::string& key, const std::string& value) {
  set_node(s, key, value_node(key, value));
}

void set_read_keys(Scenario& s, const std::vector<KeySetting>& sets) {
  // One key in both spellings is refused, as in a file (set_map).
  std::map<std::string, std::string> spelled;  // canonical key -> as written
  for (const KeySetting& k : sets) {
    const auto [it, fresh] = spelled.emplace(canonical_key(k.key), k.key);
    if (!fresh && it->second != k.key)
      throw ScenarioError(both_spellings_error(it->second == it->first ? k.key : it->second, it->first));
  }
  std::vector<KeySetting> ordered = sets;
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](const KeySetting& a, const KeySetting& b) { return rank(a.key) < rank(b.key); });
  for (const KeySetting& k : ordered) set_read_key(s, k.key, k.value);
}

void complete_read(Scenario& s) {
  check_required(s);
  checked([&] { s.validate(); });
  detail::check_timing(s, validate::format_number(s.duration), validate::format_number(s.control_period));
  detail::check_output(s.output, gives(s, "output.columns"));
  detail::derive_and_check(s);
}

Scenario load_scenario(const std::string& path, const std::vector<KeySetting>& sets, std::string* text_out) {
  const std::string text = text::read_text_file<ScenarioError>(path, "scenario file");
  const fs::path p(path);
  const std::string dir = p.parent_path().empty() ? "." : p.parent_path().string();
  Scenario s;
  if (sets.empty()) {
    s = parse_scenario(text, dir, path);
    if (text_out != nullptr) *text_out = text;
  } else {
    const std::string origin = path + " with --set";
    s = read_scenario(text, dir, origin);
    try {
      set_read_keys(s, sets);
      complete_read(s);
    } catch (const std::exception& e) {
      throw ScenarioError(origin + ": " + e.what());
    }
    if (text_out != nullptr) *text_out = resolved_yaml(resolved_keys(s));
  }
  s.path = path;
  if (s.name.empty()) {
    s.name = p.stem().string();
    detail::check_name(s.name, path + ": the name taken from the file name (set name: to choose another)");
  }
  return s;
}

Scenario load_scenario(const std::string& path, std::string* text_out) { return load_scenario(path, {}, text_out); }

}  // namespace feeddrive::sim

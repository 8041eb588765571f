#include "feeddrive/sim/scenario.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "feeddrive/common/text.hpp"
#include "feeddrive/common/text_file.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/csv/reader.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/yaml_archive.hpp"
#include "feeddrive/sim/yaml_reader.hpp"
#include "scenario_rules.hpp"

namespace feeddrive::sim {

namespace detail {
namespace {

// A name from the file as a message shows it: printable ASCII, at most 40 bytes.
std::string output_shown(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return s.size() > 40 ? out + "..." : out;
}

// A step count for a message: exact up to 10^15, else 3 significant digits ("1e+304", never
// "1.0000000000000001e+304").
std::string steps_text(double n) {
  if (n < 1e15) return validate::format_number(n);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", n);
  return buf;
}

}  // namespace

// The name goes into plot titles, summary.json and messages: printable UTF-8 of bounded length
// (a 50 MB name once made the plots take 4.8 GB).
void check_name(const std::string& name, const std::string& what) {
  if (name.size() > kMaxNameBytes)
    throw ScenarioError(what + ": " + std::to_string(name.size()) + " bytes: too long (at most " +
                        std::to_string(kMaxNameBytes) + ")");
  const std::size_t bad = text::first_unprintable(name);
  if (bad < name.size()) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(name[bad])));
    throw ScenarioError(what + ": byte " + std::to_string(bad + 1) + " (" + hex +
                        ") is not printable UTF-8 (control character or malformed sequence)");
  }
}

void check_timing(const Scenario& s, const std::string& duration, const std::string& period) {
  if (s.control_period > s.duration) throw ScenarioError("control_period = " + period + ": must be <= duration");
  if (const double n = std::round(s.duration / s.control_period); !(n <= kMaxSteps))
    throw ScenarioError("duration = " + duration + ", control_period = " + period + ": " + steps_text(n) +
                        " steps; a run has at most " + validate::format_number(kMaxSteps) +
                        " steps (docs/scenario.md, Limits)");
}

void check_output(const OutputConfig& out, bool columns_given) {
  const auto& all = record_columns();
  for (const std::string& c : out.columns) {
    if (std::find(all.begin(), all.end(), c) == all.end()) {
      std::string known;
      for (const auto& k : all) known += (known.empty() ? "" : ", ") + k;
      throw ScenarioError("output.columns: unknown column '" + output_shown(c) + "' (columns: " + known + ")");
    }
    if (std::count(out.columns.begin(), out.columns.end(), c) > 1)
      throw ScenarioError("output.columns: column '" + c + "' listed twice");
  }
  if (columns_given && out.columns.empty())
    throw ScenarioError("output.columns: empty list (leave the key out to record every column)");
}

plant::PlantParams model_of_plant(const plant::PlantParams& plant) {
  plant::PlantParams m = plant;
  m.effects = {};
  return m;
}

std::string resolved_file(const std::string& base_dir, const std::string& file) {
  namespace fs = std::filesystem;
  return fs::path(file).is_relative() ? (fs::path(base_dir) / file).string() : file;
}

const std::set<std::string>& keys_not_taken(controller::CascadeTuning t) {
  static const std::set<std::string> rule = {"kp", "kv", "ki"}, manual = {"bandwidth_scale"};
  return t == controller::CascadeTuning::kRule ? rule : manual;
}

void check_cascade_tuning(controller::CascadeTuning t, const std::function<bool(const std::string&)>& given) {
  for (const std::string& k : keys_not_taken(t))
    if (given(k))
      throw ScenarioError("controller." + k +
                          (t == controller::CascadeTuning::kRule
                               ? ": set by tuning: rule (remove it, or use tuning: manual)"
                               : ": only with tuning: rule"));
}

std::string plugin_library(const std::string& base_dir, const std::string& file) {
  return std::filesystem::path(resolved_file(base_dir, file)).lexically_normal().string();
}

bool parameter_name(const std::string& key) {
  return !key.empty() && std::all_of(key.begin(), key.end(),
                                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

}  // namespace detail

namespace {

using detail::check_name;
using detail::model_of_plant;

namespace fs = std::filesystem;
using plant::PlantParams;

// --- plant ---------------------------------------------------------------------------------
// Every section is read from its struct's one list (Serialize; sim/yaml_archive.hpp); what is
// left here are the rules of their own: a ripple preset, effects enabled by being listed, the
// cascade's tuning keys, file names resolved against the scenario's folder.

// plant.effects.<name>: listing an effect enables it (an optional `enabled: false` switches it
// off again); the parameters not given keep the struct's defaults.
// The listed ones go into `listed` by their dotted key (Scenario::listed_effects).
class EffectsReadArchive {
 public:
  EffectsReadArchive(MapReader& r, std::set<std::string>& listed) : r_(r), listed_(listed) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const bool listed = r_.has(f.meta.name);
    MapReader m = r_.child(f.meta.name);  // marks the name as known, for finish()'s hints
    if (!listed) return;
    listed_.insert(r_.key_path(f.meta.name));
    f.value->enabled = true;
    read_fields(m, *f.value);
    m.finish();
  }

 private:
  MapReader& r_;
  std::set<std::string>& listed_;
};

// plant.ripple: a map of keys, where `preset: paper` starts from the paper's values
// (RippleParams::paper()), or the preset's name alone (`ripple: paper`). Without a preset every
// part is 0 (issue 23: no surprising defaults).
void read_ripple(MapReader& r, plant::RippleParams& p) {
  std::string preset;
  const bool scalar = r.scalar_text("ripple", preset);
  MapReader m = scalar ? r.child_absent("ripple") : r.child("ripple");
  if (scalar) r.mark_given("ripple.preset");
  if (!scalar) m.string("preset", preset);
  if (!preset.empty()) {
    try {
      p = plant::RippleParams::of(fields::enum_from_name<plant::RipplePreset>(preset));
    } catch (const std::invalid_argument& e) {
      if (scalar)
        r.fail("ripple",
               " = '" + preset + "': expected a map of keys, or one of " + fields::enum_choices<plant::RipplePreset>());
      m.fail("preset", " = '" + preset + "': " + e.what());
    }
  }
  read_fields(m, p);
  m.finish();
}

// The plant (listed_effects given: the effects it lists go there) or a controller's model of it:
// a cascade's or plugin's model has no effects, they are the plant's discrepancy from the model.
void read_plant(MapReader r, PlantParams& p, std::set<std::string>* listed_effects) {
  read_fields(r, p, {"ripple", "effects"});
  read_ripple(r, p.ripple);
  if (listed_effects != nullptr) {
    MapReader e = r.child("effects");
    EffectsReadArchive a(e, *listed_effects);
    p.effects.Serialize(&a);
    e.finish();
  } else if (r.has("effects")) {
    r.fail("effects",
           ": only the sliding_mode controller's model takes effects (e.g. those "
           "feeddrive-fit found); the cascade uses the model's mass and friction only");
  }
  r.finish();
}

// --- controller ----------------------------------------------------------------------------

// type plugin (docs/plugins.md): library (resolved against the scenario's folder), parameters
// (a map of numbers and words, handed to the plugin as text), the nominal model and the limits.
// The library is opened here (file, symbols, ABI version), so a bad one fails at load.
void read_plugin(MapReader& r, controller::PluginParams& p, PlantParams& model, const std::string& base_dir) {
  read_fields(r, p);  // library, u_min, u_max
  p.library = detail::plugin_library(base_dir, p.library);
  MapReader params = r.child("parameters");
  for (const std::string& key : params.keys()) {
    if (!detail::parameter_name(key)) params.fail(key, ": a parameter name is letters, digits and _ only");
    std::string value;
    params.number_or_string(key, value);
    p.parameters.emplace_back(key, value);
  }
  params.finish();
  read_plant(r.child("model"), model, nullptr);
}

// tuning: manual (kp, kv, ki as given) or rule (kp, kv, ki must then not be given; the gains are
// set by derive() through controller::apply_tuning, not here); bandwidth_scale only with the rule.
// The list's ranges are checked here, before derive() uses bandwidth_scale.
void read_cascade(MapReader& r, controller::CascadeParams& p, PlantParams& model) {
  read_fields(r, p);
  detail::check_cascade_tuning(p.tuning, [&r](const std::string& k) { return r.has(k); });
  try {
    fields::check_fields(p, "controller");
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  read_plant(r.child("model"), model, nullptr);
}

void read_open_loop(MapReader& r, controller::OpenLoopParams& p, std::string& file, const std::string& base_dir) {
  read_fields(r, p);
  r.string("file", file);
  if (!file.empty()) file = detail::resolved_file(base_dir, file);
  if (p.kind == controller::OpenLoopKind::kCsv && file.empty())
    r.fail("file", " = '': kind = csv needs a file" + r.near_miss("file"));
}

// --- reference -----------------------------------------------------------------------------

void read_reference(MapReader r, ReferenceConfig& c, const std::string& base_dir) {
  read_fields(r, c);  // type
  detail::with_reference_params(c, c.type, [&](auto& p) { read_fields(r, p); });
  if (c.type == ReferenceType::kWaypoints)
    c.waypoints_file = detail::resolved_file(base_dir, r.required_string("file"));
  r.finish();
}

void validate_reference(const ReferenceConfig& c) {
  // The waypoints are read and checked in check_scenario.
  detail::with_reference_params(c, c.type, [](const auto& p) { p.validate("reference"); });
}

// The reference and an open-loop command are pure functions of t: a NaN or infinity they would
// produce (waypoints at 1e308, a sine at 1e308 Hz) is found here, before the run, at up to
// 100000 of the run's step times (every step of a run up to that size). The error names the
// section's keys and values as written. What depends on the motion is guarded at run time
// (simulation.cpp).
void check_functions_of_time(const Scenario& s, const YAML::Node& root) {
  const long n = s.steps();
  const long samples = std::min<long>(n + 1, 100000);
  const auto step_at = [&](long i) {
    return samples <= 1
               ? 0L
               : static_cast<long>(static_cast<double>(i) * static_cast<double>(n) / static_cast<double>(samples - 1));
  };
  const auto section = [&](const char* key) {
    YAML::Emitter e;
    if (root.IsMap()) {
      e << YAML::Flow << root[key];
    } else {  // a scenario built as a struct: the keys it gives, with their values
      const ResolvedKeys keys = resolved_keys(s);
      e << YAML::Flow << YAML::BeginMap;
      for (const auto& [k, v] : keys)
        if (k.rfind(std::string(key) + ".", 0) == 0 && detail::gives(s, k))
          e << YAML::Key << k.substr(std::strlen(key) + 1) << YAML::Value << v.text;
      e << YAML::EndMap;
    }
    std::string text = e.c_str();
    for (char& c : text)
      if (c == '\n') c = ' ';
    return text.size() > 200 ? text.substr(0, 200) + "..." : text;
  };
  const auto fail = [&](const std::string& what, double v, double t, const char* key, const char* gives) {
    throw ScenarioError(std::string(key) + ": " + what + " = " + validate::format_number(v) +
                        " at t = " + validate::format_number(t) + " s: " + key + " " + section(key) + " " + gives);
  };
  if (s.reference.type != ReferenceType::kNone) {
    const auto ref = make_reference(s);
    for (long i = 0; i < samples; ++i) {
      const double t = s.time_of(step_at(i));
      const trajectory::Sample q = ref->sample(t);
      const std::pair<const char*, double> fields[] = {
          {"position", q.position}, {"velocity", q.velocity}, {"acceleration", q.acceleration}, {"jerk", q.jerk}};
      for (const auto& [what, v] : fields)
        if (!std::isfinite(v))
          fail(std::string("the reference's ") + what, v, t, "reference", "gives no finite trajectory");
    }
  }
  if (s.controller.type == ControllerType::kOpenLoop) {
    const controller::OpenLoopSource src(s.controller.open_loop);
    for (long i = 0; i < samples; ++i) {
      const double t = s.time_of(step_at(i));
      const double f = src.force(t);
      if (!std::isfinite(f)) fail("the open-loop force", f, t, "controller", "gives no finite command");
    }
  }
}

// A plant section given with keys but without `enabled` (from the presence facts, given_keys):
// off, its keys do not act (a forgotten enabled: true). One that says `enabled: false` is off on
// purpose, and a preset alone (`ripple: none`) says what it is: no warning.
std::vector<std::string> off_sections(const Scenario& s) {
  std::vector<std::string> w;
  const std::pair<const char*, bool> sections[] = {{"ripple", s.plant.ripple.enabled},
                                                   {"grinding", s.plant.grinding.enabled},
                                                   {"electrical", s.plant.electrical.enabled}};
  for (const auto& [name, on] : sections) {
    const std::string prefix = std::string("plant.") + name + ".";
    if (on || detail::gives(s, prefix + "enabled")) continue;
    bool keys = false;
    for (auto it = s.given_keys.lower_bound(prefix); it != s.given_keys.end() && it->rfind(prefix, 0) == 0; ++it)
      keys = keys || *it != prefix + "preset";
    if (keys)
      w.push_back(std::string("plant.") + name +
                  ": keys given, but the section is off (no enabled: true): they do not act; enabled: true?");
  }
  return w;
}

// Issue 23 (unit sanity): every number of the run's lists outside its plausible range for a
// linear feed drive (common/fields.hpp), and a move that the run cuts off.
void find_warnings(Scenario& s) {
  std::vector<std::string>& w = s.warnings;
  w = s.renamed_keys;  // a key's deprecated spelling, one line each
  const auto add = [&w](const std::vector<std::string>& more) { w.insert(w.end(), more.begin(), more.end()); };
  add(off_sections(s));
  add(fields::plausibility(s, ""));
  add(fields::plausibility(s.controller, "controller"));
  add(fields::plausibility(s.plant, "plant"));  // sections that are off too: their keys were written
  const auto warned = [&w](const std::string& key, std::size_t from) {
    for (std::size_t i = from; i < w.size(); ++i)
      if (w[i].rfind(key, 0) == 0) return true;
    return false;
  };
  detail::with_controller_params(s.controller, s.controller.type,
                                 [&](const auto& p) { add(fields::plausibility(p, "controller")); });
  detail::with_reference_params(s.reference, s.reference.type,
                                [&](const auto& p) { add(fields::plausibility(p, "reference")); });
  const ReferenceType t = s.reference.type;
  if (t == ReferenceType::kAccelLimited || t == ReferenceType::kSCurve || t == ReferenceType::kWaypoints ||
      t == ReferenceType::kStep) {
    s.move_end_s = make_reference(s)->end_time();
    if (s.move_end_s > s.duration) {
      // The likely cause: a distance or a start in the wrong unit (already warned above), else
      // a duration too short for the move.
      double start = 0.0;
      if (t == ReferenceType::kAccelLimited) start = s.reference.accel_limited.start_time;
      if (t == ReferenceType::kSCurve) start = s.reference.scurve.start_time;
      if (t == ReferenceType::kStep) start = s.reference.step.step_time;
      const char* hint = warned("reference.distance", 0) ? "a distance in mm?"
                         : start >= s.duration
                             ? (t == ReferenceType::kStep ? "a step_time in ms?" : "a start_time in ms?")
                             : "a longer duration?";
      char buf[240];
      std::snprintf(
          buf, sizeof buf,
          "reference: the move ends at t = %.4g s, after duration = %.4g s: the run cuts it off (summary.json "
          "move_finished: false); %s",
          s.move_end_s, s.duration, hint);
      w.push_back(buf);
    }
  }
}

// --- read ------------------------------------------------------------------------------------
// Reading fills the struct from the YAML and checks what only the YAML can tell (keys, types,
// values as written); derive() then computes what one section takes from another, and
// check_scenario() validates the whole (parse_node: read -> derive -> check).

// The top-level list (Scenario::Serialize: name, duration, control_period, analysis, output), with
// its one-line errors; then the rules of their own: the name's bytes, the run's length (quoting
// the values as written) and the output's column names.
void read_top(MapReader& top, const YAML::Node& root, Scenario& s) {
  read_fields(top, s);
  check_name(s.name, "name");
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  detail::check_timing(s, root["duration"].Scalar(), root["control_period"].Scalar());
  detail::check_output(s.output, detail::gives(s, "output.columns"));
}

// plant: its keys; a grinding process if it gives a grinding section or lists the grinding force.
void read_plant_section(MapReader& top, Scenario& s) {
  read_plant(top.child("plant"), s.plant, &s.listed_effects);
  s.grinding_process = detail::gives(s, "plant.grinding") || s.listed_effects.count("plant.effects.grinding_force");
}

// controller: its type's keys; the nominal model (controller.model) into s.controller.model, on
// top of the plant's own parameters (a model never carries the plant's effects).
void read_controller(MapReader& top, Scenario& s, const std::string& base_dir) {
  ControllerConfig& cc = s.controller;
  MapReader c = top.child("controller");
  read_fields(c, cc);  // type, computation_delay
  try {
    cc.validate("controller");
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  cc.model = model_of_plant(s.plant);
  switch (cc.type) {
    case ControllerType::kSlidingMode:
      read_fields(c, cc.sliding_mode);
      read_plant(c.child("model"), cc.model, &s.listed_effects);
      break;
    case ControllerType::kCascade: read_cascade(c, cc.cascade, cc.model); break;
    case ControllerType::kOpenLoop: read_open_loop(c, cc.open_loop, cc.open_loop_file, base_dir); break;
    case ControllerType::kPlugin: read_plugin(c, cc.plugin, cc.model, base_dir); break;
  }
  cc.model_given = c.has("model");
  c.finish();
}

Scenario read_node(const YAML::Node& root, const std::string& base_dir) {
  if (!root.IsMap())
    throw ScenarioError(
        "the scenario must be a YAML map with keys plant, controller, reference, duration, control_period");
  Scenario s;
  MapReader top(root, "", &s.given_keys, &s.renamed_keys);
  s.base_dir = base_dir;
  read_top(top, root, s);
  read_plant_section(top, s);
  read_controller(top, s, base_dir);
  read_reference(top.child("reference"), s.reference, base_dir);
  top.finish();
  return s;
}

// --- derive ----------------------------------------------------------------------------------

// What one section takes from another: the controller's nominal model, control period and
// computation delay; the cascade's model values and its tuning rule (controller::apply_tuning);
// the open-loop command's thrust gain (the plant's Ka*Kf).
void derive(Scenario& s) {
  ControllerConfig& cc = s.controller;
  switch (cc.type) {
    case ControllerType::kSlidingMode:
      cc.sliding_mode.model = cc.model;
      cc.sliding_mode.period = s.control_period;
      cc.sliding_mode.computation_delay = cc.computation_delay;
      break;
    case ControllerType::kCascade:
      cc.cascade.mass = cc.model.mass;
      cc.cascade.thrust_gain = cc.model.thrust_gain();
      cc.cascade.friction = cc.model.friction;
      cc.cascade.quantization = cc.model.sensor.quantization;
      cc.cascade.period = s.control_period;
      cc.cascade.computation_delay = cc.computation_delay;
      controller::apply_tuning(cc.cascade, cc.model.sensor.differenced_velocity());
      break;
    case ControllerType::kOpenLoop: cc.open_loop.thrust_gain = s.plant.thrust_gain(); break;
    case ControllerType::kPlugin:
      cc.plugin.model = cc.model;
      cc.plugin.period = s.control_period;
      cc.plugin.computation_delay = cc.computation_delay;
      break;
  }
}

// --- check -----------------------------------------------------------------------------------

// Component validation (each validate() names its key and value; tables come from the files),
// the run's length, the functions of time (messages quote root's sections) and the warnings.
void check_scenario(Scenario& s, const YAML::Node& root) {
  try {
    if (s.reference.type == ReferenceType::kWaypoints)
      s.reference.waypoints = read_waypoints_file(s.reference.waypoints_file);
    if (s.controller.type == ControllerType::kOpenLoop && s.controller.open_loop.kind == controller::OpenLoopKind::kCsv)
      read_open_loop_file(s.controller.open_loop_file, s.controller.open_loop);
    s.plant.validate("plant");
    detail::with_controller_params(s.controller, s.controller.type, [](const auto& p) { p.validate("controller"); });
    if (s.controller.type == ControllerType::kPlugin) controller::PluginLibrary::open(s.controller.plugin.library);
    validate_reference(s.reference);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  if (s.steps() < 1)
    throw ScenarioError("duration = " + validate::format_number(s.duration) + ": shorter than one control period (" +
                        validate::format_number(s.control_period) + " s)");
  check_functions_of_time(s, root);
  find_warnings(s);
}

Scenario parse_node(const YAML::Node& root, const std::string& base_dir) {
  Scenario s = read_node(root, base_dir);
  derive(s);
  check_scenario(s, root);
  return s;
}

}  // namespace

std::vector<trajectory::Waypoint> read_waypoints_file(const std::string& path) {
  csv::Options o;
  o.columns = {{{"t"}}, {{"x"}}};
  o.increasing = 0;
  o.limits.min_rows = 2;  // a spline needs one interval
  const csv::Table t = csv::read_file(path, o);
  std::vector<trajectory::Waypoint> points(t.rows());
  for (std::size_t i = 0; i < t.rows(); ++i) points[i] = {t.values[0][i], t.values[1][i]};
  return points;
}

void read_open_loop_file(const std::string& path, controller::OpenLoopParams& p) {
  csv::Options o;
  o.columns = {{{"t"}}, {{"force_N", "u"}}};  // force_N when the file has both
  o.increasing = 0;
  csv::Table t = csv::read_file(path, o);
  p.table_t = std::move(t.values[0]);
  p.table_value = std::move(t.values[1]);
  p.table_is_force = t.used[1] == "force_N";
}

long Scenario::steps() const { return std::lround(duration / control_period); }

PlantParams Scenario::drive() const {
  PlantParams p = plant;
  const double d = controller.computation_delay;
  if (d > 0.0) {
    plant::InputDelayEffect& delay = p.effects.input_delay;
    if (!delay.enabled) delay.delay = 0.0;
    delay.enabled = true;
    delay.delay += d;
  }
  return p;
}

// --- the run's description from the struct (resolved_keys) -------------------------------------

namespace {

// plant.effects.<name>: the listed effects' keys (Scenario::listed_effects).
class EffectsKeyArchive {
 public:
  EffectsKeyArchive(std::string prefix, const std::set<std::string>& listed, ResolvedKeys& out)
      : prefix_(std::move(prefix)), listed_(listed), out_(out) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const std::string key = prefix_ + "." + f.meta.name;
    if (listed_.count(key)) record_fields(*f.value, key, out_);
  }

 private:
  std::string prefix_;
  const std::set<std::string>& listed_;
  ResolvedKeys& out_;
};

// A plant's keys (its list, the ripple included) and, with `listed`, the effects it lists.
void plant_keys(const PlantParams& p, const std::string& prefix, const std::set<std::string>* listed,
                ResolvedKeys& out) {
  record_fields(p, prefix, out, {"effects"});
  if (listed == nullptr) return;
  EffectsKeyArchive a(prefix + ".effects", *listed, out);
  const_cast<plant::EffectsParams&>(p.effects).Serialize(&a);  // the archive only reads
}

// A plugin parameter as read: a number (its shortest text) or else a word.
ResolvedValue parameter_value(const std::string& text) {
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return {text, text.empty() || end != text.c_str() + text.size()};
}

void controller_keys(const Scenario& s, ResolvedKeys& out) {
  const ControllerConfig& cc = s.controller;
  record_fields(cc, "controller", out);  // type, computation_delay
  switch (cc.type) {
    case ControllerType::kSlidingMode:
      record_fields(cc.sliding_mode, "controller", out);
      plant_keys(cc.model, "controller.model", &s.listed_effects, out);
      break;
    case ControllerType::kCascade:
      // Under the tuning rule the gains are not keys of the run: the rule sets them.
      record_fields(cc.cascade, "controller", out, detail::keys_not_taken(cc.cascade.tuning));
      plant_keys(cc.model, "controller.model", nullptr, out);
      break;
    case ControllerType::kOpenLoop:
      record_fields(cc.open_loop, "controller", out);
      out["controller.file"] = {cc.open_loop_file, true};
      break;
    case ControllerType::kPlugin:
      record_fields(cc.plugin, "controller", out);  // library, u_min, u_max
      for (const auto& [k, v] : cc.plugin.parameters) out["controller.parameters." + k] = parameter_value(v);
      plant_keys(cc.model, "controller.model", nullptr, out);
      break;
  }
}

void reference_keys(const ReferenceConfig& c, ResolvedKeys& out) {
  record_fields(c, "reference", out);  // type
  detail::with_reference_params(c, c.type, [&](const auto& p) { record_fields(p, "reference", out); });
  if (c.type == ReferenceType::kWaypoints) out["reference.file"] = {c.waypoints_file, true};
}

}  // namespace

ResolvedKeys resolved_keys(const Scenario& s) {
  ResolvedKeys out;
  record_fields(s, "", out);  // name, duration, control_period, analysis, output
  plant_keys(s.plant, "plant", &s.listed_effects, out);
  controller_keys(s, out);
  reference_keys(s.reference, out);
  return out;
}

void detail::derive_and_check(Scenario& s) {
  derive(s);
  check_scenario(s, YAML::Node());
}

Scenario read_scenario(const std::string& yaml_text, const std::string& base_dir, const std::string& origin,
                       const std::string& controller) {
  try {
    YAML::Node root = load_yaml_strict(yaml_text);
    if (!controller.empty() && root.IsMap()) root["controller"] = load_yaml_strict(controller);
    return read_node(root, base_dir);
  } catch (const std::exception& e) {
    throw ScenarioError(origin + ": " + e.what());
  }
}

Scenario parse_scenario(const std::string& yaml_text, const std::string& base_dir, const std::string& origin,
                        ResolvedKeys* resolved) {
  try {
    const YAML::Node root = load_yaml_strict(yaml_text);
    if (resolved) resolved->clear();
    Scenario s = parse_node(root, base_dir);
    if (resolved) *resolved = resolved_keys(s);
    return s;
  } catch (const ScenarioError& e) {
    throw ScenarioError(origin + ": " + e.what());
  } catch (const std::exception& e) {
    throw ScenarioError(origin + ": " + e.what());
  }
}

KeySetting parse_key_setting(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw ScenarioError("--set " + text + ": expected key=value (a dotted scenario key, e.g. plant.mass=110)");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace {

// Emits entries [b, e) (split dotted paths, sorted) as a map, grouping the paths that share
// their part at `depth`: all paths with one prefix are adjacent in sorted order.
void emit_map(YAML::Emitter& em, const std::vector<std::pair<std::vector<std::string>, const ResolvedValue*>>& items,
              std::size_t b, std::size_t e, std::size_t depth) {
  em << YAML::BeginMap;
  for (std::size_t i = b; i < e;) {
    const std::string& part = items[i].first[depth];
    std::size_t j = i;
    while (j < e && items[j].first[depth] == part) ++j;
    em << YAML::Key << part << YAML::Value;
    if (items[i].first.size() == depth + 1) {
      em << items[i].second->text;
    } else {
      emit_map(em, items, i, j, depth + 1);
    }
    i = j;
  }
  em << YAML::EndMap;
}

}  // namespace

std::string resolved_yaml(const ResolvedKeys& keys) {
  std::vector<std::pair<std::vector<std::string>, const ResolvedValue*>> items;
  for (const auto& [path, value] : keys) items.emplace_back(text::split(path, '.'), &value);
  // Sorted by parts, so every group of one prefix is contiguous ("a.b" and "a-c" interleave as
  // strings, not as part lists).
  std::sort(items.begin(), items.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  YAML::Emitter em;
  emit_map(em, items, 0, items.size(), 0);
  return std::string(em.c_str()) + "\n";
}

std::unique_ptr<trajectory::Trajectory> make_reference(const Scenario& s) {
  const ReferenceConfig& c = s.reference;
  switch (c.type) {
    case ReferenceType::kNone: return trajectory::make_ramp({0.0, 0.0, 0.0});
    case ReferenceType::kSine: return trajectory::make_sine(c.sine);
    case ReferenceType::kStep: return trajectory::make_step(c.step);
    case ReferenceType::kAccelLimited: return trajectory::make_accel_limited(c.accel_limited);
    case ReferenceType::kSCurve: return trajectory::make_scurve(c.scurve);
    case ReferenceType::kRamp: return trajectory::make_ramp(c.ramp);
    case ReferenceType::kWaypoints: return trajectory::make_waypoints(c.waypoints);
  }
  return nullptr;
}

std::unique_ptr<controller::Controller> make_controller(const Scenario& s) {
  switch (s.controller.type) {
    case ControllerType::kSlidingMode:
      return std::make_unique<controller::SlidingModeController>(s.controller.sliding_mode);
    case ControllerType::kCascade: return std::make_unique<controller::CascadeController>(s.controller.cascade);
    case ControllerType::kOpenLoop: return std::make_unique<controller::OpenLoopSource>(s.controller.open_loop);
    case ControllerType::kPlugin: return std::make_unique<controller::PluginController>(s.controller.plugin);
  }
  return nullptr;
}

void use_plugin(Scenario& s, const std::string& library) {
  if (s.controller.type != ControllerType::kPlugin) {
    s.controller.type = ControllerType::kPlugin;
    s.controller.plugin = {};
    s.controller.plugin.model = model_of_plant(s.plant);
    s.controller.plugin.period = s.control_period;
    s.controller.plugin.computation_delay = s.controller.computation_delay;
  }
  s.controller.plugin.library = library;
  controller::PluginLibrary::open(library);
}

}  // namespace feeddrive::sim

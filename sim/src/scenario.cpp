#include "feeddrive/sim/scenario.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "feeddrive/common/text.hpp"
#include "feeddrive/common/text_file.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/csv/reader.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::sim {
namespace {

namespace fs = std::filesystem;
using plant::PlantParams;

// A name from the file as a message shows it: printable ASCII, at most 40 bytes.
std::string output_shown(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return s.size() > 40 ? out + "..." : out;
}

// --- plant ---------------------------------------------------------------------------------

void read_friction(MapReader r, plant::FrictionParams& f) {
  std::string model = plant::to_string(f.model);
  r.string("model", model);
  try {
    f.model = plant::friction_model_from_string(model);
  } catch (const std::invalid_argument& e) {
    r.fail("model", " = '" + model + "': " + e.what());
  }
  r.number("static_force", f.static_force);
  r.number("coulomb_force", f.coulomb_force);
  r.number("stribeck_velocity", f.stribeck_velocity);
  r.number("stribeck_exponent", f.stribeck_exponent);
  r.number("bristle_stiffness", f.bristle_stiffness);
  r.number("bristle_damping", f.bristle_damping);
  r.number("viscous", f.viscous);
  r.number("damping_decay_velocity", f.damping_decay_velocity);
  r.number("static_smoothing_velocity", f.static_smoothing_velocity);
  r.number("static_smoothing_shape", f.static_smoothing_shape);
  r.finish();
}

void read_ripple(MapReader r, plant::RippleParams& p) {
  r.boolean("enabled", p.enabled);
  r.number("pitch", p.pitch);
  r.number("cogging_amplitude", p.cogging_amplitude);
  r.number("cogging_phase", p.cogging_phase);
  r.number("cogging_third", p.cogging_third);
  r.number("cogging_third_phase", p.cogging_third_phase);
  r.number("reluctance_amplitude", p.reluctance_amplitude);
  r.number("reluctance_phase", p.reluctance_phase);
  r.number("reluctance_third", p.reluctance_third);
  r.number("reluctance_third_phase", p.reluctance_third_phase);
  r.finish();
}

void read_grinding(MapReader r, plant::GrindingParams& p) {
  r.boolean("enabled", p.enabled);
  r.number("stiffness", p.stiffness);
  r.number("dullness", p.dullness);
  r.number("workpiece_diameter", p.workpiece_diameter);
  r.number("wheel_width", p.wheel_width);
  r.number_or_infinite("contact_position", p.contact_position);
  r.number("contact_width", p.contact_width);
  r.finish();
}

void read_electrical(MapReader r, plant::ElectricalParams& p) {
  r.boolean("enabled", p.enabled);
  r.number("resistance", p.resistance);
  r.number("inductance", p.inductance);
  r.number("back_emf", p.back_emf);
  r.finish();
}

void read_sensor(MapReader r, plant::SensorParams& p) {
  r.number("quantization", p.quantization);
  r.number("noise_stddev", p.noise_stddev);
  r.unsigned_integer("seed", p.seed);
  r.string("velocity", p.velocity);
  r.finish();
}

void read_integrator(MapReader r, plant::IntegratorParams& p) {
  r.number("rtol", p.rtol);
  r.number("atol_position", p.atol_position);
  r.number("atol_velocity", p.atol_velocity);
  r.number("atol_bristle", p.atol_bristle);
  r.number("atol_grinding", p.atol_grinding);
  r.number("atol_current", p.atol_current);
  r.integer("max_steps", p.max_steps);
  r.finish();
}

void read_initial(MapReader r, plant::InitialState& p) {
  r.number("position", p.position);
  r.number("velocity", p.velocity);
  r.number("bristle", p.bristle);
  r.number("grinding", p.grinding);
  r.number("current", p.current);
  r.finish();
}

// plant.effects.<name>: listing an effect enables it (an optional `enabled: false` switches it
// off again); the parameters not given keep the struct's defaults. Names: plant/effects.hpp.
void read_effects(MapReader r, plant::EffectsParams& p) {
  for (const std::string& name : plant::effect_names()) {
    const bool listed = r.has(name);
    MapReader m = r.child(name);  // marks the name as known, for finish()'s hints
    if (!listed) continue;
    bool& enabled = plant::effect_enabled(p, name);
    enabled = true;
    m.boolean("enabled", enabled);
    for (const std::string& param : plant::effect_parameter_names(name))
      m.number(param, plant::effect_parameter(p, name, param));
    m.finish();
  }
  r.finish();
}

// The plant (with_effects) or a controller's model of it: a model has no effects, they are the
// plant's discrepancy from the model.
void read_plant(MapReader r, PlantParams& p, bool with_effects) {
  r.number("mass", p.mass);
  r.number("amplifier_gain", p.amplifier_gain);
  r.number("force_constant", p.force_constant);
  r.number("input_limit", p.input_limit);
  read_friction(r.child("friction"), p.friction);
  read_ripple(r.child("ripple"), p.ripple);
  read_grinding(r.child("grinding"), p.grinding);
  read_electrical(r.child("electrical"), p.electrical);
  read_sensor(r.child("sensor"), p.sensor);
  read_integrator(r.child("integrator"), p.integrator);
  read_initial(r.child("initial"), p.initial);
  if (with_effects) {
    read_effects(r.child("effects"), p.effects);
  } else if (r.has("effects")) {
    r.fail("effects", ": only the sliding_mode controller's model takes effects (e.g. those "
                      "feeddrive-fit found); the cascade uses the model's mass and friction only");
  }
  r.finish();
}

// --- controller ----------------------------------------------------------------------------

template <typename Enum, typename Parse>
void read_enum(MapReader& r, const std::string& key, Enum& out, Parse parse, const std::string& current) {
  std::string s = current;
  r.string(key, s);
  try {
    out = parse(s);
  } catch (const std::invalid_argument& e) {
    r.fail(key, " = '" + s + "': " + e.what());
  }
}

void read_sliding_mode(MapReader& r, controller::SlidingModeParams& p) {
  r.number("eta", p.eta);
  r.number("k", p.k);
  r.number("lambda", p.lambda);
  read_enum(r, "switching", p.switching, controller::switching_from_string, controller::to_string(p.switching));
  r.number("boundary_layer", p.boundary_layer);
  r.boolean("compensate_friction", p.compensate_friction);
  r.boolean("compensate_ripple", p.compensate_ripple);
  r.boolean("compensate_grinding", p.compensate_grinding);
  r.boolean("feedforward_acceleration", p.feedforward_acceleration);
  read_enum(r, "friction_state", p.friction_state, controller::state_source_from_string,
            controller::to_string(p.friction_state));
  read_enum(r, "grinding_state", p.grinding_state, controller::state_source_from_string,
            controller::to_string(p.grinding_state));
  r.number("observer_gain", p.observer_gain);
  read_enum(r, "motion_state", p.motion_state, controller::motion_source_from_string,
            controller::to_string(p.motion_state));
  r.number("motion_observer_bandwidth", p.motion_observer_bandwidth);
  r.boolean("motion_observer_disturbance", p.motion_observer_disturbance);
  r.boolean("compensate_delay", p.compensate_delay);
  r.number("u_min", p.u_min);
  r.number("u_max", p.u_max);
  read_plant(r.child("model"), p.model, true);
}

// A controller's nominal model by default: the plant itself, without the effects it does not know.
PlantParams model_of_plant(const PlantParams& plant) {
  PlantParams m = plant;
  m.effects = {};
  return m;
}

// type plugin (docs/plugins.md): library (resolved against the scenario's folder), parameters
// (a map of numbers and words, handed to the plugin as text), the nominal model and the limits.
// The library is opened here (file, symbols, ABI version), so a bad one fails at load.
void read_plugin(MapReader& r, controller::PluginParams& p, const std::string& base_dir) {
  p.library = r.required_string("library");
  if (fs::path(p.library).is_relative()) p.library = (fs::path(base_dir) / p.library).lexically_normal().string();
  r.record("library", p.library, true);
  MapReader params = r.child("parameters");
  for (const std::string& key : params.keys()) {
    const bool word = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    });
    if (!word) params.fail(key, ": a parameter name is letters, digits and _ only");
    std::string value;
    params.number_or_string(key, value);
    p.parameters.emplace_back(key, value);
  }
  params.finish();
  r.number("u_min", p.u_min);
  r.number("u_max", p.u_max);
  read_plant(r.child("model"), p.model, false);
}

// tuning: manual (kp, kv, ki as given) or rule (controller/cascade.hpp cascade_tuning(): from the
// control period, the computation delay and whether the velocity is differenced from an encoder,
// times bandwidth_scale); with the rule, kp, kv and ki must not be given.
void read_cascade(MapReader& r, controller::CascadeParams& p, PlantParams model, double period,
                  double computation_delay) {
  std::string tuning = "manual";
  r.string("tuning", tuning);
  if (tuning != "manual" && tuning != "rule") r.fail("tuning", " = '" + tuning + "': expected one of manual, rule");
  if (tuning == "rule") {
    for (const char* key : {"kp", "kv", "ki"})
      if (r.has(key)) r.fail(key, ": set by tuning: rule (remove it, or use tuning: manual)");
    double scale = 1.0;
    r.number("bandwidth_scale", scale);
    if (!(scale > 0.0)) r.fail("bandwidth_scale", " = " + std::to_string(scale) + ": must be > 0");
    const plant::SensorParams& sensor = model.sensor;
    const bool differenced = sensor.velocity == "difference" || (sensor.velocity == "auto" && !sensor.ideal());
    const controller::CascadeGains g = controller::cascade_tuning(period, computation_delay, differenced, scale);
    p.kp = g.kp;
    p.kv = g.kv;
    p.ki = g.ki;
  } else {
    if (r.has("bandwidth_scale")) r.fail("bandwidth_scale", ": only with tuning: rule");
    r.number("kp", p.kp);
    r.number("kv", p.kv);
    r.number("ki", p.ki);
  }
  r.number("velocity_feedforward", p.velocity_feedforward);
  r.number("acceleration_feedforward", p.acceleration_feedforward);
  r.boolean("friction_feedforward", p.friction_feedforward);
  r.number("disturbance_observer_bandwidth", p.disturbance_observer_bandwidth);
  r.boolean("compensate_delay", p.compensate_delay);
  r.number("u_min", p.u_min);
  r.number("u_max", p.u_max);
  read_plant(r.child("model"), model, false);
  p.mass = model.mass;
  p.thrust_gain = model.thrust_gain();
  p.friction = model.friction;
  p.quantization = model.sensor.quantization;
}

void read_open_loop(MapReader& r, controller::OpenLoopParams& p, std::string& file, const std::string& base_dir) {
  read_enum(r, "kind", p.kind, controller::open_loop_kind_from_string, controller::to_string(p.kind));
  r.number("amplitude", p.amplitude);
  r.number("frequency", p.frequency);
  r.number("phase", p.phase);
  r.number("offset", p.offset);
  r.number("rate", p.rate);
  r.number("start_time", p.start_time);
  r.number("u_min", p.u_min);
  r.number("u_max", p.u_max);
  r.string("file", file);
  if (!file.empty() && fs::path(file).is_relative()) file = (fs::path(base_dir) / file).string();
  r.record("file", file, true);
  if (p.kind == controller::OpenLoopKind::kCsv && file.empty()) r.fail("file", " = '': kind = csv needs a file");
}

// --- reference -----------------------------------------------------------------------------

ReferenceType reference_type_from_string(MapReader& r, const std::string& s) {
  if (s == "none") return ReferenceType::kNone;
  if (s == "sine") return ReferenceType::kSine;
  if (s == "step") return ReferenceType::kStep;
  if (s == "accel_limited") return ReferenceType::kAccelLimited;
  if (s == "scurve") return ReferenceType::kSCurve;
  if (s == "ramp") return ReferenceType::kRamp;
  if (s == "waypoints") return ReferenceType::kWaypoints;
  r.fail("type", " = '" + s + "': expected one of none, sine, step, accel_limited, scurve, ramp, waypoints");
}

void read_reference(MapReader r, ReferenceConfig& c, const std::string& base_dir) {
  std::string type = "none";
  r.string("type", type);
  c.type = reference_type_from_string(r, type);
  switch (c.type) {
    case ReferenceType::kNone:
      break;
    case ReferenceType::kSine:
      r.number("amplitude", c.sine.amplitude);
      r.number("frequency", c.sine.frequency);
      r.number("phase", c.sine.phase);
      r.number("offset", c.sine.offset);
      r.number("start_time", c.sine.start_time);
      break;
    case ReferenceType::kStep:
      r.number("amplitude", c.step.amplitude);
      r.number("step_time", c.step.step_time);
      r.number("initial", c.step.initial);
      break;
    case ReferenceType::kAccelLimited:
      r.number("distance", c.accel_limited.distance);
      r.number("max_velocity", c.accel_limited.max_velocity);
      r.number("max_acceleration", c.accel_limited.max_acceleration);
      r.number("start_time", c.accel_limited.start_time);
      r.number("initial", c.accel_limited.initial);
      break;
    case ReferenceType::kSCurve:
      r.number("distance", c.scurve.distance);
      r.number("max_velocity", c.scurve.max_velocity);
      r.number("max_acceleration", c.scurve.max_acceleration);
      r.number("max_jerk", c.scurve.max_jerk);
      r.number("start_time", c.scurve.start_time);
      r.number("initial", c.scurve.initial);
      break;
    case ReferenceType::kRamp:
      r.number("velocity", c.ramp.velocity);
      r.number("start_time", c.ramp.start_time);
      r.number("initial", c.ramp.initial);
      break;
    case ReferenceType::kWaypoints:
      c.waypoints_file = r.required_string("file");
      if (fs::path(c.waypoints_file).is_relative())
        c.waypoints_file = (fs::path(base_dir) / c.waypoints_file).string();
      r.record("file", c.waypoints_file, true);
      break;
  }
  r.finish();
}

void validate_reference(const ReferenceConfig& c) {
  switch (c.type) {
    case ReferenceType::kNone: break;
    case ReferenceType::kSine: c.sine.validate("reference"); break;
    case ReferenceType::kStep: c.step.validate("reference"); break;
    case ReferenceType::kAccelLimited: c.accel_limited.validate("reference"); break;
    case ReferenceType::kSCurve: c.scurve.validate("reference"); break;
    case ReferenceType::kRamp: c.ramp.validate("reference"); break;
    case ReferenceType::kWaypoints: break;  // read and checked in parse_node
  }
}

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

// The reference and an open-loop command are pure functions of t: a NaN or infinity they would
// produce (waypoints at 1e308, a sine at 1e308 Hz) is found here, before the run, at up to
// 100000 of the run's step times (every step of a run up to that size). The error names the
// section's keys and values as written. What depends on the motion is guarded at run time
// (simulation.cpp).
void check_functions_of_time(const Scenario& s, const YAML::Node& root) {
  const long n = s.steps();
  const long samples = std::min<long>(n + 1, 100000);
  const auto step_at = [&](long i) {
    return samples <= 1 ? 0L : static_cast<long>(static_cast<double>(i) * static_cast<double>(n) / static_cast<double>(samples - 1));
  };
  const auto section = [&](const char* key) {
    YAML::Emitter e;
    e << YAML::Flow << root[key];
    std::string text = e.c_str();
    for (char& c : text)
      if (c == '\n') c = ' ';
    return text.size() > 200 ? text.substr(0, 200) + "..." : text;
  };
  const auto fail = [&](const std::string& what, double v, double t, const char* key, const char* gives) {
    throw ScenarioError(std::string(key) + ": " + what + " = " + validate::format_number(v) + " at t = " +
                        validate::format_number(t) + " s: " + key + " " + section(key) + " " + gives);
  };
  if (s.reference.type != ReferenceType::kNone) {
    const auto ref = make_reference(s);
    for (long i = 0; i < samples; ++i) {
      const double t = s.time_of(step_at(i));
      const trajectory::Sample q = ref->sample(t);
      const std::pair<const char*, double> fields[] = {
          {"position", q.position}, {"velocity", q.velocity}, {"acceleration", q.acceleration}, {"jerk", q.jerk}};
      for (const auto& [what, v] : fields)
        if (!std::isfinite(v)) fail(std::string("the reference's ") + what, v, t, "reference", "gives no finite trajectory");
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

// A step count for a message: exact up to 10^15, else 3 significant digits ("1e+304", never
// "1.0000000000000001e+304").
std::string steps_text(double n) {
  if (n < 1e15) return validate::format_number(n);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", n);
  return buf;
}

Scenario parse_node(const YAML::Node& root, const std::string& base_dir, ResolvedKeys* resolved) {
  if (!root.IsMap()) throw ScenarioError("the scenario must be a YAML map with keys plant, controller, reference, duration, control_period");
  MapReader top(root, "", resolved);
  Scenario s;
  top.string("name", s.name);
  check_name(s.name, "name");
  if (!top.has("duration")) top.fail("duration", ": missing (required)");
  if (!top.has("control_period")) top.fail("control_period", ": missing (required)");
  top.number("duration", s.duration);
  top.number("control_period", s.control_period);
  if (!(s.duration > 0.0)) top.fail("duration", " = " + root["duration"].Scalar() + ": must be > 0");
  if (!(s.control_period > 0.0))
    top.fail("control_period", " = " + root["control_period"].Scalar() + ": must be > 0");
  if (s.control_period > s.duration)
    top.fail("control_period", " = " + root["control_period"].Scalar() + ": must be <= duration");
  if (const double n = std::round(s.duration / s.control_period); !(n <= kMaxSteps))
    throw ScenarioError("duration = " + root["duration"].Scalar() + ", control_period = " + root["control_period"].Scalar() +
                        ": " + steps_text(n) + " steps; a run has at most " + validate::format_number(kMaxSteps) +
                        " steps (docs/scenario.md, Limits)");

  {
    MapReader plant = top.child("plant");
    s.grinding_process = plant.has("grinding") || plant.child("effects").has("grinding_force");
    read_plant(plant, s.plant, true);
  }

  MapReader c = top.child("controller");
  std::string type = c.required_string("type");
  c.number("computation_delay", s.controller.computation_delay);
  if (s.controller.computation_delay < 0.0)
    c.fail("computation_delay", " = " + root["controller"]["computation_delay"].Scalar() + ": must be >= 0");
  if (type == "sliding_mode") {
    s.controller.type = ControllerType::kSlidingMode;
    s.controller.sliding_mode.model = model_of_plant(s.plant);
    // A model never carries the plant's sensor or initial state; they are not part of it.
    read_sliding_mode(c, s.controller.sliding_mode);
    s.controller.sliding_mode.period = s.control_period;
    s.controller.sliding_mode.computation_delay = s.controller.computation_delay;
  } else if (type == "cascade") {
    s.controller.type = ControllerType::kCascade;
    read_cascade(c, s.controller.cascade, s.plant, s.control_period, s.controller.computation_delay);
    s.controller.cascade.period = s.control_period;
    s.controller.cascade.computation_delay = s.controller.computation_delay;
  } else if (type == "open_loop") {
    s.controller.type = ControllerType::kOpenLoop;
    read_open_loop(c, s.controller.open_loop, s.controller.open_loop_file, base_dir);
    s.controller.open_loop.thrust_gain = s.plant.thrust_gain();
  } else if (type == "plugin") {
    s.controller.type = ControllerType::kPlugin;
    s.controller.plugin.model = model_of_plant(s.plant);
    read_plugin(c, s.controller.plugin, base_dir);
    s.controller.plugin.period = s.control_period;
    s.controller.plugin.computation_delay = s.controller.computation_delay;
  } else {
    c.fail("type", " = '" + type + "': expected one of sliding_mode, cascade, open_loop, plugin");
  }
  s.controller.model_given = c.has("model");
  c.finish();

  read_reference(top.child("reference"), s.reference, base_dir);
  {
    MapReader o = top.child("output");
    o.integer("every", s.output.every);
    o.string_list("columns", s.output.columns);
    o.finish();
    if (s.output.every < 1) o.fail("every", " = " + std::to_string(s.output.every) + ": must be an integer >= 1");
    const auto& all = record_columns();
    for (const std::string& c : s.output.columns) {
      if (std::find(all.begin(), all.end(), c) == all.end()) {
        std::string known;
        for (const auto& k : all) known += (known.empty() ? "" : ", ") + k;
        o.fail("columns", ": unknown column '" + output_shown(c) + "' (columns: " + known + ")");
      }
      if (std::count(s.output.columns.begin(), s.output.columns.end(), c) > 1)
        o.fail("columns", ": column '" + c + "' listed twice");
    }
    if (top.has("output") && root["output"]["columns"].IsDefined() && s.output.columns.empty())
      o.fail("columns", ": empty list (leave the key out to record every column)");
  }
  MapReader a = top.child("analysis");
  a.number("settled_after", s.analysis.settled_after);
  a.number("settling_band", s.analysis.settling_band);
  a.finish();
  top.finish();
  if (s.analysis.settled_after < 0.0) a.fail("settled_after", " must be >= 0");
  if (s.analysis.settling_band < 0.0) a.fail("settling_band", " = " + validate::format_number(s.analysis.settling_band) + ": must be >= 0 (0: 2 % of the move's distance)");

  // Component validation: each validate() names its key and value; tables come from the files.
  try {
    if (s.reference.type == ReferenceType::kWaypoints) s.reference.waypoints = read_waypoints_file(s.reference.waypoints_file);
    if (s.controller.type == ControllerType::kOpenLoop && s.controller.open_loop.kind == controller::OpenLoopKind::kCsv)
      read_open_loop_file(s.controller.open_loop_file, s.controller.open_loop);
    s.plant.validate("plant");
    switch (s.controller.type) {
      case ControllerType::kSlidingMode: s.controller.sliding_mode.validate("controller"); break;
      case ControllerType::kCascade: s.controller.cascade.validate("controller"); break;
      case ControllerType::kOpenLoop: s.controller.open_loop.validate("controller"); break;
      case ControllerType::kPlugin:
        s.controller.plugin.validate("controller");
        controller::PluginLibrary::open(s.controller.plugin.library);
        break;
    }
    validate_reference(s.reference);
  } catch (const std::invalid_argument& e) {
    throw ScenarioError(e.what());
  }
  if (s.steps() < 1)
    throw ScenarioError("duration = " + validate::format_number(s.duration) + ": shorter than one control period (" +
                        validate::format_number(s.control_period) + " s)");
  check_functions_of_time(s, root);
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
    if (!delay.enabled) delay.delay_s = 0.0;
    delay.enabled = true;
    delay.delay_s += d;
  }
  return p;
}

Scenario parse_scenario(const std::string& yaml_text, const std::string& base_dir, const std::string& origin,
                        ResolvedKeys* resolved) {
  try {
    const YAML::Node root = load_yaml_strict(yaml_text);
    if (resolved) resolved->clear();
    Scenario s = parse_node(root, base_dir, resolved);
    return s;
  } catch (const ScenarioError& e) {
    throw ScenarioError(origin + ": " + e.what());
  } catch (const std::exception& e) {
    throw ScenarioError(origin + ": " + e.what());
  }
}

Scenario load_scenario(const std::string& path, std::string* text_out) {
  const std::string text = text::read_text_file<ScenarioError>(path, "scenario file");
  if (text_out != nullptr) *text_out = text;
  const fs::path p(path);
  Scenario s = parse_scenario(text, p.parent_path().empty() ? "." : p.parent_path().string(), path);
  s.path = path;
  if (s.name.empty()) {
    s.name = p.stem().string();
    check_name(s.name, path + ": the name taken from the file name (set name: to choose another)");
  }
  return s;
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
  for (const auto& [path, value] : keys) {
    std::vector<std::string> parts;
    for (std::size_t b = 0;;) {
      const std::size_t e = path.find('.', b);
      parts.push_back(path.substr(b, e == std::string::npos ? std::string::npos : e - b));
      if (e == std::string::npos) break;
      b = e + 1;
    }
    items.emplace_back(std::move(parts), &value);
  }
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
    case ReferenceType::kWaypoints:
      return trajectory::make_waypoints(c.waypoints);
  }
  return nullptr;
}

std::unique_ptr<controller::Controller> make_controller(const Scenario& s) {
  switch (s.controller.type) {
    case ControllerType::kSlidingMode:
      return std::make_unique<controller::SlidingModeController>(s.controller.sliding_mode);
    case ControllerType::kCascade:
      return std::make_unique<controller::CascadeController>(s.controller.cascade);
    case ControllerType::kOpenLoop:
      return std::make_unique<controller::OpenLoopSource>(s.controller.open_loop);
    case ControllerType::kPlugin:
      return std::make_unique<controller::PluginController>(s.controller.plugin);
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

#pragma once
// A scenario: everything that defines one run, loaded from YAML (schema: docs/scenario.md).
//
//   name: ...            (optional)
//   duration: 1.5        [s]
//   control_period: 1e-4 [s]
//   plant:      {...}    feeddrive::plant::PlantParams
//   controller: {type: sliding_mode | cascade | open_loop | plugin, ...}
//   reference:  {type: sine | step | accel_limited | scurve | ramp | waypoints | none, ...}
//   analysis:   {settled_after: 0.25}   (optional)
//   output:     {every: 1, columns: [t, xd, x, ...]}   (optional)
//
// Loading is strict: an unknown or misspelt key, a missing value, a non-number, NaN or a value
// that fails validate() throws ScenarioError with a one-line message naming the key and value.

#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/fields.hpp"
#include "feeddrive/controller/cascade.hpp"
#include "feeddrive/controller/open_loop.hpp"
#include "feeddrive/controller/plugin_host.hpp"
#include "feeddrive/controller/sliding_mode.hpp"
#include "feeddrive/plant/params.hpp"
#include "feeddrive/sim/yaml_reader.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::sim {

class ScenarioError : public BadInput {
 public:
  using BadInput::BadInput;
};

enum class ControllerType { kSlidingMode, kCascade, kOpenLoop, kPlugin };
inline const std::vector<std::pair<ControllerType, const char*>>& enum_names(ControllerType) {
  static const std::vector<std::pair<ControllerType, const char*>> n = {{ControllerType::kSlidingMode, "sliding_mode"},
                                                                        {ControllerType::kCascade, "cascade"},
                                                                        {ControllerType::kOpenLoop, "open_loop"},
                                                                        {ControllerType::kPlugin, "plugin"}};
  return n;
}
enum class ReferenceType { kNone, kSine, kStep, kAccelLimited, kSCurve, kRamp, kWaypoints };
inline const std::vector<std::pair<ReferenceType, const char*>>& enum_names(ReferenceType) {
  static const std::vector<std::pair<ReferenceType, const char*>> n = {
      {ReferenceType::kNone, "none"},          {ReferenceType::kSine, "sine"},
      {ReferenceType::kStep, "step"},          {ReferenceType::kAccelLimited, "accel_limited"},
      {ReferenceType::kSCurve, "scurve"},      {ReferenceType::kRamp, "ramp"},
      {ReferenceType::kWaypoints, "waypoints"}};
  return n;
}

struct ReferenceConfig {
  ReferenceType type{ReferenceType::kNone};
  trajectory::SineParams sine;
  trajectory::StepParams step;
  trajectory::AccelLimitedParams accel_limited;
  trajectory::SCurveParams scurve;
  trajectory::RampParams ramp;
  std::string waypoints_file;                   ///< resolved against the scenario file's folder
  std::vector<trajectory::Waypoint> waypoints;  ///< read from waypoints_file when loaded

  /// The key of every reference type (docs/scenario.md "reference"); each type's keys are its
  /// params struct's list (sine, step, ...), the waypoints' `file` a rule of its own (a path
  /// resolved against the scenario's folder, the table read when loaded).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(type).doc("the profile (none: x_d = 0); its keys below"));
  }
};

struct ControllerConfig {
  ControllerType type{ControllerType::kSlidingMode};
  /// controller.computation_delay [s]: the command computed from the sample at t_k acts from
  /// t_k + computation_delay (within or beyond the period). The drive applies it (drive()).
  double computation_delay{0.0};
  controller::SlidingModeParams sliding_mode;
  controller::CascadeParams cascade;
  controller::OpenLoopParams open_loop;  ///< kind csv: its table read from open_loop_file when loaded
  std::string open_loop_file;            ///< controller.file, resolved against the scenario's folder
  /// type plugin: controller.library (resolved against the scenario's folder), .parameters,
  /// .model, .u_min, .u_max (docs/plugins.md).
  controller::PluginParams plugin;
  /// The nominal model of sliding_mode, cascade and plugin (controller.model, its keys not given
  /// the plant's own parameters, without the plant's effects). The loader hands it to the
  /// controller's params (sliding_mode.model, plugin.model, the cascade's mass, thrust_gain,
  /// friction and quantization).
  plant::PlantParams model;
  /// controller.model was given (false: the model of sliding_mode, cascade and plugin is the
  /// plant's own parameters without its effects; summary.json says so as controller_model).
  bool model_given{false};

  /// The keys of every controller type (the list; docs/scenario.md "controller"). The type's own
  /// keys are its params struct's list (sliding_mode, cascade, open_loop, plugin), its model the
  /// plant's.
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(type).required().doc("the controller: one of the three built-in laws or a plugin (below)"));
    a->Visit(FD_FIELD(computation_delay)
                 .unit("s")
                 .non_negative()
                 .plausible(0, 0.01, "ms", "", "a servo drive's delay")
                 .doc("the command computed from the sample at t_k acts over [t_k + d, t_{k+1} + d), within or "
                      "beyond the period; the drive applies it as an input delay (added to a "
                      "plant.effects.input_delay), also in the lockstep service's plant process. The "
                      "controller's own computation time, which it may know (compensate_delay)"));
  }
  /// The list's ranges (check_fields); the type's keys are validated by its params struct.
  void validate(const std::string& prefix = "controller") const { fields::check_fields(*this, prefix); }
};

struct AnalysisConfig {
  /// Start [s] of the "settled" window over which the *_settled error metrics are computed.
  double settled_after{0.25};
  /// Half-width [m] of the band the move's settling time is measured to (summary.hpp, "Move
  /// metrics"); 0 (default): 2 % of the move's distance (MATLAB stepinfo's SettlingTimeThreshold).
  double settling_band{0.0};

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(settled_after)
                 .unit("s")
                 .non_negative()
                 .doc("start of the window of the *_settled metrics in summary.json (the tuning procedure's "
                      "analysis window: 0.1 s, tuning.md)"));
    a->Visit(FD_FIELD(settling_band)
                 .unit("m")
                 .non_negative()
                 .doc("half-width of the band a move's settling time is measured to (Move and step metrics); "
                      "0: 2 % of the move's distance (MATLAB stepinfo's default)"));
  }
  void validate(const std::string& prefix = "analysis") const { fields::check_fields(*this, prefix); }
};

/// What timeseries.csv records (the summary and the plots always cover every step).
struct OutputConfig {
  long every{1};                     ///< keep rows k with k % every == 0
  std::vector<std::string> columns;  ///< the columns written, in this order; empty = all

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(every).at_least(1).doc(
        "keep every N-th row of timeseries.csv: the steps k = 0, N, 2N, ... by their number, also in a record "
        "with gaps (a log, an attached monitor); the summary and the plots still cover every step"));
    a->Visit(FD_FIELD(columns).doc(
        "the columns of timeseries.csv, in the order given, e.g. [t, xd, x, u]; an unknown or repeated name "
        "is an error that lists the columns (empty: all)"));
  }
  /// every >= 1 (the list); the column names are checked against the record's columns by the
  /// scenario loader (sim::record_columns).
  void validate(const std::string& prefix = "output") const { fields::check_fields(*this, prefix); }
};

/// Largest run: steps = round(duration / control_period) <= kMaxSteps (docs/scenario.md,
/// "Limits"): 1e10 steps are about a day of wall time at the fastest measured 7 us per step.
inline constexpr double kMaxSteps = 1e10;

/// Longest scenario name accepted [bytes].
inline constexpr std::size_t kMaxNameBytes = 256;

struct Scenario {
  std::string name;             ///< printable UTF-8, at most kMaxNameBytes
  std::string path;             ///< file it was loaded from ("" if parsed from a string)
  double duration{1.0};         ///< [s]
  double control_period{1e-4};  ///< [s]
  plant::PlantParams plant;
  ControllerConfig controller;
  ReferenceConfig reference;
  AnalysisConfig analysis;
  OutputConfig output;
  /// The scenario describes a grinding process: it has a plant.grinding section (enabled or not)
  /// or lists plant.effects.grinding_force. feeddrive-fit considers a grinding force only then.
  bool grinding_process{false};
  /// The presence facts: the dotted key of every map and value the scenario gives ("plant",
  /// "plant.ripple", "plant.ripple.cogging_amplitude"; `ripple: paper` gives plant.ripple.preset),
  /// recorded by the reader from the lists (MapReader) and by set_read_key. They decide what a
  /// value not given follows (a controller model's value follows the plant's unless given), the
  /// keys a type switch must not leave behind, and the "section given but off" warning.
  std::set<std::string> given_keys;
  /// The folder the scenario's file names (reference.file, controller.file, controller.library)
  /// are resolved against.
  std::string base_dir{"."};
  /// The effects the scenario lists, by key ("plant.effects.constant_force",
  /// "controller.model.effects.spring_force"). Listing one enables it; a listed one is part of
  /// the run's description (resolved_keys) even when it says `enabled: false`.
  std::set<std::string> listed_effects;
  /// The old spellings of keys the scenario uses (fields::Meta::alias: a key renamed into the
  /// plant's vocabulary, e.g. plant.effects.cogging_ripple.amplitude_N), one line each naming the
  /// old and the new key; read as the new key, and warnings (a deprecation).
  std::vector<std::string> renamed_keys;
  /// Values that load but are implausible for a linear feed drive (each naming the key, the
  /// value, the bound and the likely unit: "reference.max_velocity: 500 m/s is above any linear
  /// drive (10 m/s); mm/s?"), and a move that does not finish within `duration`. The loader
  /// never prints: the tools show them and summary.json lists them.
  std::vector<std::string> warnings;
  /// When the reference is a move (accel_limited, scurve, waypoints): its end time [s]; NaN
  /// otherwise. The move finishes within the run iff move_end_s <= duration.
  double move_end_s{std::numeric_limits<double>::quiet_NaN()};

  /// The drive as it runs: `plant` with the controller's computation delay added to the input
  /// delay (plant.effects.input_delay; the plant applies each command that long after its
  /// sample, restarting CVODE at the switch times). Every Plant built from a scenario uses this.
  plant::PlantParams drive() const;

  /// Number of control steps: round(duration / control_period).
  long steps() const;
  /// Time of step k: k * control_period (computed, never accumulated).
  double time_of(long k) const { return static_cast<double>(k) * control_period; }

  /// The top-level keys (the list; docs/scenario.md "Top level"). The sections plant, controller
  /// and reference are read by their own lists and rules (scenario.cpp).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(
        FD_FIELD(name).doc("label used in plots and summary.json; printable UTF-8, at most 256 bytes; "
                           "default: the file's stem"));
    a->Visit(FD_FIELD(duration).unit("s").positive().required().doc(
        "simulated time; the run has round(duration/control_period) steps (at most 1e10, Limits)"));
    a->Visit(FD_FIELD(control_period)
                 .unit("s")
                 .positive()
                 .required()
                 .plausible(1e-6, 0.01, "ms", "", "a servo drive's sample period")
                 .doc("the controller's sample period T; the input is held over each period"));
    a->Visit(FD_FIELD(analysis).doc("the windows of summary.json's metrics"));
    a->Visit(FD_FIELD(output).doc("what timeseries.csv records"));
  }
  /// The list's ranges (check_fields: duration, control_period > 0), analysis's and output's;
  /// throws std::invalid_argument "KEY = VALUE: why". The run's length, the name and the sections
  /// are checked by the loader (scenario.cpp).
  void validate() const {
    fields::check_fields(*this, "");
    analysis.validate("analysis");
    output.validate("output");
  }
};

/// The keys that name a file, resolved against the scenario's folder when loaded, as (section,
/// key): reference.file (waypoints), controller.file (an open-loop table), controller.library (a
/// plugin). A tool that writes a scenario elsewhere (feeddrive-fit's model.fitted.yaml) makes
/// them absolute.
inline const std::vector<std::pair<const char*, const char*>>& file_keys() {
  static const std::vector<std::pair<const char*, const char*>> k = {
      {"reference", "file"}, {"controller", "file"}, {"controller", "library"}};
  return k;
}

/// Loads and validates a scenario file. Throws ScenarioError("<file>: <key> = <value>: <why>").
/// `text`, if given, receives the file's bytes as read (a process that must prove it runs the
/// same scenario as others hashes exactly these).
Scenario load_scenario(const std::string& path, std::string* text = nullptr);

/// One `--set key=value` of a tool: a dotted scenario key and a YAML scalar.
struct KeySetting {
  std::string key;
  std::string value;
};
/// Parses "key=value" (the key a dotted path, the value a scalar). Throws ScenarioError
/// "--set TEXT: expected key=value" otherwise.
KeySetting parse_key_setting(const std::string& text);
/// A scenario file with settings (feeddrive-sim, -launch, -fit --set): the file read once into the
/// struct (read_scenario), the settings set in it (set_read_keys), then derived and checked
/// (complete_read), so a setting is checked like the file's own keys (unknown key with "did you
/// mean", type, range). Errors name the file and "--set". `text` receives the scenario as run:
/// the file's bytes without settings, else its resolved keys as one YAML document (resolved_yaml).
Scenario load_scenario(const std::string& path, const std::vector<KeySetting>& sets, std::string* text = nullptr);
/// Parses and validates YAML text; base_dir resolves relative file names; origin names the
/// source in messages. If `resolved` is given it receives resolved_keys() of the scenario: every
/// key with its effective value (given or default; file names resolved against base_dir), the
/// complete description of the run, used by feeddrive-study to vary keys, scale them and key its
/// cases.
Scenario parse_scenario(const std::string& yaml_text, const std::string& base_dir = ".",
                        const std::string& origin = "scenario", ResolvedKeys* resolved = nullptr);

/// Reads YAML text into a scenario as read: every key, type and value as the file gives it (the
/// reader's checks), before derive() and the whole-scenario checks (complete_read). The start of
/// a scenario built as a struct (set_read_key; feeddrive-sim --set, feeddrive-study's cases).
/// `controller` (optional): the YAML text of a controller map, read in place of the text's own
/// controller section (a study's controller entry). Throws ScenarioError "<origin>: ...".
Scenario read_scenario(const std::string& yaml_text, const std::string& base_dir = ".",
                       const std::string& origin = "scenario", const std::string& controller = "");

/// `key` with each old spelling in it (fields::Meta::alias, in the lists of the plant, the
/// controller's model, the controllers and the references) replaced by its key:
/// "plant.effects.cogging_ripple.amplitude_N" -> "plant.effects.cogging_ripple.cogging_amplitude";
/// any other key as it is. `note` (optional) receives the deprecation line of a replaced one.
std::string canonical_key(const std::string& key, std::string* note = nullptr);

/// Sets one dotted key of a scenario as read to `value` (YAML scalar text, or a flow list or map
/// `[t, x]`, `{model: none}`), as if the file said so, through the sections' lists: the value
/// parsed by the reader's own accessor (yaml_archive.hpp), with the reader's rules: a plant value
/// the controller's model does not give follows into the model, a type switch, a preset (the
/// keys given below it keep their values), listing an effect enables it, the cascade's tuning
/// rule, a file resolved against base_dir, a map replaces the sub-section (its keys not given
/// take their defaults). The key is recorded in given_keys. Throws ScenarioError, one line naming
/// the key and the value, for what the file could not say either (an unknown key with "did you
/// mean", a value its accessor refuses, a key of another type left by a type switch) and for the
/// one thing a setting cannot do: replace a whole section (`plant={...}`).
void set_read_key(Scenario& s, const std::string& key, const std::string& value);
/// Sets several keys (set_read_key): the type selectors (controller.type, reference.type,
/// controller.tuning, a ripple preset) first, as in a file where they hold whatever the order,
/// the others in the order given (a later value of one key wins).
void set_read_keys(Scenario& s, const std::vector<KeySetting>& sets);
/// derive() and the checks of parse_scenario on a scenario as read (the run's length, each
/// component's validate(), the files it names, the functions of time, the warnings).
void complete_read(Scenario& s);

/// Every key that describes the run, with its effective value, from the scenario's struct: the
/// keys of each section's list (common/fields.hpp) for its controller and reference type, the
/// effects listed, the cascade's gains unless its tuning rule sets them, the files resolved
/// against the scenario's folder. The same as parse_scenario's `resolved`.
ResolvedKeys resolved_keys(const Scenario& s);

/// The resolved keys as one YAML document (nested maps, keys in sorted order, so the same keys
/// always give the same text). parse_scenario reads it back to the same scenario and the same
/// resolved keys (tests/sim/resolved_keys_test.cpp).
std::string resolved_yaml(const ResolvedKeys& keys);

/// The tables a scenario names (reference.file, controller.file), read with the one CSV reader
/// (feeddrive/csv/reader.hpp). Throw csv::CsvError (std::invalid_argument), one line naming
/// file:line:column and the value.
std::vector<trajectory::Waypoint> read_waypoints_file(const std::string& path);
/// Fills p.table_t, p.table_value and p.table_is_force from columns t and force_N (or u).
void read_open_loop_file(const std::string& path, controller::OpenLoopParams& p);

std::unique_ptr<trajectory::Trajectory> make_reference(const Scenario& s);
std::unique_ptr<controller::Controller> make_controller(const Scenario& s);

/// feeddrive-controller --plugin PATH: the scenario's controller becomes the plugin at PATH,
/// with the scenario's plugin parameters if its controller is a plugin (none otherwise), and the
/// nominal model, limits and period the scenario gives a plugin. Throws controller::PluginError.
void use_plugin(Scenario& s, const std::string& library);

}  // namespace feeddrive::sim

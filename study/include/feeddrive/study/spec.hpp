#pragma once
// A study: a base scenario plus variations (schema and examples: docs/study.md).
//
//   name: robustness
//   base: ../scenarios/paper/smc_bl_jerk_limited.yaml     # a scenario file, or an inline scenario map
//   set: {duration: 1.2}                                   # dotted keys for every case (optional)
//   model: nominal            # the controllers keep the nominal model (default), or: follows_plant
//   controllers:                                          # optional; default: the base's controller
//     - {name: smc_sgn_20us, scenario: ../scenarios/paper/smc_jerk_limited.yaml}   # its controller + control_period
//     - {name: cascade_kv3000, controller: {type: cascade, kv: 3000}, set: {control_period: 1.0e-4}}
//   families:                                             # optional; default: one case, "nominal"
//     - name: mass
//       set: {plant.sensor.noise_stddev: 1.0e-8}
//       grid:                                             # the Cartesian product of the axes
//         - {key: plant.mass, scale: [0.8, 1.2]}          # factors on the nominal value
//         - {keys: [plant.friction.static_force, plant.friction.coulomb_force], values: [[200, 150], [260, 195]]}
//     - name: monte_carlo
//       monte_carlo:
//         draws: 200
//         seed: 1
//         parameters:
//           - {key: plant.mass, distribution: uniform, low: 0.8, high: 1.2, scale: true}
//           - {keys: [plant.friction.bristle_stiffness, plant.friction.bristle_damping],
//              distribution: lognormal, mu: 0.0, sigma: 0.1, scale: true}
//           - {key: plant.effects.input_delay.delay, distribution: normal, mean: 5e-4, stddev: 2e-4,
//              low: 0, high: 1e-3}
//   report: {metric: position_error_max_abs_m, scale: 1.0e6, unit: um, limit: 0.8,   # optional
//            require: [control_signal_within_limits]}
//
// Every key is a dotted path into the scenario YAML (docs/scenario.md), checked by the scenario
// loader itself when the cases are resolved (cases.hpp), so a misspelt key gets the loader's
// one-line "unknown key (did you mean ...)" error. Loading is strict like the scenario's: an
// unknown study key, a bad distribution, an empty grid, NaN or an impossible case count throws
// StudyError with one line naming the key and the value (feeddrive-study exits 2).

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/fields.hpp"

namespace feeddrive::study {

class StudyError : public BadInput {
 public:
  using BadInput::BadInput;
};

/// One scenario key (dotted path) set to a YAML scalar (its text).
struct Setting {
  std::string key;
  std::string value;
};

/// One axis of a grid: at point i every key k takes values[i][k] together. With `scale`, the
/// values are factors on each key's nominal value (the case without variations).
struct GridAxis {
  std::vector<std::string> keys;
  std::vector<std::vector<std::string>> values;
  bool scale{false};
  bool log{false};  ///< the values were given log-spaced (--sweep KEY=log:...): the report plots a log axis
};

enum class Distribution { kUniform, kNormal, kLognormal };
/// The names of `distribution:` (fields::enum_name, enum_from_name, enum_choices).
inline const std::vector<std::pair<Distribution, const char*>>& enum_names(Distribution) {
  static const std::vector<std::pair<Distribution, const char*>> k{
      {Distribution::kUniform, "uniform"}, {Distribution::kNormal, "normal"}, {Distribution::kLognormal, "lognormal"}};
  return k;
}

/// A Monte Carlo parameter: one draw per case sets every key to the same number (with `scale`,
/// each key is its nominal value times the draw).
///   uniform:   U(a = low, b = high)
///   normal:    N(a = mean, b = stddev^2), truncated to [low, high] by redrawing
///   lognormal: exp(N(a = mu, b = sigma^2)), truncated to [low, high] by redrawing
struct DrawSpec {
  std::vector<std::string> keys;
  Distribution distribution{Distribution::kUniform};
  double a{0.0};
  double b{1.0};
  double low{-std::numeric_limits<double>::infinity()};
  double high{std::numeric_limits<double>::infinity()};
  bool scale{false};
};

struct MonteCarlo {
  long draws{0};  ///< 0: no Monte Carlo in this family
  std::uint64_t seed{0};
  std::vector<DrawSpec> parameters;
};

/// A case family: its settings, then every point of its grid (one point if none) times every
/// Monte Carlo draw (one if none).
struct Family {
  std::string name;
  std::vector<Setting> set;
  std::vector<GridAxis> grid;
  MonteCarlo monte_carlo;
};

/// A controller to compare: the YAML of its `controller` block, then its settings (from a
/// scenario file: that file's control_period first).
struct ControllerEntry {
  std::string name;
  std::string block;               ///< YAML text of the controller map ("" keeps the base's)
  std::vector<Setting> block_set;  ///< taken with the block: its scenario file's control_period
  std::vector<Setting> set;        ///< the entry's own set
};

struct ReportParams {
  std::string metric{"position_error_max_abs_m"};  ///< a summary.json key
  double scale{1e6};                               ///< shown value = metric * scale
  std::string unit{"um"};
  double limit{std::numeric_limits<double>::quiet_NaN()};  ///< a goal in shown units (NaN: none)
  /// Verdicts of summary.json (sim::summary_flag_names) that must be true for a case to pass,
  /// e.g. control_signal_within_limits. A case passes when it ran, its metric is <= limit (when
  /// a limit is given) and every required verdict is true.
  std::vector<std::string> require;
  bool has_criterion() const { return !std::isnan(limit) || !require.empty(); }
};

enum class ModelRule {
  kNominal,       ///< the controller's model is the case without the plant.* variations
  kFollowsPlant,  ///< the scenario loader's rule: the model defaults to the (varied) plant
};
/// The names of `model:` (fields::enum_name, enum_from_name, enum_choices).
inline const std::vector<std::pair<ModelRule, const char*>>& enum_names(ModelRule) {
  static const std::vector<std::pair<ModelRule, const char*>> k{{ModelRule::kNominal, "nominal"},
                                                                {ModelRule::kFollowsPlant, "follows_plant"}};
  return k;
}

inline constexpr long kMaxCases = 1000000;

struct Study {
  std::string name;
  std::string path;       ///< the study file ("" if parsed from text)
  std::string base_yaml;  ///< the base scenario's YAML text
  std::string base_dir;   ///< resolves the base scenario's relative file names
  std::vector<Setting> set;
  ModelRule model{ModelRule::kNominal};
  std::vector<ControllerEntry> controllers;  ///< never empty after loading
  std::vector<Family> families;              ///< never empty after loading
  ReportParams report;

  /// The structural rules (names unique and non-empty, grids non-empty and rectangular,
  /// distributions well-formed, case count within kMaxCases). Throws StudyError, one line.
  void validate() const;
  /// Cases of one family for one controller (grid points x draws).
  long family_cases(std::size_t f) const;
  long total_cases() const;
};

/// One --sweep of feeddrive-study: "KEY=V1,V2,..." (values as written), "KEY=START:STOP:N" (N
/// values, linear) or "KEY=log:START:STOP:N" (N values, logarithmic; START, STOP > 0). Throws
/// StudyError "--sweep TEXT: why", one line.
GridAxis parse_sweep(const std::string& text);

/// A study without a study file (feeddrive-study SCENARIO --sweep ...): the scenario is the base,
/// its controller the only one, and one family "sweep" whose grid has one axis per sweep (their
/// Cartesian product). Validated. Throws StudyError, one line, if the file is a study file (it
/// has a study's keys: base, controllers, families) or two axes vary the same key (the later
/// would silently replace the earlier's values).
Study sweep_study(const std::string& scenario_path, const std::vector<GridAxis>& axes);

/// Loads a study file (relative paths inside it are relative to its folder).
Study load_study(const std::string& path);
/// Parses study YAML text; base_dir resolves the file names in it, origin names it in errors.
Study parse_study(const std::string& yaml_text, const std::string& base_dir, const std::string& origin);

}  // namespace feeddrive::study

#pragma once
// A study's cases: expansion (which cases, which variations) and resolution (the one scenario
// each case runs), as pure functions of the study.
//
// Order: controller-major, then family, then grid point (the last axis fastest), then Monte Carlo
// draw. A case's variations are its grid values and draws; draw j of parameter p of a family is a
// pure function of (seed, j, p) (draw_value), the same for every controller, so every controller
// meets the same plants (common random numbers) and no order of evaluation changes a number.
//
// Resolution (Resolver::resolve) builds the case's scenario as a struct: the base read once
// (sim::read_scenario) with each controller's block read into it, then the settings of the layers
//   controller block's control_period -> study set -> controller set -> family set -> variations
// set in it through the sections' key lists (sim::set_read_keys: each value checked by the
// loader's own accessor; a misspelt key is the loader's one-line "unknown key" error), then
// derived and checked (sim::complete_read). No case is YAML read again. A `scale` variation multiplies the key's
// nominal value: its effective value in the case without variations (defaults included). With the nominal model rule
// (spec.hpp), the controller's model (controller.model.*) is taken from the case without the plant.* variations except
// plant.sensor.*: the mismatch is in the plant, while the controller is set up for the encoder it actually has. The
// case's scenario is then the loader's resolved keys written as one YAML document (sim::resolved_yaml): every key with
// its effective value, loadable by feeddrive-sim. Its SHA-256 keys the case in the output folder.
//
// What a case is built from, besides its controller's base, is its CaseSettings (the layers and the
// variations' values as key=value settings); CaseBuilder builds it, on rank 0 and on every other
// MPI rank alike: a rank receives the study's bases once (StudyBases) and each case's settings,
// never a YAML document of the case, so both build the same struct by the same code.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/study/spec.hpp"

namespace feeddrive::study {

/// One varied key of a case: a value (YAML scalar text), or a factor on the nominal value.
struct Variation {
  std::string key;
  std::string value;
  bool scale{false};
  double factor{1.0};
};

struct CaseSpec {
  std::size_t controller{0};
  std::size_t family{0};
  long point{0};  ///< grid point within the family (0 without a grid)
  long draw{-1};  ///< Monte Carlo draw (-1 without)
  std::vector<Variation> variations;
};

/// The number of cases of the study (Study::total_cases, at most kMaxCases).
std::size_t case_count(const Study& s);

/// Case `index` (0 <= index < case_count) of the study, made from its index alone: the cases are
/// generated lazily, one at a time, never all at once (a study has up to 10^6). Pure; the study
/// must have passed validate().
CaseSpec case_at(const Study& s, std::size_t index);

/// Every case of the study in order (case_at for each index; for tests and small studies).
std::vector<CaseSpec> expand(const Study& s);

/// The cases resolved before any case runs, so the usual mistakes exit 2 before anything is
/// written: for each controller and family its first case and one case per further value of each
/// grid axis (the other axes at their first value, draw 0), in study order, at most `budget`.
/// The other cases are resolved as they are handed out; one that fails is a failed case.
std::vector<std::size_t> probe_cases(const Study& s, std::size_t budget);

/// Grid point `point` of family f: one variation per key of every axis.
std::vector<Variation> grid_point(const Family& f, long point);

/// Draw `draw` of Monte Carlo parameter `param` under `seed`: a pure function of the four, the
/// same on every machine for the same inputs (own uniform and Box-Muller transforms on a
/// SplitMix64 stream; no std:: distribution, whose output differs between standard libraries).
double draw_value(const DrawSpec& d, std::uint64_t seed, long draw, std::size_t param);

/// The uniform number in [0, 1) that a SplitMix64 stream keyed by (seed, a, b, c) gives: 53 bits.
double unit_uniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c);

/// Every key a grid axis or a Monte Carlo parameter of the study varies, in its canonical
/// spelling (sim::canonical_key: an old spelling and its key are one column), in order of first
/// appearance (the parameter columns of results.csv).
std::vector<std::string> varied_keys(const Study& s);

/// What a case is built from, besides its controller's base (StudyBases): the settings set in
/// it as the file would say them (sim::set_read_keys), in this order, and the nominal model rule.
struct CaseSettings {
  std::size_t controller{0};
  /// The layers: the controller block's set, the study's, the controller's, the family's.
  std::vector<sim::KeySetting> layers;
  /// The variations' values (a scale's factor applied to the key's nominal value).
  std::vector<sim::KeySetting> values;
  /// The nominal model rule (spec.hpp, ModelRule::kNominal): the controller's model is that of
  /// the case without its plant-only values.
  bool nominal_model{false};
  bool operator==(const CaseSettings& o) const;
};

/// The settings as bytes for another rank (strings, each as its length and its bytes), and back.
/// unpack_settings throws StudyError on bytes that are not such a packing.
std::string pack_settings(const CaseSettings& c);
CaseSettings unpack_settings(const std::string& bytes);

/// The study's bases: the base scenario's text, read once per controller with that controller's
/// block (YAML text of a controller map, "" for the base's own) in place of its controller. What
/// a rank needs of the study to build its cases (packed once per rank, not per case).
struct StudyBases {
  std::string path;  ///< the study file, for messages
  std::string base_yaml;
  std::string base_dir;
  std::vector<std::string> names;   ///< the controllers' names
  std::vector<std::string> blocks;  ///< their blocks
  static StudyBases of(const Study& s);
  bool operator==(const StudyBases& o) const;
};
std::string pack_bases(const StudyBases& b);
StudyBases unpack_bases(const std::string& bytes);

/// Builds cases from their settings: the controller's base as read (once), the layers set in it
/// (kept for the next case of the same layers), the values set in that, with the nominal model
/// rule the model from the same without the plant-only values, then derived and checked
/// (sim::complete_read). Not thread-safe; the scenarios it returns are.
class CaseBuilder {
 public:
  /// Reads the bases; throws StudyError naming the study (and controller) and the loader's error.
  explicit CaseBuilder(const StudyBases& bases);
  ~CaseBuilder();
  /// Throws StudyError "<origin>: <the loader's key and value>".
  std::shared_ptr<const sim::Scenario> build(const CaseSettings& c, const std::string& origin);
  /// The resolved keys of the case without its values (the layers only, derived): a scale's
  /// nominal value.
  const sim::ResolvedKeys& nominal_keys(const CaseSettings& c, const std::string& origin);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// True when two cases' scenarios are the same: every section's field list (fields::same: the
/// plant, every controller's and reference's parameters, the controller's model, ...), the
/// resolved keys, and what the reader records beside the lists (given keys, listed effects, the
/// grinding process, the warnings, the move's end).
bool same_case(const sim::Scenario& a, const sim::Scenario& b);

struct ResolvedCase {
  /// The case's scenario as it runs: built as a struct, derived and checked (Resolver::resolve).
  std::shared_ptr<const sim::Scenario> scenario;
  CaseSettings settings;  ///< what the scenario is built from (another MPI rank builds it from these)
  std::string yaml;       ///< the complete scenario's keys (resolved_yaml; loads in feeddrive-sim)
  std::string hash;       ///< SHA-256 (hex) of the format tag and yaml
  /// Effective value of every key of varied_keys() that this case's scenario has, by key.
  std::map<std::string, std::string> parameters;
};

/// Resolves cases, caching the layered loads shared by cases of one controller and family.
/// Not thread-safe; the results are.
class Resolver {
 public:
  explicit Resolver(const Study& s);
  ~Resolver();
  /// Throws StudyError (one line naming the study, the case and the loader's key and value).
  ResolvedCase resolve(const CaseSpec& c);
  /// A label of the case for messages: "controller 'x', family 'y', point 2, draw 7".
  std::string label(const CaseSpec& c) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// SHA-256 of `text` as 64 lowercase hex digits.
std::string sha256_hex(const std::string& text);

/// The format tag hashed with every case: a change to how cases are run or recorded changes it.
inline constexpr const char* kCaseFormat = "feeddrive-study case format 1\n";

}  // namespace feeddrive::study

#pragma once
// Strict reading of a YAML mapping: every key read is recorded, and finish() rejects the keys
// nobody asked for (misspellings get a "did you mean" hint). Every error is one line naming the
// full dotted key and the offending value.

#include <yaml-cpp/yaml.h>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace feeddrive::sim {

/// The effective value of one scalar key of a scenario (as given, or the default), as YAML
/// scalar text that reads back to the same value (sim::resolved_keys, scenario.hpp).
struct ResolvedValue {
  std::string text;
  bool is_string{false};  ///< read as text (a name, a mode, a file), not as a number or flag
  bool operator==(const ResolvedValue& o) const { return text == o.text && is_string == o.is_string; }
};
/// Every scalar key of a run's description, by full dotted path ("plant.friction.static_force").
using ResolvedKeys = std::map<std::string, ResolvedValue>;

/// Parses YAML text strictly; every error is a ScenarioError "line N: ...":
///   * a syntax error (yaml-cpp's message, with its line);
///   * a quoted value that is not closed on the line where it opens (yaml-cpp would silently
///     swallow the rest of the file into it: "name: \"abc" then reported "duration: missing");
///   * a key that appears twice in one map ("duration: duplicate key on lines 2 and 7"; yaml-cpp
///     keeps the first silently);
///   * more than 100000 nodes (aliases that expand exponentially);
///   * a recursive alias, inside its own anchor ("line 1, column 37: friction.inner: recursive YAML
///     alias *f inside its own anchor &f (line 1): ..."): yaml-cpp would build a cycle that every
///     traversal follows until the stack overflows;
///   * a merge key ("line 3, column 3: b.<<: YAML merge key (<<) not supported ...").
/// The one YAML loader of every tool (scenario, study, fit): nothing else calls YAML::Load.
YAML::Node load_yaml_strict(const std::string& text);

class MapReader {
 public:
  /// node must be a map (or null/absent, treated as empty); path is its dotted key ("plant").
  /// `given` (optional, handed on to child readers): receives the dotted key of every map and
  /// value present in the node that is read (the presence facts, Scenario::given_keys).
  /// `renamed` (optional, handed on too): one line for each old spelling read (spelling()).
  MapReader(const YAML::Node& node, std::string path, std::set<std::string>* given = nullptr,
            std::vector<std::string>* renamed = nullptr);

  bool has(const std::string& key) const;
  /// Reads a finite number into out if the key is present; throws if present but invalid.
  void number(const std::string& key, double& out);
  /// Allows +/-inf (written .inf / -.inf), still rejects NaN.
  void number_or_infinite(const std::string& key, double& out);
  void integer(const std::string& key, long& out);
  void unsigned_integer(const std::string& key, std::uint64_t& out);
  void boolean(const std::string& key, bool& out);
  void string(const std::string& key, std::string& out);
  /// A list of strings ([a, b] or a block list) if the key is present; a single string is a
  /// list of one.
  void string_list(const std::string& key, std::vector<std::string>& out);
  /// A number (its shortest round-trip text, recorded as a number) or else a string, as text.
  void number_or_string(const std::string& key, std::string& out);
  /// The keys present in the map, in the file's order ("" for a non-scalar key).
  std::vector<std::string> keys() const;
  /// A required string key.
  std::string required_string(const std::string& key);
  /// Throws "KEY: missing (required)", naming a key of the map that is a near miss of it ("'contrl_period'
  /// is given: a misspelling of it?").
  [[noreturn]] void missing(const std::string& key) const;
  /// "; 'KEY' is given: a misspelling of it?" for the map's key nearest to `key`, "" if none is near.
  std::string near_miss(const std::string& key) const;
  /// A nested map (absent = empty).
  MapReader child(const std::string& key);
  /// If `key` holds a single value (not a map), its text in `out` and true.
  bool scalar_text(const std::string& key, std::string& out) const;
  /// An empty nested map at `key` (marked as read), whatever the node holds: a section given in
  /// another form (`ripple: paper`) is read as its defaults.
  MapReader child_absent(const std::string& key);
  /// The spelling of `key` the map gives, to read it by: `key`, or its old spelling `alias`
  /// (fields::Meta::alias; "" for none). An old spelling is recorded in `renamed`
  /// (renamed_key_note) and given as `key`. Both spellings given: a one-line error
  /// (both_spellings_error). finish() hints a word near the old spelling at `key`.
  std::string spelling(const std::string& key, const std::string& alias);
  /// Marks `key` as known (read by the caller some other way, e.g. a list), for finish().
  void known(const std::string& key) { read_.insert(key); }
  /// Records `key` (below this map) as given, for a form the accessors do not see (a preset's
  /// short form `ripple: paper` gives ripple.preset).
  void mark_given(const std::string& key) const {
    const auto old = aliases_.find(key);  // an old spelling is given as its key
    if (given_ != nullptr) given_->insert(key_path(old == aliases_.end() ? key : old->second));
  }
  /// Throws for every key present in the node but never read.
  void finish() const;

  std::string key_path(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  YAML::Node scalar(const std::string& key);
  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_;
  std::map<std::string, std::string> aliases_;  // old spelling -> key (spelling())
  std::set<std::string>* given_{nullptr};
  std::vector<std::string>* renamed_{nullptr};
};

/// The deprecation line of a key read by its old spelling (fields::Meta::alias), both dotted:
/// "plant.effects.constant_force.force_N: old spelling of plant.effects.constant_force.force
/// (deprecated: rename the key)". The one wording of the reader and the setter (canonical_key).
inline std::string renamed_key_note(const std::string& old_key, const std::string& key) {
  return old_key + ": old spelling of " + key + " (deprecated: rename the key)";
}
/// The one-line error of a map that gives a key in both spellings (`old_key` dotted).
inline std::string both_spellings_error(const std::string& old_key, const std::string& key) {
  return old_key + ": old spelling of " + key + ", which is given too: give " + key + " only";
}

/// Levenshtein distance, for "did you mean" hints.
std::size_t edit_distance(const std::string& a, const std::string& b);

/// " (did you mean 'X'?)" for the candidate X closest to `word` within two edits (the first of
/// equally close ones), "" if none is that close. `aliases` (old spelling -> key,
/// fields::Meta::alias) are candidates too: a word nearest an old spelling is hinted at its key,
/// " (did you mean 'cogging_amplitude', formerly 'amplitude_N'?)".
template <typename Names>
std::string did_you_mean(const std::string& word, const Names& candidates,
                         const std::map<std::string, std::string>& aliases = {}) {
  std::string hint;
  std::size_t best = 3;
  for (const std::string& known : candidates) {
    const std::size_t d = edit_distance(word, known);
    if (d < best) {
      best = d;
      hint = " (did you mean '" + known + "'?)";
    }
  }
  for (const auto& [old, key] : aliases) {
    const std::size_t d = edit_distance(word, old);
    if (d < best) {
      best = d;
      hint = " (did you mean '" + key + "', formerly '" + old + "'?)";
    }
  }
  return hint;
}

}  // namespace feeddrive::sim

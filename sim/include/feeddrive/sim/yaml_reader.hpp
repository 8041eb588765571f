#pragma once
// Strict reading of a YAML mapping: every key read is recorded, and finish() rejects the keys
// nobody asked for (misspellings get a "did you mean" hint). Every error is one line naming the
// full dotted key and the offending value.

#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <vector>

namespace feeddrive::sim {

/// Parses YAML text strictly; every error is a ScenarioError "line N: ...":
///   * a syntax error (yaml-cpp's message, with its line);
///   * a quoted value that is not closed on the line where it opens (yaml-cpp would silently
///     swallow the rest of the file into it: "name: \"abc" then reported "duration: missing");
///   * a key that appears twice in one map ("duration: duplicate key on lines 2 and 7"; yaml-cpp
///     keeps the first silently);
///   * more than 100000 nodes (aliases that expand exponentially).
YAML::Node load_yaml_strict(const std::string& text);

class MapReader {
 public:
  /// node must be a map (or null/absent, treated as empty); path is its dotted key ("plant").
  MapReader(const YAML::Node& node, std::string path);

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
  /// A required string key.
  std::string required_string(const std::string& key);
  /// A nested map (absent = empty).
  MapReader child(const std::string& key);
  /// Throws for every key present in the node but never read.
  void finish() const;

  std::string key_path(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  YAML::Node scalar(const std::string& key);
  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_;
};

/// Levenshtein distance, for "did you mean" hints.
std::size_t edit_distance(const std::string& a, const std::string& b);

}  // namespace feeddrive::sim

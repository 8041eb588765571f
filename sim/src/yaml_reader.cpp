#include "feeddrive/sim/yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "feeddrive/sim/scenario.hpp"

namespace feeddrive::sim {
namespace {

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "(empty)";
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "(a list)";
  return "(a map)";
}

bool parse_double(const std::string& text, double& out) {
  // YAML 1.2 core schema spellings of the special values.
  static const std::pair<const char*, double> kSpecial[] = {
      {".inf", std::numeric_limits<double>::infinity()},
      {".Inf", std::numeric_limits<double>::infinity()},
      {".INF", std::numeric_limits<double>::infinity()},
      {"+.inf", std::numeric_limits<double>::infinity()},
      {"-.inf", -std::numeric_limits<double>::infinity()},
      {"-.Inf", -std::numeric_limits<double>::infinity()},
      {"-.INF", -std::numeric_limits<double>::infinity()},
      {".nan", std::numeric_limits<double>::quiet_NaN()},
      {".NaN", std::numeric_limits<double>::quiet_NaN()},
      {".NAN", std::numeric_limits<double>::quiet_NaN()}};
  for (const auto& [s, v] : kSpecial)
    if (text == s) {
      out = v;
      return true;
    }
  if (text.empty()) return false;
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

}  // namespace

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  std::iota(prev.begin(), prev.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

MapReader::MapReader(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap())
    throw ScenarioError(path_ + " = " + describe(node_) + ": expected a map of keys");
}

std::string MapReader::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void MapReader::fail(const std::string& key, const std::string& what) const {
  throw ScenarioError(key_path(key) + what);
}

bool MapReader::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined();
}

YAML::Node MapReader::scalar(const std::string& key) {
  read_.insert(key);
  if (!node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node n = node_[key];
  if (!n.IsDefined()) return n;
  if (n.IsNull()) fail(key, ": missing value");
  if (!n.IsScalar()) fail(key, " = " + describe(n) + ": expected a single value");
  return n;
}

void MapReader::number_or_infinite(const std::string& key, double& out) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) return;
  double v = 0.0;
  if (!parse_double(n.Scalar(), v)) fail(key, " = " + describe(n) + ": not a number");
  if (std::isnan(v)) fail(key, " = " + describe(n) + ": NaN is not allowed");
  out = v;
}

void MapReader::number(const std::string& key, double& out) {
  double v = out;
  number_or_infinite(key, v);
  if (!std::isfinite(v)) fail(key, " = " + node_[key].Scalar() + ": must be finite");
  out = v;
}

void MapReader::integer(const std::string& key, long& out) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) return;
  const std::string& s = n.Scalar();
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || end != s.c_str() + s.size()) fail(key, " = " + describe(n) + ": not an integer");
  out = v;
}

void MapReader::unsigned_integer(const std::string& key, std::uint64_t& out) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) return;
  const std::string& s = n.Scalar();
  char* end = nullptr;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (s.empty() || s[0] == '-' || end != s.c_str() + s.size())
    fail(key, " = " + describe(n) + ": not a non-negative integer");
  out = v;
}

void MapReader::boolean(const std::string& key, bool& out) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) return;
  const std::string& s = n.Scalar();
  if (s == "true" || s == "True" || s == "TRUE" || s == "on" || s == "yes") {
    out = true;
  } else if (s == "false" || s == "False" || s == "FALSE" || s == "off" || s == "no") {
    out = false;
  } else {
    fail(key, " = " + describe(n) + ": expected true or false");
  }
}

void MapReader::string(const std::string& key, std::string& out) {
  const YAML::Node n = scalar(key);
  if (n.IsDefined()) out = n.Scalar();
}

void MapReader::string_list(const std::string& key, std::vector<std::string>& out) {
  read_.insert(key);
  if (!node_.IsMap()) return;
  const YAML::Node n = node_[key];
  if (!n.IsDefined()) return;
  if (n.IsNull()) fail(key, ": missing value");
  if (n.IsScalar()) {
    out = {n.Scalar()};
    return;
  }
  if (!n.IsSequence()) fail(key, " = " + describe(n) + ": expected a list of names");
  out.clear();
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(key, "[" + std::to_string(i) + "] = " + describe(n[i]) + ": expected a name");
    out.push_back(n[i].Scalar());
  }
}

std::string MapReader::required_string(const std::string& key) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) fail(key, ": missing (required)");
  return n.Scalar();
}

MapReader MapReader::child(const std::string& key) {
  read_.insert(key);
  const YAML::Node n = node_.IsMap() ? node_[key] : YAML::Node(YAML::NodeType::Undefined);
  return MapReader(n, key_path(key));
}

void MapReader::finish() const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (read_.count(key)) continue;
    std::string hint;
    std::size_t best = 3;  // suggest only close matches (<= 2 edits)
    for (const auto& known : read_) {
      const std::size_t d = edit_distance(key, known);
      if (d < best) {
        best = d;
        hint = " (did you mean '" + known + "'?)";
      }
    }
    throw ScenarioError(key_path(key) + ": unknown key" + hint);
  }
}

}  // namespace feeddrive::sim

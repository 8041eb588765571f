#include "feeddrive/sim/yaml_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <string_view>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/parser.h>
#include "feeddrive/common/validate.hpp"
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
      {".inf", std::numeric_limits<double>::infinity()},   {".Inf", std::numeric_limits<double>::infinity()},
      {".INF", std::numeric_limits<double>::infinity()},   {"+.inf", std::numeric_limits<double>::infinity()},
      {"-.inf", -std::numeric_limits<double>::infinity()}, {"-.Inf", -std::numeric_limits<double>::infinity()},
      {"-.INF", -std::numeric_limits<double>::infinity()}, {".nan", std::numeric_limits<double>::quiet_NaN()},
      {".NaN", std::numeric_limits<double>::quiet_NaN()},  {".NAN", std::numeric_limits<double>::quiet_NaN()}};
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

// The line (1-based) where a quoted scalar opens and is not closed on the same line, or 0.
// Plain scalars may contain quotes (it's); a quote opens a quoted scalar only where a value
// starts: at the start of the line's content, or after ": ", "- ", "? ", "[", "{" or ",".
// Comments and block scalars (| and >) are skipped.
struct OpenQuote {
  long line{0};
  long closed_on{0};  ///< 0: never closed
};

OpenQuote find_multiline_quote(const std::string& text) {
  std::size_t i = 0;
  long line = 1;
  long block_indent = -1;  // inside a block scalar: lines indented deeper than this are its text
  while (i < text.size()) {
    const std::size_t eol = std::min(text.find('\n', i), text.size());
    const std::string_view l(text.data() + i, eol - i);
    const std::size_t first = l.find_first_not_of(" \t\r");
    const long indent = first == std::string_view::npos ? -1 : static_cast<long>(first);
    if (block_indent >= 0 && (indent < 0 || indent > block_indent)) {
      i = eol + 1;
      ++line;
      continue;
    }
    block_indent = -1;
    char prev_token = '\n';  // last non-space character before the current position
    for (std::size_t k = first == std::string_view::npos ? l.size() : first; k < l.size(); ++k) {
      const char c = l[k];
      if (c == '#' && (k == 0 || l[k - 1] == ' ' || l[k - 1] == '\t')) break;
      const bool after_space = k > 0 && (l[k - 1] == ' ' || l[k - 1] == '\t');
      const bool value_start = k == first ||
                               (after_space && std::string_view(":-?,[{").find(prev_token) != std::string_view::npos) ||
                               std::string_view("[{,").find(prev_token) != std::string_view::npos;
      if ((c == '"' || c == '\'') && value_start) {
        // Scan to the closing quote, possibly over lines.
        const long open_line = line;
        std::size_t j = i + k + 1;
        long cur = line;
        for (;;) {
          if (j >= text.size()) return {open_line, 0};
          const char q = text[j];
          if (q == '\n') ++cur;
          if (c == '"' && q == '\\') {
            if (j + 1 < text.size() && text[j + 1] == '\n') ++cur;
            j += 2;
            continue;
          }
          if (q == c) {
            if (c == '\'' && j + 1 < text.size() && text[j + 1] == '\'') {
              j += 2;
              continue;
            }
            break;
          }
          ++j;
        }
        if (cur != open_line) return {open_line, cur};
        k = j - i;  // the closing quote
        prev_token = c;
        continue;
      }
      if (c != ' ' && c != '\t' && c != '\r') prev_token = c;
    }
    // A block scalar indicator ends the line's content: "key: |", "key: >-", "- |2".
    {
      std::string_view content = l.substr(0, l.find(" #"));
      while (!content.empty() && (content.back() == ' ' || content.back() == '\t' || content.back() == '\r'))
        content.remove_suffix(1);
      std::size_t e = content.size();
      while (e > 0 && std::string_view("+-0123456789").find(content[e - 1]) != std::string_view::npos) --e;
      if (e > 0 && (content[e - 1] == '|' || content[e - 1] == '>') &&
          (e == 1 || content[e - 2] == ' ' || content[e - 2] == '\t'))
        block_indent = std::max<long>(indent, 0);
    }
    i = eol + 1;
    ++line;
  }
  return {};
}

void check_duplicate_keys(const YAML::Node& n, const std::string& path, long& budget) {
  if (--budget < 0) throw ScenarioError("more than 100000 YAML nodes (aliases that expand too far?)");
  if (n.IsMap()) {
    std::map<std::string, long> seen;
    for (const auto& kv : n) {
      const std::string key =
          kv.first.IsScalar() ? kv.first.Scalar() : "(a " + std::string(kv.first.IsMap() ? "map" : "list") + ")";
      const std::string key_path = path.empty() ? key : path + "." + key;
      const long line = kv.first.Mark().line + 1;
      const auto [it, fresh] = seen.emplace(key, line);
      if (!fresh)
        throw ScenarioError("line " + std::to_string(line) + ": " + key_path + ": duplicate key on lines " +
                            std::to_string(it->second) + " and " + std::to_string(line));
      check_duplicate_keys(kv.second, key_path, budget);
    }
  } else if (n.IsSequence()) {
    for (std::size_t k = 0; k < n.size(); ++k) check_duplicate_keys(n[k], path + "[" + std::to_string(k) + "]", budget);
  }
}

// The parser's events of the first document, checked before any node is built: yaml-cpp 0.7 makes
// an alias the same node as its anchor, so an alias inside its own anchor ("&f {inner: *f}") is a
// cycle in the node graph on which every traversal (copy, emit, our checks) recurses until the
// stack overflows; and it reads a merge key ("<<: *a") as an ordinary key named "<<".
// Both are refused here, at the alias's or the key's own line and column.
class ConstructCheck : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {
    begin_node();
    end_node("", false);
  }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t anchor) override {
    begin_node();
    for (const Frame& f : stack_)
      if (f.anchor == anchor && anchor != YAML::NullAnchor)
        throw ScenarioError(where(mark) + path() + ": recursive YAML alias *" + name(anchor) +
                            " inside its own anchor &" + name(anchor) + " (line " + std::to_string(f.line) +
                            "): not supported (an alias may only repeat a finished node)");
    end_node("", false);
  }
  void OnScalar(const YAML::Mark& mark, const std::string& tag, YAML::anchor_t, const std::string& value) override {
    begin_node();
    if (value == "<<" && tag == "?" && !stack_.empty() && stack_.back().map && stack_.back().expect_key)
      throw ScenarioError(where(mark) + path() + (path().empty() ? "" : ".") +
                          "<<: YAML merge key (<<) not supported: write the keys out");
    end_node(value, true);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(mark, anchor, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t anchor,
                  YAML::EmitterStyle::value) override {
    open(mark, anchor, true);
  }
  void OnMapEnd() override { close(); }
  void OnAnchor(const YAML::Mark&, const std::string& anchor_name) override { names_.push_back(anchor_name); }

 private:
  struct Frame {
    bool map{false};
    YAML::anchor_t anchor{YAML::NullAnchor};
    long line{0};
    bool expect_key{true};  // map: the next node is a key
    std::string key;        // map: the current key; sequence: the current index
    long index{-1};
  };
  static std::string where(const YAML::Mark& m) {
    return "line " + std::to_string(m.line + 1) + ", column " + std::to_string(m.column + 1) + ": ";
  }
  std::string name(YAML::anchor_t a) const {
    return a >= 1 && a <= names_.size() ? names_[a - 1] : std::to_string(a);  // anchors are numbered from 1
  }
  std::string path() const {
    std::string p;
    for (const Frame& f : stack_) {
      if (f.map) {
        if (!f.expect_key) p += (p.empty() ? "" : ".") + f.key;
      } else if (f.index >= 0) {
        p += "[" + std::to_string(f.index) + "]";
      }
    }
    return p;
  }
  // A node begins in the current collection: a key or a value of a map, an item of a sequence.
  void begin_node() {
    if (stack_.empty()) return;
    Frame& f = stack_.back();
    if (!f.map) ++f.index;
  }
  // A node ended: in a map, a key is followed by its value and a value by the next key.
  void end_node(const std::string& scalar, bool is_scalar) {
    if (stack_.empty()) return;
    Frame& f = stack_.back();
    if (!f.map) return;
    if (f.expect_key) f.key = is_scalar ? scalar : std::string("(a complex key)");
    f.expect_key = !f.expect_key;
  }
  void open(const YAML::Mark& mark, YAML::anchor_t anchor, bool map) {
    begin_node();
    Frame f;
    f.map = map;
    f.anchor = anchor;
    f.line = mark.line + 1;
    stack_.push_back(f);
  }
  void close() {
    stack_.pop_back();
    end_node("", false);
  }
  std::vector<Frame> stack_;
  std::vector<std::string> names_;
};

void check_constructs(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  ConstructCheck check;
  parser.HandleNextDocument(check);  // YAML::Load reads the first document only
}

}  // namespace

YAML::Node load_yaml_strict(const std::string& text) {
  const OpenQuote q = find_multiline_quote(text);
  if (q.line > 0 && q.closed_on == 0)
    throw ScenarioError("line " + std::to_string(q.line) + ": YAML syntax error: a quote opened here is never closed");
  if (q.line > 0)
    throw ScenarioError("line " + std::to_string(q.line) +
                        ": YAML syntax error: a quote opened here closes only on line " + std::to_string(q.closed_on) +
                        " (a quoted value must end on the line where it starts)");
  YAML::Node root;
  try {
    check_constructs(text);
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ScenarioError("line " + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  long budget = 100000;
  check_duplicate_keys(root, "", budget);
  return root;
}

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

MapReader::MapReader(const YAML::Node& node, std::string path, std::set<std::string>* given,
                     std::vector<std::string>* renamed)
    : node_(node), path_(std::move(path)), given_(given), renamed_(renamed) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap())
    throw ScenarioError(path_ + " = " + describe(node_) + ": expected a map of keys");
}

std::string MapReader::key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void MapReader::fail(const std::string& key, const std::string& what) const {
  throw ScenarioError(key_path(key) + what);
}

bool MapReader::has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined(); }

std::string MapReader::spelling(const std::string& key, const std::string& alias) {
  if (alias.empty()) return key;
  aliases_[alias] = key;
  if (!has(alias)) return key;
  if (has(key)) throw ScenarioError(both_spellings_error(key_path(alias), key));
  if (renamed_ != nullptr) renamed_->push_back(renamed_key_note(key_path(alias), key_path(key)));
  return alias;
}

YAML::Node MapReader::scalar(const std::string& key) {
  read_.insert(key);
  if (!node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  const YAML::Node n = node_[key];
  if (!n.IsDefined()) return n;
  mark_given(key);
  if (n.IsNull()) fail(key, ": missing value");
  if (!n.IsScalar()) fail(key, " = " + describe(n) + ": expected a single value");
  return n;
}

void MapReader::number_or_infinite(const std::string& key, double& out) {
  const YAML::Node n = scalar(key);
  if (n.IsDefined()) {
    double v = 0.0;
    if (!parse_double(n.Scalar(), v)) fail(key, " = " + describe(n) + ": not a number");
    if (std::isnan(v)) fail(key, " = " + describe(n) + ": NaN is not allowed");
    out = v;
  }
}

void MapReader::number(const std::string& key, double& out) {
  double v = out;
  number_or_infinite(key, v);
  if (!std::isfinite(v)) fail(key, " = " + node_[key].Scalar() + ": must be finite");
  out = v;
}

std::vector<std::string> MapReader::keys() const {
  std::vector<std::string> out;
  if (!node_.IsMap()) return out;
  for (const auto& kv : node_) out.push_back(kv.first.IsScalar() ? kv.first.Scalar() : std::string());
  return out;
}

void MapReader::number_or_string(const std::string& key, std::string& out) {
  const YAML::Node n = scalar(key);
  if (!n.IsDefined()) return;
  double v = 0.0;
  if (parse_double(n.Scalar(), v)) {
    if (!std::isfinite(v)) fail(key, " = " + describe(n) + ": must be finite");
    out = validate::format_number(v);  // shortest text that reads back to the same double
  } else {
    out = n.Scalar();
  }
}

void MapReader::integer(const std::string& key, long& out) {
  const YAML::Node n = scalar(key);
  if (n.IsDefined()) {
    const std::string& s = n.Scalar();
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || end != s.c_str() + s.size()) fail(key, " = " + describe(n) + ": not an integer");
    if (errno == ERANGE)
      fail(key, " = " + describe(n) + ": out of range (" + std::to_string(LONG_MIN) + " to " +
                    std::to_string(LONG_MAX) + ")");
    out = v;
  }
}

void MapReader::unsigned_integer(const std::string& key, std::uint64_t& out) {
  const YAML::Node n = scalar(key);
  if (n.IsDefined()) {
    const std::string& s = n.Scalar();
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
    if (s.empty() || s[0] == '-' || end != s.c_str() + s.size())
      fail(key, " = " + describe(n) + ": not a non-negative integer");
    if (errno == ERANGE)
      fail(key, " = " + describe(n) + ": out of range (0 to " +
                    std::to_string(std::numeric_limits<std::uint64_t>::max()) + ")");
    out = v;
  }
}

void MapReader::boolean(const std::string& key, bool& out) {
  const YAML::Node n = scalar(key);
  if (n.IsDefined()) {
    const std::string& s = n.Scalar();
    if (s == "true" || s == "True" || s == "TRUE" || s == "on" || s == "yes") {
      out = true;
    } else if (s == "false" || s == "False" || s == "FALSE" || s == "off" || s == "no") {
      out = false;
    } else {
      fail(key, " = " + describe(n) + ": expected true or false");
    }
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
  mark_given(key);
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
  if (!n.IsDefined()) missing(key);
  return n.Scalar();
}

void MapReader::missing(const std::string& key) const { fail(key, ": missing (required)" + near_miss(key)); }

std::string MapReader::near_miss(const std::string& key) const {
  // A key of the map within did_you_mean's distance of the missing one: a misspelt required key
  // is reported as what it is, not only as missing.
  std::string near;
  std::size_t best = 3;
  for (const std::string& given : keys()) {
    const std::size_t d = edit_distance(given, key);
    if (given != key && d < best) {
      best = d;
      near = given;
    }
  }
  return near.empty() ? std::string() : "; '" + key_path(near) + "' is given: a misspelling of it?";
}

MapReader MapReader::child(const std::string& key) {
  read_.insert(key);
  const YAML::Node n = node_.IsMap() ? node_[key] : YAML::Node(YAML::NodeType::Undefined);
  if (n.IsDefined()) mark_given(key);
  return MapReader(n, key_path(key), given_, renamed_);
}

bool MapReader::scalar_text(const std::string& key, std::string& out) const {
  if (!node_.IsMap()) return false;
  const YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull() || !n.IsScalar()) return false;
  out = n.Scalar();
  return true;
}

MapReader MapReader::child_absent(const std::string& key) {
  read_.insert(key);
  if (has(key)) mark_given(key);
  return MapReader(YAML::Node(YAML::NodeType::Undefined), key_path(key), given_, renamed_);
}

void MapReader::finish() const {
  if (!node_.IsMap()) return;
  for (const auto& kv : node_) {
    const std::string key = kv.first.Scalar();
    if (read_.count(key)) continue;
    throw ScenarioError(key_path(key) + ": unknown key" + did_you_mean(key, read_, aliases_));
  }
}

}  // namespace feeddrive::sim

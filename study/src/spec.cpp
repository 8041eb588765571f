#include "feeddrive/study/spec.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "feeddrive/common/text.hpp"
#include "feeddrive/common/text_file.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/summary.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::study {
namespace {

namespace fs = std::filesystem;
using sim::MapReader;

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "(empty)";
  if (n.IsScalar()) return "'" + n.Scalar() + "'";
  if (n.IsSequence()) return "(a list)";
  return "(a map)";
}

[[noreturn]] void fail(const std::string& key, const std::string& what) { throw StudyError(key + what); }

std::string read_file(const std::string& path, const std::string& key) {
  return text::read_text_file<StudyError>(path, key + " file");
}

std::string resolve_path(const std::string& base_dir, const std::string& p) {
  return fs::path(p).is_relative() ? (fs::path(base_dir) / p).lexically_normal().string() : p;
}

// A dotted scenario key as written in a study: non-empty parts of letters, digits and _.
void check_key(const std::string& where, const std::string& key) {
  bool ok = !key.empty() && key.front() != '.' && key.back() != '.' && key.find("..") == std::string::npos;
  for (char c : key) ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.');
  if (!ok) fail(where, " = '" + key + "': not a dotted scenario key (e.g. plant.friction.static_force)");
}

std::string scalar_text(const std::string& where, const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) fail(where, ": missing value");
  if (!n.IsScalar()) fail(where, " = " + describe(n) + ": expected a single value");
  const std::string& s = n.Scalar();
  // NaN never reaches a scenario through a study (the loader would say so too, but later).
  static const char* kNaN[] = {".nan", ".NaN", ".NAN", "nan", "NaN", "NAN"};
  for (const char* x : kNaN)
    if (s == x) fail(where, " = '" + s + "': NaN is not allowed");
  return s;
}

std::vector<Setting> read_settings(const std::string& where, const YAML::Node& n) {
  std::vector<Setting> out;
  if (!n.IsDefined() || n.IsNull()) return out;
  if (!n.IsMap()) fail(where, " = " + describe(n) + ": expected a map of dotted scenario keys to values");
  for (const auto& kv : n) {
    const std::string key = kv.first.Scalar();
    check_key(where, key);
    out.push_back({key, scalar_text(where + "." + key, kv.second)});
  }
  return out;
}

// `key: K` or `keys: [K1, K2]` of a grid axis or a draw.
std::vector<std::string> read_keys(const std::string& where, const YAML::Node& n) {
  const bool one = n["key"].IsDefined(), many = n["keys"].IsDefined();
  if (one == many) fail(where, ": give exactly one of key: or keys:");
  std::vector<std::string> keys;
  if (one) {
    keys.push_back(scalar_text(where + ".key", n["key"]));
  } else {
    const YAML::Node k = n["keys"];
    if (!k.IsSequence() || k.size() == 0)
      fail(where + ".keys", " = " + describe(k) + ": expected a non-empty list of keys");
    for (std::size_t i = 0; i < k.size(); ++i)
      keys.push_back(scalar_text(where + ".keys[" + std::to_string(i) + "]", k[i]));
  }
  std::set<std::string> seen;
  for (const std::string& key : keys) {
    check_key(where + (one ? ".key" : ".keys"), key);
    if (!seen.insert(key).second) fail(where + ".keys", " = '" + key + "': listed twice");
  }
  return keys;
}

double finite_number(const std::string& where, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) fail(where, " = '" + text + "': not a number");
  if (!std::isfinite(v)) fail(where, " = '" + text + "': must be a finite number");
  return v;
}

GridAxis read_axis(const std::string& where, const YAML::Node& n) {
  if (!n.IsMap())
    fail(where, " = " + describe(n) + ": expected a map {key: K, values: [...]} or {keys: [...], scale: [...]}");
  GridAxis a;
  a.keys = read_keys(where, n);
  const bool has_values = n["values"].IsDefined(), has_scale = n["scale"].IsDefined();
  if (has_values == has_scale) fail(where, ": give exactly one of values: or scale:");
  a.scale = has_scale;
  const std::string vkey = where + (has_scale ? ".scale" : ".values");
  const YAML::Node v = has_scale ? n["scale"] : n["values"];
  if (!v.IsSequence()) fail(vkey, " = " + describe(v) + ": expected a list");
  if (v.size() == 0) fail(vkey, ": empty grid axis (no values)");
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string ik = vkey + "[" + std::to_string(i) + "]";
    std::vector<std::string> point;
    if (v[i].IsSequence()) {
      if (v[i].size() != a.keys.size())
        fail(ik, " = (a list of " + std::to_string(v[i].size()) + "): expected one value per key (" +
                     std::to_string(a.keys.size()) + ")");
      for (std::size_t k = 0; k < v[i].size(); ++k)
        point.push_back(scalar_text(ik + "[" + std::to_string(k) + "]", v[i][k]));
    } else {
      point.assign(a.keys.size(), scalar_text(ik, v[i]));  // one value for all keys
    }
    if (a.scale)
      for (const std::string& s : point) finite_number(ik, s);
    a.values.push_back(point);
  }
  for (const auto& kv : n) {
    const std::string k = kv.first.Scalar();
    if (k != "key" && k != "keys" && k != "values" && k != "scale")
      fail(where + "." + k, ": unknown key (expected key, keys, values, scale)");
  }
  return a;
}

// The enum named `name`, the value of `key` of `r`: "KEY = 'x': expected one of a, b, c" otherwise.
template <typename E>
E enum_named(const MapReader& r, const std::string& key, const std::string& name) {
  try {
    return fields::enum_from_name<E>(name);
  } catch (const std::invalid_argument& e) {
    r.fail(key, " = '" + name + "': " + e.what());
  }
}

DrawSpec read_draw(const std::string& where, const YAML::Node& n) {
  if (!n.IsMap())
    fail(where, " = " + describe(n) + ": expected a map {key: K, distribution: uniform, low: ..., high: ...}");
  DrawSpec d;
  d.keys = read_keys(where, n);
  MapReader r(n, where);
  r.known("key");  // read above; marked known
  r.known("keys");
  d.distribution = enum_named<Distribution>(r, "distribution", r.required_string("distribution"));
  r.boolean("scale", d.scale);
  auto need = [&](const char* k, double& out) {
    if (!r.has(k))
      r.fail(k, std::string(": missing (required by distribution ") + fields::enum_name(d.distribution) + ")");
    r.number(k, out);
  };
  switch (d.distribution) {
    case Distribution::kUniform:
      need("low", d.a);
      need("high", d.b);
      if (!(d.a < d.b))
        r.fail("high", " = " + validate::format_number(d.b) + ": must be > low (" + validate::format_number(d.a) + ")");
      break;
    case Distribution::kNormal:
    case Distribution::kLognormal: {
      const bool normal = d.distribution == Distribution::kNormal;
      need(normal ? "mean" : "mu", d.a);
      need(normal ? "stddev" : "sigma", d.b);
      if (!(d.b > 0.0)) r.fail(normal ? "stddev" : "sigma", " = " + validate::format_number(d.b) + ": must be > 0");
      r.number_or_infinite("low", d.low);
      r.number_or_infinite("high", d.high);
      if (!(d.low < d.high))
        r.fail("high",
               " = " + validate::format_number(d.high) + ": must be > low (" + validate::format_number(d.low) + ")");
      if (!normal && d.high <= 0.0)
        r.fail("high", " = " + validate::format_number(d.high) + ": a lognormal draw is > 0, so high must be > 0");
      // Redrawing until inside [low, high] must end: the interval must hold a real share of the
      // distribution (at least ~1e-4: within 3.7 standard deviations of the centre).
      const double centre = d.a, sd = d.b;
      const double lo = normal ? d.low : (d.low > 0.0 ? std::log(d.low) : -std::numeric_limits<double>::infinity());
      const double hi = normal ? d.high : std::log(d.high);
      const double share =
          0.5 * (std::erf((hi - centre) / (sd * std::sqrt(2.0))) - std::erf((lo - centre) / (sd * std::sqrt(2.0))));
      if (!(share >= 1e-4))
        r.fail("low", " = " + validate::format_number(d.low) +
                          ": [low, high] holds almost none of the distribution (share " +
                          validate::format_number(share) + ")");
      break;
    }
  }
  r.finish();
  return d;
}

MonteCarlo read_monte_carlo(const std::string& where, const YAML::Node& n) {
  MapReader r(n, where);
  MonteCarlo mc;
  if (!r.has("draws")) r.fail("draws", ": missing (required)");
  r.integer("draws", mc.draws);
  if (mc.draws < 1) r.fail("draws", " = " + std::to_string(mc.draws) + ": must be >= 1");
  if (mc.draws > kMaxCases)
    r.fail("draws", " = " + std::to_string(mc.draws) + ": more than " + std::to_string(kMaxCases) + " cases");
  if (!r.has("seed")) r.fail("seed", ": missing (required: the same seed gives the same draws)");
  r.unsigned_integer("seed", mc.seed);
  r.known("parameters");
  const YAML::Node p = n["parameters"];
  if (!p.IsSequence() || p.size() == 0)
    fail(where + ".parameters", " = " + describe(p) + ": expected a non-empty list of parameters");
  for (std::size_t i = 0; i < p.size(); ++i)
    mc.parameters.push_back(read_draw(where + ".parameters[" + std::to_string(i) + "]", p[i]));
  r.finish();
  return mc;
}

Family read_family(const std::string& where, const YAML::Node& n) {
  if (!n.IsMap()) fail(where, " = " + describe(n) + ": expected a map with name and optionally set, grid, monte_carlo");
  Family f;
  MapReader r(n, where);
  f.name = r.required_string("name");
  r.known("set");
  f.set = read_settings(where + ".set", n["set"]);
  r.known("grid");
  const YAML::Node g = n["grid"];
  if (g.IsDefined() && !g.IsNull()) {
    if (!g.IsSequence()) fail(where + ".grid", " = " + describe(g) + ": expected a list of axes");
    if (g.size() == 0) fail(where + ".grid", ": empty grid (no axes)");
    for (std::size_t i = 0; i < g.size(); ++i)
      f.grid.push_back(read_axis(where + ".grid[" + std::to_string(i) + "]", g[i]));
  }
  r.known("monte_carlo");
  if (n["monte_carlo"].IsDefined() && !n["monte_carlo"].IsNull())
    f.monte_carlo = read_monte_carlo(where + ".monte_carlo", n["monte_carlo"]);
  r.finish();
  return f;
}

ControllerEntry read_controller(const std::string& where, const YAML::Node& n, const std::string& base_dir) {
  if (!n.IsMap()) fail(where, " = " + describe(n) + ": expected a map with name and one of controller:, scenario:");
  ControllerEntry c;
  MapReader r(n, where);
  c.name = r.required_string("name");
  const bool inline_block = r.has("controller"), from_file = r.has("scenario");
  if (inline_block == from_file)
    fail(where,
         ": give exactly one of controller: (a controller block) or scenario: (a scenario file to take it from)");
  r.known("controller");
  if (inline_block) {
    const YAML::Node b = n["controller"];
    if (!b.IsMap()) fail(where + ".controller", " = " + describe(b) + ": expected a controller map (docs/scenario.md)");
    YAML::Emitter em;
    em << b;
    c.block = em.c_str();
  } else {
    std::string file;
    r.string("scenario", file);
    const std::string path = resolve_path(base_dir, file);
    const std::string text = read_file(path, where + ".scenario");
    YAML::Node s;
    try {
      s = sim::load_yaml_strict(text);
    } catch (const sim::ScenarioError& e) {
      fail(where + ".scenario", " = '" + file + "': " + e.what());
    }
    if (!s.IsMap() || !s["controller"].IsMap()) fail(where + ".scenario", " = '" + file + "': has no controller map");
    YAML::Emitter em;
    em << s["controller"];
    c.block = em.c_str();
    if (s["control_period"].IsDefined())
      c.block_set.push_back({"control_period", scalar_text(where + ".scenario control_period", s["control_period"])});
  }
  r.known("set");
  for (Setting& st : read_settings(where + ".set", n["set"])) c.set.push_back(std::move(st));
  r.finish();
  return c;
}

// Within one family each key is varied once, whatever its spelling (sim::canonical_key): a key
// of two grid axes, or of an axis and a Monte Carlo parameter, would silently take only the
// later's values. `sweep`: the axes are feeddrive-study's --sweep options, and are named so.
void check_varied_once(const Family& f, const std::string& where, bool sweep) {
  std::map<std::string, std::pair<std::string, std::string>> seen;  // canonical key -> (its varier, spelling)
  const auto vary = [&](const std::string& varier, const std::string& key) {
    const std::string c = sim::canonical_key(key);
    const auto [it, fresh] = seen.emplace(c, std::make_pair(varier, key));
    if (fresh) return;
    const auto& [first, spelling] = it->second;
    fail(where.empty() ? first + " " + spelling : where + ": " + first + " " + spelling,
         " and " + varier + " " + key + (spelling != c || key != c ? " (both " + c + ")" : "") + ": one key " +
             (sweep ? "swept" : "varied") + " twice in family '" + f.name + "' (give all its values in one " +
             (sweep ? "--sweep)" : "axis or parameter)"));
  };
  for (std::size_t i = 0; i < f.grid.size(); ++i)
    for (const std::string& k : f.grid[i].keys) vary(sweep ? "--sweep" : "grid[" + std::to_string(i) + "]", k);
  for (std::size_t i = 0; i < f.monte_carlo.parameters.size(); ++i)
    for (const std::string& k : f.monte_carlo.parameters[i].keys)
      vary("monte_carlo.parameters[" + std::to_string(i) + "]", k);
}

}  // namespace

long Study::family_cases(std::size_t f) const {
  long n = 1;
  for (const GridAxis& a : families.at(f).grid) n *= static_cast<long>(a.values.size());  // bounded by validate()
  return n * std::max(1L, families.at(f).monte_carlo.draws);
}

long Study::total_cases() const {
  long n = 0;
  for (std::size_t f = 0; f < families.size(); ++f) n += family_cases(f);
  return n * static_cast<long>(controllers.size());
}

void Study::validate() const {
  if (name.empty()) fail("name", ": must not be empty");
  if (controllers.empty()) fail("controllers", ": empty list");
  if (families.empty()) fail("families", ": empty list");
  std::set<std::string> names;
  for (std::size_t i = 0; i < controllers.size(); ++i) {
    const std::string& n = controllers[i].name;
    if (n.empty()) fail("controllers[" + std::to_string(i) + "].name", ": must not be empty");
    if (!names.insert(n).second) fail("controllers[" + std::to_string(i) + "].name", " = '" + n + "': used twice");
  }
  names.clear();
  // The case count, without overflow: each factor and each partial product stays <= kMaxCases.
  long total = 0;
  for (std::size_t i = 0; i < families.size(); ++i) {
    const Family& f = families[i];
    const std::string where = "families[" + std::to_string(i) + "]";
    if (f.name.empty()) fail(where + ".name", ": must not be empty");
    if (!names.insert(f.name).second) fail(where + ".name", " = '" + f.name + "': used twice");
    check_varied_once(f, where, false);
    long n = std::max(1L, f.monte_carlo.draws);
    for (const GridAxis& a : f.grid) {
      if (a.values.empty()) fail(where + ".grid", ": empty grid axis");
      if (n > kMaxCases / static_cast<long>(a.values.size()))
        fail(where, " (" + f.name + "): the grid has more than " + std::to_string(kMaxCases) + " cases");
      n *= static_cast<long>(a.values.size());
    }
    if (n > (kMaxCases - total) / static_cast<long>(controllers.size()))
      fail("families", ": " + std::to_string(controllers.size()) + " controllers x the families' cases is more than " +
                           std::to_string(kMaxCases) + " cases");
    total += n * static_cast<long>(controllers.size());
  }
  if (report.metric.empty()) fail("report.metric", ": must not be empty");
  const std::vector<std::string> metrics = sim::summary_metric_names();
  if (std::find(metrics.begin(), metrics.end(), report.metric) == metrics.end()) {
    std::string hint = sim::did_you_mean(report.metric, metrics);
    if (hint.empty())
      for (const std::string& m : metrics) hint += (hint.empty() ? "; one of " : ", ") + m;
    fail("report.metric", " = '" + report.metric + "': not a metric of summary.json" + hint);
  }
  validate::require_positive("report.scale", report.scale);
  if (!std::isnan(report.limit)) validate::require_finite("report.limit", report.limit);
  std::vector<std::string> flags = sim::summary_flag_names();
  flags.push_back("move_finished");  // a column of its own (Outcome::move_finished), a verdict too
  for (std::size_t i = 0; i < report.require.size(); ++i) {
    const std::string& r = report.require[i];
    const std::string where = "report.require[" + std::to_string(i) + "]";
    if (std::find(flags.begin(), flags.end(), r) != flags.end()) {
      if (std::find(report.require.begin(), report.require.begin() + static_cast<long>(i), r) !=
          report.require.begin() + static_cast<long>(i))
        fail(where, " = '" + r + "': listed twice");
      continue;
    }
    std::string hint = sim::did_you_mean(r, flags);
    if (hint.empty())
      for (const std::string& f : flags) hint += (hint.empty() ? "; one of " : ", ") + f;
    fail(where, " = '" + r + "': not a true/false verdict of summary.json" + hint);
  }
}

Study parse_study(const std::string& yaml_text, const std::string& base_dir, const std::string& origin) {
  try {
    const YAML::Node root = sim::load_yaml_strict(yaml_text);  // the scenario's strict YAML rules
    if (!root.IsMap()) throw StudyError("a study must be a YAML map with keys name, base, controllers, families");
    Study s;
    MapReader top(root, "");
    s.name = top.required_string("name");
    if (!top.has("base")) top.fail("base", ": missing (required: a scenario file or an inline scenario map)");
    top.known("base");
    const YAML::Node base = root["base"];
    if (base.IsScalar()) {
      const std::string path = resolve_path(base_dir, base.Scalar());
      s.base_yaml = read_file(path, "base");
      try {
        sim::load_yaml_strict(s.base_yaml);  // its YAML errors name the file (its keys are checked per case)
      } catch (const sim::ScenarioError& e) {
        fail("base", " = '" + base.Scalar() + "': " + e.what());
      }
      s.base_dir = fs::path(path).parent_path().string();
      if (s.base_dir.empty()) s.base_dir = ".";
    } else if (base.IsMap()) {
      YAML::Emitter em;
      em << base;
      s.base_yaml = em.c_str();
      s.base_dir = base_dir;
    } else {
      fail("base", " = " + describe(base) + ": expected a scenario file name or a scenario map");
    }
    top.known("set");
    s.set = read_settings("set", root["set"]);
    std::string model = fields::enum_name(s.model);
    top.string("model", model);
    s.model = enum_named<ModelRule>(top, "model", model);
    top.known("controllers");
    const YAML::Node cs = root["controllers"];
    if (cs.IsDefined() && !cs.IsNull()) {
      if (!cs.IsSequence() || cs.size() == 0) fail("controllers", " = " + describe(cs) + ": expected a non-empty list");
      for (std::size_t i = 0; i < cs.size(); ++i)
        s.controllers.push_back(read_controller("controllers[" + std::to_string(i) + "]", cs[i], base_dir));
    } else {
      s.controllers.push_back({"base", "", {}, {}});
    }
    top.known("families");
    const YAML::Node fs_ = root["families"];
    if (fs_.IsDefined() && !fs_.IsNull()) {
      if (!fs_.IsSequence() || fs_.size() == 0) fail("families", " = " + describe(fs_) + ": expected a non-empty list");
      for (std::size_t i = 0; i < fs_.size(); ++i)
        s.families.push_back(read_family("families[" + std::to_string(i) + "]", fs_[i]));
    } else {
      s.families.push_back(Family{"nominal", {}, {}, {}});
    }
    MapReader rep = top.child("report");
    rep.string("metric", s.report.metric);
    rep.number("scale", s.report.scale);
    rep.string("unit", s.report.unit);
    if (rep.has("limit")) rep.number("limit", s.report.limit);
    rep.string_list("require", s.report.require);
    rep.finish();
    top.finish();
    try {
      s.validate();
    } catch (const std::invalid_argument& e) {
      throw StudyError(e.what());
    }
    return s;
  } catch (const sim::ScenarioError& e) {
    throw StudyError(origin + ": " + e.what());
  } catch (const StudyError& e) {
    throw StudyError(origin + ": " + e.what());
  }
}

Study load_study(const std::string& path) {
  const std::string text = text::read_text_file<StudyError>(path, "study file");
  const fs::path p(path);
  Study s = parse_study(text, p.parent_path().empty() ? "." : p.parent_path().string(), path);
  s.path = path;
  return s;
}

}  // namespace feeddrive::study

namespace feeddrive::study {

GridAxis parse_sweep(const std::string& text) {
  const auto bad = [&](const std::string& why) -> StudyError {
    return StudyError("--sweep " + text + ": " + why +
                      " (KEY=V1,V2,... or KEY=START:STOP:N, linear, or KEY=log:START:STOP:N; docs/study.md)");
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) throw bad("expected KEY=VALUES");
  GridAxis axis;
  axis.keys = {text.substr(0, eq)};
  std::string values = text.substr(eq + 1);
  const bool log = values.rfind("log:", 0) == 0;
  axis.log = log;
  if (log) values = values.substr(4);
  if (values.find(':') != std::string::npos) {
    const std::vector<std::string> parts = text::split(values, ':');
    if (parts.size() != 3) throw bad("a range is START:STOP:N");
    double a = 0, z = 0;
    char* end = nullptr;
    a = std::strtod(parts[0].c_str(), &end);
    if (parts[0].empty() || *end || !std::isfinite(a)) throw bad("START = '" + parts[0] + "' is not a finite number");
    z = std::strtod(parts[1].c_str(), &end);
    if (parts[1].empty() || *end || !std::isfinite(z)) throw bad("STOP = '" + parts[1] + "' is not a finite number");
    const long n = std::strtol(parts[2].c_str(), &end, 10);
    if (parts[2].empty() || *end || n < 2 || n > 10000)
      throw bad("N = '" + parts[2] + "' must be an integer in [2, 10000]");
    if (log && !(a > 0 && z > 0)) throw bad("a logarithmic range needs START and STOP > 0");
    for (long i = 0; i < n; ++i) {
      const double f = static_cast<double>(i) / static_cast<double>(n - 1);
      const double v = i == n - 1 ? z : log ? a * std::pow(z / a, f) : a + (z - a) * f;
      axis.values.push_back({validate::format_number(v)});
    }
  } else {
    if (log) throw bad("log: needs START:STOP:N");
    for (std::size_t b = 0;;) {
      const std::size_t e = values.find(',', b);
      std::string v = values.substr(b, e == std::string::npos ? std::string::npos : e - b);
      while (!v.empty() && v.front() == ' ') v.erase(v.begin());
      while (!v.empty() && v.back() == ' ') v.pop_back();
      if (v.empty()) throw bad("an empty value");
      axis.values.push_back({v});
      if (e == std::string::npos) break;
      b = e + 1;
    }
  }
  return axis;
}

Study sweep_study(const std::string& scenario_path, const std::vector<GridAxis>& axes) {
  Study s;
  const fs::path p(scenario_path);
  s.name = p.stem().string() + " sweep";
  s.base_yaml = text::read_text_file<StudyError>(scenario_path, "scenario file");
  YAML::Node root;
  try {
    root = sim::load_yaml_strict(s.base_yaml);
  } catch (const sim::ScenarioError& e) {
    throw StudyError(scenario_path + ": " + e.what());
  }
  // A study file given to --sweep once failed on its first scenario key ("duration: missing").
  if (const YAML::Node& map = root; map.IsMap()) {
    std::string study_keys;
    for (const char* k : {"base", "controllers", "families"})
      if (map[k].IsDefined()) study_keys += (study_keys.empty() ? "" : "/") + std::string(k);
    if (!study_keys.empty())
      throw StudyError("--sweep takes a scenario file, not a study file (" + scenario_path + " has " + study_keys +
                       ")");
  }
  s.base_dir = p.parent_path().empty() ? "." : p.parent_path().string();
  s.controllers.push_back({"base", "", {}, {}});
  s.families.push_back(Family{"sweep", {}, axes, {}});
  check_varied_once(s.families.back(), "", true);  // named as the --sweep options (validate() would say grid[i])
  try {
    s.validate();
  } catch (const std::invalid_argument& e) {
    throw StudyError(scenario_path + ": " + e.what());
  }
  return s;
}

}  // namespace feeddrive::study

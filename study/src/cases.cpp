#include "feeddrive/study/cases.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::study {
namespace {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

bool starts_with(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }

// plant.* keys change only the true plant under the nominal model rule, except the sensor the
// controller is set up for (cases.hpp).
bool plant_only(const std::string& key) { return starts_with(key, "plant.") && !starts_with(key, "plant.sensor."); }

}  // namespace

double unit_uniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b, std::uint64_t c) {
  std::uint64_t state = seed;
  std::uint64_t h = splitmix64(state);
  state = h ^ a;
  h = splitmix64(state);
  state = h ^ (b * 0xD1B54A32D192ED03ULL);
  h = splitmix64(state);
  state = h ^ (c * 0xAEF17502108EF2D9ULL);
  h = splitmix64(state);
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

double draw_value(const DrawSpec& d, std::uint64_t seed, long draw, std::size_t param) {
  const auto u = [&](std::uint64_t k) { return unit_uniform(seed, static_cast<std::uint64_t>(draw), param, k); };
  if (d.distribution == Distribution::kUniform) return d.a + (d.b - d.a) * u(0);
  // Box-Muller on two uniforms per attempt; an attempt outside [low, high] is redrawn with the
  // next pair (Spec validation bounds the expected number of attempts by 1e4).
  for (std::uint64_t attempt = 0;; ++attempt) {
    const double u1 = 1.0 - u(2 * attempt);  // (0, 1]: log is finite
    const double u2 = u(2 * attempt + 1);
    const double n = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
    double v = d.a + d.b * n;
    if (d.distribution == Distribution::kLognormal) v = std::exp(v);
    if (v >= d.low && v <= d.high) return v;
  }
}

std::vector<Variation> grid_point(const Family& f, long point) {
  std::vector<Variation> out;
  // Mixed radix, the last axis fastest.
  std::vector<long> index(f.grid.size(), 0);
  long rest = point;
  for (std::size_t i = f.grid.size(); i-- > 0;) {
    const long n = static_cast<long>(f.grid[i].values.size());
    index[i] = rest % n;
    rest /= n;
  }
  for (std::size_t i = 0; i < f.grid.size(); ++i) {
    const GridAxis& a = f.grid[i];
    const auto& vals = a.values[static_cast<std::size_t>(index[i])];
    for (std::size_t k = 0; k < a.keys.size(); ++k) {
      Variation v{a.keys[k], vals[k], a.scale, 1.0};
      if (a.scale) v.factor = std::strtod(vals[k].c_str(), nullptr);  // checked finite by the spec
      out.push_back(v);
    }
  }
  return out;
}

std::size_t case_count(const Study& s) { return static_cast<std::size_t>(s.total_cases()); }

CaseSpec case_at(const Study& s, std::size_t index) {
  if (index >= case_count(s))
    throw std::out_of_range("case " + std::to_string(index) + " of " + std::to_string(case_count(s)));
  long rest = static_cast<long>(index);
  long per_controller = 0;
  for (std::size_t f = 0; f < s.families.size(); ++f) per_controller += s.family_cases(f);
  CaseSpec cs;
  cs.controller = static_cast<std::size_t>(rest / per_controller);
  rest %= per_controller;
  while (rest >= s.family_cases(cs.family)) rest -= s.family_cases(cs.family++);
  const Family& fam = s.families[cs.family];
  const long draws = fam.monte_carlo.draws;
  cs.point = draws > 0 ? rest / draws : rest;
  cs.draw = draws > 0 ? rest % draws : -1;
  cs.variations = grid_point(fam, cs.point);
  if (cs.draw >= 0) {
    for (std::size_t i = 0; i < fam.monte_carlo.parameters.size(); ++i) {
      const DrawSpec& ds = fam.monte_carlo.parameters[i];
      const double x = draw_value(ds, fam.monte_carlo.seed, cs.draw, i);
      for (const std::string& key : ds.keys) cs.variations.push_back({key, validate::format_number(x), ds.scale, x});
    }
  }
  return cs;
}

std::vector<CaseSpec> expand(const Study& s) {
  std::vector<CaseSpec> out;
  out.reserve(case_count(s));
  for (std::size_t i = 0; i < case_count(s); ++i) out.push_back(case_at(s, i));
  return out;
}

std::vector<std::size_t> probe_cases(const Study& s, std::size_t budget) {
  std::vector<std::size_t> out;
  std::size_t family_start = 0;  // index of the first case of (controller, family)
  for (std::size_t c = 0; c < s.controllers.size(); ++c) {
    for (std::size_t f = 0; f < s.families.size(); ++f) {
      const Family& fam = s.families[f];
      const long draws = std::max(1L, fam.monte_carlo.draws);
      out.push_back(family_start);
      // Each value of each axis once, the other axes at their first value (mixed radix, the last
      // axis fastest: axis i's stride is the product of the later axes' sizes).
      long stride = 1;
      for (std::size_t i = fam.grid.size(); i-- > 0;) {
        for (long v = 1; v < static_cast<long>(fam.grid[i].values.size()); ++v)
          out.push_back(family_start + static_cast<std::size_t>(v * stride * draws));
        stride *= static_cast<long>(fam.grid[i].values.size());
      }
      family_start += static_cast<std::size_t>(s.family_cases(f));
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.size() > budget) out.resize(budget);
  return out;
}

std::vector<std::string> varied_keys(const Study& s) {
  std::vector<std::string> out;
  const auto add = [&](const std::string& k) {
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  };
  for (const Family& f : s.families) {
    for (const GridAxis& a : f.grid)
      for (const std::string& k : a.keys) add(k);
    for (const DrawSpec& d : f.monte_carlo.parameters)
      for (const std::string& k : d.keys) add(k);
  }
  return out;
}

std::string sha256_hex(const std::string& text) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(text.data(), text.size(), md, &n, EVP_sha256(), nullptr) != 1 || n != 32)
    throw std::runtime_error("SHA-256 failed (libcrypto)");
  std::string hex(64, '0');
  static const char* kDigits = "0123456789abcdef";
  for (unsigned i = 0; i < 32; ++i) {
    hex[2 * i] = kDigits[md[i] >> 4];
    hex[2 * i + 1] = kDigits[md[i] & 15];
  }
  return hex;
}

struct Resolver::Impl {
  const Study& s;
  // The base as read, once per controller, with the controller's block in place of its own.
  std::vector<sim::Scenario> bases;
  // The nominal case of a controller and family: the base with the layers' settings as read
  // (each case copies it and sets its variations in it), and its keys (a scale's nominal value).
  struct Nominal {
    sim::Scenario read;
    sim::ResolvedKeys keys;
  };
  std::map<std::pair<std::size_t, std::size_t>, Nominal> nominals;
  // The controller's nominal model (the nominal model rule), by the case's settings that are not
  // plant-only; at most kMaxModels (cases come in order, so a reset costs one model per layer).
  std::map<std::string, plant::PlantParams> models;
  static constexpr std::size_t kMaxModels = 256;
  std::vector<std::string> varied;  // every key a grid or draw of the study varies
  // SHA-256 of a plugin library's bytes, once per path per study.
  std::map<std::string, std::string> digests;

  explicit Impl(const Study& st) : s(st) {
    varied = varied_keys(s);
    for (const ControllerEntry& c : s.controllers) {
      try {
        bases.push_back(sim::read_scenario(s.base_yaml, s.base_dir, "base", c.block));
      } catch (const sim::ScenarioError& e) {
        throw StudyError(s.path + (c.block.empty() ? "" : ": controller '" + c.name + "'") + ": " + e.what());
      }
    }
  }

  const std::string& library_digest(const std::string& path) {
    auto it = digests.find(path);
    if (it != digests.end()) return it->second;
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in) throw StudyError("plugin " + path + ": cannot be read to key the study's cases");
    return digests.emplace(path, sha256_hex(bytes.str())).first->second;
  }

  using Values = std::vector<sim::KeySetting>;
  static Values variation_values(const CaseSpec& c, const sim::ResolvedKeys& nominal, const std::string& origin);
  const Nominal& nominal(const CaseSpec& c, const std::string& origin);
  const plant::PlantParams& nominal_model(const CaseSpec& c, const Nominal& n, const Values& values,
                                          const std::string& origin);
  ResolvedCase result(std::shared_ptr<const sim::Scenario> sc, const Values& values);
};

namespace {

// The settings set in a scenario as read (sim::set_read_keys); with `complete`, derived and
// checked. The error names the case (origin) and the loader's key and value.
sim::Scenario with_settings(sim::Scenario sc, const std::vector<sim::KeySetting>& values, bool complete,
                            const std::string& origin) {
  try {
    sim::set_read_keys(sc, values);
    if (complete) sim::complete_read(sc);
  } catch (const sim::ScenarioError& e) {
    throw StudyError(origin + ": " + e.what());
  }
  return sc;
}

}  // namespace

// The layers without the variations: the nominal case of this controller and family. The
// study's set comes after the controller block it would otherwise be replaced by: what it sets
// holds for every controller (docs/study.md, "How a case is made").
const Resolver::Impl::Nominal& Resolver::Impl::nominal(const CaseSpec& c, const std::string& origin) {
  const auto id = std::make_pair(c.controller, c.family);
  auto it = nominals.find(id);
  if (it != nominals.end()) return it->second;
  const ControllerEntry& ctl = s.controllers[c.controller];
  std::vector<sim::KeySetting> layers;
  for (const auto* set : {&ctl.block_set, &s.set, &ctl.set, &s.families[c.family].set})
    for (const Setting& st : *set) layers.push_back({st.key, st.value});
  Nominal n;
  const std::string where = origin + " (without its variations)";
  n.read = with_settings(bases[c.controller], layers, false, where);
  n.keys = sim::resolved_keys(with_settings(n.read, {}, true, where));
  return nominals.emplace(id, std::move(n)).first->second;
}

// The variations' values as YAML scalar text: a `scale` one is its factor times the key's
// nominal value (its effective value in the case without variations, defaults included).
Resolver::Impl::Values Resolver::Impl::variation_values(const CaseSpec& c, const sim::ResolvedKeys& nominal,
                                                        const std::string& origin) {
  Values values;
  for (const Variation& v : c.variations) {
    if (!v.scale) {
      values.push_back({v.key, v.value});
      continue;
    }
    const auto it = nominal.find(sim::canonical_key(v.key));  // an old spelling scales its key
    if (it == nominal.end())
      throw StudyError(origin + ": " + v.key +
                       ": cannot scale a key the scenario does not have (misspelt, or not read for this controller or "
                       "reference type)");
    if (it->second.is_string || it->second.text == "true" || it->second.text == "false")
      throw StudyError(origin + ": " + v.key + " = '" + it->second.text +
                       "': cannot scale a value that is not a number");
    const double nominal_value = std::strtod(it->second.text.c_str(), nullptr);
    // Every factor of 0 is 0: the cases would silently all be the nominal one.
    if (nominal_value == 0.0)
      throw StudyError(origin + ": " + v.key +
                       " = 0: scaling a zero value gives 0 for every factor (give absolute values: values:, or a "
                       "distribution without scale: true)");
    values.push_back({v.key, validate::format_number(nominal_value * v.factor)});
  }
  return values;
}

// The nominal model rule (cases.hpp): the controller's model of the case without its plant-only
// variations.
const plant::PlantParams& Resolver::Impl::nominal_model(const CaseSpec& c, const Nominal& n, const Values& values,
                                                        const std::string& origin) {
  std::string id = std::to_string(c.controller) + " " + std::to_string(c.family) + "\n";
  Values others;
  for (const sim::KeySetting& k : values) {
    if (plant_only(k.key)) continue;
    others.push_back(k);
    id += k.key + "=" + k.value + "\n";
  }
  auto it = models.find(id);
  if (it != models.end()) return it->second;
  if (models.size() >= kMaxModels) models.clear();
  const sim::Scenario m = with_settings(n.read, others, false, origin + " (the controller's nominal model)");
  return models.emplace(std::move(id), m.controller.model).first->second;
}

// The case's scenario (its keys written as one YAML document), its hash and the effective value
// of every varied key of the study.
ResolvedCase Resolver::Impl::result(std::shared_ptr<const sim::Scenario> sc, const Values& values) {
  ResolvedCase r;
  const sim::ResolvedKeys keys = sim::resolved_keys(*sc);
  r.scenario = std::move(sc);
  r.yaml = sim::resolved_yaml(keys);
  // A plugin controller's case depends on the library's code too, which the keys (its path) do
  // not show: its bytes' digest joins the hash, so a rerun after a rebuild of the plugin runs the
  // cases again instead of keeping results of the old build (docs/plugins.md).
  std::string code;
  if (const auto lib = keys.find("controller.library"); lib != keys.end())  // type plugin only
    code = "plugin library sha256 " + library_digest(lib->second.text) + "\n";
  r.hash = sha256_hex(std::string(kCaseFormat) + code + r.yaml);
  // Every varied key of the study, with its effective value in this case (its nominal value
  // where this case does not vary it), so each row of results.csv places the case on every axis.
  for (const std::string& k : varied) {
    const auto it = keys.find(sim::canonical_key(k));
    if (it != keys.end()) r.parameters[k] = it->second.text;
  }
  for (const sim::KeySetting& v : values)
    if (!r.parameters.count(v.key)) r.parameters[v.key] = v.value;
  return r;
}

Resolver::Resolver(const Study& s) : impl_(std::make_unique<Impl>(s)) {}
Resolver::~Resolver() = default;

std::string Resolver::label(const CaseSpec& c) const {
  const Study& s = impl_->s;
  std::string l = "controller '" + s.controllers[c.controller].name + "', family '" + s.families[c.family].name + "'";
  if (!s.families[c.family].grid.empty()) l += ", point " + std::to_string(c.point);
  if (c.draw >= 0) l += ", draw " + std::to_string(c.draw);
  return l;
}

// The case's nominal layers are set in the base as read once per controller and family; a case
// is that scenario with its variations set in it (sim::set_read_keys), with the nominal model
// rule's model from the same struct without the plant-only variations, derived and checked
// (sim::complete_read): a struct, never YAML read again. A setting the struct cannot take is the
// case's one-line error naming the key and value.
ResolvedCase Resolver::resolve(const CaseSpec& c) {
  Impl& m = *impl_;
  const std::string origin = (m.s.path.empty() ? std::string("study") : m.s.path) + ": " + label(c);
  const Impl::Nominal& nominal = m.nominal(c, origin);
  const Impl::Values values = Impl::variation_values(c, nominal.keys, origin);
  sim::Scenario sc = with_settings(nominal.read, values, false, origin);
  if (m.s.model == ModelRule::kNominal &&
      std::any_of(values.begin(), values.end(), [](const sim::KeySetting& k) { return plant_only(k.key); }))
    sc.controller.model = m.nominal_model(c, nominal, values, origin);
  return m.result(std::make_shared<const sim::Scenario>(with_settings(std::move(sc), {}, true, origin)), values);
}

}  // namespace feeddrive::study

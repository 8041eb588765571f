#include "feeddrive/study/cases.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "feeddrive/common/fields.hpp"
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
  const auto add = [&](const std::string& written) {
    const std::string k = sim::canonical_key(written);  // an old spelling is its key's column
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

// --- settings and bases as bytes -----------------------------------------------------------

namespace {

// A list of strings as bytes: each as its length in decimal, ':', its bytes.
void put(std::string& out, const std::string& s) { out += std::to_string(s.size()) + ":" + s; }

[[noreturn]] void not_a_packing() {
  throw StudyError("a case's settings or a study's bases from rank 0 that do not unpack (another build?)");
}

class Reader {
 public:
  explicit Reader(const std::string& b) : b_(b) {}
  std::string next() {
    const std::size_t colon = b_.find(':', at_);
    if (colon == std::string::npos || colon == at_ || colon - at_ > 12) not_a_packing();
    std::size_t n = 0;
    for (std::size_t i = at_; i < colon; ++i) {
      if (b_[i] < '0' || b_[i] > '9') not_a_packing();
      n = n * 10 + static_cast<std::size_t>(b_[i] - '0');
    }
    if (n > b_.size() - colon - 1) not_a_packing();
    at_ = colon + 1 + n;
    return b_.substr(colon + 1, n);
  }
  std::size_t count() {
    const std::string s = next();
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) not_a_packing();
    return static_cast<std::size_t>(std::stoul(s));
  }
  void finish() const {
    if (at_ != b_.size()) not_a_packing();
  }

 private:
  const std::string& b_;
  std::size_t at_{0};
};

void put_settings(std::string& out, const std::vector<sim::KeySetting>& v) {
  put(out, std::to_string(v.size()));
  for (const sim::KeySetting& k : v) put(out, k.key), put(out, k.value);
}
std::vector<sim::KeySetting> get_settings(Reader& r) {
  std::vector<sim::KeySetting> v(r.count());
  for (sim::KeySetting& k : v) k.key = r.next(), k.value = r.next();
  return v;
}

bool same_settings(const std::vector<sim::KeySetting>& a, const std::vector<sim::KeySetting>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                    [](const auto& x, const auto& y) { return x.key == y.key && x.value == y.value; });
}

}  // namespace

bool CaseSettings::operator==(const CaseSettings& o) const {
  return controller == o.controller && same_settings(layers, o.layers) && same_settings(values, o.values) &&
         nominal_model == o.nominal_model;
}

std::string pack_settings(const CaseSettings& c) {
  std::string out;
  put(out, std::to_string(c.controller));
  put(out, c.nominal_model ? "1" : "0");
  put_settings(out, c.layers);
  put_settings(out, c.values);
  return out;
}

CaseSettings unpack_settings(const std::string& bytes) {
  Reader r(bytes);
  CaseSettings c;
  c.controller = r.count();
  const std::string rule = r.next();
  if (rule != "0" && rule != "1") not_a_packing();
  c.nominal_model = rule == "1";
  c.layers = get_settings(r);
  c.values = get_settings(r);
  r.finish();
  return c;
}

StudyBases StudyBases::of(const Study& s) {
  StudyBases b{s.path, s.base_yaml, s.base_dir, {}, {}};
  for (const ControllerEntry& c : s.controllers) b.names.push_back(c.name), b.blocks.push_back(c.block);
  return b;
}

bool StudyBases::operator==(const StudyBases& o) const {
  return path == o.path && base_yaml == o.base_yaml && base_dir == o.base_dir && names == o.names && blocks == o.blocks;
}

std::string pack_bases(const StudyBases& b) {
  std::string out;
  put(out, b.path);
  put(out, b.base_yaml);
  put(out, b.base_dir);
  put(out, std::to_string(b.names.size()));
  for (std::size_t i = 0; i < b.names.size(); ++i) put(out, b.names[i]), put(out, b.blocks[i]);
  return out;
}

StudyBases unpack_bases(const std::string& bytes) {
  Reader r(bytes);
  StudyBases b;
  b.path = r.next();
  b.base_yaml = r.next();
  b.base_dir = r.next();
  const std::size_t n = r.count();
  for (std::size_t i = 0; i < n; ++i) b.names.push_back(r.next()), b.blocks.push_back(r.next());
  r.finish();
  return b;
}

// --- building a case from its settings ---------------------------------------------------------

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

// A cache key of a controller and a list of settings.
std::string key_of(std::size_t controller, const std::vector<sim::KeySetting>& v) {
  std::string k = std::to_string(controller) + "\n";
  put_settings(k, v);
  return k;
}

}  // namespace

struct CaseBuilder::Impl {
  // The base as read, once per controller, with the controller's block in place of its own.
  std::vector<sim::Scenario> bases;
  // The base with a case's layers set, as read (each case copies it and sets its values in it),
  // and its keys (a scale's nominal value), by (controller, layers): in a study one per
  // controller and family.
  struct Layered {
    sim::Scenario read;
    sim::ResolvedKeys keys;
  };
  std::map<std::string, Layered> layered;
  // The controller's nominal model (the nominal model rule), by the case's settings that are not
  // plant-only; at most kMaxModels (cases come in order, so a reset costs one model per layer).
  std::map<std::string, plant::PlantParams> models;
  static constexpr std::size_t kMaxModels = 256;

  const Layered& with_layers(const CaseSettings& c, const std::string& origin) {
    if (c.controller >= bases.size())
      throw StudyError(origin + ": controller " + std::to_string(c.controller) + " of a study with " +
                       std::to_string(bases.size()));
    const std::string id = key_of(c.controller, c.layers);
    auto it = layered.find(id);
    if (it != layered.end()) return it->second;
    Layered l;
    const std::string where = origin + " (without its variations)";
    l.read = with_settings(bases[c.controller], c.layers, false, where);
    l.keys = sim::resolved_keys(with_settings(l.read, {}, true, where));
    return layered.emplace(id, std::move(l)).first->second;
  }

  // The nominal model rule (cases.hpp): the controller's model of the case without its
  // plant-only values.
  const plant::PlantParams& nominal_model(const CaseSettings& c, const Layered& l, const std::string& origin) {
    std::vector<sim::KeySetting> others;
    for (const sim::KeySetting& k : c.values)
      if (!plant_only(k.key)) others.push_back(k);
    std::string id = key_of(c.controller, c.layers) + key_of(c.controller, others);
    auto it = models.find(id);
    if (it != models.end()) return it->second;
    if (models.size() >= kMaxModels) models.clear();
    const sim::Scenario m = with_settings(l.read, others, false, origin + " (the controller's nominal model)");
    return models.emplace(std::move(id), m.controller.model).first->second;
  }
};

CaseBuilder::CaseBuilder(const StudyBases& b) : impl_(std::make_unique<Impl>()) {
  for (std::size_t i = 0; i < b.blocks.size(); ++i) {
    try {
      impl_->bases.push_back(sim::read_scenario(b.base_yaml, b.base_dir, "base", b.blocks[i]));
    } catch (const sim::ScenarioError& e) {
      throw StudyError(b.path + (b.blocks[i].empty() ? "" : ": controller '" + b.names[i] + "'") + ": " + e.what());
    }
  }
}

CaseBuilder::~CaseBuilder() = default;

const sim::ResolvedKeys& CaseBuilder::nominal_keys(const CaseSettings& c, const std::string& origin) {
  return impl_->with_layers(c, origin).keys;
}

// The base as read with the layers set (once per layers), the values set in a copy, the nominal
// model rule's model from the same without the plant-only values, derived and checked: a
// struct, never YAML read again. A setting the struct cannot take is the case's one-line error
// naming the key and value.
std::shared_ptr<const sim::Scenario> CaseBuilder::build(const CaseSettings& c, const std::string& origin) {
  const Impl::Layered& l = impl_->with_layers(c, origin);
  sim::Scenario sc = with_settings(l.read, c.values, false, origin);
  if (c.nominal_model) sc.controller.model = impl_->nominal_model(c, l, origin);
  return std::make_shared<const sim::Scenario>(with_settings(std::move(sc), {}, true, origin));
}

namespace {

bool same_lists(const sim::Scenario& a, const sim::Scenario& b) {
  const sim::ControllerConfig &ca = a.controller, &cb = b.controller;
  const sim::ReferenceConfig &ra = a.reference, &rb = b.reference;
  return fields::same(a.plant, b.plant) && fields::same(ca.model, cb.model) &&
         fields::same(ca.sliding_mode, cb.sliding_mode) && fields::same(ca.sliding_mode.model, cb.sliding_mode.model) &&
         fields::same(ca.cascade, cb.cascade) && fields::same(ca.open_loop, cb.open_loop) &&
         fields::same(ca.plugin.model, cb.plugin.model) && fields::same(ra.sine, rb.sine) &&
         fields::same(ra.step, rb.step) && fields::same(ra.accel_limited, rb.accel_limited) &&
         fields::same(ra.scurve, rb.scurve) && fields::same(ra.ramp, rb.ramp);
}

bool same_beside_lists(const sim::Scenario& a, const sim::Scenario& b) {
  const sim::ControllerConfig &ca = a.controller, &cb = b.controller;
  const sim::ReferenceConfig &ra = a.reference, &rb = b.reference;
  const auto same_points = [](const std::vector<trajectory::Waypoint>& x, const std::vector<trajectory::Waypoint>& y) {
    return std::equal(x.begin(), x.end(), y.begin(), y.end(),
                      [](const auto& p, const auto& q) { return std::memcmp(&p, &q, sizeof p) == 0; });
  };
  const bool controller =
      ca.type == cb.type && ca.computation_delay == cb.computation_delay && ca.model_given == cb.model_given &&
      ca.open_loop_file == cb.open_loop_file && ca.open_loop.table_t == cb.open_loop.table_t &&
      ca.open_loop.table_value == cb.open_loop.table_value &&
      ca.open_loop.table_is_force == cb.open_loop.table_is_force && ca.plugin.library == cb.plugin.library &&
      ca.plugin.parameters == cb.plugin.parameters && ca.plugin.period == cb.plugin.period &&
      ca.plugin.u_min == cb.plugin.u_min && ca.plugin.u_max == cb.plugin.u_max &&
      ca.plugin.computation_delay == cb.plugin.computation_delay;
  const bool reference =
      ra.type == rb.type && ra.waypoints_file == rb.waypoints_file && same_points(ra.waypoints, rb.waypoints);
  return controller && reference && a.name == b.name && a.duration == b.duration &&
         a.control_period == b.control_period && a.analysis.settled_after == b.analysis.settled_after &&
         a.analysis.settling_band == b.analysis.settling_band && a.output.every == b.output.every &&
         a.output.columns == b.output.columns && a.grinding_process == b.grinding_process &&
         a.given_keys == b.given_keys && a.listed_effects == b.listed_effects && a.base_dir == b.base_dir &&
         a.warnings == b.warnings && std::memcmp(&a.move_end_s, &b.move_end_s, sizeof(double)) == 0;
}

}  // namespace

bool same_case(const sim::Scenario& a, const sim::Scenario& b) {
  return same_lists(a, b) && same_beside_lists(a, b) && sim::resolved_keys(a) == sim::resolved_keys(b);
}

// --- resolving a case ------------------------------------------------------------------------

struct Resolver::Impl {
  const Study& s;
  CaseBuilder builder;
  std::vector<std::string> varied;  // every key a grid or draw of the study varies
  // SHA-256 of a plugin library's bytes, once per path per study.
  std::map<std::string, std::string> digests;

  explicit Impl(const Study& st) : s(st), builder(StudyBases::of(st)), varied(varied_keys(st)) {}

  const std::string& library_digest(const std::string& path) {
    auto it = digests.find(path);
    if (it != digests.end()) return it->second;
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in) throw StudyError("plugin " + path + ": cannot be read to key the study's cases");
    return digests.emplace(path, sha256_hex(bytes.str())).first->second;
  }

  CaseSettings settings(const CaseSpec& c, const std::string& origin);
  std::string scaled(const Variation& v, const CaseSettings& c, const std::string& origin);
  ResolvedCase result(std::shared_ptr<const sim::Scenario> sc, CaseSettings settings);
};

// A `scale` variation's value as YAML scalar text: its factor times the key's nominal value (its
// effective value in the case without variations, defaults included).
std::string Resolver::Impl::scaled(const Variation& v, const CaseSettings& c, const std::string& origin) {
  const sim::ResolvedKeys& nominal = builder.nominal_keys(c, origin);
  const auto it = nominal.find(sim::canonical_key(v.key));  // an old spelling scales its key
  if (it == nominal.end())
    throw StudyError(origin + ": " + v.key +
                     ": cannot scale a key the scenario does not have (misspelt, or not read for this controller or "
                     "reference type)");
  if (it->second.is_string || it->second.text == "true" || it->second.text == "false")
    throw StudyError(origin + ": " + v.key + " = '" + it->second.text + "': cannot scale a value that is not a number");
  const double nominal_value = std::strtod(it->second.text.c_str(), nullptr);
  // Every factor of 0 is 0: the cases would silently all be the nominal one.
  if (nominal_value == 0.0)
    throw StudyError(origin + ": " + v.key +
                     " = 0: scaling a zero value gives 0 for every factor (give absolute values: values:, or a "
                     "distribution without scale: true)");
  return validate::format_number(nominal_value * v.factor);
}

// The case's settings: the layers (the controller block's set; the study's set after the
// controller block it would otherwise be replaced by, so what it sets holds for every
// controller, docs/study.md "How a case is made"; the controller's; the family's), the
// variations' values, and the nominal model rule.
CaseSettings Resolver::Impl::settings(const CaseSpec& c, const std::string& origin) {
  CaseSettings out;
  out.controller = c.controller;
  const ControllerEntry& ctl = s.controllers[c.controller];
  for (const auto* set : {&ctl.block_set, &s.set, &ctl.set, &s.families[c.family].set})
    for (const Setting& st : *set) out.layers.push_back({st.key, st.value});
  for (const Variation& v : c.variations) out.values.push_back({v.key, v.scale ? scaled(v, out, origin) : v.value});
  out.nominal_model = s.model == ModelRule::kNominal && std::any_of(out.values.begin(), out.values.end(),
                                                                    [](const auto& k) { return plant_only(k.key); });
  return out;
}

// The case's scenario (its keys written as one YAML document), its hash and the effective value
// of every varied key of the study.
ResolvedCase Resolver::Impl::result(std::shared_ptr<const sim::Scenario> sc, CaseSettings settings) {
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
  for (const std::string& k : varied) {  // canonical keys (varied_keys)
    const auto it = keys.find(k);
    if (it != keys.end()) r.parameters[k] = it->second.text;
  }
  for (const sim::KeySetting& v : settings.values) {
    const std::string k = sim::canonical_key(v.key);
    if (!r.parameters.count(k)) r.parameters[k] = v.value;
  }
  r.settings = std::move(settings);
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

// A case is its settings (Impl::settings) built by the CaseBuilder: the struct another MPI rank
// builds from the same settings by the same code.
ResolvedCase Resolver::resolve(const CaseSpec& c) {
  Impl& m = *impl_;
  const std::string origin = (m.s.path.empty() ? std::string("study") : m.s.path) + ": " + label(c);
  CaseSettings settings = m.settings(c, origin);
  auto scenario = m.builder.build(settings, origin);
  return m.result(std::move(scenario), std::move(settings));
}

}  // namespace feeddrive::study

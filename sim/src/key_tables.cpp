#include "feeddrive/sim/key_tables.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <type_traits>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"

namespace feeddrive::sim {
namespace {

using fields::Check;
using fields::Meta;

struct Row {
  std::string key, unit, def, valid, plausible, meaning;
};

std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  return validate::format_number(v);
}

std::string valid_text(const Meta& m) {
  std::string s = m.required ? "required; " : "";
  switch (m.check) {
    case Check::kFinite: s += "finite"; break;
    case Check::kPositive: s += "> 0"; break;
    case Check::kNonNegative: s += "≥ 0"; break;
    case Check::kNotPlusInf: s += "finite or -.inf"; break;
    case Check::kNone: s += "its own rule (Meaning)"; break;
  }
  if (m.min > -fields::kInf) s += ", ≥ " + number(m.min);
  if (m.max < fields::kInf) s += ", ≤ " + number(m.max);
  return s;
}

std::string plausible_text(const Meta& m) {
  if (m.plausible_lo == -fields::kInf && m.plausible_hi == fields::kInf) return "–";
  return number(m.plausible_lo) + " … " + number(m.plausible_hi);
}

// The Meaning cell: the field's doc, and its old spelling (fields::Meta::alias) if it has one.
std::string meaning(const Meta& m) {
  if (!*m.alias) return m.doc;
  return std::string(m.doc) + (*m.doc ? "; " : "") + "formerly `" + m.alias + "` (still read, with a warning)";
}

// The Default cell: "required" for a key without one, else the value's text.
std::string default_text(const Meta& m, const std::string& value) { return m.required ? "required" : value; }

// One row per field; a nested struct is a row of its own (its meaning) followed by its fields.
class DocArchive {
 public:
  DocArchive(std::string prefix, std::vector<Row>* rows) : prefix_(std::move(prefix)), rows_(rows) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const Meta& m = f.meta;
    const std::string key = prefix_.empty() ? m.name : prefix_ + "." + m.name;
    const T& v = *f.value;
    if constexpr (std::is_same_v<T, double>) {
      rows_->push_back({key, m.unit, default_text(m, number(v)), valid_text(m), plausible_text(m), meaning(m)});
    } else if constexpr (std::is_same_v<T, long> || std::is_same_v<T, std::uint64_t>) {
      const std::string valid = std::is_same_v<T, long> ? "integer, " + valid_text(m) : "integer ≥ 0";
      rows_->push_back({key, m.unit, default_text(m, std::to_string(v)), valid, plausible_text(m), meaning(m)});
    } else if constexpr (std::is_same_v<T, bool>) {
      rows_->push_back({key, "–", v ? "true" : "false", "true, false", "–", meaning(m)});
    } else if constexpr (fields::is_named_enum<T>::value) {
      rows_->push_back({key, "–", default_text(m, std::string("`") + fields::enum_name(v) + "`"),
                        std::string(m.required ? "required; " : "") + fields::enum_choices<T>(), "–", meaning(m)});
    } else if constexpr (std::is_same_v<T, std::string>) {
      rows_->push_back({key, "–", default_text(m, v.empty() ? "–" : "`" + v + "`"),
                        std::string(m.required ? "required; " : "") + "text", "–", meaning(m)});
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      rows_->push_back({key, "list", v.empty() ? "[]" : "…", "a list of names", "–", meaning(m)});
    } else if constexpr (fields::is_serializable<T>::value) {
      if (*m.doc) rows_->push_back({key, "map", "", "", "", m.doc});
      DocArchive child(key, rows_);
      const_cast<T&>(v).Serialize(&child);
    }
  }

 private:
  std::string prefix_;
  std::vector<Row>* rows_;
};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += "\\|";
    else out += c;
  }
  return out;
}

template <typename S>
std::string table(S obj, const std::string& prefix = "") {
  std::vector<Row> rows;
  DocArchive a(prefix, &rows);
  obj.Serialize(&a);
  std::string t =
      "| Key | Unit | Default | Valid (else exit 2) | Plausible for a linear feed drive (else a warning) | Meaning |\n"
      "|---|---|---|---|---|---|\n";
  for (const Row& r : rows)
    t += "| `" + r.key + "` | " + r.unit + " | " + r.def + " | " + r.valid + " | " + r.plausible + " | " +
         escape(r.meaning) + " |\n";
  return t;
}

// The plant without its effects (a table of their own).
struct PlantSections {
  plant::PlantParams p;
  template <class Archive>
  void Serialize(Archive* a) {
    Filter<Archive> f{a};
    p.Serialize(&f);
  }
  template <class Archive>
  struct Filter {
    Archive* a;
    template <typename T>
    void Visit(const fields::Field<T>& f) {
      if (std::string(f.meta.name) != "effects") a->Visit(f);
    }
  };
};

template <class F>
void collect_keys(const std::string& text, F&& add) {
  // Keys are the first backquoted cell of each row.
  std::size_t i = 0;
  while ((i = text.find("| `", i)) != std::string::npos) {
    const std::size_t b = i + 3, e = text.find('`', b);
    if (e == std::string::npos) break;
    if (i == 0 || text[i - 1] == '\n') add(text.substr(b, e - b));
    i = e;
  }
}

// The key prefix of a table's rows: "" for the top level (scenario), the section for a
// controller's or a reference's type (controller.cascade -> controller), else the table's name.
std::string key_prefix(const std::string& table_name) {
  if (table_name == "scenario") return "";
  if (table_name.rfind("controller", 0) == 0) return "controller";
  if (table_name.rfind("reference.", 0) == 0) return "reference";
  return table_name;
}

std::string dotted(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> key_tables() {
  return {
      {"scenario", table(Scenario{})},
      {"plant", table(PlantSections{})},
      {"plant.effects", table(plant::EffectsParams{})},
      {"controller", table(ControllerConfig{})},
      {"controller.sliding_mode", table(controller::SlidingModeParams{})},
      {"controller.cascade", table(controller::CascadeParams{})},
      {"controller.open_loop", table(controller::OpenLoopParams{})},
      {"controller.plugin", table(controller::PluginParams{})},
      {"reference", table(ReferenceConfig{})},
      {"reference.sine", table(trajectory::SineParams{})},
      {"reference.step", table(trajectory::StepParams{})},
      {"reference.accel_limited", table(trajectory::AccelLimitedParams{})},
      {"reference.scurve", table(trajectory::SCurveParams{})},
      {"reference.ramp", table(trajectory::RampParams{})},
  };
}

namespace {
// key -> unit, from the tables' rows (| `key` | unit | ...).
const std::map<std::string, std::string>& unit_map() {
  static const std::map<std::string, std::string> units = [] {
    std::map<std::string, std::string> m;
    for (const auto& [name, text] : key_tables()) {
      std::size_t i = 0;
      while ((i = text.find("\n| `", i)) != std::string::npos) {
        const std::size_t b = i + 4, e = text.find('`', b);
        const std::size_t u = text.find("| ", e) + 2, ue = text.find(" |", u);
        m[dotted(key_prefix(name), text.substr(b, e - b))] = text.substr(u, ue - u);
        i = e;
      }
    }
    return m;
  }();
  return units;
}
}  // namespace

std::string key_unit(const std::string& key) {
  std::string k = key;
  if (k.rfind("controller.model.", 0) == 0) k = "plant." + k.substr(17);
  const auto it = unit_map().find(k);
  return it == unit_map().end() ? std::string() : it->second;
}

std::vector<std::string> listed_keys() {
  std::vector<std::string> out;
  for (const auto& [name, text] : key_tables())
    collect_keys(text, [&](const std::string& k) { out.push_back(dotted(key_prefix(name), k)); });
  return out;
}

std::string record_column_table() {
  std::string t = "| Column | Unit | Meaning |\n|---|---|---|\n";
  Record r;
  visit_record_columns(r, [&t](const char* name, const char* unit, const char* meaning, ColumnSource, double&) {
    t += std::string("| `") + name + "` | " + unit + " | " + escape(meaning) + " |\n";
  });
  return t;
}

std::string with_key_tables(const std::string& doc) {
  static const std::string kOpen = "<!-- keys: ";
  static const std::string kClose = "<!-- /keys -->";
  auto tables = key_tables();
  tables.emplace_back("columns", record_column_table());  // not keys: not in key_tables()
  std::string out;
  std::size_t pos = 0;
  std::vector<std::string> seen;
  for (;;) {
    const std::size_t b = doc.find(kOpen, pos);
    if (b == std::string::npos) break;
    const std::size_t name_end = doc.find_first_of(" \n", b + kOpen.size());
    const std::string name = doc.substr(b + kOpen.size(), name_end - b - kOpen.size());
    const std::size_t line_end = doc.find('\n', b);
    const std::size_t e = doc.find(kClose, b);
    if (line_end == std::string::npos || e == std::string::npos)
      throw std::invalid_argument("key table '" + name + "': marker without " + kClose);
    const std::string* text = nullptr;
    for (const auto& [n, t] : tables)
      if (n == name) text = &t;
    if (!text) throw std::invalid_argument("key table '" + name + "': no such table (feeddrive-keys --list)");
    if (std::find(seen.begin(), seen.end(), name) != seen.end())
      throw std::invalid_argument("key table '" + name + "': marked twice");
    seen.push_back(name);
    out += doc.substr(pos, line_end + 1 - pos) + *text;
    pos = e;
  }
  // Every list has its table: a table deleted with its marker is drift too, not a smaller document.
  std::string missing;
  for (const auto& [n, t] : tables)
    if (std::find(seen.begin(), seen.end(), n) == seen.end()) missing += (missing.empty() ? "" : ", ") + n;
  if (!missing.empty())
    throw std::invalid_argument("key table(s) " + missing + ": no marker '" + kOpen + "NAME ... -->' ... '" + kClose +
                                "' in the file; add one where the table belongs");
  return out + doc.substr(pos);
}

}  // namespace feeddrive::sim

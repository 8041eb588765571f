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
#include "lists.hpp"

namespace feeddrive::sim {
namespace {

using fields::Check;
using fields::Meta;

struct Row {
  std::string key, unit, def, valid, plausible, meaning;
  std::string old_key{};  ///< the key in its old spelling (fields::Meta::alias), "" if it has none
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
    const std::string key = detail::dotted(prefix_, m.name);
    const T& v = *f.value;
    const std::size_t first = rows_->size();
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
    if (*m.alias && rows_->size() > first) (*rows_)[first].old_key = detail::dotted(prefix_, m.alias);
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

// The rows of a list, its keys under `prefix` ("" for the table, whose rows are relative).
template <typename S>
std::vector<Row> rows_of(S list, const std::string& prefix) {
  std::vector<Row> rows;
  DocArchive a(prefix, &rows);
  list.Serialize(&a);
  return rows;
}

template <typename S>
std::string table(S list) {
  std::string t =
      "| Key | Unit | Default | Valid (else exit 2) | Plausible for a linear feed drive (else a warning) | Meaning |\n"
      "|---|---|---|---|---|---|\n";
  for (const Row& r : rows_of(list, ""))
    t += "| `" + r.key + "` | " + r.unit + " | " + r.def + " | " + r.valid + " | " + r.plausible + " | " +
         escape(r.meaning) + " |\n";
  return t;
}

// Every row of every list (detail::for_each_list), keys with their prefix: the units and the
// listed keys, walked from the lists, not parsed from the rendered tables.
const std::vector<Row>& all_rows() {
  static const std::vector<Row> rows = [] {
    std::vector<Row> out;
    detail::for_each_list([&](const char*, const char* prefix, auto list) {
      for (Row& r : rows_of(list, prefix)) out.push_back(std::move(r));
    });
    return out;
  }();
  return rows;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> key_tables() {
  std::vector<std::pair<std::string, std::string>> out;
  detail::for_each_list([&](const char* name, const char*, auto list) { out.emplace_back(name, table(list)); });
  return out;
}

std::string key_unit(const std::string& key) {
  std::string k = key;
  if (k.rfind("controller.model.", 0) == 0) k = "plant." + k.substr(17);  // the model is the plant's list
  for (const Row& r : all_rows())
    if (r.key == k) return r.unit;
  return {};
}

std::vector<std::string> listed_keys() {
  std::vector<std::string> out;
  for (const Row& r : all_rows()) out.push_back(r.key);
  return out;
}

std::vector<std::pair<std::string, std::string>> listed_old_spellings() {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Row& r : all_rows())
    if (!r.old_key.empty()) out.emplace_back(r.old_key, r.key);
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

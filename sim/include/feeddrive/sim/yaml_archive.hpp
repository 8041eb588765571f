#pragma once
// The scenario's YAML reader for a params struct's one list (common/fields.hpp): each field of
// the struct's Serialize() is read with the MapReader accessor of its type, so the key, its type,
// its one-line errors ("plant.mass = 'abc': not a number", "... = 'x': expected one of a, b")
// come from that one line; KeyRecordArchive writes the same keys back from the struct with
// their effective values (ResolvedKeys, for feeddrive-study).
//
//   double                -> number (number_or_infinite where the list allows -.inf)
//   bool / long / uint64  -> boolean / integer / unsigned_integer
//   std::string           -> string
//   std::vector<string>   -> a list of strings (output.columns)
//   a named enum          -> its name (fields::enum_names), "expected one of ..." otherwise
//   a nested params struct-> a child map, read the same way and finished (unknown keys refused)
//
// A field's old spelling (fields::Meta::alias) is read as the field, with a deprecation line
// (MapReader::spelling); both spellings given is a one-line error. A required field
// (fields::Meta::required) not given is "KEY: missing (required)".

#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/common/validate.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::sim {

class YamlReadArchive {
 public:
  /// `skip`: keys of the list the caller reads itself (a rule of their own).
  explicit YamlReadArchive(MapReader& r, std::set<std::string> skip = {}) : r_(r), skip_(std::move(skip)) {}

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    if (skip_.count(f.meta.name)) return;
    const std::string key = r_.spelling(f.meta.name, f.meta.alias);  // the name, or its old spelling
    if (f.meta.required && !r_.has(key)) r_.missing(key);
    T& v = *f.value;
    if constexpr (std::is_same_v<T, double>) {
      if (f.meta.allow_inf()) {
        r_.number_or_infinite(key, v);
      } else {
        r_.number(key, v);
      }
    } else if constexpr (std::is_same_v<T, bool>) {
      r_.boolean(key, v);
    } else if constexpr (std::is_same_v<T, long>) {
      r_.integer(key, v);
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      r_.unsigned_integer(key, v);
    } else if constexpr (std::is_same_v<T, std::string>) {
      r_.string(key, v);
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      r_.string_list(key, v);
    } else if constexpr (fields::is_named_enum<T>::value) {
      std::string name = fields::enum_name(v);
      r_.string(key, name);
      try {
        v = fields::enum_from_name<T>(name);
      } catch (const std::invalid_argument& e) {
        r_.fail(key, " = '" + name + "': " + e.what());
      }
    } else {
      static_assert(fields::is_serializable<T>::value, "a field type the YAML reader does not know");
      MapReader child = r_.child(key);
      YamlReadArchive a(child);
      v.Serialize(&a);
      child.finish();
    }
  }

 private:
  MapReader& r_;
  std::set<std::string> skip_;
};

/// Writes every key of a struct's list with its value, as the reader reads it back (ResolvedKeys:
/// "plant.friction.static_force" -> "120"), nested structs under their key: the scenario's
/// description as feeddrive-study keys and hashes its cases (sim::resolved_keys).
class KeyRecordArchive {
 public:
  /// `skip`: keys of the list the caller writes itself (or leaves out: a rule of their own).
  KeyRecordArchive(std::string prefix, ResolvedKeys& out, std::set<std::string> skip = {})
      : prefix_(std::move(prefix)), out_(out), skip_(std::move(skip)) {}

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    if (skip_.count(f.meta.name)) return;
    const std::string key = prefix_.empty() ? std::string(f.meta.name) : prefix_ + "." + f.meta.name;
    const T& v = *f.value;
    if constexpr (std::is_same_v<T, double>) {
      out_[key] = {std::isinf(v) ? (v > 0 ? ".inf" : "-.inf") : validate::format_number(v), false};
    } else if constexpr (std::is_same_v<T, bool>) {
      out_[key] = {v ? "true" : "false", false};
    } else if constexpr (std::is_same_v<T, long> || std::is_same_v<T, std::uint64_t>) {
      out_[key] = {std::to_string(v), false};
    } else if constexpr (std::is_same_v<T, std::string>) {
      out_[key] = {v, true};
    } else if constexpr (fields::is_named_enum<T>::value) {
      out_[key] = {fields::enum_name(v), true};
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      // A list (output.columns) says what is written, not what runs: it is no key of the run's
      // description, which holds one scalar per key (resolved_yaml, a study case's hash).
    } else {
      static_assert(fields::is_serializable<T>::value, "a field type the key recorder does not know");
      KeyRecordArchive a(key, out_);
      const_cast<T&>(v).Serialize(&a);  // the archive only reads
    }
  }

 private:
  std::string prefix_;
  ResolvedKeys& out_;
  std::set<std::string> skip_;
};

/// Writes every key of obj's list under `prefix` into out (KeyRecordArchive).
template <typename S>
void record_fields(const S& obj, const std::string& prefix, ResolvedKeys& out, std::set<std::string> skip = {}) {
  KeyRecordArchive a(prefix, out, std::move(skip));
  const_cast<S&>(obj).Serialize(&a);  // the archive only reads
}

/// Reads every key of obj's list from r (r is not finished: the caller may read more keys).
template <typename S>
void read_fields(MapReader& r, S& obj, std::set<std::string> skip = {}) {
  YamlReadArchive a(r, std::move(skip));
  obj.Serialize(&a);
}

}  // namespace feeddrive::sim

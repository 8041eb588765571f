#pragma once
// The scenario's YAML reader for a params struct's one list (common/fields.hpp): each field of
// the struct's Serialize() is read with the MapReader accessor of its type, so the key, its type,
// its one-line errors ("plant.mass = 'abc': not a number", "... = 'x': expected one of a, b")
// and its effective value (ResolvedKeys, for feeddrive-study) come from that one line.
//
//   double                -> number (number_or_infinite where the list allows -.inf)
//   bool / long / uint64  -> boolean / integer / unsigned_integer
//   std::string           -> string
//   a named enum          -> its name (fields::enum_names), "expected one of ..." otherwise
//   a nested params struct-> a child map, read the same way and finished (unknown keys refused)

#include <cstdint>
#include <set>
#include <string>
#include <type_traits>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/sim/yaml_reader.hpp"

namespace feeddrive::sim {

class YamlReadArchive {
 public:
  /// `skip`: keys of the list the caller reads itself (a rule of their own).
  explicit YamlReadArchive(MapReader& r, std::set<std::string> skip = {}) : r_(r), skip_(std::move(skip)) {}

  template <typename T>
  void Visit(const fields::Field<T>& f) {
    const std::string key = f.meta.name;
    if (skip_.count(key)) return;
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

/// Reads every key of obj's list from r (r is not finished: the caller may read more keys).
template <typename S>
void read_fields(MapReader& r, S& obj, std::set<std::string> skip = {}) {
  YamlReadArchive a(r, std::move(skip));
  obj.Serialize(&a);
}

}  // namespace feeddrive::sim

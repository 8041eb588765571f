#pragma once
// One list per parameter struct (Drake's Serialize style, drake/common/name_value.h): each params
// struct declares its fields once, next to the struct,
//
//   template <class Archive>
//   void Serialize(Archive* a) {
//     a->Visit(FD_FIELD(mass).unit("kg").positive().plausible(1, 5000).doc("moving mass m"));
//     a->Visit(FD_FIELD(friction).doc("friction law and parameters"));   // a nested params struct
//   }
//
// and every consumer of the keys is an archive that visits that list:
//   * the scenario's YAML reader (sim/yaml_archive.hpp): strict, unknown keys with "did you mean";
//   * validate()'s per-field ranges (check_fields() below), with the one-line messages of
//     validate.hpp ("plant.mass = -1: must be > 0");
//   * the plausibility warnings for a linear feed drive (plausibility() below);
//   * the key tables of docs/scenario.md (feeddrive-keys, checked for drift by a test);
//   * the study's key access and --set, through the scenario reader;
//   * the readers that are not C++ (flatten() below, plant/parameter_table.hpp): the controller
//     plugin ABI's model table (controller/plugin.h) and run_info_t.plant on LCM.
// Adding a key is one Visit line (docs/contributing.md, "How to add a scenario key"); renaming
// one keeps the old spelling as .alias("old") on that line.
//
// Header-only; no dependency beyond the standard library.

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "feeddrive/common/validate.hpp"

namespace feeddrive::fields {

/// The validity rule of a number (hard: validate() throws, the tools exit 2).
enum class Check {
  kFinite,       ///< any finite number
  kPositive,     ///< > 0
  kNonNegative,  ///< >= 0
  kNotPlusInf,   ///< a number or -inf (written -.inf), never NaN or +inf
  kNone,         ///< not checked by check_fields (a rule of its own in validate())
};

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// What the list says of one field besides its name and value.
struct Meta {
  const char* name{""};
  const char* unit{"-"};  ///< engineering unit as written in the docs ("m", "N*s/m", "-")
  const char* doc{""};    ///< one line for the key table
  Check check{Check::kFinite};
  /// Further hard bounds: a value outside cannot be meant (exit 2, "must be <= 1 m").
  double min{-kInf}, max{kInf};
  /// The plausible range for a linear feed drive of a machine tool: outside it the loader warns,
  /// naming the likely unit the value was written in (`hint_high` above, `hint_low` below).
  double plausible_lo{-kInf}, plausible_hi{kInf};
  const char* hint_high{""};
  const char* hint_low{""};
  const char* plausible_why{""};  ///< e.g. "any linear drive"
  /// The key's old spelling, still read with a deprecation warning (a key renamed into the one
  /// vocabulary: docs/contributing.md, "How to rename a key"); "" when it has none. Giving both
  /// spellings is an error; did-you-mean and the docs' key tables know it.
  const char* alias{""};
  /// The key must be given (no default): the reader refuses a scenario without it ("duration:
  /// missing (required)"); the docs' Default cell says "required".
  bool required{false};
  bool allow_inf() const { return check == Check::kNotPlusInf; }
};

/// A field: its Meta and a reference to its value. Built by FD_FIELD(x) and refined by chaining.
template <typename T>
struct Field {
  Meta meta;
  T* value;
  Field unit(const char* u) const {
    return with([&](Meta& m) { m.unit = u; });
  }
  Field doc(const char* d) const {
    return with([&](Meta& m) { m.doc = d; });
  }
  Field positive() const {
    return with([](Meta& m) { m.check = Check::kPositive; });
  }
  Field non_negative() const {
    return with([](Meta& m) { m.check = Check::kNonNegative; });
  }
  Field minus_inf_allowed() const {
    return with([](Meta& m) { m.check = Check::kNotPlusInf; });
  }
  /// An old spelling of the key (Meta::alias).
  Field alias(const char* old) const {
    return with([&](Meta& m) { m.alias = old; });
  }
  /// The same field under another name (two keys of one kind, e.g. a range's two ends).
  Field with_name(const char* n) const {
    return with([&](Meta& m) { m.name = n; });
  }
  /// The key has no default (Meta::required).
  Field required() const {
    return with([](Meta& m) { m.required = true; });
  }
  Field unchecked() const {
    return with([](Meta& m) { m.check = Check::kNone; });
  }
  Field at_most(double hi) const {
    return with([&](Meta& m) { m.max = hi; });
  }
  Field at_least(double lo) const {
    return with([&](Meta& m) { m.min = lo; });
  }
  /// Plausible for a linear feed drive in [lo, hi]; outside, a warning naming `hint_high`
  /// (above hi) or `hint_low` (below lo) as the unit the value was probably written in.
  Field plausible(double lo, double hi, const char* hint_high = "", const char* hint_low = "",
                  const char* why = "any linear feed drive") const {
    return with([&](Meta& m) {
      m.plausible_lo = lo;
      m.plausible_hi = hi;
      m.hint_high = hint_high;
      m.hint_low = hint_low;
      m.plausible_why = why;
    });
  }

 private:
  template <typename F>
  Field with(F f) const {
    Field c = *this;
    f(c.meta);
    return c;
  }
};

template <typename T>
Field<T> field(const char* name, T& value) {
  Field<T> f{Meta{}, &value};
  f.meta.name = name;
  return f;
}

/// FD_FIELD(mass): the field named as the member, Drake's DRAKE_NVP.
#define FD_FIELD(x) ::feeddrive::fields::field(#x, x)

// --- enums --------------------------------------------------------------------------------
// An enum is listed by an ADL function next to it:
//   inline const std::vector<std::pair<FrictionModel, const char*>>& enum_names(FrictionModel);
// and is an enum end to end: read from its name, written by its name, one table.

template <typename E, typename = void>
struct is_named_enum : std::false_type {};
template <typename E>
struct is_named_enum<E, std::void_t<decltype(enum_names(std::declval<E>()))>> : std::is_enum<E> {};

template <typename E>
std::string enum_choices() {
  std::string s;
  for (const auto& [v, n] : enum_names(E{})) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

template <typename E>
const char* enum_name(E e) {
  for (const auto& [v, n] : enum_names(E{}))
    if (v == e) return n;
  return "?";
}

/// The enum value named `s`; throws std::invalid_argument("expected one of a, b, c").
template <typename E>
E enum_from_name(const std::string& s) {
  for (const auto& [v, n] : enum_names(E{}))
    if (s == n) return v;
  throw std::invalid_argument("expected one of " + enum_choices<E>());
}

// --- nested structs -----------------------------------------------------------------------

template <typename T, typename = void>
struct is_serializable : std::false_type {};
template <typename T>
struct is_serializable<T, std::void_t<decltype(std::declval<T&>().Serialize(static_cast<int*>(nullptr)))>>
    : std::true_type {};
// (Serialize is a template, so the probe above with Archive = int only checks that it exists.)

// --- check_fields: validate()'s per-field ranges ------------------------------------------

/// Checks every number of `obj`'s list against its Check and bounds, throwing
/// std::invalid_argument "<prefix>.<name> = <value>: <why>" (validate.hpp). Nested structs,
/// strings, flags and enums are skipped (the nested ones have their own validate()). `skip`
/// names fields a rule of the struct's validate() leaves out (e.g. the static friction model's
/// bristle keys).
class CheckArchive {
 public:
  CheckArchive(std::string prefix, std::vector<std::string> skip)
      : prefix_(std::move(prefix)), skip_(std::move(skip)) {}
  template <typename T>
  void Visit(const Field<T>& f) {
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, long>) {
      for (const auto& s : skip_)
        if (s == f.meta.name) return;
      check(prefix_.empty() ? std::string(f.meta.name) : prefix_ + "." + f.meta.name, static_cast<double>(*f.value),
            f.meta);
    }
  }
  static void check(const std::string& key, double v, const Meta& m) {
    switch (m.check) {
      case Check::kNone: return;
      case Check::kFinite: validate::require_finite(key, v); break;
      case Check::kPositive: validate::require_positive(key, v); break;
      case Check::kNonNegative: validate::require_non_negative(key, v); break;
      case Check::kNotPlusInf:
        if (std::isnan(v) || v == kInf) validate::fail(key, v, "must be a number or -inf");
        break;
    }
    // Beyond the hard bounds a value cannot be meant; the likely unit is named as in the warnings.
    const std::string unit = std::string(m.unit) == "-" ? "" : std::string(" ") + m.unit;
    if (v < m.min)
      validate::fail(key, v,
                     "must be >= " + validate::format_number(m.min) + unit +
                         (*m.hint_low ? std::string(" (") + m.hint_low + "?)" : ""));
    if (v > m.max)
      validate::fail(key, v,
                     "must be <= " + validate::format_number(m.max) + unit +
                         (*m.hint_high ? std::string(" (") + m.hint_high + "?)" : ""));
  }

 private:
  std::string prefix_;
  std::vector<std::string> skip_;
};

template <typename S>
void check_fields(const S& obj, const std::string& prefix, std::vector<std::string> skip = {}) {
  CheckArchive a(prefix, std::move(skip));
  const_cast<S&>(obj).Serialize(&a);  // the archive only reads
}

// --- plausibility -------------------------------------------------------------------------

/// One line per number of `obj`'s list (nested structs included) outside its plausible range:
///   "reference.max_velocity: 500 m/s is above any linear feed drive (10 m/s); mm/s?"
class PlausibilityArchive {
 public:
  explicit PlausibilityArchive(std::string prefix, std::vector<std::string>* out)
      : prefix_(std::move(prefix)), out_(out) {}
  template <typename T>
  void Visit(const Field<T>& f) {
    const std::string key = prefix_.empty() ? f.meta.name : prefix_ + "." + f.meta.name;
    if constexpr (std::is_same_v<T, double>) {
      const Meta& m = f.meta;
      const double v = *f.value;
      if (!std::isfinite(v)) return;
      const std::string unit = std::string(m.unit) == "-" ? "" : std::string(" ") + m.unit;
      if (v > m.plausible_hi)
        out_->push_back(key + ": " + validate::format_number(v) + unit + " is above " + m.plausible_why + " (" +
                        validate::format_number(m.plausible_hi) + unit + ")" + hint(m.hint_high));
      else if (v < m.plausible_lo && v != 0.0)  // 0 switches a part off
        out_->push_back(key + ": " + validate::format_number(v) + unit + " is below " + m.plausible_why + " (" +
                        validate::format_number(m.plausible_lo) + unit + ")" + hint(m.hint_low));
    } else if constexpr (is_serializable<T>::value) {
      PlausibilityArchive child(key, out_);
      f.value->Serialize(&child);
    }
  }

 private:
  static std::string hint(const char* h) { return *h ? std::string("; ") + h + "?" : std::string(); }
  std::string prefix_;
  std::vector<std::string>* out_;
};

template <typename S>
std::vector<std::string> plausibility(const S& obj, const std::string& prefix) {
  std::vector<std::string> out;
  PlausibilityArchive a(prefix, &out);
  const_cast<S&>(obj).Serialize(&a);
  return out;
}

// --- flatten: the list as (key, value) pairs ---------------------------------------------------

/// One value of a list, nested structs flattened to dotted keys ("friction.stribeck_exponent").
struct FlatValue {
  std::string key;
  /// A number (an integer converted), a flag 1 or 0; NaN for a name.
  double number{std::numeric_limits<double>::quiet_NaN()};
  /// An enum's name or a string's text; "" for a number or a flag.
  std::string name;
  bool is_name{false};
};

/// Collects every value of a list in list order, nested structs under their key; a key in
/// `skip` (a dotted key, a whole nested struct by its key) is left out with what is below it.
class FlattenArchive {
 public:
  FlattenArchive(std::string prefix, const std::vector<std::string>* skip, std::vector<FlatValue>* out)
      : prefix_(std::move(prefix)), skip_(skip), out_(out) {}
  template <typename T>
  void Visit(const Field<T>& f) {
    const std::string key = prefix_.empty() ? std::string(f.meta.name) : prefix_ + "." + f.meta.name;
    for (const std::string& s : *skip_)
      if (s == key) return;
    const T& v = *f.value;
    if constexpr (std::is_same_v<T, bool>) {
      out_->push_back({key, v ? 1.0 : 0.0, "", false});
    } else if constexpr (std::is_arithmetic_v<T>) {
      out_->push_back({key, static_cast<double>(v), "", false});
    } else if constexpr (is_named_enum<T>::value) {
      out_->push_back({key, std::numeric_limits<double>::quiet_NaN(), enum_name(v), true});
    } else if constexpr (std::is_same_v<T, std::string>) {
      out_->push_back({key, std::numeric_limits<double>::quiet_NaN(), v, true});
    } else {
      static_assert(is_serializable<T>::value, "fields::flatten: a field type it does not know");
      FlattenArchive child(key, skip_, out_);
      const_cast<T&>(v).Serialize(&child);  // the archive only reads
    }
  }

 private:
  std::string prefix_;
  const std::vector<std::string>* skip_;
  std::vector<FlatValue>* out_;
};

/// Every value of `obj`'s list as (dotted key, value), in list order, without the keys in `skip`
/// (and what is below them): the list handed to a reader that is not C++ (the controller plugin
/// ABI, run_info_t), so a field added to the list reaches it without further code.
template <typename S>
std::vector<FlatValue> flatten(const S& obj, const std::vector<std::string>& skip = {}) {
  std::vector<FlatValue> out;
  FlattenArchive a("", &skip, &out);
  const_cast<S&>(obj).Serialize(&a);  // the archive only reads
  return out;
}

/// The inverse of flatten: sets every field of `obj`'s list whose dotted key `find(key)` knows
/// (a const FlatValue*, nullptr for a key it does not have; those fields keep their values), a
/// flag from number != 0, an integer from the number, an enum from its name (std::invalid_argument
/// "KEY = 'NAME': expected one of ..." for another). Returns how many fields it set. A reader of
/// a table (run_info_t.plant) fills its params struct by the struct's own list.
class UnflattenArchive {
 public:
  using Find = std::function<const FlatValue*(const std::string&)>;
  UnflattenArchive(std::string prefix, const Find* find, std::size_t* set)
      : prefix_(std::move(prefix)), find_(find), set_(set) {}
  template <typename T>
  void Visit(const Field<T>& f) {
    const std::string key = prefix_.empty() ? std::string(f.meta.name) : prefix_ + "." + f.meta.name;
    if constexpr (is_serializable<T>::value) {
      UnflattenArchive child(key, find_, set_);
      f.value->Serialize(&child);
      return;
    } else {
      const FlatValue* v = (*find_)(key);
      if (v == nullptr) return;
      T& out = *f.value;
      if constexpr (std::is_same_v<T, bool>) {
        out = v->number != 0.0;
      } else if constexpr (std::is_arithmetic_v<T>) {
        out = static_cast<T>(v->number);
      } else if constexpr (is_named_enum<T>::value) {
        try {
          out = enum_from_name<T>(v->name);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(key + " = '" + v->name + "': " + e.what());
        }
      } else {
        static_assert(std::is_same_v<T, std::string>, "fields::unflatten: a field type it does not know");
        out = v->name;
      }
      ++*set_;
    }
  }

 private:
  std::string prefix_;
  const Find* find_;
  std::size_t* set_;
};

template <typename S>
std::size_t unflatten(S& obj, const UnflattenArchive::Find& find) {
  std::size_t set = 0;
  UnflattenArchive a("", &find, &set);
  obj.Serialize(&a);
  return set;
}

// --- same: equality through the list --------------------------------------------------------

/// Collects the bytes of every value of a list, nested structs included, in list order: two
/// objects of one struct are the same when their collections are (doubles compared bit for bit,
/// so NaN equals NaN and a cache keyed by it never misses a changed field).
class BytesArchive {
 public:
  explicit BytesArchive(std::string* out) : out_(out) {}
  template <typename T>
  void Visit(const Field<T>& f) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      out_->append(reinterpret_cast<const char*>(f.value), sizeof(T));
    } else if constexpr (std::is_same_v<T, std::string>) {
      out_->append(*f.value);
      out_->push_back('\0');
    } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
      for (const std::string& e : *f.value) out_->append(e).push_back('\0');
      out_->push_back('\1');
    } else if constexpr (is_serializable<T>::value) {
      f.value->Serialize(this);
    } else {
      static_assert(sizeof(T) == 0, "fields::same: a field type without a comparison");
    }
  }

 private:
  std::string* out_;
};

/// True when every field of `a`'s list equals `b`'s (BytesArchive). One list: a field added to
/// the struct's Serialize is compared without further code (the fit's force cache, model.cpp).
template <typename S>
bool same(const S& a, const S& b) {
  std::string ba, bb;
  BytesArchive xa(&ba), xb(&bb);
  const_cast<S&>(a).Serialize(&xa);  // the archive only reads
  const_cast<S&>(b).Serialize(&xb);
  return ba == bb;
}

}  // namespace feeddrive::fields

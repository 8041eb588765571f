#pragma once
// Text helpers of the fit library's messages (private to fit/src): one printf-style formatter and
// one parameter lookup, shared by the rules, the sanity checks, the workflow and the verdicts.
#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

#include "feeddrive/common/fields.hpp"

#include "feeddrive/plant/effects.hpp"

namespace feeddrive::fit::text {

/// printf of up to four numbers into a string (a message fragment).
inline std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

/// Every parameter name of the vocabulary (the effects' lists, plant::EffectsParams).
inline const std::set<std::string>& effect_parameter_names() {
  static const std::set<std::string> names = [] {
    std::set<std::string> out;
    for (const fields::FlatValue& v : fields::flatten(plant::EffectsParams{}))
      out.insert(v.key.substr(v.key.find('.') + 1));  // "constant_force.force" -> "force"
    return out;
  }();
  return names;
}

/// A parameter of an effect, 0 if this effect has none of that name. A name that no effect's list
/// has is a programming error (a key renamed in the lists, a rule left behind): std::logic_error,
/// never a silent 0 that switches the rule off.
inline double par(const plant::NamedEffect& e, const char* k) {
  const auto it = e.parameters.find(k);
  if (it != e.parameters.end()) return it->second;
  if (!effect_parameter_names().count(k))
    throw std::logic_error(std::string("fit: '") + k + "' is a parameter of no effect's list (renamed?)");
  return 0.0;
}

}  // namespace feeddrive::fit::text

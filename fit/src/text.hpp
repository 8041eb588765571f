#pragma once
// Text helpers of the fit library's messages (private to fit/src): one printf-style formatter and
// one parameter lookup, shared by the rules, the sanity checks, the workflow and the verdicts.
#include <cstdio>
#include <string>

#include "feeddrive/plant/effects.hpp"

namespace feeddrive::fit::text {

/// printf of up to four numbers into a string (a message fragment).
inline std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

/// A parameter of an effect, 0 if it has none of that name.
inline double par(const plant::NamedEffect& e, const char* k) {
  const auto it = e.parameters.find(k);
  return it == e.parameters.end() ? 0.0 : it->second;
}

}  // namespace feeddrive::fit::text

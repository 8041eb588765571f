#pragma once
// Validation helpers of the controller params structs (private to the library): the shared
// one-line errors (common/validate.hpp) and the u_min < u_max check.
#include <string>

#include "feeddrive/common/validate.hpp"

namespace feeddrive::controller::detail {

using validate::fail;
using validate::require_finite;
using validate::require_non_negative;
using validate::require_positive;

inline void require_range(const std::string& prefix, double lo, double hi) {
  require_finite(prefix + ".u_min", lo);
  require_finite(prefix + ".u_max", hi);
  if (!(lo < hi)) fail(prefix + ".u_max", hi, "must be > u_min");
}

}  // namespace feeddrive::controller::detail

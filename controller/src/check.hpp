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

/// The normalised gradient step of feedforward_adaptation.hpp is theta += gamma*T*r*phi/(F0^2 +
/// phi.phi); with r ~ (theta* - theta)*phi its error contracts by (1 - gamma*T*phi^2/(F0^2 +
/// phi.phi)) per period, which is stable only for gamma*T < 2 (Astrom & Wittenmark, "Adaptive
/// Control", 2nd ed., ch. 2, the normalised projection algorithm's 0 < gamma*T < 2).
inline void require_adaptation_stable(const std::string& key, double rate, double period) {
  if (rate * period >= 2.0)
    fail(key, rate,
         "rate * control period = " + validate::format_number(rate * period) +
             " must be < 2 (the normalised gradient update diverges); max " + validate::format_number(2.0 / period) +
             " 1/s at this period");
}

}  // namespace feeddrive::controller::detail

#pragma once
// Private helpers of the trajectory library (not installed, not part of the public API): the
// shared one-line validation errors (common/validate.hpp) and the NaN sample.

#include <limits>

#include "feeddrive/common/validate.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory::detail {

using validate::fail;
using validate::format_number;
using validate::require_finite;
using validate::require_non_negative;
using validate::require_positive;

/// A sample with every field NaN: what every profile returns for t = NaN, so that a bad time
/// propagates to the caller instead of being silently mapped to the start or end state.
inline Sample nan_sample() {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  return Sample{kNaN, kNaN, kNaN, kNaN};
}

}  // namespace feeddrive::trajectory::detail

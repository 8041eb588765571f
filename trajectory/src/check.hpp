#pragma once
// Private helpers of the trajectory library (not installed, not part of the public API):
// shortest round-trip number formatting and the one-line validation errors
// "<key> = <value>: <reason>" thrown as std::invalid_argument.

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory::detail {

/// Shortest text that reads back as exactly `v` ("0.1", "-3", "1e-06", "nan", "inf").
inline std::string format_number(double v) {
  std::array<char, 64> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), res.ptr);
}

[[noreturn]] inline void fail(const std::string& key, double value, const std::string& why) {
  throw std::invalid_argument(key + " = " + format_number(value) + ": " + why);
}

inline void require_finite(const std::string& key, double v) {
  if (!std::isfinite(v)) fail(key, v, "must be a finite number");
}

inline void require_positive(const std::string& key, double v) {
  require_finite(key, v);
  if (!(v > 0.0)) fail(key, v, "must be > 0");
}

inline void require_non_negative(const std::string& key, double v) {
  require_finite(key, v);
  if (v < 0.0) fail(key, v, "must be >= 0");
}

/// A sample with every field NaN: what every profile returns for t = NaN, so that a bad time
/// propagates to the caller instead of being silently mapped to the start or end state.
inline Sample nan_sample() {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  return Sample{kNaN, kNaN, kNaN, kNaN};
}

}  // namespace feeddrive::trajectory::detail

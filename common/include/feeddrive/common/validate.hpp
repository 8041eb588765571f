#pragma once
// The one-line validation errors of every params struct's validate():
//   "<key> = <value>: <reason>"  thrown as std::invalid_argument,
// with the value in its shortest round-trip form ("0.1", "-3", "1e-06", "nan", "inf").
// Header-only, shared by the plant, controller and trajectory libraries.

#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace feeddrive::validate {

/// Shortest text that reads back as exactly `v`.
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

}  // namespace feeddrive::validate

#pragma once
// Validation helpers shared by the controller params structs (private to the library).
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace feeddrive::controller::detail {

[[noreturn]] inline void fail(const std::string& key, double value, const std::string& why) {
  std::ostringstream os;
  os.precision(17);
  os << key << " = " << value << ": " << why;
  throw std::invalid_argument(os.str());
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
inline void require_range(const std::string& prefix, double lo, double hi) {
  require_finite(prefix + ".u_min", lo);
  require_finite(prefix + ".u_max", hi);
  if (!(lo < hi)) fail(prefix + ".u_max", hi, "must be > u_min");
}

}  // namespace feeddrive::controller::detail

#include "feeddrive/controller/open_loop.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "check.hpp"

namespace feeddrive::controller {

std::string to_string(OpenLoopKind k) { return fields::enum_name(k); }

void OpenLoopParams::validate(const std::string& prefix) const {
  using namespace detail;
  fields::check_fields(*this, prefix);  // the list's ranges (open_loop.hpp)
  require_positive(prefix + ".thrust_gain", thrust_gain);
  require_range(prefix, u_min, u_max);
  if (kind == OpenLoopKind::kCsv) {
    if (table_t.empty()) throw std::invalid_argument(prefix + ".file: kind = csv needs a table of at least one row");
    if (table_value.size() != table_t.size())
      throw std::invalid_argument(prefix + ".file: the table has " + std::to_string(table_t.size()) + " times and " +
                                  std::to_string(table_value.size()) + " values");
    const std::string value = table_is_force ? ".force_N" : ".u";
    for (std::size_t i = 0; i < table_t.size(); ++i) {
      const std::string row = prefix + ".file[" + std::to_string(i) + "]";
      require_finite(row + ".t", table_t[i]);
      require_finite(row + value, table_value[i]);
      if (i > 0 && !(table_t[i] > table_t[i - 1]))
        fail(row + ".t", table_t[i],
             "must be greater than the previous t = " + validate::format_number(table_t[i - 1]));
    }
  }
}

OpenLoopSource::OpenLoopSource(const OpenLoopParams& p) : p_(p) {
  p_.validate("controller");
  for (double v : p_.table_value) csv_u_.push_back(p_.table_is_force ? v / p_.thrust_gain : v);
}

double OpenLoopSource::force(double t) const {
  if (p_.kind == OpenLoopKind::kCsv) {
    // Zero-order hold; before the first row the force is 0.
    const auto it = std::upper_bound(p_.table_t.begin(), p_.table_t.end(), t);
    if (it == p_.table_t.begin()) return 0.0;
    return csv_u_[static_cast<std::size_t>(it - p_.table_t.begin()) - 1] * p_.thrust_gain;
  }
  if (t < p_.start_time) return p_.offset;
  const double tau = t - p_.start_time;
  switch (p_.kind) {
    case OpenLoopKind::kStep: return p_.offset + p_.amplitude;
    case OpenLoopKind::kSine: return p_.offset + p_.amplitude * std::sin(2.0 * M_PI * p_.frequency * tau + p_.phase);
    case OpenLoopKind::kRamp: {
      double f = p_.rate * tau;
      if (p_.amplitude > 0.0) f = std::clamp(f, -p_.amplitude, p_.amplitude);
      return p_.offset + f;
    }
    case OpenLoopKind::kCsv: break;
  }
  return 0.0;
}

Command OpenLoopSource::update(const trajectory::Sample& /*ref*/, const plant::Measurement& meas,
                               const Truth* /*truth*/) {
  Command cmd;
  cmd.u_unsaturated = force(meas.t) / p_.thrust_gain;
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);
  return cmd;
}

}  // namespace feeddrive::controller

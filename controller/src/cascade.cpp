#include "feeddrive/controller/cascade.hpp"

#include <algorithm>
#include <cmath>

#include "check.hpp"

namespace feeddrive::controller {

double saturate(double u, double lo, double hi) {
  if (std::isnan(u)) return 0.0;
  return std::clamp(u, lo, hi);
}

void CascadeParams::validate(const std::string& prefix) const {
  using namespace detail;
  require_non_negative(prefix + ".kp", kp);
  require_non_negative(prefix + ".kv", kv);
  require_non_negative(prefix + ".ki", ki);
  require_finite(prefix + ".velocity_feedforward", velocity_feedforward);
  require_finite(prefix + ".acceleration_feedforward", acceleration_feedforward);
  require_positive(prefix + ".model.mass", mass);
  require_positive(prefix + ".model.thrust_gain", thrust_gain);
  require_range(prefix, u_min, u_max);
  require_positive(prefix + ".period", period);
}

CascadeController::CascadeController(const CascadeParams& p) : p_(p) { p_.validate("controller"); }

Command CascadeController::update(const trajectory::Sample& ref, const plant::Measurement& meas,
                                  const Truth* /*truth*/) {
  const double v_cmd = p_.velocity_feedforward * ref.velocity + p_.kp * (ref.position - meas.x);
  const double ev = v_cmd - meas.v;
  const double force =
      p_.mass * (p_.kv * ev + p_.ki * integral_ + p_.acceleration_feedforward * ref.acceleration);
  Command cmd;
  cmd.u_unsaturated = force / p_.thrust_gain;
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);
  // Conditional integration: integrate unless saturated and the error would push further out.
  const bool high = cmd.u_unsaturated > p_.u_max && ev > 0.0;
  const bool low = cmd.u_unsaturated < p_.u_min && ev < 0.0;
  if (!high && !low) integral_ += ev * p_.period;
  return cmd;
}

}  // namespace feeddrive::controller

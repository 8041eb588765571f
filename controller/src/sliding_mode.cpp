#include "feeddrive/controller/sliding_mode.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "check.hpp"
#include "feeddrive/plant/forces.hpp"

namespace feeddrive::controller {

std::string to_string(Switching s) {
  switch (s) {
    case Switching::kSign: return "sgn";
    case Switching::kSaturation: return "sat";
    case Switching::kTanh: return "tanh";
  }
  return "?";
}

Switching switching_from_string(const std::string& s) {
  if (s == "sgn") return Switching::kSign;
  if (s == "sat") return Switching::kSaturation;
  if (s == "tanh") return Switching::kTanh;
  throw std::invalid_argument("expected one of sgn, sat, tanh");
}

std::string to_string(StateSource s) { return s == StateSource::kTrue ? "true" : "observer"; }

StateSource state_source_from_string(const std::string& s) {
  if (s == "true") return StateSource::kTrue;
  if (s == "observer") return StateSource::kObserver;
  throw std::invalid_argument("expected one of true, observer");
}

std::string to_string(MotionSource s) { return s == MotionSource::kMeasured ? "measured" : "observer"; }

MotionSource motion_source_from_string(const std::string& s) {
  if (s == "measured") return MotionSource::kMeasured;
  if (s == "observer") return MotionSource::kObserver;
  throw std::invalid_argument("expected one of measured, observer");
}

void SlidingModeParams::validate(const std::string& prefix) const {
  using namespace detail;
  require_non_negative(prefix + ".eta", eta);
  require_non_negative(prefix + ".k", k);
  require_positive(prefix + ".lambda", lambda);
  if (switching != Switching::kSign) require_positive(prefix + ".boundary_layer", boundary_layer);
  require_non_negative(prefix + ".observer_gain", observer_gain);
  require_positive(prefix + ".motion_observer_bandwidth", motion_observer_bandwidth);
  require_range(prefix, u_min, u_max);
  require_positive(prefix + ".period", period);
  model.validate(prefix + ".model");
}

namespace {

double switching_function(const SlidingModeParams& p, double s) {
  switch (p.switching) {
    case Switching::kSign: return (s > 0.0) - (s < 0.0);
    case Switching::kSaturation: return std::clamp(s / p.boundary_layer, -1.0, 1.0);
    case Switching::kTanh: return std::tanh(s / p.boundary_layer);
  }
  return 0.0;
}

}  // namespace

SlidingModeController::SlidingModeController(const SlidingModeParams& p)
    : p_(p),
      friction_observer_(p.model.friction, p.period, p.observer_gain),
      grinding_observer_(p.model.grinding, p.period),
      motion_observer_(p.motion_observer_bandwidth, p.period, p.motion_observer_disturbance,
                       p.model.sensor.quantization) {
  p_.validate("controller");
}

bool SlidingModeController::needs_truth() const {
  const bool friction = p_.compensate_friction && p_.friction_state == StateSource::kTrue &&
                        p_.model.friction.model == plant::FrictionModel::kLuGre;
  const bool grinding = p_.compensate_grinding && p_.grinding_state == StateSource::kTrue &&
                        p_.model.grinding.enabled;
  return friction || grinding;
}

Command SlidingModeController::update(const trajectory::Sample& ref, const plant::Measurement& meas,
                                      const Truth* truth) {
  if (truth == nullptr && needs_truth())
    throw std::logic_error(
        "sliding_mode: friction_state/grinding_state = true needs the plant's true z and Fg, "
        "which this plant does not provide; use the observers");

  double x = meas.x;
  double v = meas.v;
  // Until the observer has seen a finite sample it has no estimate: use the measurement as is.
  const bool use_observer = p_.motion_state == MotionSource::kObserver;
  if (use_observer) motion_observer_.correct(meas.x, meas.v);
  if (use_observer && motion_observer_.initialised()) {
    x = motion_observer_.position();
    v = motion_observer_.velocity();
  }

  const plant::PlantParams& m = p_.model;
  const double e = ref.position - x;
  const double ed = ref.velocity - v;
  const double s = ed + p_.lambda * e;
  const double a_cmd = (p_.feedforward_acceleration ? ref.acceleration : 0.0) + p_.lambda * ed +
                       p_.eta * switching_function(p_, s) + p_.k * s;

  Command cmd;
  cmd.sliding = s;

  // Model forces (each opposing the thrust), Xie & Liang eq. 19.
  double f_friction = 0.0;
  if (m.friction.model != plant::FrictionModel::kNone) {
    if (p_.friction_state == StateSource::kTrue && m.friction.model == plant::FrictionModel::kLuGre) {
      // The bristle rate from the true z itself, not from the model's g(v) (sliding_mode.hpp).
      const double z = truth != nullptr ? truth->z : 0.0;
      const double zdot = last_true_z_ ? (z - *last_true_z_) / p_.period : plant::lugre_zdot(m.friction, v, z);
      if (std::isfinite(z)) last_true_z_ = z;  // a NaN sample is not kept for the next rate
      f_friction = m.friction.bristle_stiffness * z + plant::micro_damping(m.friction, v) * zdot +
                   m.friction.viscous * v;
      cmd.z_estimate = z;
    } else {
      f_friction = friction_observer_.estimate(v);
      cmd.z_estimate = friction_observer_.z();
    }
  }
  double f_grinding = 0.0;
  if (m.grinding.enabled) {
    f_grinding = p_.grinding_state == StateSource::kTrue
                     ? plant::grinding_force(m.grinding, x, truth != nullptr ? truth->fg : 0.0)
                     : grinding_observer_.estimate(x);
  }
  double cogging = 0.0;
  double reluctance = 0.0;
  if (m.ripple.enabled) {
    cogging = plant::cogging_force(m.ripple, x);
    reluctance = plant::reluctance_factor(m.ripple, x);
  }

  const double fc = p_.compensate_friction ? f_friction : 0.0;
  const double gc = p_.compensate_grinding ? f_grinding : 0.0;
  const double cc = p_.compensate_ripple ? cogging : 0.0;
  const double rc = p_.compensate_ripple ? reluctance : 0.0;
  // Lumped disturbance of the x,v observer (0 unless motion_state = observer with d).
  const double dc = p_.motion_state == MotionSource::kObserver ? -m.mass * motion_observer_.disturbance() : 0.0;
  const double kakf = m.thrust_gain();
  cmd.u_unsaturated = (m.mass * a_cmd + fc + gc + cc + dc) / (kakf * (1.0 - rc));
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);

  // Advance the observers over [t_k, t_k + T] with everything held at its t_k value.
  friction_observer_.advance(v, ed);
  grinding_observer_.advance(x, v);
  if (use_observer && motion_observer_.initialised()) {
    const double thrust = kakf * cmd.u * (1.0 - reluctance);
    motion_observer_.predict((thrust - cogging - f_friction - f_grinding) / m.mass);
  }
  return cmd;
}

}  // namespace feeddrive::controller

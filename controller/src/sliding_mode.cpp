#include "feeddrive/controller/sliding_mode.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "check.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/forces.hpp"

namespace feeddrive::controller {

std::string to_string(Switching s) { return fields::enum_name(s); }
Switching switching_from_string(const std::string& s) { return fields::enum_from_name<Switching>(s); }
std::string to_string(StateSource s) { return fields::enum_name(s); }
StateSource state_source_from_string(const std::string& s) { return fields::enum_from_name<StateSource>(s); }

void SlidingModeParams::validate(const std::string& prefix) const {
  using namespace detail;
  fields::check_fields(*this, prefix);  // the list's ranges (sliding_mode.hpp)
  if (switching != Switching::kSign) require_positive(prefix + ".boundary_layer", boundary_layer);
  require_range(prefix, u_min, u_max);
  require_positive(prefix + ".period", period);
  require_non_negative(prefix + ".computation_delay", computation_delay);
  if (compensate_delay && motion_state != MotionSource::kObserver)
    throw std::invalid_argument(prefix + ".compensate_delay = true: needs motion_state: observer (the model predictor)");
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

namespace {
// The controller's model with the effects that modify a sub-model (mass_error, presliding,
// grinding_force) folded in (plant/effects.hpp); the additive ones stay and are compensated.
SlidingModeParams with_effective_model(SlidingModeParams p) {
  p.validate("controller");
  p.model = plant::effective_params(p.model);
  return p;
}
}  // namespace

SlidingModeController::SlidingModeController(const SlidingModeParams& given)
    : p_(with_effective_model(given)),
      has_extra_(plant::has_extra_force(p_.model.effects)),
      friction_observer_(p_.model.friction, p_.period, p_.observer_gain),
      grinding_observer_(p_.model.grinding, p_.period),
      motion_observer_(p_.motion_observer_bandwidth, p_.period, p_.motion_observer_disturbance,
                       p_.model.sensor.quantization),
      // snap: the plant's switch-time tolerance (plant.cpp), 1e-9 T
      delay_line_(p_.compensate_delay ? p_.computation_delay : 0.0, 1e-9 * p_.period) {}

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
  const bool delayed = p_.compensate_delay && p_.computation_delay > 0.0 && std::isfinite(meas.t);
  Command cmd;

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

  // The model's additive effects (a fitted model, docs/fit.md), affine in the thrust F:
  // F_extra = e0 + e1*F (e1: the reluctance_ripple effect), evaluated at (x^, v^).
  double e0 = 0.0, e1 = 0.0;
  if (has_extra_) {
    e0 = plant::extra_force(m, x, v, 0.0);
    e1 = plant::extra_force(m, x, v, 1.0) - e0;
  }
  // The state and reference the law acts on: now, or predicted to when the command acts.
  double xc = x;
  double vc = v;
  trajectory::Sample r = ref;
  const double kakf = m.thrust_gain();
  // Model acceleration under command u with the forces held at their t_k values (d^ excluded).
  const auto model_acceleration = [&](double u) {
    const double thrust = kakf * u;
    return (thrust * (1.0 - reluctance - e1) - cogging - f_friction - f_grinding - e0) / m.mass;
  };
  double f_friction_law = f_friction;  // F^f when the command acts
  if (delayed && use_observer && motion_observer_.initialised()) {
    const double a_d = motion_observer_.disturbance();
    // With the bristle observer, its z^ is carried along the prediction too, so F^f follows the
    // predicted velocity (the friction changes fastest at breakaway, within one delay).
    const bool carry_friction = p_.friction_state == StateSource::kObserver &&
                                m.friction.model == plant::FrictionModel::kLuGre;
    FrictionObserver ahead = friction_observer_;
    const double f_now = f_friction;
    for (const DelayLine::Piece& piece : delay_line_.pieces(meas.t, meas.t + p_.computation_delay)) {
      const double tau = piece.t1 - piece.t0;
      if (carry_friction) f_friction = ahead.estimate(vc);
      const double a = model_acceleration(piece.u) + a_d;
      if (carry_friction) ahead.advance(vc, 0.0, tau);
      xc += vc * tau + 0.5 * a * tau * tau;
      vc += a * tau;
    }
    f_friction_law = carry_friction ? ahead.estimate(vc) : f_now;
    f_friction = f_now;
    r = preview(ref, p_.computation_delay);
    if (m.ripple.enabled) {  // the ripple where the command will act
      cogging = plant::cogging_force(m.ripple, xc);
      reluctance = plant::reluctance_factor(m.ripple, xc);
    }
  }
  const double e = r.position - xc;
  const double ed = r.velocity - vc;
  const double s = ed + p_.lambda * e;
  const double a_cmd = (p_.feedforward_acceleration ? r.acceleration : 0.0) + p_.lambda * ed +
                       p_.eta * switching_function(p_, s) + p_.k * s;
  cmd.sliding = s;

  const double fc = p_.compensate_friction ? f_friction_law : 0.0;
  const double gc = p_.compensate_grinding ? f_grinding : 0.0;
  const double cc = p_.compensate_ripple ? cogging : 0.0;
  const double rc = p_.compensate_ripple ? reluctance : 0.0;
  // Lumped disturbance of the x,v observer (0 unless motion_state = observer with d).
  const double dc = p_.motion_state == MotionSource::kObserver ? -m.mass * motion_observer_.disturbance() : 0.0;
  cmd.u_unsaturated = (m.mass * a_cmd + fc + gc + cc + dc + e0) / (kakf * (1.0 - rc - e1));
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);

  // Advance the observers over [t_k, t_k + T] with everything held at its t_k value.
  friction_observer_.advance(v, ref.velocity - v);
  grinding_observer_.advance(x, v);
  if (delayed) {
    delay_line_.push(meas.t, cmd.u);
    if (use_observer && motion_observer_.initialised()) {
      // The command acting within the period is piecewise constant (switch at t_j + d).
      if (m.ripple.enabled) {  // back to the forces at x^(t_k)
        cogging = plant::cogging_force(m.ripple, x);
        reluctance = plant::reluctance_factor(m.ripple, x);
      }
      double dv = 0.0, dx = 0.0;
      const double t_end = meas.t + p_.period;
      for (const DelayLine::Piece& piece : delay_line_.pieces(meas.t, t_end)) {
        const double tau = piece.t1 - piece.t0;
        const double a = model_acceleration(piece.u);
        dv += a * tau;
        dx += a * tau * (0.5 * tau + (t_end - piece.t1));
      }
      motion_observer_.predict_increments(dv, dx);
    }
    delay_line_.forget_before(meas.t + p_.period);
  } else if (use_observer && motion_observer_.initialised()) {
    motion_observer_.predict(model_acceleration(cmd.u));
  }
  return cmd;
}

}  // namespace feeddrive::controller

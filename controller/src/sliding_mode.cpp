#include "feeddrive/controller/sliding_mode.hpp"
#include "feeddrive/controller/sliding_mode_law.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "check.hpp"
#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/forces.hpp"

namespace feeddrive::controller {

std::string to_string(Switching s) { return fields::enum_name(s); }
std::string to_string(StateSource s) { return fields::enum_name(s); }

void SlidingModeParams::validate(const std::string& prefix) const {
  using namespace detail;
  fields::check_fields(*this, prefix);  // the list's ranges (sliding_mode.hpp)
  if (switching != Switching::kSign) require_positive(prefix + ".boundary_layer", boundary_layer);
  require_range(prefix, u_min, u_max);
  require_positive(prefix + ".period", period);
  require_non_negative(prefix + ".computation_delay", computation_delay);
  if (compensate_delay && motion_state != MotionSource::kObserver)
    throw std::invalid_argument(prefix +
                                ".compensate_delay = true: needs motion_state: observer (the model predictor)");
  if (adaptation_rate > 0.0 && (motion_state != MotionSource::kObserver || !motion_observer_disturbance))
    fail(prefix + ".adaptation_rate", adaptation_rate,
         "needs motion_state: observer with motion_observer_disturbance (the residual d^)");
  if (adaptation_rate > 0.0 && friction_state != StateSource::kObserver)
    fail(prefix + ".adaptation_rate", adaptation_rate,
         "needs friction_state: observer (the level scales the bristle observer's friction; with the true z it "
         "never acts)");
  require_adaptation_stable(prefix + ".adaptation_rate", adaptation_rate, period);
  model.validate(prefix + ".model");
}

namespace smc {

double switching_function(Switching sw, double boundary_layer, double s) {
  switch (sw) {
    case Switching::kSign: return (s > 0.0) - (s < 0.0);
    case Switching::kSaturation: return std::clamp(s / boundary_layer, -1.0, 1.0);
    case Switching::kTanh: return std::tanh(s / boundary_layer);
  }
  return 0.0;
}

double reaching_acceleration(const SlidingModeParams& p, double ref_acceleration, double ed, double s) {
  return (p.feedforward_acceleration ? ref_acceleration : 0.0) + p.lambda * ed +
         p.eta * switching_function(p.switching, p.boundary_layer, s) + p.k * s;
}

double control_input(const SlidingModeParams& p, double a_cmd, const ModelForces& f, double disturbance_force) {
  const plant::PlantParams& m = p.model;
  const double fc = p.compensate_friction ? f.friction : 0.0;
  const double gc = p.compensate_grinding ? f.grinding : 0.0;
  const double cc = p.compensate_ripple ? f.cogging : 0.0;
  const double rc = p.compensate_ripple ? f.reluctance : 0.0;
  return (m.mass * a_cmd + fc + gc + cc + disturbance_force + f.e0) / (m.thrust_gain() * (1.0 - rc - f.e1));
}

double limit_output(const SlidingModeParams& p, double u) { return saturate(u, p.u_min, p.u_max); }

double model_acceleration(const plant::PlantParams& m, const ModelForces& f, double u) {
  const double thrust = m.thrust_gain() * u;
  return (thrust * (1.0 - f.reluctance - f.e1) - f.cogging - f.friction - f.grinding - f.e0) / m.mass;
}

}  // namespace smc

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
      delay_line_(p_.compensate_delay ? p_.computation_delay : 0.0, 1e-9 * p_.period),
      adaptation_(p_.adaptation_rate, p_.period, p_.model.friction.coulomb_force) {}

bool SlidingModeController::needs_truth() const {
  const bool friction = p_.compensate_friction && p_.friction_state == StateSource::kTrue &&
                        p_.model.friction.model == plant::FrictionModel::kLuGre;
  const bool grinding = p_.compensate_grinding && p_.grinding_state == StateSource::kTrue && p_.model.grinding.enabled;
  return friction || grinding;
}

struct SlidingModeController::LawInput {
  double x;
  double v;
  trajectory::Sample ref;
  smc::ModelForces forces;
};

SlidingModeController::Estimate SlidingModeController::estimate_state(const plant::Measurement& meas) {
  Estimate est{meas.x, meas.v, p_.motion_state == MotionSource::kObserver, false};
  if (est.use_observer) motion_observer_.correct(meas.x, meas.v);
  // Until the observer has seen a finite sample it has no estimate: use the measurement as is.
  if (est.use_observer && motion_observer_.initialised()) {
    est.x = motion_observer_.position();
    est.v = motion_observer_.velocity();
    est.observed = true;
  }
  return est;
}

double SlidingModeController::true_friction(double v, double z) {
  const plant::FrictionParams& f = p_.model.friction;
  // The bristle rate from the true z itself, not from the model's g(v) (sliding_mode.hpp).
  const double zdot = last_true_z_ ? (z - *last_true_z_) / p_.period : plant::lugre_zdot(f, v, z);
  if (std::isfinite(z)) last_true_z_ = z;  // a NaN sample is not kept for the next rate
  return f.bristle_stiffness * z + plant::micro_damping(f, v) * zdot + f.viscous * v;
}

smc::ModelForces SlidingModeController::model_forces(double x, double v, const Truth* truth) {
  const plant::PlantParams& m = p_.model;
  smc::ModelForces f;
  if (m.friction.model != plant::FrictionModel::kNone) {
    if (p_.friction_state == StateSource::kTrue && m.friction.model == plant::FrictionModel::kLuGre) {
      const double z = truth != nullptr ? truth->z : 0.0;
      f.friction = true_friction(v, z);
      f.z = z;
    } else {
      f.friction = friction_observer_.estimate(v);
      f.z = friction_observer_.z();
    }
  }
  if (m.grinding.enabled) {
    f.grinding = p_.grinding_state == StateSource::kTrue
                     ? plant::grinding_force(m.grinding, x, truth != nullptr ? truth->fg : 0.0)
                     : grinding_observer_.estimate(x);
  }
  if (m.ripple.enabled) {
    f.cogging = plant::cogging_force(m.ripple, x);
    f.reluctance = plant::reluctance_factor(m.ripple, x);
  }
  // The model's additive effects (a fitted model, docs/fit.md), evaluated at (x^, v^).
  if (has_extra_) {
    f.e0 = plant::extra_force(m, x, v, 0.0);
    f.e1 = plant::extra_force(m, x, v, 1.0) - f.e0;
  }
  return f;
}

SlidingModeController::LawInput SlidingModeController::predict_to_action(const Estimate& est,
                                                                         const trajectory::Sample& ref, double t,
                                                                         const smc::ModelForces& now) const {
  const plant::PlantParams& m = p_.model;
  const double a_d = motion_observer_.disturbance();
  // With the bristle observer, its z^ is carried along the prediction too, so F^f follows the
  // predicted velocity (the friction changes fastest at breakaway, within one delay).
  const bool carry_friction =
      p_.friction_state == StateSource::kObserver && m.friction.model == plant::FrictionModel::kLuGre;
  FrictionObserver ahead = friction_observer_;
  smc::ModelForces held = now;  // the forces at t_k, F^f carried along when carry_friction
  LawInput in{est.x, est.v, preview(ref, p_.computation_delay), now};
  for (const DelayLine::Piece& piece : delay_line_.pieces(t, t + p_.computation_delay)) {
    const double tau = piece.t1 - piece.t0;
    if (carry_friction) held.friction = ahead.estimate(in.v);
    const double a = smc::model_acceleration(m, held, piece.u) + a_d;
    if (carry_friction) ahead.advance(in.v, 0.0, tau);
    in.x += in.v * tau + 0.5 * a * tau * tau;
    in.v += a * tau;
  }
  if (carry_friction) in.forces.friction = ahead.estimate(in.v);  // F^f when the command acts
  if (m.ripple.enabled) {                                         // the ripple where the command will act
    in.forces.cogging = plant::cogging_force(m.ripple, in.x);
    in.forces.reluctance = plant::reluctance_factor(m.ripple, in.x);
  }
  return in;
}

void SlidingModeController::advance_observers(const Estimate& est, const trajectory::Sample& ref, double t,
                                              bool delayed, double u, const smc::ModelForces& now) {
  // Everything held at its t_k value over [t_k, t_k + T].
  friction_observer_.advance(est.v, ref.velocity - est.v);
  grinding_observer_.advance(est.x, est.v);
  if (!delayed) {
    if (est.observed) motion_observer_.predict(smc::model_acceleration(p_.model, now, u));
    return;
  }
  delay_line_.push(t, u);
  if (est.observed) {
    // The command acting within the period is piecewise constant (switch at t_j + d).
    double dv = 0.0, dx = 0.0;
    const double t_end = t + p_.period;
    for (const DelayLine::Piece& piece : delay_line_.pieces(t, t_end)) {
      const double tau = piece.t1 - piece.t0;
      const double a = smc::model_acceleration(p_.model, now, piece.u);
      dv += a * tau;
      dx += a * tau * (0.5 * tau + (t_end - piece.t1));
    }
    motion_observer_.predict_increments(dv, dx);
  }
  delay_line_.forget_before(t + p_.period);
}

Command SlidingModeController::update(const trajectory::Sample& ref, const plant::Measurement& meas,
                                      const Truth* truth) {
  if (truth == nullptr && needs_truth())
    throw std::logic_error(
        "sliding_mode: friction_state/grinding_state = true needs the plant's true z and Fg, "
        "which this plant does not provide; use the observers");
  const Estimate est = estimate_state(meas);
  const bool adapt = adaptation_.enabled() && est.observed;
  // The adapted model (sliding_mode.hpp): the bristle observer at the adapted friction level,
  // the inertial force the model's mass misses added as e0.
  if (adapt) friction_observer_.set_level(adaptation_.friction_level());
  smc::ModelForces now = model_forces(est.x, est.v, truth);
  const double inertial = p_.model.mass * ref.acceleration;
  if (adapt) now.e0 += adaptation_.inertial_force(inertial);
  const bool delayed = p_.compensate_delay && p_.computation_delay > 0.0 && std::isfinite(meas.t);
  // The state and reference the law acts on: now, or predicted to when the command acts.
  const LawInput in =
      delayed && est.observed ? predict_to_action(est, ref, meas.t, now) : LawInput{est.x, est.v, ref, now};

  Command cmd;
  if (now.z) cmd.z_estimate = *now.z;
  const double ed = in.ref.velocity - in.v;
  cmd.sliding = smc::sliding_variable(in.ref.position - in.x, ed, p_.lambda);
  const double a_cmd = smc::reaching_acceleration(p_, in.ref.acceleration, ed, cmd.sliding);
  // Lumped disturbance of the x,v observer (0 unless motion_state = observer with d).
  const double disturbance = est.use_observer ? -p_.model.mass * motion_observer_.disturbance() : 0.0;
  cmd.u_unsaturated = smc::control_input(p_, a_cmd, in.forces, disturbance);
  cmd.u = smc::limit_output(p_, cmd.u_unsaturated);
  advance_observers(est, ref, meas.t, delayed, cmd.u, now);
  // Learn in sliding only: within a presliding transition the residual is the bristle dynamics'
  // mismatch, which the level does not describe (feedforward_adaptation.hpp).
  if (adapt && friction_observer_.transient(est.v) < kAdaptationTransient)
    adaptation_.update(-p_.model.mass * motion_observer_.disturbance(), now.friction, inertial);
  return cmd;
}

}  // namespace feeddrive::controller

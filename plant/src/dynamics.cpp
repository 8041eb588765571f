#include "feeddrive/plant/dynamics.hpp"

#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/forces.hpp"

namespace feeddrive::plant {
namespace {

// The equations on params p already folded by effective_params(); `extra` = has_extra_force().
// Without an additive effect F_extra and its gradient stay exactly 0, and subtracting them
// leaves every value bit for bit as without the effects vocabulary.

double thrust_of(const PlantParams& p, const State& s, double u) {
  return p.electrical.enabled ? p.force_constant * s.i : p.thrust_gain() * u;
}

Forces forces_of(const PlantParams& p, bool extra, const State& s, double u) {
  Forces f;
  f.thrust = thrust_of(p, s, u);
  f.friction = friction_force(p.friction, s.v, s.z);
  f.ripple = ripple_force(p.ripple, s.x, f.thrust);
  f.grinding = grinding_force(p.grinding, s.x, s.fg);
  if (extra) f.extra = extra_force(p, s.x, s.v, f.thrust);
  return f;
}

StateVector derivative_of(const PlantParams& p, bool extra, const State& s, double u) {
  const Forces f = forces_of(p, extra, s, u);
  StateVector d{};
  d[kX] = s.v;
  d[kV] = (f.thrust - f.friction - f.ripple - f.grinding - f.extra) / p.mass;
  d[kZ] = p.friction.model == FrictionModel::kLuGre ? lugre_zdot(p.friction, s.v, s.z) : 0.0;
  d[kFg] = grinding_rate(p.grinding, s.x, s.v, s.fg);
  d[kI] = p.electrical.enabled ? (p.amplifier_gain * u - p.electrical.resistance * s.i - p.electrical.back_emf * s.v) /
                                     p.electrical.inductance
                               : 0.0;
  return d;
}

Jacobian jacobian_of(const PlantParams& p, bool extra, const State& s, double u) {
  Jacobian J{};
  const double m = p.mass;
  const double F_thrust = thrust_of(p, s, u);
  const FrictionJacobian fj = friction_jacobian(p.friction, s.v, s.z);

  // x' = v
  J[kX][kV] = 1.0;

  // v' = (F_thrust - Ff(v,z) - Fr(x, F_thrust) - Fg(x, fg) - Fe(x, v, F_thrust)) / m
  double dFr_dx = 0.0, dFr_dthrust = 0.0;
  if (p.ripple.enabled) {
    dFr_dx = cogging_force_dx(p.ripple, s.x) + F_thrust * reluctance_factor_dx(p.ripple, s.x);
    dFr_dthrust = reluctance_factor(p.ripple, s.x);
  }
  ExtraForceGradient dFe;
  if (extra) dFe = extra_force_gradient(p, s.x, s.v, F_thrust);
  const double ds_dx = p.grinding.enabled ? contact_fraction_dx(p.grinding, s.x) : 0.0;
  J[kV][kX] = -(dFr_dx + dFe.dx + ds_dx * s.fg) / m;
  J[kV][kV] = -(fj.dF_dv + dFe.dv) / m;
  J[kV][kZ] = -fj.dF_dz / m;
  J[kV][kFg] = p.grinding.enabled ? -contact_fraction(p.grinding, s.x) / m : 0.0;
  if (p.electrical.enabled) J[kV][kI] = p.force_constant * (1.0 - dFr_dthrust - dFe.dthrust) / m;

  // z' = v - sigma0*|v|*z/g(v)
  if (p.friction.model == FrictionModel::kLuGre) {
    J[kZ][kV] = fj.dzdot_dv;
    J[kZ][kZ] = fj.dzdot_dz;
  }

  // Fg' = s(x)*ke*v - (ke/C)*Fg
  if (p.grinding.enabled) {
    J[kFg][kX] = ds_dx * p.grinding.stiffness * s.v;
    J[kFg][kV] = contact_fraction(p.grinding, s.x) * p.grinding.stiffness;
    J[kFg][kFg] = -1.0 / p.grinding.time_constant();
  }

  // i' = (Ka*u - R*i - Ke*v)/L
  if (p.electrical.enabled) {
    J[kI][kV] = -p.electrical.back_emf / p.electrical.inductance;
    J[kI][kI] = -p.electrical.resistance / p.electrical.inductance;
  }
  return J;
}

std::array<bool, kStateSize> active_of(const PlantParams& p) {
  return {true, true, p.friction.model == FrictionModel::kLuGre, p.grinding.enabled, p.electrical.enabled};
}

// Calls f(effective params, has_extra_force) on p, copying p only when an effect folds into it.
template <typename F>
auto on_effective(const PlantParams& p, F f) {
  if (!folds_into_params(p.effects)) return f(p, has_extra_force(p.effects));
  const PlantParams e = effective_params(p);
  return f(e, has_extra_force(e.effects));
}

}  // namespace

EffectiveParams::EffectiveParams(const PlantParams& p)
    : params_(effective_params(p)), has_extra_force_(plant::has_extra_force(p.effects)) {}

double thrust(const PlantParams& p, const State& s, double u) {
  return on_effective(p, [&](const PlantParams& e, bool) { return thrust_of(e, s, u); });
}
double thrust(const EffectiveParams& p, const State& s, double u) { return thrust_of(p.params(), s, u); }

Forces forces(const PlantParams& p, const State& s, double u) {
  return on_effective(p, [&](const PlantParams& e, bool extra) { return forces_of(e, extra, s, u); });
}
Forces forces(const EffectiveParams& p, const State& s, double u) {
  return forces_of(p.params(), p.has_extra_force(), s, u);
}

StateVector derivative(const PlantParams& p, const State& s, double u) {
  return on_effective(p, [&](const PlantParams& e, bool extra) { return derivative_of(e, extra, s, u); });
}
StateVector derivative(const EffectiveParams& p, const State& s, double u) {
  return derivative_of(p.params(), p.has_extra_force(), s, u);
}

Jacobian jacobian(const PlantParams& p, const State& s, double u) {
  return on_effective(p, [&](const PlantParams& e, bool extra) { return jacobian_of(e, extra, s, u); });
}
Jacobian jacobian(const EffectiveParams& p, const State& s, double u) {
  return jacobian_of(p.params(), p.has_extra_force(), s, u);
}

std::array<bool, kStateSize> active_states(const PlantParams& p) {
  return on_effective(p, [](const PlantParams& e, bool) { return active_of(e); });
}
std::array<bool, kStateSize> active_states(const EffectiveParams& p) { return active_of(p.params()); }

}  // namespace feeddrive::plant

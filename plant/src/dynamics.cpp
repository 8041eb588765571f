#include "feeddrive/plant/dynamics.hpp"

#include "feeddrive/plant/forces.hpp"

namespace feeddrive::plant {

double thrust(const PlantParams& p, const State& s, double u) {
  return p.electrical.enabled ? p.force_constant * s.i : p.thrust_gain() * u;
}

Forces forces(const PlantParams& p, const State& s, double u) {
  Forces f;
  f.thrust = thrust(p, s, u);
  f.friction = friction_force(p.friction, s.v, s.z);
  f.ripple = ripple_force(p.ripple, s.x, f.thrust);
  f.grinding = grinding_force(p.grinding, s.x, s.fg);
  return f;
}

StateVector derivative(const PlantParams& p, const State& s, double u) {
  const Forces f = forces(p, s, u);
  StateVector d{};
  d[kX] = s.v;
  d[kV] = (f.thrust - f.friction - f.ripple - f.grinding) / p.mass;
  d[kZ] = p.friction.model == FrictionModel::kLuGre ? lugre_zdot(p.friction, s.v, s.z) : 0.0;
  d[kFg] = grinding_rate(p.grinding, s.x, s.v, s.fg);
  d[kI] = p.electrical.enabled
              ? (p.amplifier_gain * u - p.electrical.resistance * s.i - p.electrical.back_emf * s.v) /
                    p.electrical.inductance
              : 0.0;
  return d;
}

Jacobian jacobian(const PlantParams& p, const State& s, double u) {
  Jacobian J{};
  const double m = p.mass;
  const double F_thrust = thrust(p, s, u);
  const FrictionJacobian fj = friction_jacobian(p.friction, s.v, s.z);

  // x' = v
  J[kX][kV] = 1.0;

  // v' = (F_thrust - Ff(v,z) - Fr(x, F_thrust) - Fg(x, fg)) / m
  double dFr_dx = 0.0, dFr_dthrust = 0.0;
  if (p.ripple.enabled) {
    dFr_dx = cogging_force_dx(p.ripple, s.x) + F_thrust * reluctance_factor_dx(p.ripple, s.x);
    dFr_dthrust = reluctance_factor(p.ripple, s.x);
  }
  J[kV][kX] = -dFr_dx / m;
  J[kV][kV] = -fj.dF_dv / m;
  J[kV][kZ] = -fj.dF_dz / m;
  J[kV][kFg] = (p.grinding.enabled && in_contact(p.grinding, s.x)) ? -1.0 / m : 0.0;
  if (p.electrical.enabled) J[kV][kI] = p.force_constant * (1.0 - dFr_dthrust) / m;

  // z' = v - sigma0*|v|*z/g(v)
  if (p.friction.model == FrictionModel::kLuGre) {
    J[kZ][kV] = fj.dzdot_dv;
    J[kZ][kZ] = fj.dzdot_dz;
  }

  // Fg' = ke*v - (ke/C)*Fg   (in contact);  -(ke/C)*Fg out of contact
  if (p.grinding.enabled) {
    J[kFg][kV] = in_contact(p.grinding, s.x) ? p.grinding.stiffness : 0.0;
    J[kFg][kFg] = -1.0 / p.grinding.time_constant();
  }

  // i' = (Ka*u - R*i - Ke*v)/L
  if (p.electrical.enabled) {
    J[kI][kV] = -p.electrical.back_emf / p.electrical.inductance;
    J[kI][kI] = -p.electrical.resistance / p.electrical.inductance;
  }
  return J;
}

std::array<bool, kStateSize> active_states(const PlantParams& p) {
  return {true, true, p.friction.model == FrictionModel::kLuGre, p.grinding.enabled,
          p.electrical.enabled};
}

}  // namespace feeddrive::plant

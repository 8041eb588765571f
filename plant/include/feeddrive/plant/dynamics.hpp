#pragma once
// The feed-drive equations of motion as a pure function of (state, input, params).
//
//   x' = v
//   v' = (F_thrust - F_friction(v, z) - F_ripple(x, F_thrust) - F_grinding(x, Fg)) / m
//   z' = v - sigma0*|v|*z/g(v)                       (LuGre; 0 for the other friction models)
//   Fg' = ke*v - (ke/C)*Fg                           (Hahn-Lindsay, only while grinding is enabled)
//   i' = (Ka*u - R*i - Ke*v)/L                       (only with the electrical option)
//
//   F_thrust = Ka*Kf*u  (no electrical dynamics, Xie & Liang eq. 4 / Fig. 16)
//            = Kf*i     (with the electrical option)
//
// The state vector always has kStateSize entries; entries of disabled sub-models stay constant.

#include <array>

#include "feeddrive/plant/params.hpp"

namespace feeddrive::plant {

enum StateIndex : int { kX = 0, kV = 1, kZ = 2, kFg = 3, kI = 4, kStateSize = 5 };
using StateVector = std::array<double, kStateSize>;

/// The named view of a state vector.
struct State {
  double x{0.0};   ///< position [m]
  double v{0.0};   ///< velocity [m/s]
  double z{0.0};   ///< LuGre bristle deflection [m]
  double fg{0.0};  ///< grinding normal force state [N]
  double i{0.0};   ///< armature current [A]

  StateVector to_vector() const { return {x, v, z, fg, i}; }
  static State from_vector(const StateVector& s) { return {s[kX], s[kV], s[kZ], s[kFg], s[kI]}; }
};

/// Force breakdown at a state under a held input u.
struct Forces {
  double thrust{0.0};    ///< F_thrust [N]
  double friction{0.0};  ///< F_friction [N]
  double ripple{0.0};    ///< F_ripple [N]
  double grinding{0.0};  ///< F_grinding [N] (0 out of contact)
};

/// Thrust produced by input u [V] at state s: Ka*Kf*u, or Kf*i with the electrical option.
double thrust(const PlantParams& p, const State& s, double u);

/// All forces at state s under input u.
Forces forces(const PlantParams& p, const State& s, double u);

/// Right-hand side f(s, u) of the equations above.
StateVector derivative(const PlantParams& p, const State& s, double u);

/// Analytic Jacobian df/ds (row = equation, column = state), row-major.
using Jacobian = std::array<std::array<double, kStateSize>, kStateSize>;
Jacobian jacobian(const PlantParams& p, const State& s, double u);

/// Which entries of the state vector evolve for these params (others stay constant).
std::array<bool, kStateSize> active_states(const PlantParams& p);

}  // namespace feeddrive::plant

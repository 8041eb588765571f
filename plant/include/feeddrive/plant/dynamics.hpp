#pragma once
// The feed-drive equations of motion as a pure function of (state, input, params).
//
//   x' = v
//   v' = (F_thrust - F_friction(v, z) - F_ripple(x, F_thrust) - F_grinding(x, Fg)
//         - F_extra(x, v, F_thrust)) / m
//   z' = v - sigma0*|v|*z/g(v)                       (LuGre; 0 for the other friction models)
//   Fg' = ke*v - (ke/C)*Fg                           (Hahn-Lindsay, only while grinding is enabled)
//   i' = (Ka*u - R*i - Ke*v)/L                       (only with the electrical option)
//
//   F_thrust = Ka*Kf*u  (no electrical dynamics, Xie & Liang eq. 4 / Fig. 16)
//            = Kf*i     (with the electrical option)
//
// with the model-discrepancy effects (effects.hpp) included: every function here works on
// effective_params(p) (presliding, grinding_force and mass_error folded into the friction,
// grinding and mass), and F_extra = extra_force(p, x, v, F_thrust) is the sum of the additive
// effects (0 when none is on). input_delay is not part of f: Plant::advance() feeds it the
// delayed input.
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
  double extra{0.0};     ///< F_extra [N] (effects.hpp)
};

/// The params the equations run on: effective_params(p) (effects.hpp), computed once, and whether
/// any additive effect is on. Build one per plant (Plant and CvodeIntegrator do) and pass it to
/// the overloads below, which then copy nothing per call. The PlantParams overloads fold the
/// effects on every call (a copy of the params when presliding, grinding_force or mass_error is
/// on) and give the same results.
class EffectiveParams {
 public:
  explicit EffectiveParams(const PlantParams& p);
  /// effective_params(p) of the constructor's p.
  const PlantParams& params() const { return params_; }
  /// True if extra_force() can be non-zero (an additive effect is on).
  bool has_extra_force() const { return has_extra_force_; }

 private:
  PlantParams params_;
  bool has_extra_force_;
};

/// Thrust produced by input u [V] at state s: Ka*Kf*u, or Kf*i with the electrical option.
double thrust(const PlantParams& p, const State& s, double u);
double thrust(const EffectiveParams& p, const State& s, double u);

/// All forces at state s under input u.
Forces forces(const PlantParams& p, const State& s, double u);
Forces forces(const EffectiveParams& p, const State& s, double u);

/// Right-hand side f(s, u) of the equations above.
StateVector derivative(const PlantParams& p, const State& s, double u);
StateVector derivative(const EffectiveParams& p, const State& s, double u);

/// Analytic Jacobian df/ds (row = equation, column = state), row-major. The effects enter row v
/// through -(dF_extra/dx, dF_extra/dv)/m, and with the electrical option through
/// dF_thrust/di = Kf in the thrust-proportional terms: dv'/di = Kf*(1 - r(x) - dF_extra/dF_thrust)/m.
using Jacobian = std::array<std::array<double, kStateSize>, kStateSize>;
Jacobian jacobian(const PlantParams& p, const State& s, double u);
Jacobian jacobian(const EffectiveParams& p, const State& s, double u);

/// Which entries of the state vector evolve for these params (others stay constant); presliding
/// makes z evolve, grinding_force Fg.
std::array<bool, kStateSize> active_states(const PlantParams& p);
std::array<bool, kStateSize> active_states(const EffectiveParams& p);

}  // namespace feeddrive::plant

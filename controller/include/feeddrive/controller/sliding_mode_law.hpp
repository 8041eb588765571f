#pragma once
// The parts of the sliding-mode law of Xie & Liang (Sec. 5.2, eqs. 16-19), as pure functions of
// (estimates, reference, params); SlidingModeController::update (sliding_mode.hpp) wires them with
// its observers, in this order:
//   1. the state estimate (x, v): measured, or the x,v observer's      (sliding_mode.cpp)
//   2. the model forces F^f, F^g, F^r at the estimate: model_forces    (sliding_mode.cpp)
//   3. the sliding variable S = de/dt + lambda*e:  sliding_variable    (eq. 16)
//   4. the switching term sw(S) and the reaching law's acceleration:
//      switching_function, reaching_acceleration                       (eqs. 18, 19)
//   5. the control input solved from eq. 19: control_input
//   6. the output limits: limit_output
// Each is unit-tested in tests/controller/sliding_mode_law_test.cpp.

#include <optional>

#include "feeddrive/controller/sliding_mode.hpp"
#include "feeddrive/plant/params.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::controller::smc {

/// The model's forces at the estimate (each opposing the thrust, eq. 19) and its additive effects,
/// affine in the thrust F: F_extra = e0 + e1*F (e1: the reluctance_ripple effect, docs/fit.md).
struct ModelForces {
  double friction{0.0};     ///< F^f [N]
  double grinding{0.0};     ///< F^g [N]
  double cogging{0.0};      ///< Fcog(x) [N]
  double reluctance{0.0};   ///< r(x) [-], the thrust-proportional ripple
  double e0{0.0};           ///< [N]
  double e1{0.0};           ///< [-]
  std::optional<double> z;  ///< the bristle state used for F^f (none without friction)
};

/// The sliding variable, eq. 16: S = de/dt + lambda*e with e = xd - x [m/s].
inline double sliding_variable(double e, double ed, double lambda) { return ed + lambda * e; }

/// The switching function sw(S) of the reaching law (eq. 18): sgn(S) (the paper), sat(S/phi) or
/// tanh(S/phi) with phi the boundary layer [m/s].
double switching_function(Switching sw, double boundary_layer, double s);

/// The acceleration the law asks of the model (the bracket of eq. 19):
///   a = xd'' + lambda*(xd' - x') + eta*sw(S) + k*S     (xd'' only with feedforward_acceleration)
double reaching_acceleration(const SlidingModeParams& p, double ref_acceleration, double ed, double s);

/// Eq. 19 solved for u with the reluctance ripple and the affine effects on the thrust:
///   Ka*Kf*u*(1 - r - e1) = m*a + F^f + F^g + Fcog + F_d + e0
/// where each model force enters only when its compensate_* flag is set, and F_d = -m*d^ is the
/// x,v observer's lumped disturbance force (0 without it). Returns u before the limits [V].
double control_input(const SlidingModeParams& p, double a_cmd, const ModelForces& f, double disturbance_force);

/// The output limits: u clamped to [u_min, u_max], NaN to 0 V (saturate(), controller.hpp).
double limit_output(const SlidingModeParams& p, double u);

/// The model's acceleration under command u with the forces f held (eq. 1 of the paper with the
/// model's parameters, the observer's d^ excluded):
///   a = (Ka*Kf*u*(1 - r - e1) - Fcog - F^f - F^g - e0) / m
double model_acceleration(const plant::PlantParams& m, const ModelForces& f, double u);

}  // namespace feeddrive::controller::smc

#pragma once
// The model-discrepancy effects (params.hpp: EffectsParams; docs/fit.md) as pure functions.
//
// The plant equation with effects is
//   m_eff*x'' = F_thrust_eff - F_friction_eff - F_ripple - F_grinding_eff - F_extra
// where
//   * effective_params() folds the effects that *modify* a sub-model into the base sections:
//       presliding     -> friction.model = lugre, friction.bristle_stiffness = bristle_stiffness,
//                         friction.bristle_damping = bristle_damping (Fs, Fc, vs, delta, sigma2 kept);
//       grinding_force -> grinding.enabled, C = damping (dullness = C/(pi*dw*bs)),
//                         grinding.stiffness = stiffness, grinding.contact_position = contact_position;
//       mass_error     -> mass = mass;
//     (input_delay is applied by Plant::advance: the thrust uses u(t - delay));
//   * extra_force() is the sum of the additive effects:
//       constant_force     F = force
//       coulomb_friction   F = coulomb_force*sgn_eps(v)
//       viscous_friction   F = viscous*v
//       stribeck_friction  F = sgn_eps(v)*(coulomb_force + (static_force - coulomb_force)
//                                          *exp(-|v/stribeck_velocity|^delta))
//       cogging_ripple     F = cogging_amplitude*sin(2 pi x/pitch + cogging_phase)
//                            + cogging_third*sin(6 pi x/pitch + cogging_third_phase)
//       reluctance_ripple  F = F_thrust*reluctance_amplitude*sin(2 pi x/pitch + reluctance_phase)
//       spring_force       F = stiffness*(x - rest_position)
//     with sgn_eps(v) the smoothed sign of forces.hpp (tanh(v/eps) by default), eps =
//     friction.static_smoothing_velocity, and delta = friction.stribeck_exponent. Each effect's
//     parameters have the names of the plant's sections (params.hpp, `quantity`).

#include <map>
#include <string>
#include <vector>

#include "feeddrive/plant/params.hpp"

namespace feeddrive::plant {

/// The params with presliding, grinding_force and mass_error folded into the base sections
/// (see above). The effects themselves are left in place (extra_force() ignores those three).
PlantParams effective_params(const PlantParams& p);

/// Sum of the additive effects at position x [m], velocity v [m/s] and produced thrust [N].
double extra_force(const PlantParams& p, double x, double v, double thrust);

/// Partial derivatives of extra_force() with respect to x and v (for the analytic Jacobian), and
/// with respect to the thrust (reluctance_ripple: reluctance_amplitude*sin(2 pi x/pitch + reluctance_phase);
/// the Jacobian's d/di is Kf times it with the electrical option).
struct ExtraForceGradient {
  double dx{0.0};
  double dv{0.0};
  double dthrust{0.0};
};
ExtraForceGradient extra_force_gradient(const PlantParams& p, double x, double v, double thrust);

/// True if any effect that effective_params() folds in (presliding, grinding_force, mass_error) is on.
bool folds_into_params(const EffectsParams& e);
/// True if any additive effect (a term of extra_force()) is on; extra_force() is 0 otherwise.
bool has_extra_force(const EffectsParams& e);

/// The vocabulary by name: an effect and its parameters, named as in params.hpp (SI units).
/// The one mapping between names and EffectsParams fields, for the scenario reader and the fit.
struct NamedEffect {
  std::string name;
  std::map<std::string, double> parameters;
};

/// The effect names, in vocabulary order.
const std::vector<std::string>& effect_names();
/// The parameter names of effect `name`. Throws std::invalid_argument for an unknown name.
const std::vector<std::string>& effect_parameter_names(const std::string& name);
/// The unit of parameter `param` of effect `name`, as its list gives it ("m", "N", "N*s/m", "-"):
/// the names carry no unit. Throws std::invalid_argument for an unknown effect or parameter.
const std::string& effect_parameter_unit(const std::string& name, const std::string& param);
/// The field of parameter `param` of effect `name` and the effect's enabled flag, in e.
double& effect_parameter(EffectsParams& e, const std::string& name, const std::string& param);
bool& effect_enabled(EffectsParams& e, const std::string& name);
/// Enables effect.name in e with effect.parameters (parameters not given keep their values).
/// Throws std::invalid_argument for an unknown effect or parameter name.
void set_effect(EffectsParams& e, const NamedEffect& effect);
/// The enabled effects of e with all their parameters, in vocabulary order.
std::vector<NamedEffect> enabled_effects(const EffectsParams& e);

}  // namespace feeddrive::plant

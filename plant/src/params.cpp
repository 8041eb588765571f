#include "feeddrive/plant/params.hpp"

#include "feeddrive/common/validate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace feeddrive::plant {
using validate::fail;
using validate::require_finite;
using validate::require_non_negative;
using validate::require_positive;

std::string to_string(FrictionModel m) {
  switch (m) {
    case FrictionModel::kLuGre: return "lugre";
    case FrictionModel::kStatic: return "static";
    case FrictionModel::kNone: return "none";
  }
  return "?";
}

FrictionModel friction_model_from_string(const std::string& s) {
  if (s == "lugre") return FrictionModel::kLuGre;
  if (s == "static") return FrictionModel::kStatic;
  if (s == "none") return FrictionModel::kNone;
  throw std::invalid_argument("expected one of lugre, static, none");
}

namespace {
// b of the smoothed sign (forces.hpp, smoothed_sign): a blend weight in [0, 1].
void require_smoothing_shape(const std::string& key, double b) {
  if (!(b >= 0.0 && b <= 1.0)) fail(key, b, "must be in [0, 1]");
}
}  // namespace

void FrictionParams::validate(const std::string& prefix) const {
  if (model == FrictionModel::kNone) return;
  require_positive(prefix + ".coulomb_force", coulomb_force);
  require_positive(prefix + ".static_force", static_force);
  if (static_force < coulomb_force)
    fail(prefix + ".static_force", static_force, "must be >= coulomb_force");
  require_positive(prefix + ".stribeck_velocity", stribeck_velocity);
  require_positive(prefix + ".stribeck_exponent", stribeck_exponent);
  require_non_negative(prefix + ".viscous", viscous);
  require_non_negative(prefix + ".damping_decay_velocity", damping_decay_velocity);
  if (model == FrictionModel::kLuGre) {
    require_positive(prefix + ".bristle_stiffness", bristle_stiffness);
    require_non_negative(prefix + ".bristle_damping", bristle_damping);
  } else {
    require_positive(prefix + ".static_smoothing_velocity", static_smoothing_velocity);
    require_smoothing_shape(prefix + ".static_smoothing_shape", static_smoothing_shape);
  }
}

void RippleParams::validate(const std::string& prefix) const {
  if (!enabled) return;
  require_positive(prefix + ".pitch", pitch);
  require_finite(prefix + ".cogging_amplitude", cogging_amplitude);
  require_finite(prefix + ".cogging_phase", cogging_phase);
  require_finite(prefix + ".cogging_third", cogging_third);
  require_finite(prefix + ".cogging_third_phase", cogging_third_phase);
  require_finite(prefix + ".reluctance_amplitude", reluctance_amplitude);
  require_finite(prefix + ".reluctance_phase", reluctance_phase);
  require_finite(prefix + ".reluctance_third", reluctance_third);
  require_finite(prefix + ".reluctance_third_phase", reluctance_third_phase);
  // |r(x)| < 1 keeps the thrust's sign: F_des*(1 - r(x)) never reverses.
  if (std::abs(reluctance_amplitude) + std::abs(reluctance_third) >= 1.0)
    fail(prefix + ".reluctance_amplitude", reluctance_amplitude,
         "|reluctance_amplitude| + |reluctance_third| must be < 1");
}

double GrindingParams::damping() const {
  return dullness * M_PI * workpiece_diameter * wheel_width;
}
double GrindingParams::time_constant() const { return damping() / stiffness; }

void GrindingParams::validate(const std::string& prefix) const {
  if (!enabled) return;
  require_positive(prefix + ".stiffness", stiffness);
  require_positive(prefix + ".dullness", dullness);
  require_positive(prefix + ".workpiece_diameter", workpiece_diameter);
  require_positive(prefix + ".wheel_width", wheel_width);
  if (!(contact_width >= 0.0) || !std::isfinite(contact_width)) fail(prefix + ".contact_width", contact_width, "must be >= 0");
  if (std::isnan(contact_position) || contact_position == std::numeric_limits<double>::infinity())
    fail(prefix + ".contact_position", contact_position, "must be a number or -inf");
}

void ElectricalParams::validate(const std::string& prefix) const {
  if (!enabled) return;
  require_positive(prefix + ".resistance", resistance);
  require_positive(prefix + ".inductance", inductance);
  require_non_negative(prefix + ".back_emf", back_emf);
}

bool EffectsParams::any() const {
  return constant_force.enabled || coulomb_friction.enabled || viscous_friction.enabled ||
         stribeck_friction.enabled || presliding.enabled || cogging_ripple.enabled ||
         reluctance_ripple.enabled || grinding_force.enabled || spring_force.enabled ||
         mass_error.enabled || input_delay.enabled;
}

void EffectsParams::validate(const std::string& prefix) const {
  if (constant_force.enabled) require_finite(prefix + ".constant_force.force_N", constant_force.force_N);
  if (coulomb_friction.enabled)
    require_non_negative(prefix + ".coulomb_friction.coulomb_N", coulomb_friction.coulomb_N);
  if (viscous_friction.enabled)
    require_non_negative(prefix + ".viscous_friction.viscous_Ns_per_m", viscous_friction.viscous_Ns_per_m);
  if (stribeck_friction.enabled) {
    const std::string k = prefix + ".stribeck_friction";
    require_non_negative(k + ".coulomb_N", stribeck_friction.coulomb_N);
    require_finite(k + ".static_N", stribeck_friction.static_N);
    if (stribeck_friction.static_N < stribeck_friction.coulomb_N)
      fail(k + ".static_N", stribeck_friction.static_N, "must be >= coulomb_N");
    require_positive(k + ".stribeck_velocity_mps", stribeck_friction.stribeck_velocity_mps);
  }
  if (presliding.enabled) {
    require_positive(prefix + ".presliding.bristle_stiffness_N_per_m", presliding.bristle_stiffness_N_per_m);
    require_non_negative(prefix + ".presliding.bristle_damping_Ns_per_m", presliding.bristle_damping_Ns_per_m);
  }
  if (cogging_ripple.enabled) {
    const std::string k = prefix + ".cogging_ripple";
    require_positive(k + ".pitch_m", cogging_ripple.pitch_m);
    require_finite(k + ".amplitude_N", cogging_ripple.amplitude_N);
    require_finite(k + ".phase_rad", cogging_ripple.phase_rad);
    require_finite(k + ".third_harmonic_N", cogging_ripple.third_harmonic_N);
    require_finite(k + ".third_phase_rad", cogging_ripple.third_phase_rad);
  }
  if (reluctance_ripple.enabled) {
    const std::string k = prefix + ".reluctance_ripple";
    require_positive(k + ".pitch_m", reluctance_ripple.pitch_m);
    require_finite(k + ".relative_amplitude", reluctance_ripple.relative_amplitude);
    require_finite(k + ".phase_rad", reluctance_ripple.phase_rad);
    // As for ripple.reluctance_amplitude: |amplitude| < 1 keeps the thrust's sign.
    if (std::abs(reluctance_ripple.relative_amplitude) >= 1.0)
      fail(k + ".relative_amplitude", reluctance_ripple.relative_amplitude, "|relative_amplitude| must be < 1");
  }
  if (grinding_force.enabled) {
    const std::string k = prefix + ".grinding_force";
    require_positive(k + ".gain_Ns_per_m", grinding_force.gain_Ns_per_m);
    require_positive(k + ".stiffness_N_per_m", grinding_force.stiffness_N_per_m);
    require_finite(k + ".contact_position_m", grinding_force.contact_position_m);
  }
  if (spring_force.enabled) {
    require_non_negative(prefix + ".spring_force.stiffness_N_per_m", spring_force.stiffness_N_per_m);
    require_finite(prefix + ".spring_force.rest_position_m", spring_force.rest_position_m);
  }
  if (mass_error.enabled) require_positive(prefix + ".mass_error.mass_kg", mass_error.mass_kg);
  if (input_delay.enabled) require_non_negative(prefix + ".input_delay.delay_s", input_delay.delay_s);
}

void SensorParams::validate(const std::string& prefix) const {
  require_non_negative(prefix + ".quantization", quantization);
  require_non_negative(prefix + ".noise_stddev", noise_stddev);
  // Beyond these the measurement overflows (a 1e308 noise gave inf measurements) or rounds to
  // nothing: a step of 1 pm is far below any encoder's, 1 m of noise far above any drive's.
  if (quantization > 0.0 && quantization < 1e-12) fail(prefix + ".quantization", quantization, "must be 0 or >= 1e-12 m");
  if (quantization > 1.0) fail(prefix + ".quantization", quantization, "must be <= 1 m");
  if (noise_stddev > 1.0) fail(prefix + ".noise_stddev", noise_stddev, "must be <= 1 m");
  if (velocity != "auto" && velocity != "true" && velocity != "difference")
    throw std::invalid_argument(prefix + ".velocity = '" + velocity +
                                "': expected one of auto, true, difference");
  // An encoder measures position only: with quantization or noise the velocity a drive sees is
  // formed from the counts, never the true velocity (issue 10: honest velocity estimation).
  if (velocity == "true" && !ideal())
    throw std::invalid_argument(prefix + ".velocity = 'true': an encoder with quantization or noise "
                                "measures position only; use difference (or auto)");
}

void IntegratorParams::validate(const std::string& prefix) const {
  require_positive(prefix + ".rtol", rtol);
  require_positive(prefix + ".atol_position", atol_position);
  require_positive(prefix + ".atol_velocity", atol_velocity);
  require_positive(prefix + ".atol_bristle", atol_bristle);
  require_positive(prefix + ".atol_grinding", atol_grinding);
  require_positive(prefix + ".atol_current", atol_current);
  if (max_steps <= 0) fail(prefix + ".max_steps", static_cast<double>(max_steps), "must be > 0");
}

void PlantParams::validate(const std::string& prefix) const {
  require_positive(prefix + ".mass", mass);
  require_positive(prefix + ".amplifier_gain", amplifier_gain);
  require_positive(prefix + ".force_constant", force_constant);
  require_positive(prefix + ".input_limit", input_limit);
  friction.validate(prefix + ".friction");
  ripple.validate(prefix + ".ripple");
  grinding.validate(prefix + ".grinding");
  electrical.validate(prefix + ".electrical");
  sensor.validate(prefix + ".sensor");
  integrator.validate(prefix + ".integrator");
  effects.validate(prefix + ".effects");
  // The friction and grinding sections' values the effects use, checked even where the section
  // itself is off (its validate() then skips them).
  if (effects.presliding.enabled) {  // the friction becomes LuGre with Fs, Fc, vs, delta, sigma2
    FrictionParams lugre = friction;
    lugre.model = FrictionModel::kLuGre;
    lugre.bristle_stiffness = effects.presliding.bristle_stiffness_N_per_m;
    lugre.bristle_damping = effects.presliding.bristle_damping_Ns_per_m;
    lugre.validate(prefix + ".friction");
  }
  if (effects.coulomb_friction.enabled || effects.stribeck_friction.enabled) {  // sgn_eps(v)
    require_positive(prefix + ".friction.static_smoothing_velocity", friction.static_smoothing_velocity);
    require_smoothing_shape(prefix + ".friction.static_smoothing_shape", friction.static_smoothing_shape);
  }
  if (effects.stribeck_friction.enabled)
    require_positive(prefix + ".friction.stribeck_exponent", friction.stribeck_exponent);
  if (effects.grinding_force.enabled) {  // dullness = C/(pi*dw*bs)
    require_positive(prefix + ".grinding.workpiece_diameter", grinding.workpiece_diameter);
    require_positive(prefix + ".grinding.wheel_width", grinding.wheel_width);
  }
  require_finite(prefix + ".initial.position", initial.position);
  require_finite(prefix + ".initial.velocity", initial.velocity);
  require_finite(prefix + ".initial.bristle", initial.bristle);
  require_finite(prefix + ".initial.grinding", initial.grinding);
  require_finite(prefix + ".initial.current", initial.current);
}

std::string PlantParams::fastest_time_scales(std::size_t n) const {
  using validate::format_number;
  struct Scale {
    double rate;  // [1/s]
    std::string keys;
    const char* what;
  };
  std::vector<Scale> s;
  const std::string m = "plant.mass = " + format_number(mass);
  if (friction.model == FrictionModel::kLuGre) {
    s.push_back({std::sqrt(friction.bristle_stiffness / mass),
                 "plant.friction.bristle_stiffness = " + format_number(friction.bristle_stiffness) + " with " + m,
                 "presliding oscillation"});
    s.push_back({friction.bristle_damping / mass,
                 "plant.friction.bristle_damping = " + format_number(friction.bristle_damping) + " with " + m, "bristle damping"});
  }
  if (friction.model != FrictionModel::kNone && friction.viscous > 0)
    s.push_back({friction.viscous / mass, "plant.friction.viscous = " + format_number(friction.viscous) + " with " + m,
                 "viscous damping"});
  if (grinding.enabled)
    s.push_back({1.0 / grinding.time_constant(),
                 "plant.grinding.stiffness = " + format_number(grinding.stiffness) + ", dullness = " +
                     format_number(grinding.dullness),
                 "grinding force lag"});
  if (electrical.enabled)
    s.push_back({electrical.resistance / electrical.inductance,
                 "plant.electrical.resistance = " + format_number(electrical.resistance) + ", inductance = " +
                     format_number(electrical.inductance),
                 "current loop"});
  if (effects.presliding.enabled)
    s.push_back({std::sqrt(effects.presliding.bristle_stiffness_N_per_m / mass),
                 "plant.effects.presliding.bristle_stiffness_N_per_m = " +
                     format_number(effects.presliding.bristle_stiffness_N_per_m) + " with " + m,
                 "presliding oscillation"});
  if (effects.spring_force.enabled)
    s.push_back({std::sqrt(effects.spring_force.stiffness_N_per_m / mass),
                 "plant.effects.spring_force.stiffness_N_per_m = " + format_number(effects.spring_force.stiffness_N_per_m) +
                     " with " + m,
                 "spring oscillation"});
  if (effects.viscous_friction.enabled)
    s.push_back({effects.viscous_friction.viscous_Ns_per_m / mass,
                 "plant.effects.viscous_friction.viscous_Ns_per_m = " +
                     format_number(effects.viscous_friction.viscous_Ns_per_m) + " with " + m,
                 "viscous damping"});
  std::sort(s.begin(), s.end(), [](const Scale& a, const Scale& b) { return a.rate > b.rate; });
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < n; ++i) {
    char buf[96];
    std::snprintf(buf, sizeof buf, " (%s: %.3g 1/s, time scale %.3g s)", s[i].what, s[i].rate, 1.0 / s[i].rate);
    out += (i ? "; " : "") + s[i].keys + buf;
  }
  if (out.empty()) out = "no fast dynamics in the model (mass " + format_number(mass) + ")";
  return "fastest time scales: " + out + "; plant.integrator.max_steps = " + std::to_string(integrator.max_steps) +
         " per control period, rtol = " + format_number(integrator.rtol);
}

}  // namespace feeddrive::plant

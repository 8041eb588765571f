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

std::string to_string(FrictionModel m) { return fields::enum_name(m); }

// Each validate(): the ranges of the struct's list (Serialize, params.hpp), then the rules that
// tie fields together.

namespace {
// b of the smoothed sign (forces.hpp, smoothed_sign): a blend weight in [0, 1].
void require_smoothing_shape(const std::string& key, double b) {
  if (!(b >= 0.0 && b <= 1.0)) fail(key, b, "must be in [0, 1]");
}
}  // namespace

void FrictionParams::validate(const std::string& prefix) const {
  if (model == FrictionModel::kNone) return;
  // The keys of the other law are not used, so not checked.
  if (model == FrictionModel::kLuGre) {
    fields::check_fields(*this, prefix, {"static_smoothing_velocity", "static_smoothing_shape"});
  } else {
    fields::check_fields(*this, prefix, {"bristle_stiffness", "bristle_damping"});
  }
  if (static_force < coulomb_force) fail(prefix + ".static_force", static_force, "must be >= coulomb_force");
}

// A section that is off is checked as well: a key written in it must be valid even while it does
// not act (docs/scenario.md, "Valid (else exit 2)"); the loader warns that it does not act.
void RippleParams::validate(const std::string& prefix) const {
  fields::check_fields(*this, prefix);
  // |r(x)| < 1 keeps the thrust's sign: F_des*(1 - r(x)) never reverses.
  if (std::abs(reluctance_amplitude) + std::abs(reluctance_third) >= 1.0)
    fail(prefix + ".reluctance_amplitude", reluctance_amplitude,
         "|reluctance_amplitude| + |reluctance_third| must be < 1");
}

double GrindingParams::damping() const { return dullness * M_PI * workpiece_diameter * wheel_width; }
double GrindingParams::time_constant() const { return damping() / stiffness; }

void GrindingParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

void ElectricalParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

bool EffectsParams::any() const {
  return constant_force.enabled || coulomb_friction.enabled || viscous_friction.enabled || stribeck_friction.enabled ||
         presliding.enabled || cogging_ripple.enabled || reluctance_ripple.enabled || grinding_force.enabled ||
         spring_force.enabled || mass_error.enabled || input_delay.enabled;
}

namespace {
// Checks the list of every enabled effect.
class EnabledEffectsCheck {
 public:
  explicit EnabledEffectsCheck(std::string prefix) : prefix_(std::move(prefix)) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    if (f.value->enabled) fields::check_fields(*f.value, prefix_ + "." + f.meta.name);
  }

 private:
  std::string prefix_;
};
}  // namespace

void EffectsParams::validate(const std::string& prefix) const {
  EnabledEffectsCheck check(prefix);
  const_cast<EffectsParams&>(*this).Serialize(&check);
  if (stribeck_friction.enabled && stribeck_friction.static_force < stribeck_friction.coulomb_force)
    fail(prefix + ".stribeck_friction.static_force", stribeck_friction.static_force, "must be >= coulomb_force");
  // As for ripple.reluctance_amplitude: |amplitude| < 1 keeps the thrust's sign.
  if (reluctance_ripple.enabled && std::abs(reluctance_ripple.reluctance_amplitude) >= 1.0)
    fail(prefix + ".reluctance_ripple.reluctance_amplitude", reluctance_ripple.reluctance_amplitude,
         "|reluctance_amplitude| must be < 1");
}

void SensorParams::validate(const std::string& prefix) const {
  // Beyond the list's bounds the measurement overflows (a 1e308 noise gave inf measurements) or
  // rounds to nothing: a step of 1 pm is far below any encoder's, 1 m of noise far above any drive's.
  fields::check_fields(*this, prefix);
  if (quantization > 0.0 && quantization < 1e-12)
    fail(prefix + ".quantization", quantization, "must be 0 or >= 1e-12 m");
  // An encoder measures position only: with quantization or noise the velocity a drive sees is
  // formed from the counts, never the true velocity (issue 10: honest velocity estimation).
  if (velocity == VelocityMeasurement::kTrue && !ideal())
    throw std::invalid_argument(prefix +
                                ".velocity = 'true': an encoder with quantization or noise "
                                "measures position only; use difference (or auto)");
}

void IntegratorParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

void PlantParams::validate(const std::string& prefix) const {
  fields::check_fields(*this, prefix);
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
    lugre.bristle_stiffness = effects.presliding.bristle_stiffness;
    lugre.bristle_damping = effects.presliding.bristle_damping;
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
  fields::check_fields(initial, prefix + ".initial");
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
                 "plant.friction.bristle_damping = " + format_number(friction.bristle_damping) + " with " + m,
                 "bristle damping"});
  }
  if (friction.model != FrictionModel::kNone && friction.viscous > 0)
    s.push_back({friction.viscous / mass, "plant.friction.viscous = " + format_number(friction.viscous) + " with " + m,
                 "viscous damping"});
  if (grinding.enabled)
    s.push_back({1.0 / grinding.time_constant(),
                 "plant.grinding.stiffness = " + format_number(grinding.stiffness) +
                     ", dullness = " + format_number(grinding.dullness),
                 "grinding force lag"});
  if (electrical.enabled)
    s.push_back({electrical.resistance / electrical.inductance,
                 "plant.electrical.resistance = " + format_number(electrical.resistance) +
                     ", inductance = " + format_number(electrical.inductance),
                 "current loop"});
  if (effects.presliding.enabled)
    s.push_back({std::sqrt(effects.presliding.bristle_stiffness / mass),
                 "plant.effects.presliding.bristle_stiffness = " + format_number(effects.presliding.bristle_stiffness) +
                     " with " + m,
                 "presliding oscillation"});
  if (effects.spring_force.enabled)
    s.push_back(
        {std::sqrt(effects.spring_force.stiffness / mass),
         "plant.effects.spring_force.stiffness = " + format_number(effects.spring_force.stiffness) + " with " + m,
         "spring oscillation"});
  if (effects.viscous_friction.enabled)
    s.push_back(
        {effects.viscous_friction.viscous / mass,
         "plant.effects.viscous_friction.viscous = " + format_number(effects.viscous_friction.viscous) + " with " + m,
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

#include "feeddrive/plant/params.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace feeddrive::plant {
namespace {

[[noreturn]] void fail(const std::string& key, double value, const std::string& why) {
  std::ostringstream os;
  os.precision(17);
  os << key << " = " << value << ": " << why;
  throw std::invalid_argument(os.str());
}

void require_finite(const std::string& key, double v) {
  if (!std::isfinite(v)) fail(key, v, "must be a finite number");
}
void require_positive(const std::string& key, double v) {
  require_finite(key, v);
  if (!(v > 0.0)) fail(key, v, "must be > 0");
}
void require_non_negative(const std::string& key, double v) {
  require_finite(key, v);
  if (v < 0.0) fail(key, v, "must be >= 0");
}

}  // namespace

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
  if (std::isnan(contact_position) || contact_position == std::numeric_limits<double>::infinity())
    fail(prefix + ".contact_position", contact_position, "must be a number or -inf");
}

void ElectricalParams::validate(const std::string& prefix) const {
  if (!enabled) return;
  require_positive(prefix + ".resistance", resistance);
  require_positive(prefix + ".inductance", inductance);
  require_non_negative(prefix + ".back_emf", back_emf);
}

void SensorParams::validate(const std::string& prefix) const {
  require_non_negative(prefix + ".quantization", quantization);
  require_non_negative(prefix + ".noise_stddev", noise_stddev);
  if (velocity != "auto" && velocity != "true" && velocity != "difference")
    throw std::invalid_argument(prefix + ".velocity = '" + velocity +
                                "': expected one of auto, true, difference");
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
  require_finite(prefix + ".initial.position", initial.position);
  require_finite(prefix + ".initial.velocity", initial.velocity);
  require_finite(prefix + ".initial.bristle", initial.bristle);
  require_finite(prefix + ".initial.grinding", initial.grinding);
  require_finite(prefix + ".initial.current", initial.current);
}

}  // namespace feeddrive::plant

#include "feeddrive/plant/effects.hpp"

#include <cmath>
#include <functional>
#include <stdexcept>
#include <type_traits>

#include "feeddrive/plant/forces.hpp"

namespace feeddrive::plant {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// The Stribeck curve of the stribeck_friction effect as a FrictionParams, so that it shares
// forces.hpp's g(v) and dg/dv (and their delta = 1, 2 fast paths):
//   g(v) = coulomb_N + (static_N - coulomb_N)*exp(-|v/stribeck_velocity_mps|^delta).
FrictionParams stribeck_curve(const PlantParams& p) {
  const StribeckFrictionEffect& e = p.effects.stribeck_friction;
  FrictionParams f;
  f.static_force = e.static_N;
  f.coulomb_force = e.coulomb_N;
  f.stribeck_velocity = e.stribeck_velocity_mps;
  f.stribeck_exponent = p.friction.stribeck_exponent;
  return f;
}

}  // namespace

bool folds_into_params(const EffectsParams& e) {
  return e.presliding.enabled || e.grinding_force.enabled || e.mass_error.enabled;
}

bool has_extra_force(const EffectsParams& e) {
  return e.constant_force.enabled || e.coulomb_friction.enabled || e.viscous_friction.enabled ||
         e.stribeck_friction.enabled || e.cogging_ripple.enabled || e.reluctance_ripple.enabled ||
         e.spring_force.enabled;
}

PlantParams effective_params(const PlantParams& p) {
  PlantParams e = p;
  const EffectsParams& fx = p.effects;
  if (fx.presliding.enabled) {
    e.friction.model = FrictionModel::kLuGre;
    e.friction.bristle_stiffness = fx.presliding.bristle_stiffness_N_per_m;
    e.friction.bristle_damping = fx.presliding.bristle_damping_Ns_per_m;
  }
  if (fx.grinding_force.enabled) {
    e.grinding.enabled = true;
    // C = c*pi*dw*bs (GrindingParams::damping), solved for the dullness c.
    e.grinding.dullness =
        fx.grinding_force.gain_Ns_per_m / (M_PI * p.grinding.workpiece_diameter * p.grinding.wheel_width);
    e.grinding.stiffness = fx.grinding_force.stiffness_N_per_m;
    e.grinding.contact_position = fx.grinding_force.contact_position_m;
  }
  if (fx.mass_error.enabled) e.mass = fx.mass_error.mass_kg;
  return e;
}

double extra_force(const PlantParams& p, double x, double v, double thrust) {
  const EffectsParams& fx = p.effects;
  double F = 0.0;
  if (fx.constant_force.enabled) F += fx.constant_force.force_N;
  if (fx.coulomb_friction.enabled) F += fx.coulomb_friction.coulomb_N * smoothed_sign(p.friction, v);
  if (fx.viscous_friction.enabled) F += fx.viscous_friction.viscous_Ns_per_m * v;
  if (fx.stribeck_friction.enabled) F += smoothed_sign(p.friction, v) * stribeck(stribeck_curve(p), v);
  if (fx.cogging_ripple.enabled) {
    const CoggingRippleEffect& c = fx.cogging_ripple;
    const double th = kTwoPi * x / c.pitch_m;
    F += c.amplitude_N * std::sin(th + c.phase_rad) + c.third_harmonic_N * std::sin(3.0 * th + c.third_phase_rad);
  }
  if (fx.reluctance_ripple.enabled) {
    const ReluctanceRippleEffect& r = fx.reluctance_ripple;
    F += thrust * r.relative_amplitude * std::sin(kTwoPi * x / r.pitch_m + r.phase_rad);
  }
  if (fx.spring_force.enabled) F += fx.spring_force.stiffness_N_per_m * (x - fx.spring_force.rest_position_m);
  return F;
}

ExtraForceGradient extra_force_gradient(const PlantParams& p, double x, double v, double thrust) {
  const EffectsParams& fx = p.effects;
  ExtraForceGradient g;
  if (fx.coulomb_friction.enabled) g.dv += fx.coulomb_friction.coulomb_N * smoothed_sign_derivative(p.friction, v);
  if (fx.viscous_friction.enabled) g.dv += fx.viscous_friction.viscous_Ns_per_m;
  if (fx.stribeck_friction.enabled) {
    // d/dv [sgn_eps(v)*g(v)] = sgn_eps'(v)*g(v) + sgn_eps(v)*g'(v)
    const FrictionParams curve = stribeck_curve(p);
    g.dv += smoothed_sign_derivative(p.friction, v) * stribeck(curve, v) +
            smoothed_sign(p.friction, v) * stribeck_derivative(curve, v);
  }
  if (fx.cogging_ripple.enabled) {
    const CoggingRippleEffect& c = fx.cogging_ripple;
    const double w = kTwoPi / c.pitch_m;
    const double th = w * x;
    g.dx += w * (c.amplitude_N * std::cos(th + c.phase_rad) +
                 3.0 * c.third_harmonic_N * std::cos(3.0 * th + c.third_phase_rad));
  }
  if (fx.reluctance_ripple.enabled) {
    const ReluctanceRippleEffect& r = fx.reluctance_ripple;
    const double w = kTwoPi / r.pitch_m;
    const double phase = w * x + r.phase_rad;
    g.dx += thrust * r.relative_amplitude * w * std::cos(phase);
    g.dthrust += r.relative_amplitude * std::sin(phase);
  }
  if (fx.spring_force.enabled) g.dx += fx.spring_force.stiffness_N_per_m;
  return g;
}

namespace {

// The vocabulary is EffectsParams::Serialize and each effect's Serialize (params.hpp): the
// effects in order, each with `enabled` and its parameters (the numbers).

// One effect's parameters: their names, or the field named `param`.
class EffectFields {
 public:
  explicit EffectFields(const std::string* param = nullptr) : param_(param) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    if constexpr (std::is_same_v<T, double>) {
      names.push_back(f.meta.name);
      if (param_ && *param_ == f.meta.name) found = f.value;
    }
  }
  std::vector<std::string> names;
  double* found{nullptr};

 private:
  const std::string* param_;
};

// The effects: their names and parameter names, or the effect named `name` in an EffectsParams.
class EffectList {
 public:
  explicit EffectList(const std::string* name = nullptr, const std::string* param = nullptr)
      : name_(name), param_(param) {}
  template <typename T>
  void Visit(const fields::Field<T>& f) {
    EffectFields inner(name_ && *name_ == f.meta.name ? param_ : nullptr);
    f.value->Serialize(&inner);
    names.push_back(f.meta.name);
    parameters[f.meta.name] = inner.names;
    if (name_ && *name_ == f.meta.name) {
      enabled = &f.value->enabled;
      param = inner.found;
    }
  }
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::string>> parameters;
  bool* enabled{nullptr};
  double* param{nullptr};

 private:
  const std::string* name_;
  const std::string* param_;
};

const EffectList& vocabulary() {
  static const EffectList list = [] {
    EffectList l;
    EffectsParams e;
    e.Serialize(&l);
    return l;
  }();
  return list;
}

EffectList find(EffectsParams& e, const std::string& name, const std::string* param) {
  EffectList l(&name, param);
  e.Serialize(&l);
  if (!l.enabled) throw std::invalid_argument("unknown effect '" + name + "'");
  return l;
}

}  // namespace

const std::vector<std::string>& effect_names() { return vocabulary().names; }

const std::vector<std::string>& effect_parameter_names(const std::string& name) {
  const auto& p = vocabulary().parameters;
  const auto it = p.find(name);
  if (it == p.end()) throw std::invalid_argument("unknown effect '" + name + "'");
  return it->second;
}

double& effect_parameter(EffectsParams& e, const std::string& name, const std::string& param) {
  const EffectList l = find(e, name, &param);
  if (!l.param) throw std::invalid_argument("effect " + name + ": unknown parameter '" + param + "'");
  return *l.param;
}

bool& effect_enabled(EffectsParams& e, const std::string& name) { return *find(e, name, nullptr).enabled; }

void set_effect(EffectsParams& e, const NamedEffect& effect) {
  effect_enabled(e, effect.name) = true;
  for (const auto& [k, v] : effect.parameters) effect_parameter(e, effect.name, k) = v;
}

std::vector<NamedEffect> enabled_effects(const EffectsParams& e) {
  EffectsParams copy = e;  // the list hands out mutable references
  std::vector<NamedEffect> out;
  for (const std::string& name : effect_names()) {
    if (!effect_enabled(copy, name)) continue;
    NamedEffect ne{name, {}};
    for (const std::string& param : effect_parameter_names(name))
      ne.parameters[param] = effect_parameter(copy, name, param);
    out.push_back(ne);
  }
  return out;
}

}  // namespace feeddrive::plant

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
//   g(v) = coulomb_force + (static_force - coulomb_force)*exp(-|v/stribeck_velocity|^delta).
FrictionParams stribeck_curve(const PlantParams& p) {
  const StribeckFrictionEffect& e = p.effects.stribeck_friction;
  FrictionParams f;
  f.static_force = e.static_force;
  f.coulomb_force = e.coulomb_force;
  f.stribeck_velocity = e.stribeck_velocity;
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
    e.friction.bristle_stiffness = fx.presliding.bristle_stiffness;
    e.friction.bristle_damping = fx.presliding.bristle_damping;
  }
  if (fx.grinding_force.enabled) {
    e.grinding.enabled = true;
    // C = c*pi*dw*bs (GrindingParams::damping), solved for the dullness c.
    e.grinding.dullness = fx.grinding_force.damping / (M_PI * p.grinding.workpiece_diameter * p.grinding.wheel_width);
    e.grinding.stiffness = fx.grinding_force.stiffness;
    e.grinding.contact_position = fx.grinding_force.contact_position;
  }
  if (fx.mass_error.enabled) e.mass = fx.mass_error.mass;
  return e;
}

double extra_force(const PlantParams& p, double x, double v, double thrust) {
  const EffectsParams& fx = p.effects;
  double F = 0.0;
  if (fx.constant_force.enabled) F += fx.constant_force.force;
  if (fx.coulomb_friction.enabled) F += fx.coulomb_friction.coulomb_force * smoothed_sign(p.friction, v);
  if (fx.viscous_friction.enabled) F += fx.viscous_friction.viscous * v;
  if (fx.stribeck_friction.enabled) F += smoothed_sign(p.friction, v) * stribeck(stribeck_curve(p), v);
  if (fx.cogging_ripple.enabled) {
    const CoggingRippleEffect& c = fx.cogging_ripple;
    const double th = kTwoPi * x / c.pitch;
    F += c.cogging_amplitude * std::sin(th + c.cogging_phase) +
         c.cogging_third * std::sin(3.0 * th + c.cogging_third_phase);
  }
  if (fx.reluctance_ripple.enabled) {
    const ReluctanceRippleEffect& r = fx.reluctance_ripple;
    F += thrust * r.reluctance_amplitude * std::sin(kTwoPi * x / r.pitch + r.reluctance_phase);
  }
  if (fx.spring_force.enabled) F += fx.spring_force.stiffness * (x - fx.spring_force.rest_position);
  return F;
}

ExtraForceGradient extra_force_gradient(const PlantParams& p, double x, double v, double thrust) {
  const EffectsParams& fx = p.effects;
  ExtraForceGradient g;
  if (fx.coulomb_friction.enabled) g.dv += fx.coulomb_friction.coulomb_force * smoothed_sign_derivative(p.friction, v);
  if (fx.viscous_friction.enabled) g.dv += fx.viscous_friction.viscous;
  if (fx.stribeck_friction.enabled) {
    // d/dv [sgn_eps(v)*g(v)] = sgn_eps'(v)*g(v) + sgn_eps(v)*g'(v)
    const FrictionParams curve = stribeck_curve(p);
    g.dv += smoothed_sign_derivative(p.friction, v) * stribeck(curve, v) +
            smoothed_sign(p.friction, v) * stribeck_derivative(curve, v);
  }
  if (fx.cogging_ripple.enabled) {
    const CoggingRippleEffect& c = fx.cogging_ripple;
    const double w = kTwoPi / c.pitch;
    const double th = w * x;
    g.dx += w * (c.cogging_amplitude * std::cos(th + c.cogging_phase) +
                 3.0 * c.cogging_third * std::cos(3.0 * th + c.cogging_third_phase));
  }
  if (fx.reluctance_ripple.enabled) {
    const ReluctanceRippleEffect& r = fx.reluctance_ripple;
    const double w = kTwoPi / r.pitch;
    const double phase = w * x + r.reluctance_phase;
    g.dx += thrust * r.reluctance_amplitude * w * std::cos(phase);
    g.dthrust += r.reluctance_amplitude * std::sin(phase);
  }
  if (fx.spring_force.enabled) g.dx += fx.spring_force.stiffness;
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
      units[f.meta.name] = f.meta.unit;
      if (param_ && *param_ == f.meta.name) found = f.value;
    }
  }
  std::vector<std::string> names;
  std::map<std::string, std::string> units;
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
    units[f.meta.name] = inner.units;
    if (name_ && *name_ == f.meta.name) {
      enabled = &f.value->enabled;
      param = inner.found;
    }
  }
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::string>> parameters;
  std::map<std::string, std::map<std::string, std::string>> units;
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

const std::string& effect_parameter_unit(const std::string& name, const std::string& param) {
  effect_parameter_names(name);  // an unknown effect throws
  const auto& u = vocabulary().units.at(name);
  const auto it = u.find(param);
  if (it == u.end()) throw std::invalid_argument("effect " + name + ": unknown parameter '" + param + "'");
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

#include "feeddrive/fit/plausibility.hpp"
#include "text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace feeddrive::fit {
using text::fmt;
using text::par;
namespace {

constexpr double kAsymmetry = kAsymmetryTolerance;

std::string ripple_pitch(const Envelope& env, double p) {
  if (p > env.max_pitch())
    return fmt("pitch %.3g mm: fewer than two periods within the %.3g mm travelled", p * 1e3, env.travel * 1e3);
  if (p < env.min_pitch())
    return fmt("pitch %.3g mm: shorter than the %.3g mm the data resolves at %.3g mm/s", p * 1e3, env.min_pitch() * 1e3,
               env.v_max * 1e3);
  return "";
}

// Why a force `what` of size |f| is within the direction asymmetry real friction has,
// kAsymmetryTolerance of a friction level (> 0), ending with `so`; "" if it is not: a constant
// force, a change of the Coulomb level or a spring's change over the travel that small is within
// the friction's form.
std::string within_asymmetry(const std::string& what, double f, double level, const char* so) {
  if (!(level > 0 && std::abs(f) < kAsymmetry * level)) return "";
  return what + fmt(" %.3g N is within %.0f %% of the %.4g N friction level: ", std::abs(f), 100 * kAsymmetry, level) +
         so;
}

}  // namespace

double friction_level(const plant::PlantParams& m) {
  double c = 0.0;
  if (m.friction.model != plant::FrictionModel::kNone) c += std::max(m.friction.static_force, m.friction.coulomb_force);
  if (m.effects.coulomb_friction.enabled) c += m.effects.coulomb_friction.coulomb_force;
  if (m.effects.stribeck_friction.enabled) c += m.effects.stribeck_friction.static_force;
  return c;
}

double Envelope::min_pitch() const { return std::max({1e-3, 8.0 * v_max * period, 4.0 * v_max * filter_half_width}); }

Envelope envelope(const Record& rec, const plant::PlantParams& model) {
  Envelope e;
  const MeasuredData& d = *rec.data;
  e.x_min = rec.x_min;
  e.x_max = rec.x_max;
  e.travel = rec.x_max - rec.x_min;
  e.v_max = rec.v_max_abs;
  e.period = rec.period;
  e.filter_half_width = rec.bank.half_width;
  e.nominal_mass = plant::effective_params(model).mass;
  e.duration = d.t.back() - d.t.front();
  e.resolution =
      std::max(model.sensor.ideal() ? smallest_position_step(d) : model.sensor.quantization, model.sensor.noise_stddev);
  const double gain = thrust_per_input(rec, model);
  for (double u : d.input) e.peak_thrust = std::max(e.peak_thrust, std::abs(gain * u));
  e.stick_velocity = stick_velocity(model);
  long run = 0, in_stick = 0;
  for (std::size_t k = 0; k <= d.size(); ++k) {
    if (k < d.size() && std::abs(rec.motion.v[k]) < e.stick_velocity) {
      ++run;
      continue;
    }
    if (run >= 5) {
      ++e.stick_phases;
      in_stick += run;
    }
    run = 0;
  }
  e.stick_fraction = static_cast<double>(in_stick) / static_cast<double>(d.size());
  int sign = 0;
  for (double v : rec.motion.v) {
    if (std::abs(v) < e.stick_velocity) continue;
    const int s = v > 0 ? 1 : -1;
    if (sign != 0 && s != sign) ++e.reversals;
    sign = s;
  }
  return e;
}

std::string prerequisite(const Envelope& env, const plant::PlantParams& model, const std::string& name,
                         const PlausibilityOptions& opt) {
  if (name == "grinding_force" && !opt.grinding_process)
    return "the scenario describes no grinding process (plant.grinding) and --effects does not ask for it";
  if (name == "presliding") {
    if (model.friction.model == plant::FrictionModel::kNone)
      return "the model has no friction (friction.model: none) whose presliding regime could be missing";
    if (env.stick_phases + env.reversals < 3)
      return fmt(
          "the data has too few stick phases or reversals to show presliding (%.0f stick phases below %.3g mm/s, "
          "%.0f reversals)",
          env.stick_phases, env.stick_velocity * 1e3, env.reversals);
  }
  if (is_ripple(name) && env.min_pitch() > env.max_pitch())
    return fmt("the travel (%.3g mm) spans no two periods of the shortest pitch the data resolves (%.3g mm)",
               env.travel * 1e3, env.min_pitch() * 1e3);
  // k (x - x_rest) + F is the spring k (x - x_rest + F/k): a spring and a constant force in one
  // model cannot be told apart; the spring's rest position carries the constant.
  if (name == "spring_force" && model.effects.constant_force.enabled)
    return "a constant force is in the model: with a spring, their sum is one spring with another rest position";
  if (name == "constant_force" && model.effects.spring_force.enabled)
    return "a spring is in the model: its rest position already carries a constant force";
  if (name == "spring_force" && env.travel < 1e-4)
    return fmt("the travel (%.3g um) is too short to show a position-dependent force", env.travel * 1e6);
  return "";
}

bool small_mass_change(const Envelope& env, const plant::NamedEffect& e) {
  return e.name == "mass_error" && std::abs(par(e, "mass") - env.nominal_mass) < kSmallMassChange * env.nominal_mass;
}

// long-function: a flat list of rules, one or two per effect, each independent of the others.
std::string implausible(const Envelope& env, const plant::PlantParams& model, const plant::NamedEffect& e) {
  const std::string& n = e.name;
  const double F = env.peak_thrust;
  const auto above = [&](const char* what, double value) {
    char buf[320];
    std::snprintf(buf, sizeof buf, "%s %.4g N exceeds the peak thrust of the record (%.4g N)", what, value, F);
    return std::string(buf);
  };
  if (n == "constant_force" && std::abs(par(e, "force")) > F) return above("force", std::abs(par(e, "force")));
  if (n == "constant_force") {
    // While the drive moves, a constant force F and a Coulomb friction whose level differs by 2F
    // between the directions are the same force (they differ only in stick phases, which the fit
    // leaves out). Real friction is asymmetric by a few per cent; a smaller force is not told
    // from that.
    const std::string w = within_asymmetry("force", par(e, "force"), friction_level(model),
                                           "a direction asymmetry of the friction, from which moving data cannot "
                                           "tell it");
    if (!w.empty()) return w;
  }
  if (n == "coulomb_friction" && par(e, "coulomb_force") > F) return above("Coulomb level", par(e, "coulomb_force"));
  if (n == "coulomb_friction") {
    // A change of the friction level by less than the asymmetry real friction has between its
    // directions is within the friction's form, as a constant force that size is (issue 20's
    // review: a 0.02 N Coulomb friction against 120 N of friction named as the explanation of a
    // 0.2 N s/m viscous friction).
    plant::PlantParams without = model;
    without.effects.coulomb_friction.enabled = false;
    const std::string w = within_asymmetry("Coulomb level", par(e, "coulomb_force"), friction_level(without),
                                           "a change of the level within the friction's form");
    if (!w.empty()) return w;
  }
  if (n == "viscous_friction" && par(e, "viscous") * env.v_max > F)
    return above("viscous force at the peak speed", par(e, "viscous") * env.v_max);
  if (n == "stribeck_friction") {
    if (par(e, "static_force") > F) return above("static level", par(e, "static_force"));
    if (par(e, "static_force") - par(e, "coulomb_force") < 0.05 * par(e, "coulomb_force"))
      return fmt(
          "no Stribeck hump: the static level %.4g N is within 5 %% of the Coulomb level %.4g N (that is Coulomb "
          "friction)",
          par(e, "static_force"), par(e, "coulomb_force"));
    const double vs = par(e, "stribeck_velocity");
    if (vs < 0.5 * env.stick_velocity || vs > 0.5 * env.v_max)
      return fmt("Stribeck velocity %.3g mm/s is not resolved by the data (between %.3g and %.3g mm/s)", vs * 1e3,
                 0.5 * env.stick_velocity * 1e3, 0.5 * env.v_max * 1e3);
    // The Stribeck curve is the fall of friction once the drive slides: a hump that has decayed
    // before the sign sgn_eps(v) has changed (v_s below its transition velocity eps) only reshapes
    // the sign change, the model form's job, and is no Stribeck effect the data resolve.
    const double eps = model.friction.static_smoothing_velocity;
    if (vs < eps)
      return fmt(
          "Stribeck velocity %.3g mm/s is below the Coulomb transition velocity %.3g mm/s: the hump lies "
          "within the sign change",
          vs * 1e3, eps * 1e3);
  }
  if (n == "presliding") {
    const double d = model.friction.coulomb_force / std::max(par(e, "bristle_stiffness"), 1e-300);
    if (d < 1e-8 || d > 1e-3)
      return fmt("presliding displacement Fc/sigma0 = %.3g um is outside 0.01 um .. 1 mm", d * 1e6);
    // The bristles deflect by Fc/sigma0 before the drive slides: a deflection within one count of
    // the sensor (or its noise) is not seen in the position record, and bristles that stiff only
    // reshape the friction's sign change, the model form's job (docs/fit.md, "Plausibility").
    if (d < env.resolution)
      return fmt(
          "presliding displacement Fc/sigma0 = %.3g um is below the sensor's resolution (%.3g um): the "
          "bristles' deflection is not resolved by the record",
          d * 1e6, env.resolution * 1e6);
  }
  if (n == "cogging_ripple") {
    const std::string p = ripple_pitch(env, par(e, "pitch"));
    if (!p.empty()) return p;
    const double a = std::abs(par(e, "cogging_amplitude")) + std::abs(par(e, "cogging_third"));
    if (a > 0.2 * F) return fmt("ripple amplitude %.3g N exceeds a fifth of the peak thrust (%.3g N)", a, F);
  }
  if (n == "reluctance_ripple") {
    const std::string p = ripple_pitch(env, par(e, "pitch"));
    if (!p.empty()) return p;
    const double a = std::abs(par(e, "reluctance_amplitude"));
    if (a > 0.2) return fmt("relative ripple amplitude %.3g exceeds 0.2", a);
    // The ripple scales the thrust by 1 + A sin(...), as a mass error scales the inertial force:
    // a modulation below kLeastMassChange is what a mass change that small is (plausibility.hpp),
    // another effect's form error, not a ripple worth naming.
    if (a < kLeastMassChange)
      return fmt("relative ripple amplitude %.3g %% is below the %.0f %% of the thrust a ripple is named at", 100 * a,
                 100 * kLeastMassChange);
  }
  if (n == "grinding_force") {
    const double xc = par(e, "contact_position");
    if (xc > env.x_max) return fmt("contact position %.4g mm lies beyond the travel", xc * 1e3);
    const double tau = par(e, "damping") / std::max(par(e, "stiffness"), 1e-300);
    if (tau < env.period || tau > 0.25 * env.duration)
      return fmt("time constant C/ke = %.3g ms is not resolved by the record (%.3g ms .. %.3g s)", tau * 1e3,
                 env.period * 1e3, 0.25 * env.duration);
    if (par(e, "damping") * env.v_max > 2.0 * F)
      return above("grinding force at the peak speed", par(e, "damping") * env.v_max);
  }
  if (n == "spring_force") {
    const double rest = par(e, "rest_position");
    if (rest < env.x_min - env.travel || rest > env.x_max + env.travel)
      return fmt("rest position %.4g mm lies more than one travel (%.3g mm) outside the travelled range", rest * 1e3,
                 env.travel * 1e3);
    if (par(e, "stiffness") * env.travel > F)
      return above("spring force over the travel", par(e, "stiffness") * env.travel);
    const std::string w = within_asymmetry("its change over the travel,", par(e, "stiffness") * env.travel,
                                           friction_level(model), "a constant force in disguise");
    if (!w.empty()) return w;
  }
  if (n == "mass_error") {
    const double m = par(e, "mass");
    if (m < 0.5 * env.nominal_mass || m > 2.0 * env.nominal_mass)
      return fmt("mass %.4g kg is not within a factor of two of the nominal %.4g kg", m, env.nominal_mass);
    // A drive's moving mass is known to a few per cent (payload, cables, bearings); a smaller
    // change is, unless the record shows it away from low speed too, the mass absorbing model-form
    // error of friction at reversals; one below kLeastMassChange is never named (plausibility.hpp).
    if (std::abs(m - env.nominal_mass) < kLeastMassChange * env.nominal_mass)
      return fmt("mass %.4g kg is within %.0f %% of the nominal %.4g kg: no mass error worth naming", m,
                 100 * kLeastMassChange, env.nominal_mass);
    if (small_mass_change(env, e))
      return fmt("mass %.4g kg is within %.0f %% of the nominal %.4g kg", m, 100 * kSmallMassChange, env.nominal_mass) +
             ", and the record does not show it away from low speed, where friction's form cannot fake it";
  }
  if (n == "input_delay") {
    const double d = par(e, "delay");
    if (d >= 0.999 * env.filter_half_width)
      return fmt("delay %.3g ms reaches the filter half-width (%.3g ms): longer delays are not resolved", d * 1e3,
                 env.filter_half_width * 1e3);
  }
  return "";
}

}  // namespace feeddrive::fit

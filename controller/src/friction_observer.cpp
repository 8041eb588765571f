#include "feeddrive/controller/friction_observer.hpp"

#include <cmath>

#include "feeddrive/plant/forces.hpp"

namespace feeddrive::controller {

FrictionObserver::FrictionObserver(const plant::FrictionParams& p, double period, double gain)
    : p_(p), static_force_(p.static_force), coulomb_force_(p.coulomb_force), period_(period), gain_(gain) {}

void FrictionObserver::set_level(double level) {
  p_.static_force = level * static_force_;
  p_.coulomb_force = level * coulomb_force_;
}

double FrictionObserver::transient(double v) const {
  if (p_.model != plant::FrictionModel::kLuGre || !std::isfinite(v)) return 0.0;
  const double z_ss = plant::stribeck(p_, v) / p_.bristle_stiffness;
  const double sign = (v > 0.0) - (v < 0.0);
  return std::abs(z_ - sign * z_ss) / z_ss;
}

double FrictionObserver::estimate(double v) const { return plant::friction_force(p_, v, z_); }

void FrictionObserver::advance(double v, double velocity_error) { advance(v, velocity_error, period_); }

void FrictionObserver::advance(double v, double velocity_error, double dt) {
  if (p_.model != plant::FrictionModel::kLuGre) return;
  // A non-finite velocity carries no information for this period: hold z^ rather than take a
  // NaN into the state for good. A non-finite correction is dropped likewise.
  if (!std::isfinite(v)) return;
  const double a = p_.bristle_stiffness * std::abs(v) / plant::stribeck(p_, v);
  // Correction +L*e_v with e_v = v_d - v_m (Canudas de Wit 1995's -k*e with e = v_m - v_d): a
  // lagging drive (e_v > 0) means F^f is too small, so z^ must grow. With this sign the cross
  // terms of V = m S^2/2 + sigma0 (z - z^)^2/(2L) cancel.
  const double correction = gain_ * velocity_error;
  const double b = v + (std::isfinite(correction) ? correction : 0.0);
  if (a > 0.0) {
    const double zs = b / a;
    z_ = zs + (z_ - zs) * std::exp(-a * dt);
  } else {
    z_ += b * dt;
  }
}

GrindingObserver::GrindingObserver(const plant::GrindingParams& p, double period) : p_(p), period_(period) {}

double GrindingObserver::estimate(double x) const { return plant::grinding_force(p_, x, fg_); }

void GrindingObserver::advance(double x, double v) {
  if (!p_.enabled) return;
  if (!std::isfinite(x) || !std::isfinite(v)) return;  // no information: hold F^g
  const double tau = p_.time_constant();
  const double decay = std::exp(-period_ / tau);
  const double target = plant::contact_fraction(p_, x) * p_.damping() * v;
  fg_ = target + (fg_ - target) * decay;
}

}  // namespace feeddrive::controller

#include "feeddrive/plant/forces.hpp"

#include <algorithm>
#include <cmath>

namespace feeddrive::plant {
namespace {
constexpr double kTwoPi = 2.0 * M_PI;
double sgn(double v) { return (v > 0.0) - (v < 0.0); }
// r^d, with the paper's delta = 2 (and 1) special-cased: std::pow is the costliest call of the
// right-hand side, and r*r is exact.
double power(double r, double d) {
  if (d == 2.0) return r * r;
  if (d == 1.0) return r;
  return std::pow(r, d);
}
}  // namespace

double stribeck(const FrictionParams& p, double v) {
  const double r = std::abs(v / p.stribeck_velocity);
  return p.coulomb_force + (p.static_force - p.coulomb_force) * std::exp(-power(r, p.stribeck_exponent));
}

double stribeck_derivative(const FrictionParams& p, double v) {
  // d/dv exp(-|v/vs|^d) = -exp(.) * d*|v/vs|^(d-1) * sgn(v)/vs
  if (v == 0.0) return 0.0;  // exact for d > 1; the one-sided limit is used for d <= 1
  const double r = std::abs(v / p.stribeck_velocity);
  const double d = p.stribeck_exponent;
  return -(p.static_force - p.coulomb_force) * std::exp(-power(r, d)) * d * power(r, d - 1.0) * sgn(v) /
         p.stribeck_velocity;
}

double micro_damping(const FrictionParams& p, double v) {
  if (p.damping_decay_velocity <= 0.0) return p.bristle_damping;
  const double r = v / p.damping_decay_velocity;
  return p.bristle_damping * std::exp(-r * r);
}

double micro_damping_derivative(const FrictionParams& p, double v) {
  if (p.damping_decay_velocity <= 0.0) return 0.0;
  const double vd2 = p.damping_decay_velocity * p.damping_decay_velocity;
  return micro_damping(p, v) * (-2.0 * v / vd2);
}

double lugre_zdot(const FrictionParams& p, double v, double z) {
  return v - p.bristle_stiffness * std::abs(v) * z / stribeck(p, v);
}

double smoothed_sign(const FrictionParams& p, double v) {
  const double eps = p.static_smoothing_velocity, b = p.static_smoothing_shape;
  const double th = std::tanh(v / eps);
  return b == 0.0 ? th : (1.0 - b) * th + b * v / std::sqrt(v * v + eps * eps);
}

double smoothed_sign_derivative(const FrictionParams& p, double v) {
  const double eps = p.static_smoothing_velocity, b = p.static_smoothing_shape;
  const double th = std::tanh(v / eps);
  const double d_tanh = (1.0 - th * th) / eps;
  if (b == 0.0) return d_tanh;
  const double q = v * v + eps * eps;
  return (1.0 - b) * d_tanh + b * eps * eps / (q * std::sqrt(q));
}

double friction_force(const FrictionParams& p, double v, double z) {
  switch (p.model) {
    case FrictionModel::kLuGre:
      return p.bristle_stiffness * z + micro_damping(p, v) * lugre_zdot(p, v, z) + p.viscous * v;
    case FrictionModel::kStatic: return stribeck(p, v) * smoothed_sign(p, v) + p.viscous * v;
    case FrictionModel::kNone: return 0.0;
  }
  return 0.0;
}

FrictionJacobian friction_jacobian(const FrictionParams& p, double v, double z) {
  FrictionJacobian J;
  switch (p.model) {
    case FrictionModel::kLuGre: {
      const double g = stribeck(p, v);
      const double dg = stribeck_derivative(p, v);
      const double s0 = p.bristle_stiffness;
      const double av = std::abs(v);
      // zdot = v - s0*|v|*z/g  =>  d/dv = 1 - s0*z*(sgn(v)*g - |v|*g')/g^2,  d/dz = -s0*|v|/g
      J.dzdot_dv = 1.0 - s0 * z * (sgn(v) * g - av * dg) / (g * g);
      J.dzdot_dz = -s0 * av / g;
      const double s1 = micro_damping(p, v);
      const double zdot = v - s0 * av * z / g;
      J.dF_dz = s0 + s1 * J.dzdot_dz;
      J.dF_dv = micro_damping_derivative(p, v) * zdot + s1 * J.dzdot_dv + p.viscous;
      break;
    }
    case FrictionModel::kStatic: {
      J.dF_dv =
          stribeck_derivative(p, v) * smoothed_sign(p, v) + stribeck(p, v) * smoothed_sign_derivative(p, v) + p.viscous;
      break;
    }
    case FrictionModel::kNone: break;
  }
  return J;
}

double cogging_force(const RippleParams& p, double x) {
  const double th = kTwoPi * x / p.pitch;
  return p.cogging_amplitude * std::sin(th + p.cogging_phase) +
         p.cogging_third * std::sin(3.0 * th + p.cogging_third_phase);
}

double cogging_force_dx(const RippleParams& p, double x) {
  const double w = kTwoPi / p.pitch;
  const double th = w * x;
  return w * (p.cogging_amplitude * std::cos(th + p.cogging_phase) +
              3.0 * p.cogging_third * std::cos(3.0 * th + p.cogging_third_phase));
}

double reluctance_factor(const RippleParams& p, double x) {
  const double th = kTwoPi * x / p.pitch;
  return p.reluctance_amplitude * std::sin(th + p.reluctance_phase) +
         p.reluctance_third * std::sin(3.0 * th + p.reluctance_third_phase);
}

double reluctance_factor_dx(const RippleParams& p, double x) {
  const double w = kTwoPi / p.pitch;
  const double th = w * x;
  return w * (p.reluctance_amplitude * std::cos(th + p.reluctance_phase) +
              3.0 * p.reluctance_third * std::cos(3.0 * th + p.reluctance_third_phase));
}

double ripple_force(const RippleParams& p, double x, double desired_force) {
  if (!p.enabled) return 0.0;
  return cogging_force(p, x) + desired_force * reluctance_factor(p, x);
}

double contact_fraction(const GrindingParams& p, double x) {
  if (!(x > p.contact_position)) return 0.0;
  if (p.contact_width <= 0.0) return 1.0;
  return std::min(1.0, (x - p.contact_position) / p.contact_width);
}

double contact_fraction_dx(const GrindingParams& p, double x) {
  return (p.contact_width > 0.0 && x > p.contact_position && x < p.contact_position + p.contact_width)
             ? 1.0 / p.contact_width
             : 0.0;
}

double grinding_rate(const GrindingParams& p, double x, double v, double fg) {
  if (!p.enabled) return 0.0;
  return contact_fraction(p, x) * p.stiffness * v - p.stiffness / p.damping() * fg;
}

double grinding_force(const GrindingParams& p, double x, double fg) {
  return p.enabled ? contact_fraction(p, x) * fg : 0.0;
}

}  // namespace feeddrive::plant

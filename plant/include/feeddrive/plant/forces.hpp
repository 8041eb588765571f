#pragma once
// Pure force laws of the feed drive: no state beyond the arguments, no I/O.
// Each function gives the equation it implements and its source. Sign convention: every force
// here *opposes* the thrust, as in m*x'' = Ka*Kf*u - F_friction - F_ripple - F_grinding (the
// model-discrepancy effects add - F_extra: effects.hpp).

#include "feeddrive/plant/params.hpp"

namespace feeddrive::plant {

/// Stribeck curve  g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta)  > 0.
/// Canudas de Wit et al. 1995 eq. (3); Xie & Liang eq. (7) with the sign taken out (the paper's
/// signed g combined with sgn-free z-dynamics equals the standard form below).
double stribeck(const FrictionParams& p, double v);
/// dg/dv.
double stribeck_derivative(const FrictionParams& p, double v);

/// Micro-damping  sigma1(v) = sigma1*exp(-(v/vd)^2)  if vd > 0, else the constant sigma1.
/// Canudas de Wit et al. 1995 Sec. 2 / Olsson et al. 1998 (passivity remedy).
double micro_damping(const FrictionParams& p, double v);
double micro_damping_derivative(const FrictionParams& p, double v);

/// LuGre bristle dynamics  dz/dt = v - sigma0*|v|*z/g(v)   (Canudas de Wit 1995 eq. 1).
double lugre_zdot(const FrictionParams& p, double v, double z);

/// Smoothed sign of the static friction model and of the Coulomb-type effects (effects.hpp):
///   sgn_eps(v) = (1 - b)*tanh(v/eps) + b*v/sqrt(v^2 + eps^2),
/// eps = static_smoothing_velocity, b = static_smoothing_shape in [0, 1]. The two are the usual
/// regularisations of sgn(v) in static friction maps; they differ in how the level is reached:
/// tanh exponentially (1 - 2 exp(-2|v|/eps)), the algebraic form slowly (1 - eps^2/(2 v^2)), so a
/// real transition can lie between them. b = 0 (the default) is tanh.
double smoothed_sign(const FrictionParams& p, double v);
/// d sgn_eps / dv = (1 - b)*(1 - tanh^2(v/eps))/eps + b*eps^2/(v^2 + eps^2)^(3/2).
double smoothed_sign_derivative(const FrictionParams& p, double v);

/// Friction force by the selected model:
///  LuGre:  F = sigma0*z + sigma1(v)*dz/dt + sigma2*v                (Canudas de Wit 1995 eq. 2)
///  static: F = g(v)*sgn_eps(v) + sigma2*v   (Coulomb+Stribeck+viscous, smoothed sign)
///  none:   F = 0
double friction_force(const FrictionParams& p, double v, double z);

/// Partial derivatives of friction_force and lugre_zdot, for the analytic Jacobian.
struct FrictionJacobian {
  double dF_dv{0.0}, dF_dz{0.0};
  double dzdot_dv{0.0}, dzdot_dz{0.0};
};
FrictionJacobian friction_jacobian(const FrictionParams& p, double v, double z);

/// Cogging force  Fc(x) = ac*sin(2*pi*x/p + phi_c1) + bc*sin(6*pi*x/p + phi_c3)
/// (Van den Braembussche et al. 1996; Xie & Liang eq. 15).
double cogging_force(const RippleParams& p, double x);
double cogging_force_dx(const RippleParams& p, double x);

/// Relative reluctance ripple  r(x) = af*sin(2*pi*x/p + phi11) + bf*sin(6*pi*x/p + phi12),
/// so that F_reluctance = F_desired * r(x)   (Xie & Liang eq. 14).
double reluctance_factor(const RippleParams& p, double x);
double reluctance_factor_dx(const RippleParams& p, double x);

/// Total ripple  F_r = Fc(x) + F_desired*r(x);  0 when ripple is disabled.
double ripple_force(const RippleParams& p, double x, double desired_force);

/// Contact fraction s(x) = clamp((x - x_c)/w, 0, 1), x_c = contact_position, w = contact_width
/// (a step at x_c when w = 0): 0 out of contact, 1 in full contact.
double contact_fraction(const GrindingParams& p, double x);
/// ds/dx (0 outside the engagement band).
double contact_fraction_dx(const GrindingParams& p, double x);
/// Hahn-Lindsay normal force rate (Xie & Liang eq. 13 as an ODE, V_r = v):
///   dFg/dt = s(x)*ke*v - (ke/C)*Fg,   C = c*pi*dw*bs
/// (in full contact eq. 13; out of contact the deflection relaxes: dFg/dt = -(ke/C)*Fg).
double grinding_rate(const GrindingParams& p, double x, double v, double fg);
/// The grinding force acting on the slide: s(x)*Fg (Fg in full contact, 0 out of contact), 0
/// when disabled.
double grinding_force(const GrindingParams& p, double x, double fg);

}  // namespace feeddrive::plant

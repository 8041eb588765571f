#pragma once
// Observers of the drive's unmeasurable force states, advanced once per control period.
//
// Bristle observer (Canudas de Wit et al. 1995, Sec. 4, driven by measured velocity v_m):
//   dz^/dt = v_m - sigma0*|v_m|*z^/g(v_m) - L*e_v,   e_v = v_d - v_m (optional correction, L>=0)
// Over one period with v_m held the equation is linear in z^, so it is advanced exactly:
//   a = sigma0*|v|/g(v),  b = v - L*e_v,  z^+ = b/a + (z^ - b/a)*exp(-a*T)   (a > 0)
//                                          z^+ = z^ + b*T                    (a = 0)
// which stays stable for any T (the z-dynamics are stiff: a reaches 2e4 1/s at 0.8 m/s).
// F^f = sigma0*z^ + sigma1(v)*dz^/dt + sigma2*v  with dz^/dt evaluated at (v_m, z^).
//
// Grinding observer (Xie & Liang eq. 13 driven by measured velocity, exact for held v):
//   dF^g/dt = ke*v_m - F^g/tau  =>  F^g+ = C*v + (F^g - C*v)*exp(-T/tau)   (in contact)

#include "feeddrive/plant/params.hpp"

namespace feeddrive::controller {

class FrictionObserver {
 public:
  FrictionObserver(const plant::FrictionParams& p, double period, double gain);
  /// Friction estimate at the current sample for measured velocity v (uses the current z^).
  double estimate(double v) const;
  double z() const { return z_; }
  /// Advances z^ over one period with v held; e_v is the velocity error for the correction.
  void advance(double v, double velocity_error);
  /// The same over a duration dt [s] instead of one period (the delay predictor's pieces).
  void advance(double v, double velocity_error, double dt);
  /// Sets the model's Fs and Fc to level x their given values (g(v) -> level*g(v) for sigma2 = 0;
  /// the adapted friction level of feedforward_adaptation.hpp). 1: the given model.
  void set_level(double level);
  /// How far the bristles are from their steady state at v, in units of the steady deflection:
  /// |z^ - sgn(v)*g(v)/sigma0| / (g(v)/sigma0); 0 in steady sliding, up to 2 just after a
  /// velocity reversal (the presliding transition), 0 for a model without bristles.
  double transient(double v) const;

 private:
  plant::FrictionParams p_;
  double static_force_;  // Fs, Fc as given
  double coulomb_force_;
  double period_;
  double gain_;
  double z_{0.0};
};

class GrindingObserver {
 public:
  GrindingObserver(const plant::GrindingParams& p, double period);
  double estimate(double x) const;  ///< F^g applied at position x (0 out of contact)
  void advance(double x, double v);

 private:
  plant::GrindingParams p_;
  double period_;
  double fg_{0.0};
};

}  // namespace feeddrive::controller

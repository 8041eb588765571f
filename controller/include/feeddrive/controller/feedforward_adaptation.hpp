#pragma once
// Friction level and inertia adapted online from the disturbance observer's residual (issue 24,
// item 5; docs/controllers.md, "Velocity reversals: what happens and the fix").
//
// The x,v,d observer's lumped disturbance d^ [m/s^2] is what the model misses; r = -m^*d^ [N] is
// the force the drive needs beyond the model forces. With a plant whose Fs and Fc are a factor
// off the model's and whose mass differs from the model's,
//   r = (Ff - F^f) + (m - m^)*a  ~  (theta* - theta)*phi_f + (delta_m* - delta_m)*m^*xd''
// where theta is the factor the controller's bristle observer applies to its Fs and Fc (its
// g(v) becomes theta*g(v): the LuGre model with an unknown level, Canudas de Wit & Lischinsky,
// "Adaptive friction compensation with partially known dynamic friction model", Int. J. Adaptive
// Control and Signal Processing 11, 1997), phi_f = F^f/theta (the friction estimate's derivative
// by theta in sliding, where F^f = theta*g) and a ~ xd'' while tracking. The two parameters are
// identified by the normalised gradient (least-mean-squares) estimator (Astrom & Wittenmark,
// "Adaptive Control", 2nd ed., 1995, ch. 2), once per control period T:
//   phi = [F^f/theta, m^*xd'']  [N]
//   theta   += gamma*T * r*phi_1 / (F0^2 + phi.phi),   theta   in [0.2, 3]
//   delta_m += gamma*T * r*phi_2 / (F0^2 + phi.phi),   delta_m in [-0.5, 1]
// with F0 the model's Coulomb force (at rest phi ~ 0 and nothing is learnt from the observer's
// noise) and gamma [1/s] the adaptation rate. r is measured with the adapted model already in
// the observer's prediction, so r itself is the estimator's error.
// Why the level goes into the bristle observer and not onto its output: the presliding
// transition at a velocity reversal spans the bristle deflection 2*g/sigma0, so with the plant's
// Fs, Fc at half the model's the plant's friction reverses over half the model's travel. Scaling
// g inside the observer gives the plant's travel; scaling F^f would keep the model's and leave a
// force error during every reversal (measured: docs/controllers.md).
// Not identified: sigma0 and sigma1 (the transition's stiffness and damping), which only a
// reversal excites; the controllers therefore learn only in sliding (kAdaptationTransient):
// a gradient step during the transition would fit the level to the bristles' mismatch (measured
// without the gate: sigma0, sigma1 x0.5 on the sine 1.17 -> 1.24 um at gamma = 20 1/s, 1.72 um
// at 200 1/s).

namespace feeddrive::controller {

/// The controllers learn only while their bristle observer is within this fraction of its
/// steady deflection (FrictionObserver::transient): in sliding, not in a presliding transition,
/// where the residual is the bristle dynamics' mismatch (sigma0, sigma1), not the level's.
inline constexpr double kAdaptationTransient = 0.1;

class FeedforwardAdaptation {
 public:
  /// rate: gamma [1/s] (0: off, the model as it is); period: T [s]; force_scale: F0 [N] (> 0).
  FeedforwardAdaptation(double rate, double period, double force_scale);
  bool enabled() const { return rate_ > 0.0; }
  /// theta: the factor on the model's Fs and Fc (1: the model's).
  double friction_level() const { return theta_; }
  /// delta_m: the mass error as a fraction of the model's mass (0: the model's).
  double mass_error() const { return delta_m_; }
  /// The inertial feedforward the model misses: delta_m*inertial [N] (inertial = m^*xd'').
  double inertial_force(double inertial) const { return delta_m_ * inertial; }
  /// One gradient step with the residual r = -m^*d^ [N], the friction estimate F^f made with the
  /// current level [N] and the inertial force m^*xd'' [N]; non-finite inputs are skipped (no
  /// information this period).
  void update(double residual, double friction, double inertial);

 private:
  double rate_;
  double period_;
  double force_scale_;
  double theta_{1.0};
  double delta_m_{0.0};
};

}  // namespace feeddrive::controller

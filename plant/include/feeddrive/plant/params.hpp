#pragma once
// Parameter structs of the linear-motor feed-drive plant.
//
// Every struct has its defaults in place (the paper's Table 1 where the paper gives a value,
// docs/parameters.md for the rationale of every value it does not give) and one validate()
// that throws std::invalid_argument naming the offending field and its value.
//
// Units are SI throughout: m, m/s, N, N/m, N*s/m, kg, s, V, A, ohm, H.

#include <cstdint>
#include <limits>
#include <string>

namespace feeddrive::plant {

/// Friction law selected for the plant (and, separately, for a controller's model).
enum class FrictionModel {
  kLuGre,   ///< LuGre dynamic friction (Canudas de Wit et al. 1995), state z.
  kStatic,  ///< Coulomb + Stribeck + viscous static map, with a smoothed sign.
  kNone,    ///< No friction.
};

std::string to_string(FrictionModel m);
/// Parses "lugre" | "static" | "none"; throws std::invalid_argument otherwise.
FrictionModel friction_model_from_string(const std::string& s);

/// LuGre / static friction parameters. Defaults: Xie & Liang Table 1, delta = 2.
struct FrictionParams {
  FrictionModel model{FrictionModel::kLuGre};
  double static_force{120.0};       ///< Fs [N], stiction level of g(v).
  double coulomb_force{80.0};       ///< Fc [N], Coulomb level of g(v).
  double stribeck_velocity{0.1};    ///< vs [m/s].
  double stribeck_exponent{2.0};    ///< delta [-], shape of exp(-|v/vs|^delta).
  double bristle_stiffness{2e6};    ///< sigma0 [N/m].
  double bristle_damping{2e4};      ///< sigma1 [N*s/m].
  double viscous{0.4};              ///< sigma2 [N*s/m].
  /// vd [m/s]: if > 0, sigma1(v) = sigma1*exp(-(v/vd)^2) (passivity remedy, Olsson et al. 1998).
  /// 0 (default) keeps the paper's constant sigma1.
  double damping_decay_velocity{0.0};
  /// eps [m/s] of the smoothed sign sgn_eps(v) (forces.hpp, smoothed_sign) of the static model
  /// and of the Coulomb-type effects.
  double static_smoothing_velocity{1e-5};
  /// b [-] in [0, 1], the shape of the smoothed sign: 0 (default) tanh(v/eps), 1 the algebraic
  /// v/sqrt(v^2 + eps^2), between a blend (forces.hpp, smoothed_sign).
  double static_smoothing_shape{0.0};

  void validate(const std::string& prefix = "friction") const;
};

/// Force ripple (Van den Braembussche et al. 1996; Xie & Liang eqs. 14-15).
struct RippleParams {
  bool enabled{false};
  double pitch{0.03};             ///< p [m], magnet pitch.
  double cogging_amplitude{3.0};  ///< ac [N].
  double cogging_phase{0.0};      ///< phi_c1 [rad].
  double cogging_third{1.0};      ///< bc [N], third harmonic (6*pi*x/p).
  double cogging_third_phase{0.0};///< phi_c3 [rad].
  double reluctance_amplitude{0.03};   ///< af [-], fraction of the desired force.
  double reluctance_phase{0.0};        ///< phi_11 [rad].
  double reluctance_third{0.01};       ///< bf [-].
  double reluctance_third_phase{0.0};  ///< phi_12 [rad].

  void validate(const std::string& prefix = "ripple") const;
};

/// Hahn-Lindsay plunge-grinding normal force (Xie & Liang eq. 13).
struct GrindingParams {
  bool enabled{false};
  double stiffness{2e7};              ///< ke [N/m], effective wheel-work-machine stiffness.
  double dullness{2.5e9};             ///< c [N*s/m^3], force per material removal rate.
  double workpiece_diameter{0.05};    ///< dw [m].
  double wheel_width{0.02};           ///< bs [m].
  /// Contact begins when x > contact_position [m]. -inf (default): always in contact.
  double contact_position{-std::numeric_limits<double>::infinity()};
  /// w [m]: the wheel engages over x in (contact_position, contact_position + w) (surface
  /// roughness), so the force is continuous in x and the integrator never chatters on the
  /// contact surface. 0: a step.
  double contact_width{1e-6};

  /// C = c*pi*dw*bs [N*s/m]: the steady-state force per infeed velocity.
  double damping() const;
  /// tau = C/ke [s]: the time constant of eq. 13.
  double time_constant() const;
  void validate(const std::string& prefix = "grinding") const;
};

/// Optional R-L armature circuit: L di/dt = Ka*u - R i - Ke v, thrust = Kf i.
/// Off by default, as in the paper (Section 2.1 neglects the electrical dynamics).
struct ElectricalParams {
  bool enabled{false};
  double resistance{1.0};     ///< R [ohm].
  double inductance{2e-3};    ///< L [H].
  double back_emf{100.0};     ///< Ke [V*s/m].

  void validate(const std::string& prefix = "electrical") const;
};

/// Extra forces of the model-discrepancy vocabulary (issue: feeddrive-fit, docs/fit.md). Each
/// adds one more force F_extra to  m*x'' = Ka*Kf*u - F_friction - F_ripple - F_grinding - F_extra,
/// or modifies the model as named. Every effect is off (enabled = false) by default. The field
/// names are the vocabulary's parameter names; the YAML keys under plant.effects.<name> are the
/// same strings.
struct ConstantForceEffect {  ///< F = force_N (gravity on an incline, cable weight, offset)
  bool enabled{false};
  double force_N{0.0};
};
struct CoulombFrictionEffect {  ///< F = coulomb_N*sgn(v), sgn smoothed as tanh(v/eps) (eps: friction.static_smoothing_velocity)
  bool enabled{false};
  double coulomb_N{0.0};
};
struct ViscousFrictionEffect {  ///< F = viscous_Ns_per_m*v
  bool enabled{false};
  double viscous_Ns_per_m{0.0};
};
/// F = sgn(v)*(coulomb_N + (static_N - coulomb_N)*exp(-|v/stribeck_velocity_mps|^delta)), delta =
/// friction.stribeck_exponent, sgn smoothed as for coulomb_friction.
struct StribeckFrictionEffect {
  bool enabled{false};
  double static_N{0.0};
  double coulomb_N{0.0};
  double stribeck_velocity_mps{0.01};
};
/// The LuGre bristle dynamics (Canudas de Wit 1995): the friction becomes LuGre with
/// sigma0 = bristle_stiffness_N_per_m and sigma1 = bristle_damping_Ns_per_m, keeping Fs, Fc, vs,
/// delta and sigma2 of the friction section. F_extra = F_LuGre - F_friction(model).
struct PreslidingEffect {
  bool enabled{false};
  double bristle_stiffness_N_per_m{2e6};
  double bristle_damping_Ns_per_m{0.0};
};
/// F = amplitude_N*sin(2 pi x/pitch_m + phase_rad) + third_harmonic_N*sin(6 pi x/pitch_m + third_phase_rad)
struct CoggingRippleEffect {
  bool enabled{false};
  double pitch_m{0.03};
  double amplitude_N{0.0};
  double phase_rad{0.0};
  double third_harmonic_N{0.0};
  double third_phase_rad{0.0};
};
/// F = Ka*Kf*u*relative_amplitude*sin(2 pi x/pitch_m + phase_rad)  (the thrust actually produced)
struct ReluctanceRippleEffect {
  bool enabled{false};
  double pitch_m{0.03};
  double relative_amplitude{0.0};
  double phase_rad{0.0};
};
/// Hahn-Lindsay grinding force (the grinding section's model) with C = gain_Ns_per_m,
/// ke = stiffness_N_per_m and contact past contact_position_m. Uses the Fg state.
struct GrindingForceEffect {
  bool enabled{false};
  double gain_Ns_per_m{7.85e6};
  double stiffness_N_per_m{2e7};
  double contact_position_m{0.0};
};
/// F = stiffness_N_per_m*(x - rest_position_m)  (a cable carrier)
struct SpringForceEffect {
  bool enabled{false};
  double stiffness_N_per_m{0.0};
  double rest_position_m{0.0};
};
/// The true moving mass replaces PlantParams::mass.
struct MassErrorEffect {
  bool enabled{false};
  double mass_kg{102.04};
};
/// The thrust acts delay_s after the command: F_thrust(t) = Ka*Kf*u(t - delay_s) (u = 0 before t0).
struct InputDelayEffect {
  bool enabled{false};
  double delay_s{0.0};
};

struct EffectsParams {
  ConstantForceEffect constant_force;
  CoulombFrictionEffect coulomb_friction;
  ViscousFrictionEffect viscous_friction;
  StribeckFrictionEffect stribeck_friction;
  PreslidingEffect presliding;
  CoggingRippleEffect cogging_ripple;
  ReluctanceRippleEffect reluctance_ripple;
  GrindingForceEffect grinding_force;
  SpringForceEffect spring_force;
  MassErrorEffect mass_error;
  InputDelayEffect input_delay;

  bool any() const;
  void validate(const std::string& prefix = "effects") const;
};

/// Position sensor (encoder) model. Both effects off by default.
struct SensorParams {
  double quantization{0.0};    ///< q [m]; 0 = ideal. x_meas = q*round((x + n)/q).
  double noise_stddev{0.0};    ///< standard deviation of Gaussian position noise n [m].
  std::uint64_t seed{1};       ///< seed of the noise generator (std::mt19937_64).
  /// How the measured velocity is formed:
  ///   "auto": the true velocity when the sensor is ideal, else "difference";
  ///   "true": the true velocity (a tachometer-like ideal sensor; only with an ideal sensor:
  ///           validate() refuses it with quantization or noise, which measure position only);
  ///   "difference": (x_meas[k] - x_meas[k-1]) / T, what a drive computes from an encoder.
  std::string velocity{"auto"};

  bool ideal() const { return quantization == 0.0 && noise_stddev == 0.0; }
  void validate(const std::string& prefix = "sensor") const;
};

/// CVODE settings: BDF + Newton + dense direct solver, analytic Jacobian.
/// Defaults are tight enough that halving them moves every paper figure by < 1% (tested).
struct IntegratorParams {
  double rtol{1e-8};
  double atol_position{1e-12};   ///< [m]
  double atol_velocity{1e-12};   ///< [m/s]
  double atol_bristle{1e-13};    ///< [m]
  double atol_grinding{1e-9};    ///< [N]
  double atol_current{1e-9};     ///< [A]
  long max_steps{100000};        ///< per control period.

  void validate(const std::string& prefix = "integrator") const;
};

/// Initial state.
struct InitialState {
  double position{0.0};  ///< [m]
  double velocity{0.0};  ///< [m/s]
  double bristle{0.0};   ///< z [m]
  double grinding{0.0};  ///< Fg [N]
  double current{0.0};   ///< i [A]
};

/// Everything that defines the plant.
struct PlantParams {
  /// m [kg]: from the paper's zeta = 0.7, m = ((sigma1+sigma2)/1.4)^2/sigma0 = 102.04 kg.
  double mass{102.04};
  double amplifier_gain{2.6};   ///< Ka [A/V] (or V/V with the electrical option); Ka*Kf = 260 N/V.
  double force_constant{100.0}; ///< Kf [N/A]. Thrust = Ka*Kf*u without electrical dynamics.
  /// Amplifier input range [V]: |u| above it is clipped, a non-finite u is rejected
  /// (command.hpp). 100 V: far above every controller's own limit, so it only guards.
  double input_limit{100.0};
  FrictionParams friction;
  RippleParams ripple;
  GrindingParams grinding;
  ElectricalParams electrical;
  SensorParams sensor;
  IntegratorParams integrator;
  InitialState initial;
  EffectsParams effects;  ///< model-discrepancy effects (docs/fit.md); all off by default

  double thrust_gain() const { return amplifier_gain * force_constant; }  ///< Ka*Kf [N/V]
  void validate(const std::string& prefix = "plant") const;
  /// For an integrator failure message: the `n` fastest rates of the model [1/s] with the keys
  /// and values that set them (presliding oscillation sqrt(sigma0/m), bristle damping sigma1/m,
  /// viscous c/m, grinding lag 1/tau_g, current loop R/L, the effects' springs and dampers),
  /// and the integrator's limits. One line.
  std::string fastest_time_scales(std::size_t n = 2) const;
};

}  // namespace feeddrive::plant

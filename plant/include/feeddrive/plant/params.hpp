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
#include <utility>
#include <vector>

#include "feeddrive/common/fields.hpp"

namespace feeddrive::plant {

/// Friction law selected for the plant (and, separately, for a controller's model).
enum class FrictionModel {
  kLuGre,   ///< LuGre dynamic friction (Canudas de Wit et al. 1995), state z.
  kStatic,  ///< Coulomb + Stribeck + viscous static map, with a smoothed sign.
  kNone,    ///< No friction.
};

inline const std::vector<std::pair<FrictionModel, const char*>>& enum_names(FrictionModel) {
  static const std::vector<std::pair<FrictionModel, const char*>> n = {
      {FrictionModel::kLuGre, "lugre"}, {FrictionModel::kStatic, "static"}, {FrictionModel::kNone, "none"}};
  return n;
}
std::string to_string(FrictionModel m);
/// Parses "lugre" | "static" | "none"; throws std::invalid_argument otherwise.

// Every struct below lists its keys once, in Serialize (common/fields.hpp): name, unit, validity
// rule, plausible range for a linear feed drive, one line of meaning. The scenario reader,
// validate()'s ranges, the plausibility warnings and docs/scenario.md's tables come from it.

// The quantities a plant section and an effect of the model-discrepancy vocabulary (EffectsParams)
// share, one vocabulary per physical effect: each is declared once here (name, unit, rule,
// plausible range, meaning) and listed by both (RippleParams and CoggingRippleEffect, ...). A rule
// that depends on the role is chained where the field is listed (the friction law's Fs, Fc > 0
// against an additive effect's >= 0).
namespace quantity {
using fields::field;
using fields::Field;

// --- friction (FrictionParams; coulomb_friction, viscous_friction, stribeck_friction, presliding)
// A force level of the Stribeck curve g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta): Fs and Fc.
inline Field<double> friction_level(const char* name, double& v, const char* doc) {
  return field(name, v).unit("N").non_negative().plausible(0.1, 2e4, "", "", "a linear guide").doc(doc);
}
inline Field<double> static_force(double& v) {
  return friction_level("static_force", v, "Fs, stiction level of g(v); >= coulomb_force");
}
inline Field<double> coulomb_force(double& v) {
  return friction_level("coulomb_force", v, "Fc, Coulomb level of g(v)");
}
inline Field<double> stribeck_velocity(double& v) {
  return field("stribeck_velocity", v).unit("m/s").positive().plausible(1e-6, 1.0, "mm/s").doc("vs, Stribeck velocity");
}
inline Field<double> bristle_stiffness(double& v) {
  return field("bristle_stiffness", v)
      .unit("N/m")
      .positive()
      .plausible(1e3, 1e10, "", "N/um")
      .doc("sigma0, LuGre bristle stiffness");
}
inline Field<double> bristle_damping(double& v) {
  return field("bristle_damping", v)
      .unit("N*s/m")
      .non_negative()
      .plausible(0, 1e7)
      .doc("sigma1, LuGre bristle damping");
}
inline Field<double> viscous(double& v) {
  return field("viscous", v).unit("N*s/m").non_negative().plausible(0, 1e5).doc("sigma2, viscous coefficient");
}

// --- force ripple (RippleParams; cogging_ripple, reluctance_ripple) --------------------------
inline Field<double> pitch(double& v) {
  return field("pitch", v).unit("m").positive().at_most(10).plausible(1e-3, 0.2, "mm").doc("p, magnet pitch");
}
inline Field<double> cogging_amplitude(double& v) {
  return field("cogging_amplitude", v).unit("N").plausible(-2000, 2000).doc("ac, cogging amplitude");
}
inline Field<double> cogging_phase(double& v) {
  return field("cogging_phase", v).unit("rad").plausible(-7, 7, "deg").doc("phi_c1");
}
inline Field<double> cogging_third(double& v) {
  return field("cogging_third", v).unit("N").plausible(-2000, 2000).doc("bc, cogging third harmonic (6*pi*x/p)");
}
inline Field<double> cogging_third_phase(double& v) {
  return field("cogging_third_phase", v).unit("rad").plausible(-7, 7, "deg").doc("phi_c3");
}
inline Field<double> reluctance_amplitude(double& v) {
  return field("reluctance_amplitude", v)
      .unit("-")
      .plausible(-0.5, 0.5, "%")
      .doc("af, fraction of the thrust; |af| + |bf| < 1");
}
inline Field<double> reluctance_phase(double& v) {
  return field("reluctance_phase", v).unit("rad").plausible(-7, 7, "deg").doc("phi_11");
}

// --- grinding (GrindingParams; grinding_force) -----------------------------------------------
inline Field<double> grinding_stiffness(double& v) {
  return field("stiffness", v)
      .unit("N/m")
      .positive()
      .plausible(1e5, 1e10, "", "N/um")
      .doc("ke, wheel-work-machine stiffness");
}
inline Field<double> contact_position(double& v) {
  return field("contact_position", v).unit("m").plausible(-5, 5, "mm").doc("contact for x > contact_position");
}

// --- the moving mass (PlantParams; mass_error) ------------------------------------------------
inline Field<double> mass(double& v) {
  return field("mass", v).unit("kg").positive().plausible(0.5, 5000, "g").doc("m, moving mass");
}
}  // namespace quantity

/// LuGre / static friction parameters. Defaults: Xie & Liang Table 1, delta = 2.
struct FrictionParams {
  FrictionModel model{FrictionModel::kLuGre};
  double static_force{120.0};     ///< Fs [N], stiction level of g(v).
  double coulomb_force{80.0};     ///< Fc [N], Coulomb level of g(v).
  double stribeck_velocity{0.1};  ///< vs [m/s].
  double stribeck_exponent{2.0};  ///< delta [-], shape of exp(-|v/vs|^delta).
  double bristle_stiffness{2e6};  ///< sigma0 [N/m].
  double bristle_damping{2e4};    ///< sigma1 [N*s/m].
  double viscous{0.4};            ///< sigma2 [N*s/m].
  /// vd [m/s]: if > 0, sigma1(v) = sigma1*exp(-(v/vd)^2) (passivity remedy, Olsson et al. 1998).
  /// 0 (default) keeps the paper's constant sigma1.
  double damping_decay_velocity{0.0};
  /// eps [m/s] of the smoothed sign sgn_eps(v) (forces.hpp, smoothed_sign) of the static model
  /// and of the Coulomb-type effects.
  double static_smoothing_velocity{1e-5};
  /// b [-] in [0, 1], the shape of the smoothed sign: 0 (default) tanh(v/eps), 1 the algebraic
  /// v/sqrt(v^2 + eps^2), between a blend (forces.hpp, smoothed_sign).
  double static_smoothing_shape{0.0};

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(model).doc("friction law: lugre, static (Coulomb + Stribeck + viscous map) or none"));
    // The friction law divides by g(v) = Fc + (Fs - Fc)*exp(...): its levels are > 0.
    a->Visit(quantity::static_force(static_force).positive());
    a->Visit(quantity::coulomb_force(coulomb_force).positive());
    a->Visit(quantity::stribeck_velocity(stribeck_velocity));
    a->Visit(
        FD_FIELD(stribeck_exponent).unit("-").positive().plausible(0.3, 5.0).doc("delta, shape of exp(-|v/vs|^delta)"));
    a->Visit(quantity::bristle_stiffness(bristle_stiffness));
    a->Visit(quantity::bristle_damping(bristle_damping));
    a->Visit(quantity::viscous(viscous));
    a->Visit(FD_FIELD(damping_decay_velocity)
                 .unit("m/s")
                 .non_negative()
                 .plausible(0, 1.0, "mm/s")
                 .doc("vd: > 0 gives sigma1(v) = sigma1*exp(-(v/vd)^2); 0 keeps sigma1 constant"));
    a->Visit(FD_FIELD(static_smoothing_velocity)
                 .unit("m/s")
                 .positive()
                 .plausible(1e-9, 1e-2, "mm/s")
                 .doc("eps of the static model's smoothed sign sgn_eps(v) (static only)"));
    a->Visit(FD_FIELD(static_smoothing_shape)
                 .unit("-")
                 .non_negative()
                 .at_most(1)
                 .doc("b: sgn_eps(v) = (1-b)*tanh(v/eps) + b*v/sqrt(v^2+eps^2); 0 tanh, 1 algebraic (static only)"));
  }
  void validate(const std::string& prefix = "friction") const;
};

/// Named sets of ripple values (plant.ripple.preset, or `ripple: paper`).
enum class RipplePreset {
  kNone,   ///< every part 0: the ripple is only what the keys give
  kPaper,  ///< Xie & Liang's values (Table 1): ac = 3 N, bc = 1 N, af = 0.03, bf = 0.01, on
};
inline const std::vector<std::pair<RipplePreset, const char*>>& enum_names(RipplePreset) {
  static const std::vector<std::pair<RipplePreset, const char*>> n = {{RipplePreset::kNone, "none"},
                                                                      {RipplePreset::kPaper, "paper"}};
  return n;
}

/// Force ripple (Van den Braembussche et al. 1996; Xie & Liang eqs. 14-15). Every part is 0
/// unless given or taken from a preset (RippleParams::paper(), the paper's values): a user who
/// writes only cogging_amplitude gets only that part (issue 23).
struct RippleParams {
  RipplePreset preset{RipplePreset::kNone};
  bool enabled{false};
  double pitch{0.03};                  ///< p [m], magnet pitch.
  double cogging_amplitude{0.0};       ///< ac [N].
  double cogging_phase{0.0};           ///< phi_c1 [rad].
  double cogging_third{0.0};           ///< bc [N], third harmonic (6*pi*x/p).
  double cogging_third_phase{0.0};     ///< phi_c3 [rad].
  double reluctance_amplitude{0.0};    ///< af [-], fraction of the desired force.
  double reluctance_phase{0.0};        ///< phi_11 [rad].
  double reluctance_third{0.0};        ///< bf [-].
  double reluctance_third_phase{0.0};  ///< phi_12 [rad].

  /// The preset's values (kNone: the defaults above).
  static RippleParams of(RipplePreset preset) {
    RippleParams r;
    r.preset = preset;
    if (preset == RipplePreset::kPaper) {
      r.enabled = true;
      r.cogging_amplitude = 3.0;
      r.cogging_third = 1.0;
      r.reluctance_amplitude = 0.03;
      r.reluctance_third = 0.01;
    }
    return r;
  }
  /// The paper's ripple (Xie & Liang Table 1), enabled.
  static RippleParams paper() { return of(RipplePreset::kPaper); }

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(
        FD_FIELD(preset).doc("paper: start from the paper's values (ac 3 N, bc 1 N, af 0.03, bf 0.01, on); `ripple: "
                             "paper` alone says the same; none: every part 0"));
    a->Visit(FD_FIELD(enabled).doc("the ripple force of eqs. 14-15 acts"));
    a->Visit(quantity::pitch(pitch));
    a->Visit(quantity::cogging_amplitude(cogging_amplitude));
    a->Visit(quantity::cogging_phase(cogging_phase));
    a->Visit(quantity::cogging_third(cogging_third));
    a->Visit(quantity::cogging_third_phase(cogging_third_phase));
    a->Visit(quantity::reluctance_amplitude(reluctance_amplitude));
    a->Visit(quantity::reluctance_phase(reluctance_phase));
    a->Visit(FD_FIELD(reluctance_third).unit("-").plausible(-0.5, 0.5, "%").doc("bf, third harmonic fraction"));
    a->Visit(FD_FIELD(reluctance_third_phase).unit("rad").plausible(-7, 7, "deg").doc("phi_12"));
  }
  void validate(const std::string& prefix = "ripple") const;
};

/// Hahn-Lindsay plunge-grinding normal force (Xie & Liang eq. 13).
struct GrindingParams {
  bool enabled{false};
  double stiffness{2e7};            ///< ke [N/m], effective wheel-work-machine stiffness.
  double dullness{2.5e9};           ///< c [N*s/m^3], force per material removal rate.
  double workpiece_diameter{0.05};  ///< dw [m].
  double wheel_width{0.02};         ///< bs [m].
  /// Contact begins when x > contact_position [m]. -inf (default): always in contact.
  double contact_position{-std::numeric_limits<double>::infinity()};
  /// w [m]: the wheel engages over x in (contact_position, contact_position + w) (surface
  /// roughness), so the force is continuous in x and the integrator never chatters on the
  /// contact surface. 0: a step.
  double contact_width{1e-6};

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(enabled).doc("the Hahn-Lindsay grinding force of eq. 13 acts"));
    a->Visit(quantity::grinding_stiffness(stiffness));
    a->Visit(
        FD_FIELD(dullness).unit("N*s/m^3").positive().plausible(1e6, 1e13).doc("c, force per material removal rate"));
    a->Visit(FD_FIELD(workpiece_diameter).unit("m").positive().plausible(1e-3, 2.0, "mm").doc("dw"));
    a->Visit(FD_FIELD(wheel_width).unit("m").positive().plausible(1e-3, 0.5, "mm").doc("bs"));
    a->Visit(quantity::contact_position(contact_position)
                 .minus_inf_allowed()
                 .doc("contact for x > contact_position; -.inf: always in contact"));
    a->Visit(FD_FIELD(contact_width)
                 .unit("m")
                 .non_negative()
                 .plausible(0, 1e-2, "um")
                 .doc("w: the force rises linearly over (contact_position, contact_position + w); 0: a step"));
  }
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
  double resistance{1.0};   ///< R [ohm].
  double inductance{2e-3};  ///< L [H].
  double back_emf{100.0};   ///< Ke [V*s/m].

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(enabled).doc("the R-L armature circuit is modelled"));
    a->Visit(FD_FIELD(resistance).unit("ohm").positive().plausible(1e-3, 100).doc("R"));
    a->Visit(FD_FIELD(inductance).unit("H").positive().plausible(1e-6, 1.0, "mH").doc("L"));
    a->Visit(FD_FIELD(back_emf).unit("V*s/m").non_negative().plausible(0, 2000).doc("Ke"));
  }
  void validate(const std::string& prefix = "electrical") const;
};

/// Extra forces of the model-discrepancy vocabulary (issue: feeddrive-fit, docs/fit.md). Each
/// adds one more force F_extra to  m*x'' = Ka*Kf*u - F_friction - F_ripple - F_grinding - F_extra,
/// or modifies the model as named. Every effect is off (enabled = false) by default. The field
/// names are the vocabulary's parameter names and the YAML keys under plant.effects.<name>; a
/// quantity the plant's own sections have is named, and declared, as there (`quantity` above:
/// cogging_ripple.cogging_amplitude is ripple.cogging_amplitude). Units are in the list, not in
/// the names; each key's old spelling (amplitude_N, ...) is its alias, still read with a warning.
/// Every effect's `enabled`: listing the effect turns it on (`enabled: false` switches it off again).
inline fields::Field<bool> listed_enabled(bool& v) {
  return fields::field("enabled", v).doc("on (listing the effect turns it on)");
}

struct ConstantForceEffect {  ///< F = force (gravity on an incline, cable weight, offset)
  bool enabled{false};
  double force{0.0};  ///< [N]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(FD_FIELD(force).unit("N").plausible(-1e4, 1e4).doc("the constant force").alias("force_N"));
  }
};
struct CoulombFrictionEffect {  ///< F = coulomb_force*sgn(v), sgn smoothed as tanh(v/eps) (eps:
                                ///< friction.static_smoothing_velocity)
  bool enabled{false};
  double coulomb_force{0.0};  ///< Fc [N]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::coulomb_force(coulomb_force).alias("coulomb_N"));
  }
};
struct ViscousFrictionEffect {  ///< F = viscous*v
  bool enabled{false};
  double viscous{0.0};  ///< sigma2 [N*s/m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::viscous(viscous).alias("viscous_Ns_per_m"));
  }
};
/// F = sgn(v)*(coulomb_force + (static_force - coulomb_force)*exp(-|v/stribeck_velocity|^delta)),
/// delta = friction.stribeck_exponent, sgn smoothed as for coulomb_friction.
struct StribeckFrictionEffect {
  bool enabled{false};
  double static_force{0.0};        ///< Fs [N]
  double coulomb_force{0.0};       ///< Fc [N]
  double stribeck_velocity{0.01};  ///< vs [m/s]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::static_force(static_force).alias("static_N"));
    a->Visit(quantity::coulomb_force(coulomb_force).alias("coulomb_N"));
    a->Visit(quantity::stribeck_velocity(stribeck_velocity).alias("stribeck_velocity_mps"));
  }
};
/// The LuGre bristle dynamics (Canudas de Wit 1995): the friction becomes LuGre with
/// sigma0 = bristle_stiffness and sigma1 = bristle_damping, keeping Fs, Fc, vs, delta and sigma2
/// of the friction section. F_extra = F_LuGre - F_friction(model).
struct PreslidingEffect {
  bool enabled{false};
  double bristle_stiffness{2e6};  ///< sigma0 [N/m]
  double bristle_damping{0.0};    ///< sigma1 [N*s/m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::bristle_stiffness(bristle_stiffness).alias("bristle_stiffness_N_per_m"));
    a->Visit(quantity::bristle_damping(bristle_damping).alias("bristle_damping_Ns_per_m"));
  }
};
/// F = cogging_amplitude*sin(2 pi x/pitch + cogging_phase)
///   + cogging_third*sin(6 pi x/pitch + cogging_third_phase)   (ripple's cogging part, eq. 14)
struct CoggingRippleEffect {
  bool enabled{false};
  double pitch{0.03};               ///< p [m]
  double cogging_amplitude{0.0};    ///< ac [N]
  double cogging_phase{0.0};        ///< phi_c1 [rad]
  double cogging_third{0.0};        ///< bc [N]
  double cogging_third_phase{0.0};  ///< phi_c3 [rad]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::pitch(pitch).alias("pitch_m"));
    a->Visit(quantity::cogging_amplitude(cogging_amplitude).alias("amplitude_N"));
    a->Visit(quantity::cogging_phase(cogging_phase).alias("phase_rad"));
    a->Visit(quantity::cogging_third(cogging_third).alias("third_harmonic_N"));
    a->Visit(quantity::cogging_third_phase(cogging_third_phase).alias("third_phase_rad"));
  }
};
/// F = F_thrust*reluctance_amplitude*sin(2 pi x/pitch + reluctance_phase)  (the thrust actually
/// produced; ripple's reluctance fundamental, eq. 15)
struct ReluctanceRippleEffect {
  bool enabled{false};
  double pitch{0.03};                ///< p [m]
  double reluctance_amplitude{0.0};  ///< af [-]
  double reluctance_phase{0.0};      ///< phi_11 [rad]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::pitch(pitch).alias("pitch_m"));
    a->Visit(quantity::reluctance_amplitude(reluctance_amplitude).alias("relative_amplitude"));
    a->Visit(quantity::reluctance_phase(reluctance_phase).alias("phase_rad"));
  }
};
/// Hahn-Lindsay grinding force (the grinding section's model) with C = damping (GrindingParams::
/// damping(), c*pi*dw*bs), ke = stiffness and contact past contact_position. Uses the Fg state.
struct GrindingForceEffect {
  bool enabled{false};
  double damping{7.85e6};        ///< C [N*s/m]
  double stiffness{2e7};         ///< ke [N/m]
  double contact_position{0.0};  ///< [m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(FD_FIELD(damping)
                 .unit("N*s/m")
                 .positive()
                 .plausible(1e3, 1e10)
                 .doc("C = c*pi*dw*bs, the steady-state force per infeed velocity (grinding: damping())")
                 .alias("gain_Ns_per_m"));
    a->Visit(quantity::grinding_stiffness(stiffness).alias("stiffness_N_per_m"));
    a->Visit(quantity::contact_position(contact_position).alias("contact_position_m"));
  }
};
/// F = stiffness*(x - rest_position)  (a cable carrier)
struct SpringForceEffect {
  bool enabled{false};
  double stiffness{0.0};      ///< [N/m]
  double rest_position{0.0};  ///< [m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(FD_FIELD(stiffness)
                 .unit("N/m")
                 .non_negative()
                 .plausible(0, 1e7)
                 .doc("spring rate (a cable carrier's)")
                 .alias("stiffness_N_per_m"));
    a->Visit(FD_FIELD(rest_position)
                 .unit("m")
                 .plausible(-5, 5, "mm")
                 .doc("where the spring force is 0")
                 .alias("rest_position_m"));
  }
};
/// The true moving mass replaces PlantParams::mass.
struct MassErrorEffect {
  bool enabled{false};
  double mass{102.04};  ///< [kg]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(quantity::mass(mass).alias("mass_kg"));
  }
};
/// The thrust acts `delay` after the command: F_thrust(t) = Ka*Kf*u(t - delay) (u = 0 before t0).
struct InputDelayEffect {
  bool enabled{false};
  double delay{0.0};  ///< [s]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(listed_enabled(enabled));
    a->Visit(FD_FIELD(delay)
                 .unit("s")
                 .non_negative()
                 .plausible(0, 0.1, "ms")
                 .doc("the command's delay to the thrust")
                 .alias("delay_s"));
  }
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

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(constant_force).doc("F = force (gravity on an incline, cable weight, an offset)"));
    a->Visit(FD_FIELD(coulomb_friction).doc("F = coulomb_force*sgn_eps(v)"));
    a->Visit(FD_FIELD(viscous_friction).doc("F = viscous*v"));
    a->Visit(
        FD_FIELD(stribeck_friction)
            .doc("F = sgn_eps(v)*(coulomb_force + (static_force - coulomb_force)*exp(-|v/stribeck_velocity|^delta))"));
    a->Visit(
        FD_FIELD(presliding)
            .doc(
                "the friction becomes LuGre with sigma0, sigma1 below, keeping Fs, Fc, vs, delta, sigma2 of friction"));
    a->Visit(FD_FIELD(cogging_ripple)
                 .doc("F = cogging_amplitude*sin(2 pi x/pitch + cogging_phase) + cogging_third*sin(6 pi x/pitch + "
                      "cogging_third_phase)"));
    a->Visit(FD_FIELD(reluctance_ripple).doc("F = F_thrust*reluctance_amplitude*sin(2 pi x/pitch + reluctance_phase)"));
    a->Visit(FD_FIELD(grinding_force)
                 .doc("the grinding section's force on, with C = damping, ke = stiffness, contact past "
                      "contact_position"));
    a->Visit(FD_FIELD(spring_force).doc("F = stiffness*(x - rest_position) (a cable carrier)"));
    a->Visit(FD_FIELD(mass_error).doc("the true moving mass `mass` replaces plant.mass"));
    a->Visit(FD_FIELD(input_delay).doc("F_thrust(t) = Ka*Kf*u(t - delay)"));
  }
  bool any() const;
  void validate(const std::string& prefix = "effects") const;
};

/// How the measured velocity is formed (SensorParams::velocity).
enum class VelocityMeasurement {
  kAuto,        ///< the true velocity when the sensor is ideal, else kDifference
  kTrue,        ///< the true velocity (a tachometer-like ideal sensor; only with an ideal sensor)
  kDifference,  ///< (x_meas[k] - x_meas[k-1]) / T, what a drive computes from an encoder
};
inline const std::vector<std::pair<VelocityMeasurement, const char*>>& enum_names(VelocityMeasurement) {
  static const std::vector<std::pair<VelocityMeasurement, const char*>> n = {
      {VelocityMeasurement::kAuto, "auto"},
      {VelocityMeasurement::kTrue, "true"},
      {VelocityMeasurement::kDifference, "difference"}};
  return n;
}

/// Position sensor (encoder) model. Both effects off by default.
struct SensorParams {
  double quantization{0.0};  ///< q [m]; 0 = ideal. x_meas = q*round((x + n)/q).
  double noise_stddev{0.0};  ///< standard deviation of Gaussian position noise n [m].
  std::uint64_t seed{1};     ///< seed of the noise generator (std::mt19937_64).
  /// How the measured velocity is formed; kTrue only with an ideal sensor: validate() refuses
  /// it with quantization or noise, which measure position only.
  VelocityMeasurement velocity{VelocityMeasurement::kAuto};

  bool ideal() const { return quantization == 0.0 && noise_stddev == 0.0; }
  /// The one rule of kAuto: the velocity is differenced from the counts unless the sensor is
  /// ideal (then it is the true velocity).
  bool differenced_velocity() const {
    return velocity == VelocityMeasurement::kDifference || (velocity == VelocityMeasurement::kAuto && !ideal());
  }
  template <class Archive>
  void Serialize(Archive* a) {
    // 0 or in [1e-12, 1] m: beyond, the measurement overflows or rounds to nothing (validate()).
    a->Visit(FD_FIELD(quantization)
                 .unit("m")
                 .non_negative()
                 .at_most(1.0)
                 .plausible(1e-10, 1e-4, "um")
                 .doc("encoder count q; 0 = ideal; else in [1e-12, 1]"));
    a->Visit(FD_FIELD(noise_stddev)
                 .unit("m")
                 .non_negative()
                 .at_most(1.0)
                 .plausible(0, 1e-4, "um")
                 .doc("standard deviation of Gaussian position noise; at most 1"));
    a->Visit(FD_FIELD(seed).doc("seed of the noise generator"));
    a->Visit(
        FD_FIELD(velocity).doc("auto: true for an ideal sensor, else difference; true (a tachometer) only with an "
                               "ideal sensor; difference: (x_k - x_k-1)/T"));
  }
  void validate(const std::string& prefix = "sensor") const;
};

/// CVODE settings: BDF + Newton + dense direct solver, analytic Jacobian.
/// Defaults are tight enough that halving them moves every paper figure by < 1% (tested).
struct IntegratorParams {
  double rtol{1e-8};
  double atol_position{1e-12};  ///< [m]
  double atol_velocity{1e-12};  ///< [m/s]
  double atol_bristle{1e-13};   ///< [m]
  double atol_grinding{1e-9};   ///< [N]
  double atol_current{1e-9};    ///< [A]
  long max_steps{100000};       ///< per control period.

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(rtol).unit("-").positive().plausible(1e-14, 1e-3).doc("CVODE relative tolerance"));
    a->Visit(FD_FIELD(atol_position).unit("m").positive().plausible(1e-18, 1e-6).doc("absolute tolerance of x"));
    a->Visit(FD_FIELD(atol_velocity).unit("m/s").positive().plausible(1e-18, 1e-6).doc("absolute tolerance of v"));
    a->Visit(FD_FIELD(atol_bristle).unit("m").positive().plausible(1e-18, 1e-6).doc("absolute tolerance of z"));
    a->Visit(FD_FIELD(atol_grinding).unit("N").positive().plausible(1e-15, 1e-3).doc("absolute tolerance of Fg"));
    a->Visit(FD_FIELD(atol_current).unit("A").positive().plausible(1e-15, 1e-3).doc("absolute tolerance of i"));
    a->Visit(FD_FIELD(max_steps).unit("-").positive().doc("CVODE steps per control period"));
  }
  void validate(const std::string& prefix = "integrator") const;
};

/// Initial state.
struct InitialState {
  double position{0.0};  ///< [m]
  double velocity{0.0};  ///< [m/s]
  double bristle{0.0};   ///< z [m]
  double grinding{0.0};  ///< Fg [N]
  double current{0.0};   ///< i [A]

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(position).unit("m").plausible(-5, 5, "mm").doc("x(0)"));
    a->Visit(FD_FIELD(velocity).unit("m/s").plausible(-10, 10, "mm/s").doc("v(0)"));
    a->Visit(FD_FIELD(bristle).unit("m").plausible(-1e-3, 1e-3).doc("z(0)"));
    a->Visit(FD_FIELD(grinding).unit("N").plausible(-1e5, 1e5).doc("Fg(0)"));
    a->Visit(FD_FIELD(current).unit("A").plausible(-1000, 1000).doc("i(0)"));
  }
};

/// Everything that defines the plant.
struct PlantParams {
  /// m [kg]: from the paper's zeta = 0.7, m = ((sigma1+sigma2)/1.4)^2/sigma0 = 102.04 kg.
  double mass{102.04};
  double amplifier_gain{2.6};    ///< Ka [A/V] (or V/V with the electrical option); Ka*Kf = 260 N/V.
  double force_constant{100.0};  ///< Kf [N/A]. Thrust = Ka*Kf*u without electrical dynamics.
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

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(quantity::mass(mass));
    a->Visit(FD_FIELD(amplifier_gain)
                 .unit("A/V")
                 .positive()
                 .plausible(0.01, 100)
                 .doc("Ka (V/V with the electrical option); Ka*Kf = thrust per volt"));
    a->Visit(FD_FIELD(force_constant).unit("N/A").positive().plausible(1, 2000).doc("Kf"));
    a->Visit(FD_FIELD(input_limit)
                 .unit("V")
                 .positive()
                 .plausible(1, 1000)
                 .doc("the amplifier's input range: a larger |u| is clipped, a NaN/inf u is rejected and 0 V applied"));
    a->Visit(FD_FIELD(friction));
    a->Visit(FD_FIELD(ripple));
    a->Visit(FD_FIELD(grinding));
    a->Visit(FD_FIELD(electrical));
    a->Visit(FD_FIELD(sensor));
    a->Visit(FD_FIELD(integrator));
    a->Visit(FD_FIELD(initial));
    a->Visit(FD_FIELD(effects));
  }
  double thrust_gain() const { return amplifier_gain * force_constant; }  ///< Ka*Kf [N/V]
  void validate(const std::string& prefix = "plant") const;
  /// For an integrator failure message: the `n` fastest rates of the model [1/s] with the keys
  /// and values that set them (presliding oscillation sqrt(sigma0/m), bristle damping sigma1/m,
  /// viscous c/m, grinding lag 1/tau_g, current loop R/L, the effects' springs and dampers),
  /// and the integrator's limits. One line.
  std::string fastest_time_scales(std::size_t n = 2) const;
};

}  // namespace feeddrive::plant

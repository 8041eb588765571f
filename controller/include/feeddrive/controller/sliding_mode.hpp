#pragma once
// Model-based sliding-mode controller of Xie & Liang (Sec. 5.2, eqs. 16-19):
//
//   e = xd - x,   S = de/dt + lambda*e,   reaching law dS/dt = -eta*sw(S) - k*S   (eq. 18)
//   u = m/(Ka*Kf) * (xd'' + lambda*(xd' - x') + eta*sw(S) + k*S) + (F^f + F^g + F^r)/(Ka*Kf)
//                                                                                 (eq. 19)
// with sw = sgn (the paper), sat(S/phi) or tanh(S/phi) (boundary layer phi [m/s]).
// Units are SI, eta in m/s^2 (see paper-analysis.md Sec. 3.3). m, Ka*Kf and the force models
// are the controller's *model* (SlidingModeParams::model), which may differ from the plant.
//
// The reluctance ripple depends on the commanded force itself, F^r = Fcog(x) + Ka*Kf*u*r(x),
// so the law is solved for u exactly:  Ka*Kf*u*(1 - r(x)) = m*(...) + F^f + F^g + Fcog(x).
//
// Friction estimate with the plant's true z (friction_state = true, the paper's "all states
// available"): F^f = sigma0*z + sigma1(v)*zdot^ + sigma2*v with the model's sigma0, sigma1,
// sigma2 and the bristle *rate* taken from the true z as well,
//   zdot^_k = (z_k - z_{k-1})/T            (the model rate v - sigma0|v|z/g(v) at the first sample)
// not from the model law zdot = v - sigma0*|v|*z/g(v). The model law mixes the plant's z with the
// model's g(v): with the plant's Fs, Fc 30 % off, z settles at g_plant/sigma0 and the model rate
// reads zdot = v*(1 - g_plant/g_model) = -+0.3 v in steady sliding, i.e. sigma1*zdot ~ 1,200 N at
// 0.2 m/s (more than the switching authority m*eta = 510 N, so S leaves the layer and the error
// grows to millimetres). The difference of the true z is the plant's own rate, whatever its
// parameters, and is 0 in steady sliding. See docs/controllers.md ("Model mismatch").
//
// A model with effects (plant.effects keys under controller.model, e.g. the effects feeddrive-fit
// found: docs/fit.md): the modifying ones (mass_error, presliding, grinding_force) are folded
// into the model (plant::effective_params), the additive ones are compensated with the others:
// with F_extra = e0(x, v) + e1(x)*F (e1 from reluctance_ripple),
//   Ka*Kf*u*(1 - r(x) - e1) = m*(...) + F^f + F^g + Fcog(x) + e0.
// input_delay in a model is ignored (the controller's delay is computation_delay).
//
// Delay compensation (compensate_delay, computation delay d > 0): the command u_k acts only
// over [t_k + d, t_{k+1} + d). The controller keeps its issued commands (delay_line.hpp); the
// x,v,d observer predicts each period with the command that acts in it (piecewise constant),
// so its estimate at t_k is the drive's state now; the law then uses
//   x_p, v_p = the model prediction from (x^, v^) over [t_k, t_k + d] through the commands
//              already issued (model forces and d^ held at their t_k values),
//   r_p      = the reference previewed to t_k + d (preview(), exact for polynomial segments),
// i.e. a Smith-predictor structure (Smith 1957): with an exact model the loop is the delay-free
// loop shifted by d; model errors enter through the observer's d^ and correction.
//
// Adapted model (adaptation_rate gamma > 0, feedforward_adaptation.hpp): the bristle observer
// runs with the adapted friction level theta (its Fs, Fc times theta), and the inertial force the
// model's mass misses, delta_m*m*xd'', is added to the model forces as an additive force e0 (so
// the law and the observer's prediction both carry it; over the predictor's interval it is held
// at its t_k value); theta and delta_m are updated once per period from the residual -m*d^ at t_k.
//
// Order within one period: (optionally) correct the x,v observer with the new sample; compute
// u from the estimates at t_k; then advance the force observers and predict x,v over [t_k, t_k+T]
// with u held (so nothing uses information from after t_k).

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "feeddrive/controller/controller.hpp"
#include "feeddrive/controller/delay_line.hpp"
#include "feeddrive/controller/feedforward_adaptation.hpp"
#include "feeddrive/controller/friction_observer.hpp"
#include "feeddrive/controller/quantity.hpp"
#include "feeddrive/controller/state_observer.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::controller {

namespace smc {
struct ModelForces;  // sliding_mode_law.hpp
}  // namespace smc

enum class Switching { kSign, kSaturation, kTanh };
inline const std::vector<std::pair<Switching, const char*>>& enum_names(Switching) {
  static const std::vector<std::pair<Switching, const char*>> n = {
      {Switching::kSign, "sgn"}, {Switching::kSaturation, "sat"}, {Switching::kTanh, "tanh"}};
  return n;
}
std::string to_string(Switching s);

/// Where the friction estimate F^f gets its bristle state.
enum class StateSource {
  kTrue,      ///< from the plant's true state (the paper's "all states available")
  kObserver,  ///< from an observer driven by the measured velocity
};
inline const std::vector<std::pair<StateSource, const char*>>& enum_names(StateSource) {
  static const std::vector<std::pair<StateSource, const char*>> n = {{StateSource::kTrue, "true"},
                                                                     {StateSource::kObserver, "observer"}};
  return n;
}
std::string to_string(StateSource s);

struct SlidingModeParams {
  double eta{5.0};      ///< [m/s^2]
  double k{10.0};       ///< [1/s]
  double lambda{50.0};  ///< [1/s]
  Switching switching{Switching::kSign};
  double boundary_layer{1e-3};  ///< phi [m/s], for sat and tanh
  bool compensate_friction{true};
  bool compensate_ripple{true};
  bool compensate_grinding{true};
  bool feedforward_acceleration{true};  ///< include m*xd''
  StateSource friction_state{StateSource::kTrue};
  StateSource grinding_state{StateSource::kTrue};
  double observer_gain{0.0};  ///< L [1/s] of the bristle observer correction, see friction_observer.hpp
  MotionSource motion_state{MotionSource::kMeasured};
  double motion_observer_bandwidth{300.0};  ///< w_o [rad/s] of the x,v observer
  /// Estimate a lumped disturbance acceleration d^ in the x,v observer and add m*d^ to the
  /// force (motion_state = observer only).
  bool motion_observer_disturbance{true};
  /// Computation delay d [s] (scenario controller.computation_delay): the command computed from
  /// the sample at t_k acts over [t_k + d, t_{k+1} + d); the plant applies it.
  double computation_delay{0.0};
  /// Compensate the known delay (needs motion_state = observer): the x,v observer predicts with
  /// the command that actually acts (DelayLine), and the law acts on the state predicted to
  /// t_k + d through the commands already issued, with the reference previewed to t_k + d.
  bool compensate_delay{false};
  /// gamma [1/s] of the friction and inertia feedforward adapted online from the x,v,d observer's
  /// residual (feedforward_adaptation.hpp; needs motion_state = observer with the disturbance
  /// state); 0: off, the model's feedforward as it is.
  double adaptation_rate{0.0};
  double u_min{-10.0};       ///< [V]
  double u_max{10.0};        ///< [V]
  plant::PlantParams model;  ///< the controller's model of the drive
  double period{1e-4};       ///< control period T [s] (for the observers)

  /// The scenario keys (controller.*); model, period and computation_delay come from the
  /// scenario (controller.model, control_period, controller.computation_delay).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(eta).unit("m/s^2").non_negative().plausible(0, 1000, "mm/s^2").doc("constant reaching rate"));
    a->Visit(FD_FIELD(k).unit("1/s").non_negative().plausible(0, 1e4).doc("proportional reaching rate"));
    a->Visit(FD_FIELD(lambda).unit("1/s").positive().plausible(0.1, 1e5).doc("sliding-surface slope"));
    a->Visit(FD_FIELD(switching).doc("sgn, sat (sat(S/phi)) or tanh (tanh(S/phi))"));
    a->Visit(FD_FIELD(boundary_layer)
                 .unit("m/s")
                 .unchecked()
                 .plausible(1e-9, 1.0, "mm/s")
                 .doc("phi, for sat and tanh (> 0 there)"));
    a->Visit(FD_FIELD(compensate_friction).doc("the model friction term of eq. 19"));
    a->Visit(FD_FIELD(compensate_ripple).doc("the model ripple term of eq. 19"));
    a->Visit(FD_FIELD(compensate_grinding).doc("the model grinding term of eq. 19"));
    a->Visit(FD_FIELD(feedforward_acceleration).doc("the m*xd'' term"));
    a->Visit(FD_FIELD(friction_state)
                 .doc("true: the friction estimate from the plant's true z (the paper); observer: from the bristle "
                      "observer"));
    a->Visit(FD_FIELD(grinding_state).doc("the same choice for the grinding force"));
    a->Visit(FD_FIELD(observer_gain)
                 .unit("1/s")
                 .non_negative()
                 .plausible(0, 1e5)
                 .doc("correction gain of the bristle observer"));
    a->Visit(FD_FIELD(motion_state)
                 .doc("measured: e and de/dt from the measured x and v (the paper); observer: from the x,v observer"));
    a->Visit(FD_FIELD(motion_observer_bandwidth)
                 .unit("rad/s")
                 .positive()
                 .plausible(1, 1e5)
                 .doc("pole of the x,v observer, p = exp(-w*T)"));
    a->Visit(FD_FIELD(motion_observer_disturbance)
                 .doc("with motion_state observer: estimate a disturbance acceleration and add m*d^"));
    a->Visit(
        FD_FIELD(compensate_delay).doc("predict the state to t_k + computation_delay (needs motion_state observer)"));
    a->Visit(quantity::adaptation_rate(adaptation_rate));
    a->Visit(quantity::u_min(u_min));
    a->Visit(quantity::u_max(u_max));
  }
  void validate(const std::string& prefix = "controller") const;
};

class SlidingModeController final : public Controller {
 public:
  explicit SlidingModeController(const SlidingModeParams& p);
  Command update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) override;
  bool needs_truth() const override;
  std::string name() const override { return "sliding_mode"; }

 private:
  /// The state the law starts from: the measurement, or the x,v observer's estimate once it has one.
  struct Estimate {
    double x;
    double v;
    bool use_observer;  ///< motion_state = observer
    bool observed;      ///< x, v are the observer's (it has seen a finite sample)
  };
  /// What the law acts on: the state, the reference and the model forces, at t_k or predicted to
  /// t_k + d (compensate_delay).
  struct LawInput;  // sliding_mode.cpp
  /// Corrects the x,v observer with the sample (motion_state = observer) and returns the estimate.
  Estimate estimate_state(const plant::Measurement& meas);
  /// F^f from the plant's true z (friction_state = true): sigma0*z + sigma1(v)*zdot^ + sigma2*v
  /// with zdot^_k = (z_k - z_{k-1})/T (see above); keeps z for the next rate.
  double true_friction(double v, double z);
  /// The model forces of eq. 19 at (x, v): friction and grinding from the truth or the observers,
  /// the ripple, and the model's additive effects.
  smc::ModelForces model_forces(double x, double v, const Truth* truth);
  /// The Smith predictor (see above): the state predicted from (x^, v^) over [t_k, t_k + d] through
  /// the commands already issued, the reference previewed to t_k + d, the ripple (and with the
  /// bristle observer F^f) at the predicted state.
  LawInput predict_to_action(const Estimate& est, const trajectory::Sample& ref, double t,
                             const smc::ModelForces& now) const;
  /// Advances the force observers over [t_k, t_k + T] and predicts the x,v observer with the
  /// command u (with compensate_delay: with the commands that act within the period).
  void advance_observers(const Estimate& est, const trajectory::Sample& ref, double t, bool delayed, double u,
                         const smc::ModelForces& now);

  SlidingModeParams p_;  ///< with the model's modifying effects folded in
  bool has_extra_;       ///< the model has additive effects (compensated with the others)
  FrictionObserver friction_observer_;
  GrindingObserver grinding_observer_;
  StateObserver motion_observer_;
  DelayLine delay_line_;
  FeedforwardAdaptation adaptation_;
  std::optional<double> last_true_z_;
};

}  // namespace feeddrive::controller

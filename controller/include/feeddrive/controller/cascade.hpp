#pragma once
// The usual CNC cascade: P position loop, PI velocity loop, velocity and acceleration feedforward,
// optional friction feedforward from the model and an optional disturbance observer.
//
//   v_cmd = kff_v*xd' + kp*(xd - x_m)
//   e_v   = v_cmd - v_m
//   F     = m^*( kv*e_v + ki*Integral(e_v) + kff_a*xd'' ) + F^f_ff - m^*d^
//   u     = sat(F/(Ka*Kf)^, u_min, u_max)
// The integrator is frozen while the output saturates in the direction of the error
// (conditional-integration anti-windup). Gains are scaled by the model mass so they read as
// bandwidths: kv [1/s], ki [1/s^2], kp [1/s].
//
// * Friction feedforward (friction_feedforward): F^f_ff = the model's LuGre friction along the
//   reference, from a bristle observer (friction_observer.hpp) driven by xd' (not by the
//   measurement: a feedforward term, free of sensor noise).
// * Disturbance observer (disturbance_observer_bandwidth w_d > 0): the x,v,d observer of
//   state_observer.hpp fed by the encoder (dead zone of one count q = quantization), predicting
//   with the model m^*x'' = F - F^f_ff; its lumped disturbance d^ [m/s^2] is cancelled by -m^*d^.
//   This is the extended-state form of the disturbance observer (Han 2009, "From PID to active
//   disturbance rejection control"; Ohnishi's DOB with the model as the nominal plant).
// * Delay (computation_delay d, compensate_delay): the feedforward forces (m^*kff_a*xd'' and
//   F^f_ff) use the reference previewed to t_k + d (delay_line.hpp, preview()), when the command
//   acts; the feedback compares the measurement with the reference at t_k; the disturbance
//   observer predicts with the command that acts.
// * Observer feedback (motion_state = observer; needs w_d > 0): the loops feed back the
//   observer's x^, v^ instead of the encoder's x_m and backward-differenced v_m, as the
//   sliding-mode controller does. With compensate_delay as well, the same Smith predictor as the
//   sliding-mode law (sliding_mode.hpp): x^, v^ predicted over [t_k, t_k + d] through the
//   commands already issued (model acceleration and d^ held at their t_k values), compared with
//   the reference previewed to t_k + d.
// * Velocity filter (velocity_filter_cutoff f_v > 0 [Hz]): the velocity fed back passes a
//   first-order low-pass 1/(1 + s/(2 pi f_v)), discretised exactly for a sample held over T:
//   v_f,k = v_f,k-1 + (1 - exp(-2 pi f_v T))*(v_k - v_f,k-1), started at the first finite v.
// * Adapted feedforward (adaptation_rate gamma > 0; needs w_d > 0): the friction feedforward's
//   bristle observer runs at the adapted level theta (Fs, Fc times theta) and delta_m*m^*xd''(t_k
//   + d) is added to the feedforward force (and so to the observer's model force); theta and
//   delta_m are updated once per period from the residual -m^*d^ (feedforward_adaptation.hpp).
//
// The tuning rule (cascade_tuning()) sets kv, ki, kp from the sample period, the computation
// delay and the sensor; see docs/controllers.md ("Cascade tuning rule").

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

/// controller.tuning: kp, kv, ki as given, or from cascade_tuning() (the rule).
enum class CascadeTuning { kManual, kRule };
inline const std::vector<std::pair<CascadeTuning, const char*>>& enum_names(CascadeTuning) {
  static const std::vector<std::pair<CascadeTuning, const char*>> n = {{CascadeTuning::kManual, "manual"},
                                                                       {CascadeTuning::kRule, "rule"}};
  return n;
}

struct CascadeParams {
  CascadeTuning tuning{CascadeTuning::kManual};
  double bandwidth_scale{1.0};                 ///< with the rule: multiplies its bandwidth
  double kp{100.0};                            ///< position gain [1/s]
  double kv{600.0};                            ///< velocity gain [1/s]
  double ki{40000.0};                          ///< velocity integral gain [1/s^2]
  double velocity_feedforward{1.0};            ///< kff_v [-]
  double acceleration_feedforward{1.0};        ///< kff_a [-]
  bool friction_feedforward{false};            ///< add the model friction along the reference
  double disturbance_observer_bandwidth{0.0};  ///< w_d [rad/s]; 0 = no disturbance observer
  double quantization{0.0};                    ///< encoder count q [m] for the observer's dead zone
  double computation_delay{0.0};               ///< d [s]: the command acts d after its sample
  bool compensate_delay{false};  ///< preview the reference by d; observer predicts with the acting command
  /// Feed back the observer's x^, v^ (observer; needs disturbance_observer_bandwidth > 0) or the
  /// measurement (measured, the default); with compensate_delay: predicted to t_k + d.
  MotionSource motion_state{MotionSource::kMeasured};
  double velocity_filter_cutoff{0.0};  ///< f_v [Hz] of the velocity low-pass; 0 = none
  double adaptation_rate{0.0};         ///< gamma [1/s] of the adapted feedforward; 0 = off
  double mass{102.04};                 ///< m^ [kg]
  double thrust_gain{260.0};           ///< (Ka*Kf)^ [N/V]
  plant::FrictionParams friction;      ///< the model's friction (friction feedforward)
  double u_min{-10.0};                 ///< [V]
  double u_max{10.0};                  ///< [V]
  double period{1e-4};                 ///< T [s]

  /// The scenario keys (controller.*); quantization, computation_delay, mass, thrust_gain,
  /// friction and period come from the scenario (controller.model, control_period, ...).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(
        FD_FIELD(tuning).doc("manual: kp, kv, ki as given; rule: from the control period, computation_delay and the "
                             "sensor (kp, kv, ki then not given)"));
    a->Visit(FD_FIELD(bandwidth_scale)
                 .unit("-")
                 .positive()
                 .plausible(0.01, 10)
                 .doc("with tuning rule: multiplies the rule's bandwidth"));
    a->Visit(FD_FIELD(kp).unit("1/s").non_negative().plausible(0, 1e4).doc("position gain"));
    a->Visit(FD_FIELD(kv).unit("1/s").non_negative().plausible(0, 1e5).doc("velocity gain"));
    a->Visit(FD_FIELD(ki).unit("1/s^2").non_negative().plausible(0, 1e9).doc("velocity integral gain"));
    a->Visit(FD_FIELD(velocity_feedforward).unit("-").plausible(0, 2).doc("kff_v"));
    a->Visit(FD_FIELD(acceleration_feedforward).unit("-").plausible(0, 2).doc("kff_a"));
    a->Visit(FD_FIELD(friction_feedforward).doc("add the model's LuGre friction along the reference"));
    a->Visit(FD_FIELD(disturbance_observer_bandwidth)
                 .unit("rad/s")
                 .non_negative()
                 .plausible(0, 1e5)
                 .doc("x,v,d observer fed by the encoder; 0: off"));
    a->Visit(FD_FIELD(compensate_delay)
                 .doc("feedforward forces at t_k + computation_delay; the observer predicts with the acting command "
                      "(with motion_state observer: the feedback state too)"));
    a->Visit(FD_FIELD(motion_state)
                 .doc("the x, v fed back: measured (the encoder, velocity as the sensor gives it) or observer (x^, v^; "
                      "needs disturbance_observer_bandwidth > 0)"));
    a->Visit(FD_FIELD(velocity_filter_cutoff)
                 .unit("Hz")
                 .non_negative()
                 .plausible(0, 1e5)
                 .doc("first-order low-pass on the velocity fed back; 0: none"));
    a->Visit(quantity::adaptation_rate(adaptation_rate));
    a->Visit(quantity::u_min(u_min));
    a->Visit(quantity::u_max(u_max));
  }
  void validate(const std::string& prefix = "controller") const;
};

/// With tuning rule: sets kp, kv, ki from cascade_tuning() with the params' period,
/// computation_delay and bandwidth_scale; `differenced_velocity`: the model's sensor differences
/// the velocity from the encoder (plant::SensorParams::differenced_velocity()). The observer's v^
/// is no backward difference; the Smith predictor (motion_state observer with compensate_delay)
/// takes the known delay out of the loop; a velocity filter adds its lag 1/(2 pi f_v).
/// Manual: no change.
void apply_tuning(CascadeParams& p, bool differenced_velocity);

/// The cascade tuning rule (docs/controllers.md, "Cascade tuning rule"): with the effective
/// loop delay tau = d + T/2 (zero-order hold) + T/2 (velocity differenced from the encoder;
/// 0 for a measured velocity), the velocity loop L(s) = (kv + ki/s)/s * exp(-s*tau) crosses over
/// at w_v with phase margin 45 deg when the PI corner is w_v/4:
///   w_v = (pi/4 - atan(1/4))/tau,  kv = w_v/sqrt(1 + 1/16),  ki = kv*w_v/4,  kp = w_v/4.
/// `scale` multiplies w_v (1 = the rule). Returns {kp, kv, ki}.
/// `extra_lag` [s] adds to tau (a velocity filter's time constant 1/(2 pi f_v)); a delay that
/// the Smith predictor removes (motion_state observer with compensate_delay) is passed as 0.
struct CascadeGains {
  double kp, kv, ki;
};
CascadeGains cascade_tuning(double period, double computation_delay, bool differenced_velocity, double scale = 1.0,
                            double extra_lag = 0.0);

class CascadeController final : public Controller {
 public:
  explicit CascadeController(const CascadeParams& p);
  Command update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) override;
  std::string name() const override { return "cascade"; }

 private:
  double filter_velocity(double v);  ///< the velocity low-pass (identity without a cutoff)
  CascadeParams p_;
  double integral_{0.0};
  FrictionObserver friction_ff_;
  StateObserver observer_;
  DelayLine delay_line_;
  FeedforwardAdaptation adaptation_;
  double velocity_filter_gain_{1.0};  // 1 - exp(-2 pi f_v T); 1 = no filter
  double v_filtered_{0.0};
  bool v_filter_started_{false};
};

}  // namespace feeddrive::controller

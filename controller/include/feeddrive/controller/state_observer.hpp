#pragma once
// Model-based observer of position, velocity and (optionally) a lumped disturbance
// acceleration, for a quantized encoder. A discrete extended-state observer (Luenberger
// predictor-corrector) whose prediction step is the controller's drive model.
//
// State w = [x, v, d]: d [m/s^2] lumps every acceleration the model misses (model error, the
// variation of friction within a period, ...). Per control period T, with the command u_k just
// decided and the model force
//   a_k = (Ka*Kf*u_k*(1 - r(x^)) - Fcog(x^) - F^f - F^g) / m          (Xie & Liang eq. 4 model)
// predict:   x^- = x^ + v^*T + (a_k + d^)*T^2/2,   v^- = v^ + (a_k + d^)*T,   d^- = d^
// correct at the next sample with the innovation r:
//   x^ = x^- + l1*r,   v^ = v^- + l2*r,   d^ = d^- + l3*r
// For an encoder of resolution q the measurement only says x lies in the cell
// [x_meas - q/2, x_meas + q/2]; the innovation is the distance from x^- to that cell
//   r = (x_meas - q/2) - x^-  if x^- is below it,  (x_meas + q/2) - x^-  if above,  else 0
// (a dead zone of one count, the set-membership view of quantization). A prediction that stays
// consistent with the encoder is not disturbed, so the quantization staircase does not leak into
// v^. With q = 0 this is the usual r = x_meas - x^-.
// The gains place every pole of the error dynamics e+ = (I - L*C)*A*e at p = exp(-w_o*T):
//   with d:     l1 = 1 - p^3,  l2 = 3(1-p)^2(1+p)/(2T),  l3 = (1-p)^3/T^2
//   without d:  l1 = 1 - p^2,  l2 = (1-p)^2/T             (the critically damped alpha-beta
//                                                          filter, Kalata 1984)
// (derived by matching det(zI - (I-LC)A) to (z-p)^n). The model carries the fast dynamics and
// the encoder only corrects slow drift, so w_o can sit far below the quantization noise band.

#include <string>
#include <utility>
#include <vector>

namespace feeddrive::controller {

/// Where a controller's feedback takes x and v from (the sliding-mode law's e and de/dt, the
/// cascade's loops).
enum class MotionSource {
  kMeasured,  ///< the measured position and velocity as they are (the paper)
  kObserver,  ///< a model-based observer of x and v (this StateObserver) fed by the encoder
};
inline const std::vector<std::pair<MotionSource, const char*>>& enum_names(MotionSource) {
  static const std::vector<std::pair<MotionSource, const char*>> n = {{MotionSource::kMeasured, "measured"},
                                                                      {MotionSource::kObserver, "observer"}};
  return n;
}
std::string to_string(MotionSource s);

class StateObserver {
 public:
  /// bandwidth: w_o [rad/s]; period: T [s]; with_disturbance: estimate d; quantization: the
  /// encoder's resolution q [m] (0: an ideal sensor).
  StateObserver(double bandwidth, double period, bool with_disturbance = true, double quantization = 0.0);

  /// Corrects the prediction with a new measurement; the first call initialises x^ = x_meas,
  /// v^ = v0, d^ = 0.
  void correct(double x_measured, double v0 = 0.0);
  /// Predicts one period ahead under model acceleration a [m/s^2] (d^ is added here).
  void predict(double acceleration);
  /// Predicts one period ahead when the model acceleration is piecewise constant within it (a
  /// delayed command switching inside the period): dv = sum a_i*tau_i and dx = the double
  /// integral of the model acceleration over the period (sum a_i*tau_i*(tau_i/2 + time after
  /// piece i)); d^ is added as in predict().
  void predict_increments(double dv, double dx);

  double position() const { return x_; }
  double velocity() const { return v_; }
  double disturbance() const { return d_; }  ///< d^ [m/s^2]; 0 without the disturbance state
  bool initialised() const { return initialised_; }

 private:
  double l1_, l2_, l3_;
  double period_;
  double half_cell_;
  double x_{0.0};
  double v_{0.0};
  double d_{0.0};
  bool initialised_{false};
};

}  // namespace feeddrive::controller

#pragma once
// The simulated drive as a component: CVODE-integrated dynamics plus the encoder model.
// One object, two calls per control period, shaped like drive hardware:
//   Measurement m = plant.measure();   // what the controller sees at t_k
//   plant.advance(u, t_{k+1});         // apply the held command over [t_k, t_{k+1})
//
// With the input_delay effect (params.hpp) the ODE sees u_d(t) = u(t - d), d = delay: the
// command held from t_j acts from t_j + d until the next command's t_{j+1} + d, and u_d = 0
// before the first command's t_0 + d. advance() keeps the commands (t_j, u_j) that still act or
// will, and integrates [t, t_next] piecewise, restarting CVODE at every switch time t_j + d
// inside the interval (the CVODE guide's jump discontinuity); at most d/T + 2 commands are kept.
// Without the effect advance() is one integrator step per period, as before.

#include <cstddef>
#include <deque>
#include <utility>
#include <vector>

#include "feeddrive/plant/cvode_integrator.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"

namespace feeddrive::plant {

class Plant {
 public:
  /// period: the control period T [s] (the sensor's sample period).
  Plant(const PlantParams& params, double period, double t0 = 0.0);

  /// The params as given (effects not folded in).
  const PlantParams& params() const { return params_; }
  double time() const { return integrator_.time(); }
  State state() const { return State::from_vector(integrator_.state()); }

  /// Samples the encoder at the current time. Call exactly once per control period.
  Measurement measure();
  /// Force breakdown at the current state when u is commanded now; with input_delay the thrust
  /// is that of the delayed input u_d(t) acting now (u itself if delay = 0).
  Forces forces(double u) const;
  /// Integrates to t_next with input u held (zero-order hold), delayed by input_delay if enabled.
  void advance(double u, double t_next);

  /// Number of held commands kept for the input delay (0 without the effect).
  std::size_t input_history_size() const { return history_.size(); }
  /// Commands (t_j, u_j) issued before the start time that still act through the input delay
  /// (replaying a record from mid-way); in time order, before the first advance(). No-op without
  /// the effect.
  void prime_input_history(const std::vector<std::pair<double, double>>& commands);

  CvodeIntegrator::Stats integrator_stats() const { return integrator_.stats(); }

 private:
  struct HeldCommand {
    double t;  ///< time the command was issued [s]; it acts from t + delay
    double u;  ///< [V]
  };
  void advance_delayed(double u, double t_next);
  /// u_d at time tau from the history (0 before the first command acts).
  double delayed_input(double tau) const;

  PlantParams params_;
  EffectiveParams effective_;
  CvodeIntegrator integrator_;
  Sensor sensor_;
  bool delayed_;  ///< input_delay enabled
  double delay_;  ///< d [s]
  double snap_;   ///< switch times within snap_ of an interval end are taken as that end [s]
  std::deque<HeldCommand> history_;
};

}  // namespace feeddrive::plant

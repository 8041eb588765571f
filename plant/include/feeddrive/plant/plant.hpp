#pragma once
// The simulated drive as a component: CVODE-integrated dynamics plus the encoder model.
// One object, two calls per control period, shaped like drive hardware:
//   Measurement m = plant.measure();   // what the controller sees at t_k
//   plant.advance(u, t_{k+1});         // apply the held command over [t_k, t_{k+1})

#include "feeddrive/plant/cvode_integrator.hpp"
#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/sensor.hpp"

namespace feeddrive::plant {

class Plant {
 public:
  /// period: the control period T [s] (the sensor's sample period).
  Plant(const PlantParams& params, double period, double t0 = 0.0);

  const PlantParams& params() const { return params_; }
  double time() const { return integrator_.time(); }
  State state() const { return State::from_vector(integrator_.state()); }

  /// Samples the encoder at the current time. Call exactly once per control period.
  Measurement measure();
  /// Force breakdown at the current state under input u.
  Forces forces(double u) const;
  /// Integrates to t_next with input u held (zero-order hold).
  void advance(double u, double t_next);

  CvodeIntegrator::Stats integrator_stats() const { return integrator_.stats(); }

 private:
  PlantParams params_;
  CvodeIntegrator integrator_;
  Sensor sensor_;
};

}  // namespace feeddrive::plant

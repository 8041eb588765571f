#pragma once
// The usual CNC cascade: P position loop, PI velocity loop, velocity and acceleration feedforward.
//
//   v_cmd = kff_v*xd' + kp*(xd - x_m)
//   e_v   = v_cmd - v_m
//   F     = m^*( kv*e_v + ki*Integral(e_v) + kff_a*xd'' )
//   u     = sat(F/(Ka*Kf)^, u_min, u_max)
// The integrator is frozen while the output saturates in the direction of the error
// (conditional-integration anti-windup). Gains are scaled by the model mass so they read as
// bandwidths: kv [1/s], ki [1/s^2], kp [1/s].

#include "feeddrive/controller/controller.hpp"

namespace feeddrive::controller {

struct CascadeParams {
  double kp{100.0};            ///< position gain [1/s]
  double kv{600.0};            ///< velocity gain [1/s]
  double ki{40000.0};          ///< velocity integral gain [1/s^2]
  double velocity_feedforward{1.0};      ///< kff_v [-]
  double acceleration_feedforward{1.0};  ///< kff_a [-]
  double mass{102.04};         ///< m^ [kg]
  double thrust_gain{260.0};   ///< (Ka*Kf)^ [N/V]
  double u_min{-10.0};         ///< [V]
  double u_max{10.0};          ///< [V]
  double period{1e-4};         ///< T [s]
  void validate(const std::string& prefix = "controller") const;
};

class CascadeController final : public Controller {
 public:
  explicit CascadeController(const CascadeParams& p);
  Command update(const trajectory::Sample& ref, const plant::Measurement& meas,
                 const Truth* truth) override;
  std::string name() const override { return "cascade"; }

 private:
  CascadeParams p_;
  double integral_{0.0};
};

}  // namespace feeddrive::controller

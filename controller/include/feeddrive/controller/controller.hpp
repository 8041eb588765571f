#pragma once
// The controller interface. A controller sees the reference and the *measured* signals; the
// plant's hidden states (bristle deflection z, grinding force Fg) are passed only to
// controllers configured for the paper's "all states available" assumption.

#include <limits>
#include <string>

#include "feeddrive/plant/sensor.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::controller {

/// Plant states that real hardware cannot measure; available only in simulation.
struct Truth {
  double z{0.0};   ///< LuGre bristle deflection [m]
  double fg{0.0};  ///< grinding force state [N]
};

/// One controller output.
struct Command {
  double u{0.0};              ///< applied (saturated) control input [V]
  double u_unsaturated{0.0};  ///< before saturation [V]
  /// Controller-internal diagnostics (NaN when a controller has no such quantity).
  double sliding{std::numeric_limits<double>::quiet_NaN()};     ///< S [m/s]
  double z_estimate{std::numeric_limits<double>::quiet_NaN()};  ///< z used for F^_f [m]
};

class Controller {
 public:
  virtual ~Controller() = default;
  /// Computes the command for sample instant ref/meas (both at the same t). Called once per
  /// control period, in time order. `truth` may be nullptr (hardware); a controller that
  /// needs it (needs_truth()) throws std::logic_error then.
  virtual Command update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) = 0;
  virtual bool needs_truth() const { return false; }
  virtual std::string name() const = 0;
};

/// Saturates u to [lo, hi]; NaN maps to 0 (never apply a NaN command).
double saturate(double u, double lo, double hi);

}  // namespace feeddrive::controller

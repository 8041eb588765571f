#pragma once
// RAII wrapper of SUNDIALS CVODE (v6.4) for the feed-drive ODE.
//
// Method: BDF, Newton iteration, dense direct linear solver with the analytic Jacobian of
// dynamics.hpp, per-state absolute tolerances. The held control input u is piecewise constant,
// so the caller advances exactly to each control-period boundary and the integrator restarts
// there (CVodeReInit), as the CVODE guide prescribes for jump discontinuities in f.
// Within a period CVODE integrates only the active states (dynamics.hpp active_states), and for
// x and v their deviations from the period's Taylor prediction
//   x = x_k + v_k*tau + a_k*tau^2/2 + j_k*tau^3/6 + y_x,   v = v_k + a_k*tau + j_k*tau^2/2 + y_v
// (a_k = f_v, j_k = sum_j df_v/dy_j * f_j at the period start). Their errors are then bounded by
// the absolute tolerances, not by rtol times the axis position, and the BDF restart at order 1
// needs few steps because the deviations start at O(tau^3).
// The right-hand side is dynamics.hpp's on the effective params (effects.hpp), folded once at
// construction; the input u given to advance() is the one the ODE sees (Plant::advance delays it
// for the input_delay effect).
// Every failed SUNDIALS call becomes a std::runtime_error naming the call and its flag.

#include <memory>
#include <stdexcept>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/plant/dynamics.hpp"

namespace feeddrive::plant {

/// CVODE could not integrate a control period (too stiff, too fast, or a state that runs away):
/// a property of the scenario's keys, which the message names (PlantParams::fastest_time_scales).
/// The tools report it as bad input (exit 2).
class IntegrationError : public BadInput {  // the scenario's keys make the model unintegrable: exit 2
 public:
  using BadInput::BadInput;
};

class CvodeIntegrator {
 public:
  CvodeIntegrator(const PlantParams& params, double t0, const StateVector& y0);
  ~CvodeIntegrator();
  CvodeIntegrator(const CvodeIntegrator&) = delete;
  CvodeIntegrator& operator=(const CvodeIntegrator&) = delete;

  /// Integrates from the current time to t_next with the input held at u; restarts the
  /// integrator at the current time first (the input may have jumped there).
  void advance(double u, double t_next);

  double time() const { return t_; }
  const StateVector& state() const { return y_; }

  /// Replace the state (e.g. the plant is reset to a measured state) at time t.
  void reset(double t, const StateVector& y);

  /// Cumulative CVODE statistics (steps, rhs and Jacobian evaluations).
  struct Stats {
    long steps{0}, rhs_evals{0}, jac_evals{0}, error_test_fails{0}, nonlinear_fails{0};
  };
  Stats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double t_;
  StateVector y_;
};

}  // namespace feeddrive::plant

#pragma once
// RAII wrapper of SUNDIALS CVODE (v6.4) for the feed-drive ODE.
//
// Method: BDF, Newton iteration, dense direct linear solver with the analytic Jacobian of
// dynamics.hpp, per-state absolute tolerances. The held control input u is piecewise constant,
// so the caller advances exactly to each control-period boundary and the integrator restarts
// there (CVodeReInit), as the CVODE guide prescribes for jump discontinuities in f.
// Every failed SUNDIALS call becomes a std::runtime_error naming the call and its flag.

#include <memory>

#include "feeddrive/plant/dynamics.hpp"

namespace feeddrive::plant {

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

// The sliding-mode controller in closed loop with the CVODE plant reduced to a pure mass, against
// the analytic reaching-phase solution (Xie & Liang Fig. 18, notes Sec. 3.3), and the x,v,d
// observer's disturbance compensation against the analytic steady state.
#include <gtest/gtest.h>

#include <cmath>

#include "controller_util.hpp"
#include "feeddrive/controller/sliding_mode.hpp"

namespace feeddrive::controller {
namespace {

using test::kPi;

// Ideal (continuous, exact model) error dynamics of the SMC from rest against xd = A sin(w t):
//   e(0) = 0, S(0) = vd(0) = A w,   dS/dt = -eta sgn(S) - k S,   de/dt = S - lambda e.
// While S > 0 (until t_r = ln(1 + k S0/eta)/k) both are linear with closed forms
//   S(t) = (S0 + eta/k) e^{-kt} - eta/k,
//   e(t) = (S0 + eta/k)(e^{-kt} - e^{-lambda t})/(lambda - k) - eta/(k lambda) (1 - e^{-lambda t}).
// max e is where de/dt = S - lambda e = 0, found by bisection. Returns {max e, t of max, t_r}.
struct Reaching {
  double e_max, t_max, t_reach;
};
Reaching analytic_reaching(double s0, double eta, double k, double lambda) {
  const double c = s0 + eta / k;
  const auto S = [&](double t) { return c * std::exp(-k * t) - eta / k; };
  const auto e = [&](double t) {
    return c * (std::exp(-k * t) - std::exp(-lambda * t)) / (lambda - k) -
           eta / (k * lambda) * (1.0 - std::exp(-lambda * t));
  };
  const double t_reach = std::log(1.0 + k * s0 / eta) / k;
  double lo = 0.0, hi = t_reach;  // de/dt(0) = S0 > 0; de/dt(t_r) = -lambda e(t_r) < 0
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (S(mid) - lambda * e(mid) > 0 ? lo : hi) = mid;
  }
  return {e(lo), lo, t_reach};
}

// The same error dynamics integrated by RK4 with a small step, as an independent check of the
// closed form (the paper-analysis notes got 6.84 mm from a numerical integration).
double rk4_reaching_max(double s0, double eta, double k, double lambda) {
  double s = s0, e = 0.0, e_max = 0.0;
  const double h = 1e-6;
  const auto fs = [&](double sv) { return -eta * ((sv > 0) - (sv < 0)) - k * sv; };
  for (int i = 0; i < 200000; ++i) {  // 0.2 s; S reaches 0 at ~0.08 s (sgn flips only then)
    const double k1s = fs(s), k1e = s - lambda * e;
    const double k2s = fs(s + 0.5 * h * k1s), k2e = (s + 0.5 * h * k1s) - lambda * (e + 0.5 * h * k1e);
    const double k3s = fs(s + 0.5 * h * k2s), k3e = (s + 0.5 * h * k2s) - lambda * (e + 0.5 * h * k2e);
    const double k4s = fs(s + h * k3s), k4e = (s + h * k3s) - lambda * (e + h * k3e);
    s += h / 6 * (k1s + 2 * k2s + 2 * k3s + k4s);
    e += h / 6 * (k1e + 2 * k2e + 2 * k3e + k4e);
    e_max = std::max(e_max, e);
  }
  return e_max;
}

// The same loop in exact discrete time: a pure mass under a zero-order hold is integrated exactly
// by x+ = x + v T + a T^2/2, v+ = v + a T with a = Ka*Kf*u/m = the law's commanded acceleration
// (exact model, no forces). Written out here from eq. 19, independently of the controller class.
double discrete_reaching_max_window(double amplitude, double omega, double eta, double k, double lambda, double period,
                                    double t0, double t1) {
  double x = 0.0, v = 0.0, e_max = 0.0;
  const long n = std::lround(t1 / period) + 1;
  for (long i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * period;
    const double xd = amplitude * std::sin(omega * t), vd = amplitude * omega * std::cos(omega * t);
    const double ad = -amplitude * omega * omega * std::sin(omega * t);
    const double e = xd - x, ed = vd - v, s = ed + lambda * e;
    if (t >= t0 && t <= t1) e_max = std::max(e_max, std::abs(e));
    const double a = ad + lambda * ed + eta * ((s > 0) - (s < 0)) + k * s;
    x += v * period + 0.5 * a * period * period;
    v += a * period;
  }
  return e_max;
}

// max |e| over [0, t_end) of the exact discrete loop.
double discrete_reaching_max(double amplitude, double omega, double eta, double k, double lambda, double period,
                             double t_end) {
  return discrete_reaching_max_window(amplitude, omega, eta, k, lambda, period, 0.0, t_end - 0.5 * period);
}

// Fig. 18 on an exact pure-mass plant: 100 mm, 1 Hz sinusoid from rest, period 1e-4 s, the paper's
// eta = 5 m/s^2, k = 10 1/s, lambda = 50 1/s, hard sgn, model = plant.
TEST(SlidingModeClosedLoop, SinusoidFromRestMatchesTheReachingPhaseSolution) {
  const double A = 0.1, w = 2 * kPi, eta = 5.0, k = 10.0, lambda = 50.0, T = 1e-4;
  const Reaching ideal = analytic_reaching(A * w, eta, k, lambda);
  // The closed form, a fine RK4 and the notes' value agree (the notes quote 3 digits: 6.84 mm).
  EXPECT_NEAR(ideal.e_max, rk4_reaching_max(A * w, eta, k, lambda), 1e-9);
  EXPECT_NEAR(ideal.e_max, 6.84e-3, 0.005e-3);
  EXPECT_LT(ideal.t_max, ideal.t_reach);  // the peak is inside the reaching phase (S > 0)

  SlidingModeParams p;
  p.eta = eta;
  p.k = k;
  p.lambda = lambda;
  p.switching = Switching::kSign;
  p.model = test::pure_mass();
  p.period = T;
  p.u_min = -100.0;  // peak demand m*(lambda*A*w + eta + k*A*w)/(Ka*Kf) = 16.8 V: no saturation
  p.u_max = 100.0;
  SlidingModeController ctl(p);
  trajectory::SineParams sp;
  sp.amplitude = A;
  sp.frequency = 1.0;
  const auto ref = trajectory::make_sine(sp);
  const auto run = test::run_loop(p.model, ctl, *ref, T, std::lround(2.0 / T));

  const double peak = test::max_abs_error(run, 0.0, 0.5);
  // (1) Against the exact discrete-time loop: the pure mass under ZOH has no integration error,
  // so the only difference is CVODE's (rtol 1e-8 on the per-period increments, <= 6e-5 m each:
  // ~1e-12 m per period, ~1e-9 m over the 1000 periods to the peak). The peak lies in the
  // reaching phase (S > 0.3 m/s), where sgn(S) cannot flip on a rounding difference.
  EXPECT_NEAR(peak, discrete_reaching_max(A, w, eta, k, lambda, T, 0.5), 1e-9);
  // (2) Against the continuous-time solution: the ZOH holds the command over T while e' and xd''
  // move, which perturbs dS/dt at first order by ~lambda*T/2 = 0.25 % (the notes' 1e-4 s ZOH
  // run gave 6.82 vs 6.84 mm). 1 % = 4x that first-order effect; a wrong eta unit (5 mm/s^2)
  // gives 8.40 mm, a missing k*S term 7.6 mm, both far outside.
  EXPECT_NEAR(peak, ideal.e_max, 0.01 * ideal.e_max);
  // The peak occurs near the start, at the analytic t_max = 0.029 s (within 2 ms: the ZOH shift
  // is ~T/2 and e is flat at its maximum, so the sampled argmax can move by a few periods).
  double t_peak = 0.0;
  for (const auto& s : run)
    if (std::abs(s.xd - s.x) == peak) t_peak = s.t;
  EXPECT_NEAR(t_peak, ideal.t_max, 2e-3);
  // sliding = S: at t = 0, S = vd(0) = A w exactly (plant at rest at x = 0 = xd(0)).
  EXPECT_NEAR(run.front().sliding, A * w, 1e-15);
  // After the reaching phase (S = 0 at t_r = 0.08 s) e decays like e^{-lambda t}: by 1.5 s the
  // 6.8 mm have become 1e-30 m; what remains is the discrete sgn chatter. In discrete time the
  // hard sgn holds S only inside the quasi-sliding band |S| <= (eta + k|S|)*T ~ eta*T = 5e-4 m/s
  // (one period of full switching action), and e = S filtered by 1/(s + lambda), so
  // |e| <= eta*T/lambda = 1e-5 m. The exact discrete loop gives 2.08 um (max |S| 3.6e-4 m/s).
  const double settled = test::max_abs_error(run, 1.5, 2.0);
  const double settled_discrete = discrete_reaching_max_window(A, w, eta, k, lambda, T, 1.5, 2.0);
  EXPECT_LT(settled, eta * T / lambda);
  // CVODE vs the exact discrete loop in the chattering phase: a rounding-level difference can
  // flip one sgn inside the band and shift the chatter pattern, so not 1e-9 as in the reaching
  // phase; 10 % still fails a wrong law (a missing k*S or lambda*e' term changes the band).
  EXPECT_NEAR(settled, settled_discrete, 0.1 * settled_discrete);
  // Fig. 18 "then -> 0": over 3 orders of magnitude below the 6.84 mm start error.
  EXPECT_LT(settled, 1e-3 * peak);
}

// The x,v,d observer's disturbance estimate compensates a force the model does not know. A pure
// mass pushed by an unmodelled constant force F (acceleration d = F/m), exact discrete ZOH loop,
// SMC with sat(S/phi), reference xd = 0. Without d^ the steady state inside the boundary layer is
//   0 = dS/dt = -(eta/phi + k) S - d   =>  S = -d/(eta/phi + k),  e = S/lambda
// (exact also in discrete time: at rest the held command is constant). With d^ (all observer poles
// at exp(-wT), exact model otherwise) d^ -> d and the steady error -> 0; we require < 1 % of the
// uncompensated one. The sign of the compensation is what this checks: with the sign reversed the
// force would add 2 d instead of cancelling it.
TEST(SlidingModeClosedLoop, MotionObserverDisturbanceRemovesTheSteadyStateError) {
  const double T = 1e-4, force = 10.0;
  SlidingModeParams p;
  p.switching = Switching::kSaturation;
  p.boundary_layer = 1e-3;  // (eta/phi + k) T = 0.50 < 2: the discrete layer is stable
  p.model = test::pure_mass();
  p.period = T;
  p.u_min = -100.0;
  p.u_max = 100.0;
  const double d = force / p.model.mass;
  const double e_uncompensated = -d / (p.eta / p.boundary_layer + p.k) / p.lambda;

  const auto steady_error = [&](MotionSource source, bool with_d) {
    SlidingModeParams q = p;
    q.motion_state = source;
    q.motion_observer_disturbance = with_d;
    SlidingModeController ctl(q);
    double x = 0.0, v = 0.0;
    for (long i = 0; i < 30000; ++i) {  // 3 s: e settles with lambda = 50 1/s (e^-150)
      const plant::Measurement m{static_cast<double>(i) * T, x, v};
      const Command c = ctl.update({0.0, 0.0, 0.0, 0.0}, m, nullptr);
      const double a = q.model.thrust_gain() * c.u / q.model.mass + d;
      x += v * T + 0.5 * a * T * T;
      v += a * T;
    }
    return -x;  // e = xd - x
  };
  // Measured x, v (ideal sensor): the analytic boundary-layer steady state, to rounding.
  EXPECT_NEAR(steady_error(MotionSource::kMeasured, false), e_uncompensated, 1e-9 * std::abs(e_uncompensated));
  // With d^: the error is removed.
  EXPECT_LT(std::abs(steady_error(MotionSource::kObserver, true)), 0.01 * std::abs(e_uncompensated));
}

}  // namespace
}  // namespace feeddrive::controller

// The x,v(,d) observer: exact tracking under an exact model, pole placement of its error dynamics,
// and the velocity estimate from a 50 nm quantized encoder.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "feeddrive/controller/state_observer.hpp"

namespace feeddrive::controller {
namespace {

constexpr double kT = 1e-4;   // control period [s]
constexpr double kW = 300.0;  // observer bandwidth [rad/s] (the SMC default)

// With the exact model acceleration and ideal measurements of a constant-acceleration motion
// x = x0 + v0 t + a t^2/2, the prediction lands exactly on the next sample, so the innovation is 0
// and x^, v^ equal the motion (d^ stays 0). Tolerance: rounding of x ~ 0.2 m over 5000 steps
// (1e-12 m) and v ~ 1 m/s (1e-12 m/s).
TEST(StateObserver, TracksConstantAccelerationExactly) {
  const double x0 = 0.013, v0 = -0.2, a = 3.7;
  for (bool with_d : {false, true}) {
    StateObserver obs(kW, kT, with_d);
    for (int k = 0; k <= 5000; ++k) {
      const double t = k * kT;
      obs.correct(x0 + v0 * t + 0.5 * a * t * t, v0 + a * t);
      ASSERT_NEAR(obs.position(), x0 + v0 * t + 0.5 * a * t * t, 1e-12) << k;
      ASSERT_NEAR(obs.velocity(), v0 + a * t, 1e-12) << k;
      ASSERT_NEAR(obs.disturbance(), 0.0, 1e-6) << k;  // 1e-12 m / T^2 = 1e-4 m/s^2 scale, far less here
      obs.predict(a);
    }
  }
}

// The first correct() initialises x^ = x_meas, v^ = v0, d^ = 0.
TEST(StateObserver, FirstCorrectInitialises) {
  StateObserver obs(kW, kT, true, 50e-9);
  EXPECT_FALSE(obs.initialised());
  obs.correct(0.123, 0.4);
  EXPECT_TRUE(obs.initialised());
  EXPECT_EQ(obs.position(), 0.123);
  EXPECT_EQ(obs.velocity(), 0.4);
  EXPECT_EQ(obs.disturbance(), 0.0);
}

// Error sequences after each correction, for a motion at rest (x = v = 0, measurements 0), so the
// estimates *are* the errors and no cancellation limits how far they can decay.
struct ErrorRun {
  std::vector<double> ex, ev, ed;
};
ErrorRun error_run(bool with_d, double v0_error, int n) {
  StateObserver obs(kW, kT, with_d);
  ErrorRun r;
  for (int k = 0; k < n; ++k) {
    obs.correct(0.0, v0_error);  // v0 only used by the first call
    r.ex.push_back(obs.position());
    r.ev.push_back(obs.velocity());
    r.ed.push_back(obs.disturbance());
    obs.predict(0.0);
  }
  return r;
}

// All poles of e+ = (I - LC) A e at p = exp(-w T). By Cayley-Hamilton every error component then
// satisfies (q - p)^n e = 0 (q the shift): for the alpha-beta filter
//   e[k+2] - 2p e[k+1] + p^2 e[k] = 0,
// for the x,v,d observer
//   e[k+3] - 3p e[k+2] + 3p^2 e[k+1] - p^3 e[k] = 0.
// A single misplaced pole or wrong gain breaks the identity at O(1) of the terms. Tolerance:
// 1e-9 of the sum of the terms' magnitudes (rounding only).
TEST(StateObserver, ErrorDynamicsHaveAllPolesAtExpMinusWT) {
  const double p = std::exp(-kW * kT);
  const int n = 400;
  {
    const ErrorRun r = error_run(false, 1e-3, n);
    for (const auto* e : {&r.ex, &r.ev}) {
      for (int k = 0; k + 2 < n; ++k) {
        const double a = (*e)[k + 2], b = 2 * p * (*e)[k + 1], c = p * p * (*e)[k];
        ASSERT_NEAR(a - b + c, 0.0, 1e-9 * (std::abs(a) + std::abs(b) + std::abs(c))) << k;
      }
    }
  }
  {
    const ErrorRun r = error_run(true, 1e-3, n);
    for (const auto* e : {&r.ex, &r.ev, &r.ed}) {
      for (int k = 0; k + 3 < n; ++k) {
        const double a = (*e)[k + 3], b = 3 * p * (*e)[k + 2], c = 3 * p * p * (*e)[k + 1], d = p * p * p * (*e)[k];
        ASSERT_NEAR(a - b + c - d, 0.0, 1e-9 * (std::abs(a) + std::abs(b) + std::abs(c) + std::abs(d))) << k;
      }
    }
  }
}

// The same from the decay itself: for a double pole e[n] = (c1 + c2 n) p^n. From a velocity
// error c1 = e_v[0] with x^ exact, one period gives e_v[1] = c1 (1 - (1-p)^2) (prediction error
// c1 T, corrected by l2 = (1-p)^2/T), hence c2 = (1 - p) c1 and
//   e_v[n] = c1 (1 + (1-p) n) p^n.
// The ratio e_v[n+1]/e_v[n] = p (1 + 1/(n + 1/(1-p))) tends to p, from above, like 1/n.
// Tolerance of the closed form: 1e-9 relative (rounding over up to 3000 steps).
TEST(StateObserver, DecayRatioApproachesThePole) {
  const double p = std::exp(-kW * kT);
  const double c1 = 1e-3;
  const int n = 3000;
  const ErrorRun r = error_run(false, c1, n + 1);
  for (int k : {0, 1, 10, 100, 1000, 3000}) {
    const double expected = c1 * (1 + (1 - p) * k) * std::pow(p, k);
    EXPECT_NEAR(r.ev[k], expected, 1e-9 * expected) << k;
  }
  const double ratio = r.ev[n] / r.ev[n - 1];
  EXPECT_GT(ratio, p);                   // slower than a single pole: the n p^n term is there
  EXPECT_NEAR(ratio / p, 1.0, 1.0 / n);  // ... but it approaches p (here 1 + 1/(3000 + 33))
}

// Sum over j of |h_v(j)|, the l1 norm of the impulse response from a measurement error to the
// velocity estimate, computed from the pole-placement gains by iterating the error system
// e+ = (I - LC) A e + L n (independently of the observer class).
double velocity_noise_gain(bool with_d) {
  const double p = std::exp(-kW * kT), q = 1 - p, T = kT;
  const double l1 = with_d ? 1 - p * p * p : 1 - p * p;
  const double l2 = with_d ? 1.5 * q * q * (1 + p) / T : q * q / T;
  const double l3 = with_d ? q * q * q / (T * T) : 0.0;
  double x = l1, v = l2, d = l3;  // response to a unit measurement error at j = 0
  double sum = 0.0;
  for (int j = 0; j < 200000; ++j) {
    sum += std::abs(v);
    // predict (A), then correct with innovation r = -x^- (no further measurement error)
    const double xp = x + v * T + 0.5 * d * T * T, vp = v + d * T;
    x = xp - l1 * xp;
    v = vp - l2 * xp;
    d = d - l3 * xp;
  }
  return sum;
}

// 50 nm encoder, constant-velocity ramp. The dead-zone innovation is exactly the linear
// innovation with the effective measurement y = clamp(x^-, cell), and the cell contains the true
// x, so |y - x| <= q: the velocity error (after the initial transient) is bounded by
// q * sum|h_v|. For the alpha-beta filter the closed form is
//   sum|h_v| = l2 * 2 * max_N (N+1) p^N ~ 2 w/e   (V/Y = l2 z(z-1)/(z-p)^2, telescoping sum),
// i.e. ~ 2*300/e * 50 nm = 11 um/s (26 um/s with d), while the difference velocity (x_m[k]-x_m[k-1])/T has errors
// up to q/T = 500 um/s. The bound is rigorous, so it is checked as is.
TEST(StateObserver, QuantizedRampVelocityErrorFarBelowQOverT) {
  const double q = 50e-9;
  const double v = 1.234e-3;  // m/s: 2.468 counts per period, not commensurate with q
  const double x0 = 17e-9;
  const double p = std::exp(-kW * kT);
  {
    // The closed form of sum|h_v| for the alpha-beta filter agrees with the iterated one.
    double max_partial = 0.0;
    for (int N = 0; N < 100000; ++N) max_partial = std::max(max_partial, (N + 1) * std::pow(p, N));
    const double closed = (1 - p) * (1 - p) / kT * 2.0 * max_partial;
    EXPECT_NEAR(velocity_noise_gain(false), closed, 1e-9 * closed);
  }
  for (bool with_d : {false, true}) {
    SCOPED_TRACE(with_d ? "x,v,d" : "x,v");
    const double bound = q * velocity_noise_gain(with_d);
    EXPECT_LT(bound, 0.1 * q / kT);  // the bound itself is "well below q/T"
    StateObserver obs(kW, kT, with_d, q);
    double max_err = 0.0, max_diff_err = 0.0, last_meas = 0.0;
    for (int k = 0; k <= 20000; ++k) {
      const double x = x0 + v * k * kT;
      const double xm = q * std::round(x / q);
      obs.correct(xm, 0.0);  // velocity unknown at start: the transient decays like n^2 p^n
      if (k >= 2000) {       // 60 time constants: (1 + n + n^2) p^n * 1.2e-3 < 1e-14 m/s
        max_err = std::max(max_err, std::abs(obs.velocity() - v));
        max_diff_err = std::max(max_diff_err, std::abs((xm - last_meas) / kT - v));
      }
      last_meas = xm;
      obs.predict(0.0);  // exact model: no force on the ramp
    }
    EXPECT_LE(max_err, bound);
    EXPECT_LT(max_err, 0.1 * q / kT);
    // The difference velocity alternates 2 and 3 counts per period: errors of 0.47 and 0.53 q/T.
    EXPECT_GT(max_diff_err, 0.4 * q / kT);
  }
}

// A non-finite measurement carries no information: the observer skips the correction (coasts on
// its prediction) instead of taking the NaN into x^, v^, d^ for good.
TEST(StateObserver, NonFiniteMeasurementIsSkipped) {
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    StateObserver obs(kW, kT, true, 50e-9);
    obs.correct(bad, bad);
    EXPECT_FALSE(obs.initialised());
    obs.correct(0.0, 0.1);
    obs.predict(0.0);
    const double x_pred = obs.position(), v_pred = obs.velocity();
    obs.correct(bad);
    EXPECT_EQ(obs.position(), x_pred);
    EXPECT_EQ(obs.velocity(), v_pred);
    EXPECT_EQ(obs.disturbance(), 0.0);
  }
}

}  // namespace
}  // namespace feeddrive::controller

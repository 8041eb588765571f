// Computation delay (issue 10 point 3): the controller's record of its own delayed commands, the
// reference preview, the cascade tuning rule, and the sliding-mode delay compensation in closed
// loop on the CVODE plant with the plant's input_delay effect.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "controller_util.hpp"
#include "feeddrive/controller/cascade.hpp"
#include "feeddrive/controller/delay_line.hpp"
#include "feeddrive/controller/sliding_mode.hpp"

namespace feeddrive::controller {
namespace {

// Commands issued at 0, T, 2T with d = 1.5 T act from 1.5T, 2.5T, 3.5T: [2T, 3T] splits at 2.5T
// into u0 then u1, [3T, 4T] at 3.5T into u1 then u2; before 1.5T nothing acts (0). Exact: the switch times are sums of
// binary fractions here (T = 0.25).
TEST(DelayLine, SplitsAPeriodAtTheSwitchTimes) {
  DelayLine line(0.375, 1e-12);
  line.push(0.0, 1.0);
  line.push(0.25, 2.0);
  line.push(0.5, 3.0);
  const auto early = line.pieces(0.0, 0.25);
  ASSERT_EQ(early.size(), 1u);
  EXPECT_EQ(early[0].u, 0.0);
  const auto p = line.pieces(0.5, 0.75);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].t0, 0.5);
  EXPECT_EQ(p[0].t1, 0.625);
  EXPECT_EQ(p[0].u, 1.0);
  EXPECT_EQ(p[1].t0, 0.625);
  EXPECT_EQ(p[1].t1, 0.75);
  EXPECT_EQ(p[1].u, 2.0);
  line.forget_before(0.75);  // u0 no longer acts after 0.625
  const auto q = line.pieces(0.75, 1.0);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_EQ(q[0].u, 2.0);
  EXPECT_EQ(q[1].u, 3.0);
  // Zero delay: one piece, the command just issued.
  DelayLine none(0.0, 1e-12);
  none.push(0.0, 4.0);
  const auto n = none.pieces(0.0, 0.25);
  ASSERT_EQ(n.size(), 1u);
  EXPECT_EQ(n[0].u, 4.0);
}

// increments() integrates the piecewise-constant model acceleration twice over [t0, t1]: the
// commands of SplitsAPeriodAtTheSwitchTimes with a(u) = 2u act as a = 2 on [0.5, 0.625] and
// a = 4 on [0.625, 0.75]. By hand from rest: v = 2*0.125 = 0.25, x = 2*0.125^2/2 = 0.015625 after
// the first piece; then v += 4*0.125 -> 0.75, x += 0.25*0.125 + 4*0.125^2/2 -> 0.078125. Exact:
// every number is a binary fraction.
TEST(DelayLine, IncrementsIntegrateThePiecewiseAccelerationTwice) {
  DelayLine line(0.375, 1e-12);
  line.push(0.0, 1.0);
  line.push(0.25, 2.0);
  line.push(0.5, 3.0);
  const DelayLine::Increments inc = line.increments(0.5, 0.75, [](double u) { return 2.0 * u; });
  EXPECT_EQ(inc.dv, 0.75);
  EXPECT_EQ(inc.dx, 0.078125);
  // Before the first command acts, nothing does: a(0) over the whole interval.
  const DelayLine::Increments none = line.increments(0.0, 0.25, [](double u) { return 2.0 * u + 1.0; });
  EXPECT_EQ(none.dv, 0.25);
  EXPECT_EQ(none.dx, 0.03125);
}

// preview() is the cubic's Taylor expansion: exact for a cubic x(t) = a + b t + c t^2 + j t^3/6.
// Tolerance 1e-15 relative: rounding of a few operations.
TEST(DelayLine, PreviewIsExactForACubicSegment) {
  const auto x = [](double t) { return 0.01 + 0.2 * t + 0.5 * t * t + 2.4 * t * t * t / 6.0; };
  const auto v = [](double t) { return 0.2 + t + 1.2 * t * t; };
  const auto a = [](double t) { return 1.0 + 2.4 * t; };
  const double t = 0.3, h = 1e-3;
  const trajectory::Sample s{x(t), v(t), a(t), 2.4};
  const trajectory::Sample p = preview(s, h);
  EXPECT_NEAR(p.position, x(t + h), 1e-15 * x(t + h));
  EXPECT_NEAR(p.velocity, v(t + h), 1e-15 * v(t + h));
  EXPECT_NEAR(p.acceleration, a(t + h), 1e-15 * a(t + h));
}

// The tuning rule's velocity loop L(jw) = (kv + ki/(jw))/(jw) * exp(-jw tau) crosses over at
// w_v with the stated 45 deg phase margin: |L(j w_v)| = 1 and arg L = -135 deg. Tolerances:
// 1e-12 (closed forms, rounding only).
TEST(CascadeTuning, RuleGivesFortyFiveDegreesOfPhaseMargin) {
  const double pi = 3.14159265358979323846;
  for (const double delay : {0.0, 1e-4, 1e-3}) {
    for (const bool differenced : {false, true}) {
      const double T = 1e-4;
      const CascadeGains g = cascade_tuning(T, delay, differenced);
      const double tau = delay + 0.5 * T + (differenced ? 0.5 * T : 0.0);
      const double wv = 4.0 * g.kp;
      const std::complex<double> jw(0.0, wv);
      const std::complex<double> L = (g.kv + g.ki / jw) / jw * std::exp(-jw * tau);
      EXPECT_NEAR(std::abs(L), 1.0, 1e-12);
      EXPECT_NEAR(std::arg(L), -0.75 * pi, 1e-12);
    }
  }
  // A longer delay lowers every bandwidth in proportion (the rule is w_v = const/tau).
  EXPECT_NEAR(cascade_tuning(1e-4, 1e-3, true).kv / cascade_tuning(1e-4, 0.0, true).kv, 1e-4 / 1.1e-3, 1e-12);
}

// The sliding-mode controller with a 1 ms computation delay (10 periods) on the jerk-limited move,
// nominal model, ideal sensor. Uncompensated, the near-deadbeat loop ((lambda + eta/phi + k)*T =
// 1.006) cannot work through 10 periods of delay: the command saturates in a limit cycle and the error
// reaches tens of micrometres;
// with the state predictor and the reference preview the loop is the delay-free one shifted by d,
// and the error stays below 0.1 um (measured 0.0013 um; the residue is the friction held within
// each prediction piece).
TEST(SlidingModeDelay, CompensationKeepsTheDelayFreeAccuracy) {
  const double T = 1e-4, d = 1e-3;
  plant::PlantParams drive;  // nominal LuGre drive
  drive.effects.input_delay.enabled = true;
  drive.effects.input_delay.delay = d;
  const auto reference = trajectory::make_scurve(trajectory::SCurveParams{});
  const auto error_with = [&](bool compensate) {
    SlidingModeParams c;
    c.switching = Switching::kSaturation;
    c.boundary_layer = 5e-4;
    c.lambda = 200.0;
    c.friction_state = StateSource::kObserver;
    c.grinding_state = StateSource::kObserver;
    c.motion_state = MotionSource::kObserver;
    c.motion_observer_bandwidth = 2000.0;
    c.computation_delay = d;
    c.compensate_delay = compensate;
    c.model = plant::PlantParams{};
    c.period = T;
    SlidingModeController controller(c);
    const auto run = test::run_loop(drive, controller, *reference, T, std::lround(1.5 / T));
    return test::max_abs_error(run, 0.0, 1.5);
  };
  const double compensated = error_with(true);
  const double uncompensated = error_with(false);
  EXPECT_LT(compensated, 0.1e-6);
  EXPECT_GT(uncompensated, 100.0 * compensated) << "the delay must matter without compensation";
}

TEST(SlidingModeDelay, CompensationNeedsTheModelPredictor) {
  SlidingModeParams c;
  c.compensate_delay = true;
  c.computation_delay = 1e-3;
  c.motion_state = MotionSource::kMeasured;
  try {
    c.validate("controller");
    FAIL() << "validate() accepted compensate_delay without the observer";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "controller.compensate_delay = true: needs motion_state: observer (the model predictor)");
  }
}

}  // namespace
}  // namespace feeddrive::controller

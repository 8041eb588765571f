// The parts of the sliding-mode law (sliding_mode_law.hpp), each against Xie & Liang eqs. 16-19
// computed by hand: the sliding variable (eq. 16), the switching function and the reaching law's
// acceleration (eq. 18), the control input solved from eq. 19, the output limits, the model
// acceleration the law inverts, and the state estimate the law starts from.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "controller_util.hpp"
#include "feeddrive/controller/sliding_mode.hpp"
#include "feeddrive/controller/sliding_mode_law.hpp"

namespace feeddrive::controller::smc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Eq. 16: S = de/dt + lambda*e. On the surface e(t) = e0*exp(-lambda t) (de/dt = -lambda*e) S is
// exactly 0: the two products are the same floating-point number.
TEST(SlidingModeParts, SlidingVariableIsEq16) {
  EXPECT_EQ(sliding_variable(3e-4, 2e-3, 40.0), 2e-3 + 40.0 * 3e-4);
  EXPECT_EQ(sliding_variable(-5e-4, -1e-3, 40.0), -1e-3 - 40.0 * 5e-4);
  const double e = 1.7e-3, lambda = 50.0;
  EXPECT_EQ(sliding_variable(e, -lambda * e, lambda), 0.0);
}

// sw(S): sgn is -1, 0, +1 (sgn(0) = 0); sat(S/phi) is linear inside the layer, +-1 outside and
// continuous at |S| = phi; tanh(S/phi) is odd, ~S/phi near 0 and -> +-1 far out. Exact values
// (EXPECT_EQ) where the function is a division or a constant; tanh within 1e-15 (rounding).
TEST(SlidingModeParts, SwitchingFunctionIsSignSaturationOrTanh) {
  EXPECT_EQ(switching_function(Switching::kSign, 1e-3, 0.2), 1.0);
  EXPECT_EQ(switching_function(Switching::kSign, 1e-3, -1e-12), -1.0);
  EXPECT_EQ(switching_function(Switching::kSign, 1e-3, 0.0), 0.0);
  const double phi = 0.01;
  EXPECT_EQ(switching_function(Switching::kSaturation, phi, 0.004), 0.004 / phi);
  EXPECT_EQ(switching_function(Switching::kSaturation, phi, -0.004), -0.004 / phi);
  EXPECT_EQ(switching_function(Switching::kSaturation, phi, phi), 1.0);
  EXPECT_EQ(switching_function(Switching::kSaturation, phi, 3 * phi), 1.0);
  EXPECT_EQ(switching_function(Switching::kSaturation, phi, -3 * phi), -1.0);
  EXPECT_NEAR(switching_function(Switching::kTanh, phi, 0.5 * phi), std::tanh(0.5), 1e-15);
  EXPECT_EQ(switching_function(Switching::kTanh, phi, -0.5 * phi),
            -switching_function(Switching::kTanh, phi, 0.5 * phi));
  EXPECT_NEAR(switching_function(Switching::kTanh, phi, 40 * phi), 1.0, 1e-15);
}

// The bracket of eq. 19: xd'' + lambda*ed + eta*sw(S) + k*S, xd'' only with feedforward.
TEST(SlidingModeParts, ReachingAccelerationIsTheBracketOfEq19) {
  SlidingModeParams p;
  p.eta = 4.0;
  p.k = 12.0;
  p.lambda = 40.0;
  p.switching = Switching::kSign;
  const double ad = 0.7, ed = 2e-3, s = 0.014;
  EXPECT_EQ(reaching_acceleration(p, ad, ed, s), ad + 40.0 * ed + 4.0 * 1.0 + 12.0 * s);
  p.feedforward_acceleration = false;
  EXPECT_EQ(reaching_acceleration(p, ad, ed, s), 0.0 + 40.0 * ed + 4.0 * 1.0 + 12.0 * s);
  EXPECT_EQ(reaching_acceleration(p, ad, ed, -s), 0.0 + 40.0 * ed + 4.0 * -1.0 + 12.0 * -s);
  // On the surface with sgn(0) = 0 only the feedback of the error rate is left.
  EXPECT_EQ(reaching_acceleration(p, ad, ed, 0.0), 40.0 * ed);
}

SlidingModeParams law_params() {
  SlidingModeParams p;
  p.model.mass = 80.0;
  p.model.amplifier_gain = 2.0;
  p.model.force_constant = 90.0;  // Ka*Kf = 180 N/V
  return p;
}

// Eq. 19 solved for u: Ka*Kf*u*(1 - r - e1) = m*a + F^f + F^g + Fcog + F_d + e0, each model force
// only with its compensate_* flag. Hand values: m*a = 80*2 = 160 N. Tolerance 1e-13 relative:
// rounding of a handful of operations on O(1e2) N.
TEST(SlidingModeParts, ControlInputSolvesEq19) {
  SlidingModeParams p = law_params();
  ModelForces f;
  f.friction = 30.0;
  f.grinding = 12.0;
  f.cogging = -5.0;
  f.reluctance = 0.02;
  const double a = 2.0;
  const double all = (160.0 + 30.0 + 12.0 - 5.0) / (180.0 * (1.0 - 0.02));
  EXPECT_NEAR(control_input(p, a, f, 0.0), all, 1e-13 * all);
  p.compensate_friction = false;
  EXPECT_NEAR(control_input(p, a, f, 0.0), (160.0 + 12.0 - 5.0) / (180.0 * 0.98), 1e-13);
  p.compensate_grinding = false;
  p.compensate_ripple = false;  // drops both Fcog and r
  EXPECT_NEAR(control_input(p, a, f, 0.0), 160.0 / 180.0, 1e-15);
  // The observer's disturbance force and the model's additive effects always enter.
  EXPECT_NEAR(control_input(p, a, f, -8.0), (160.0 - 8.0) / 180.0, 1e-15);
  f.e0 = 4.0;
  f.e1 = 0.1;
  EXPECT_NEAR(control_input(p, a, f, 0.0), (160.0 + 4.0) / (180.0 * 0.9), 1e-15);
}

// The limits: clamp to [u_min, u_max]; NaN or +-inf never reaches the amplifier as such.
TEST(SlidingModeParts, LimitOutputClampsAndMapsNaNToZero) {
  SlidingModeParams p;
  p.u_min = -2.0;
  p.u_max = 1.0;
  EXPECT_EQ(limit_output(p, 0.5), 0.5);
  EXPECT_EQ(limit_output(p, 3.0), 1.0);
  EXPECT_EQ(limit_output(p, -3.0), -2.0);
  EXPECT_EQ(limit_output(p, kNaN), 0.0);
  EXPECT_EQ(limit_output(p, -std::numeric_limits<double>::infinity()), -2.0);
}

// The law inverts the model (eq. 19 is eq. 1 solved for u): with every force compensated and no
// disturbance, the model's acceleration under the law's u is the asked acceleration. Tolerance
// 1e-12 relative: two chains of rounding on O(1e2) N.
TEST(SlidingModeParts, ModelAccelerationInvertsTheLaw) {
  const SlidingModeParams p = law_params();
  ModelForces f;
  f.friction = 30.0;
  f.grinding = 12.0;
  f.cogging = -5.0;
  f.reluctance = 0.02;
  f.e0 = 4.0;
  f.e1 = 0.05;
  for (double a : {2.0, -7.5, 0.0}) {
    const double u = control_input(p, a, f, 0.0);
    EXPECT_NEAR(model_acceleration(p.model, f, u), a, 1e-12 * std::max(1.0, std::abs(a))) << a;
  }
  // No thrust: the forces alone decelerate the mass, a = -(Fcog + F^f + F^g + e0)/m.
  EXPECT_NEAR(model_acceleration(p.model, f, 0.0), -(-5.0 + 30.0 + 12.0 + 4.0) / 80.0, 1e-15);
}

// The state estimate: with motion_state = observer the first sample initialises the x,v observer
// to the measurement (x^ = x, v^ = v), so the first command equals the measured-state law's
// exactly; from the second sample on the law acts on the observer's estimate, which differs from
// a measurement that disagrees with the prediction.
TEST(SlidingModeParts, StateEstimateIsTheMeasurementUntilTheObserverPredicts) {
  SlidingModeParams p = law_params();
  p.model.friction.model = plant::FrictionModel::kNone;
  p.motion_observer_disturbance = false;
  SlidingModeParams po = p;
  po.motion_state = MotionSource::kObserver;
  SlidingModeController measured(p), observed(po);
  const trajectory::Sample ref{0.0123, 0.050, 0.7, 0.0};
  const plant::Measurement m1{0.0, 0.0120, 0.048};
  EXPECT_EQ(observed.update(ref, m1, nullptr).u_unsaturated, measured.update(ref, m1, nullptr).u_unsaturated);
  const plant::Measurement m2{p.period, 0.0130, 0.030};  // far from the observer's prediction
  const trajectory::Sample ref2{0.0124, 0.050, 0.7, 0.0};
  const double s_measured = measured.update(ref2, m2, nullptr).sliding;
  const double s_observed = observed.update(ref2, m2, nullptr).sliding;
  EXPECT_EQ(s_measured, (0.050 - 0.030) + p.lambda * (0.0124 - 0.0130));
  EXPECT_NE(s_observed, s_measured);
}

}  // namespace
}  // namespace feeddrive::controller::smc

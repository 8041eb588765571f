// The sliding-mode law of Xie & Liang eqs. 16-19 against a hand computation, its saturation and
// NaN handling, needs_truth(), and validate() messages.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "controller_util.hpp"
#include "feeddrive/controller/sliding_mode.hpp"

namespace feeddrive::controller {
namespace {

using test::hand_cogging;
using test::hand_lugre;
using test::hand_reluctance;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A model with every force of eq. 19 switched on and parameters that differ from the defaults
// (so a term that silently used a default would be caught): LuGre friction, ripple with
// non-zero phases, grinding in contact.
SlidingModeParams full_model_params() {
  SlidingModeParams p;
  p.eta = 4.0;
  p.k = 12.0;
  p.lambda = 40.0;
  p.u_min = -1e6;  // no saturation in the law tests
  p.u_max = 1e6;
  p.model.mass = 80.0;
  p.model.amplifier_gain = 2.0;
  p.model.force_constant = 90.0;  // Ka*Kf = 180 N/V
  p.model.friction.model = plant::FrictionModel::kLuGre;
  p.model.ripple = plant::RippleParams::paper();
  p.model.ripple.cogging_phase = 0.3;
  p.model.ripple.cogging_third_phase = -0.7;
  p.model.ripple.reluctance_phase = 0.5;
  p.model.ripple.reluctance_third_phase = 1.1;
  p.model.grinding.enabled = true;  // contact_position = -inf: always in contact
  return p;
}

// Eq. 19 solved for u by hand:
//   u = (m*(ad + lambda*ed + eta*sw(S) + k*S) + F^f + F^g + Fcog) / (Ka*Kf*(1 - r(x)))
double hand_u(const SlidingModeParams& p, const trajectory::Sample& ref, const plant::Measurement& m,
              const Truth& truth, double sw) {
  const double e = ref.position - m.x;
  const double ed = ref.velocity - m.v;
  const double s = ed + p.lambda * e;
  const double ad = p.feedforward_acceleration ? ref.acceleration : 0.0;
  const double ff = p.compensate_friction ? hand_lugre(p.model.friction, m.v, truth.z) : 0.0;
  const double fg = p.compensate_grinding ? truth.fg : 0.0;
  const double fcog = p.compensate_ripple ? hand_cogging(p.model.ripple, m.x) : 0.0;
  const double r = p.compensate_ripple ? hand_reluctance(p.model.ripple, m.x) : 0.0;
  const double kakf = p.model.amplifier_gain * p.model.force_constant;
  return (p.model.mass * (ad + p.lambda * ed + p.eta * sw + p.k * s) + ff + fg + fcog) / (kakf * (1.0 - r));
}

struct LawCase {
  trajectory::Sample ref;
  plant::Measurement meas;
};

// Two operating points, S > 0 and S < 0, with every term of the law non-zero.
const LawCase kCases[] = {
    // e = 3e-4 m, ed = 2e-3 m/s  =>  S = 2e-3 + 40*3e-4 = 0.014 m/s
    {{0.0123, 0.050, 0.7, 3.0}, {0.2, 0.0120, 0.048}},
    // e = -5e-4 m, ed = -1e-3 m/s  =>  S = -1e-3 - 40*5e-4 = -0.021 m/s
    {{0.0415, -0.031, -1.3, 0.0}, {0.4, 0.0420, -0.030}},
};
const Truth kTruth{2.1e-5, 35.0};  // z [m], Fg [N]

// The law matches the hand computation for every switching function and every combination of
// compensations and acceleration feedforward. Tolerance: relative 1e-12, i.e. only floating-point
// rounding of the ~10 operations (each term is O(1e2..1e3) N, summed with a few ulp of error).
TEST(SlidingModeLaw, MatchesEquation19ForEverySwitchingAndCompensation) {
  struct Sw {
    Switching kind;
    double phi;
  };
  // sat with phi = 1e-3 m/s: |S| = 0.014 / 0.021 m/s lie outside the layer (sw = +-1);
  // sat with phi = 0.1 m/s: inside the layer (sw = S/phi, linear);
  // tanh with phi = 0.02 m/s: tanh(S/phi) in its curved part.
  const Sw switchings[] = {{Switching::kSign, 1e-3},
                           {Switching::kSaturation, 1e-3},
                           {Switching::kSaturation, 0.1},
                           {Switching::kTanh, 0.02}};
  for (const Sw& sw : switchings) {
    for (int mask = 0; mask < 16; ++mask) {
      for (const LawCase& c : kCases) {
        SlidingModeParams p = full_model_params();
        p.switching = sw.kind;
        p.boundary_layer = sw.phi;
        p.compensate_friction = (mask & 1) != 0;
        p.compensate_grinding = (mask & 2) != 0;
        p.compensate_ripple = (mask & 4) != 0;
        p.feedforward_acceleration = (mask & 8) != 0;
        SlidingModeController ctl(p);
        const Command cmd = ctl.update(c.ref, c.meas, &kTruth);

        const double s = (c.ref.velocity - c.meas.v) + p.lambda * (c.ref.position - c.meas.x);
        double expected_sw = 0.0;
        switch (sw.kind) {
          case Switching::kSign: expected_sw = s > 0 ? 1.0 : -1.0; break;
          case Switching::kSaturation: expected_sw = std::abs(s) < sw.phi ? s / sw.phi : (s > 0 ? 1.0 : -1.0); break;
          case Switching::kTanh: expected_sw = std::tanh(s / sw.phi); break;
        }
        const double u = hand_u(p, c.ref, c.meas, kTruth, expected_sw);
        SCOPED_TRACE(to_string(sw.kind) + " phi=" + std::to_string(sw.phi) + " mask=" + std::to_string(mask) +
                     " S=" + std::to_string(s));
        EXPECT_NEAR(cmd.u_unsaturated, u, 1e-12 * std::abs(u));
        EXPECT_EQ(cmd.u, cmd.u_unsaturated);  // far inside +-1e6 V
        EXPECT_NEAR(cmd.sliding, s, 1e-15);   // S is O(1e-2) m/s: a few ulp
        // z_estimate reports the z the friction estimate used: here the true z.
        EXPECT_EQ(cmd.z_estimate, kTruth.z);
      }
    }
  }
}

// The boundary layer is linear inside, +-1 outside, and continuous at |S| = phi: evaluated at
// S = +-phi/2 and +-2 phi. The switching term alone is isolated by subtracting the sgn-free part
// (eta = 0). Tolerance 1e-12 relative: rounding only.
TEST(SlidingModeLaw, SaturationIsLinearInsideTheLayerAndUnitOutside) {
  for (double ratio : {0.5, -0.5, 2.0, -2.0}) {
    SlidingModeParams p = full_model_params();
    p.switching = Switching::kSaturation;
    p.boundary_layer = 0.01;
    const trajectory::Sample ref{0.0, ratio * p.boundary_layer, 0.0, 0.0};  // e = 0: S = ed
    const plant::Measurement meas{0.0, 0.0, 0.0};
    SlidingModeController with_eta(p);
    SlidingModeParams p0 = p;
    p0.eta = 0.0;
    SlidingModeController without_eta(p0);
    const double kakf = p.model.thrust_gain();
    const double r = hand_reluctance(p.model.ripple, 0.0);
    const double du =
        with_eta.update(ref, meas, &kTruth).u_unsaturated - without_eta.update(ref, meas, &kTruth).u_unsaturated;
    const double sw = du * kakf * (1.0 - r) / (p.model.mass * p.eta);
    const double expected = std::clamp(ratio, -1.0, 1.0);
    EXPECT_NEAR(sw, expected, 1e-12) << ratio;
  }
}

// sgn(0) = 0 (notes Sec. 5): on the surface the switching term vanishes.
TEST(SlidingModeLaw, SignOfZeroIsZero) {
  SlidingModeParams p = full_model_params();
  p.compensate_friction = p.compensate_grinding = p.compensate_ripple = false;
  SlidingModeController ctl(p);
  const Command cmd = ctl.update({0.01, 0.0, 0.0, 0.0}, {0.0, 0.01, 0.0}, &kTruth);  // e = ed = 0
  EXPECT_EQ(cmd.sliding, 0.0);
  EXPECT_EQ(cmd.u_unsaturated, 0.0);
}

// Saturation: u is clamped to [u_min, u_max] while u_unsaturated keeps the raw law value.
TEST(SlidingModeLaw, SaturatesButReportsTheRawValue) {
  SlidingModeParams p = full_model_params();
  p.u_min = -2.0;
  p.u_max = 1.0;
  for (double sign : {1.0, -1.0}) {
    SlidingModeController ctl(p);
    // A 10 mm position error: S = 40*0.01 = 0.4 m/s, m*(eta + k S + lambda*0) ~ 700 N ~ 4 V.
    const trajectory::Sample ref{sign * 0.01, 0.0, 0.0, 0.0};
    const plant::Measurement meas{0.0, 0.0, 0.0};
    const Command cmd = ctl.update(ref, meas, &kTruth);
    const double raw = hand_u(p, ref, meas, kTruth, sign);
    EXPECT_NEAR(cmd.u_unsaturated, raw, 1e-12 * std::abs(raw));
    EXPECT_EQ(cmd.u, sign > 0 ? p.u_max : p.u_min);
    EXPECT_GT(std::abs(cmd.u_unsaturated), 2.0);  // the case really saturates
  }
}

// A NaN anywhere in the inputs makes the law NaN; saturate() maps it to 0 V (never apply NaN).
TEST(SlidingModeLaw, NaNInputGivesZeroCommand) {
  const trajectory::Sample good_ref{0.01, 0.02, 0.3, 0.0};
  const plant::Measurement good_meas{0.0, 0.009, 0.019};
  const trajectory::Sample nan_refs[] = {{kNaN, 0.02, 0.3, 0.0}, {0.01, kNaN, 0.3, 0.0}, {0.01, 0.02, kNaN, 0.0}};
  for (const auto& r : nan_refs) {
    SlidingModeController ctl(full_model_params());
    const Command cmd = ctl.update(r, good_meas, &kTruth);
    EXPECT_EQ(cmd.u, 0.0);
    EXPECT_TRUE(std::isnan(cmd.u_unsaturated));
  }
  const plant::Measurement nan_meas[] = {{0.0, kNaN, 0.019}, {0.0, 0.009, kNaN}};
  for (const auto& m : nan_meas) {
    SlidingModeController ctl(full_model_params());
    const Command cmd = ctl.update(good_ref, m, &kTruth);
    EXPECT_EQ(cmd.u, 0.0);
    EXPECT_TRUE(std::isnan(cmd.u_unsaturated));
  }
  EXPECT_EQ(saturate(kNaN, -1.0, 1.0), 0.0);
  EXPECT_EQ(saturate(std::numeric_limits<double>::infinity(), -1.0, 1.0), 1.0);
  EXPECT_EQ(saturate(-std::numeric_limits<double>::infinity(), -1.0, 1.0), -1.0);
}

// One bad sample must not disable the controller for good: the observers carry state from one
// period to the next, so a NaN reference or measurement must not get into z^, F^g, x^ or v^.
TEST(SlidingModeLaw, OneNaNSampleDoesNotPoisonTheObservers) {
  SlidingModeParams p = full_model_params();
  p.friction_state = StateSource::kObserver;
  p.grinding_state = StateSource::kObserver;
  const trajectory::Sample ref{0.01, 0.02, 0.3, 0.0};
  const plant::Measurement m0{0.0, 0.0, 0.02};
  const plant::Measurement m1{1e-4, 2e-6, 0.02};
  const plant::Measurement m2{2e-4, 4e-6, 0.02};

  // (a) NaN reference. With observer_gain = 0 the reference does not enter z^ or F^g, and with
  // the measured x, v the applied u does not enter any observer, so the command after the bad
  // sample must equal that of a controller that saw a good reference instead (bit for bit).
  SlidingModeController clean(p);
  clean.update(ref, m0, nullptr);
  clean.update(ref, m1, nullptr);
  const Command want = clean.update(ref, m2, nullptr);
  ASSERT_TRUE(std::isfinite(want.u_unsaturated));
  SlidingModeController bad_ref(p);
  bad_ref.update(ref, m0, nullptr);
  EXPECT_EQ(bad_ref.update({kNaN, kNaN, kNaN, kNaN}, m1, nullptr).u, 0.0);
  EXPECT_EQ(bad_ref.update(ref, m2, nullptr).u_unsaturated, want.u_unsaturated);

  // (b) NaN measured velocity: no information for one period. That sample gives u = 0; the next
  // good sample gives a finite command and a finite z^ again.
  SlidingModeController bad_meas(p);
  bad_meas.update(ref, m0, nullptr);
  EXPECT_EQ(bad_meas.update(ref, {1e-4, 2e-6, kNaN}, nullptr).u, 0.0);
  const Command after = bad_meas.update(ref, m2, nullptr);
  EXPECT_TRUE(std::isfinite(after.u_unsaturated));
  EXPECT_TRUE(std::isfinite(after.z_estimate));

  // (c) With the x,v observer a bad position sample is skipped: the observer coasts on its model
  // prediction, so even that period's command is finite; a NaN first sample gives u = 0 and the
  // observer initialises on the next good one.
  p.motion_state = MotionSource::kObserver;
  const double bad_x[] = {kNaN, std::numeric_limits<double>::infinity()};
  for (double x : bad_x) {
    SlidingModeController coast(p);
    coast.update(ref, m0, nullptr);
    EXPECT_TRUE(std::isfinite(coast.update(ref, {1e-4, x, x}, nullptr).u_unsaturated)) << x;
    EXPECT_TRUE(std::isfinite(coast.update(ref, m2, nullptr).u_unsaturated)) << x;
    SlidingModeController first_bad(p);
    EXPECT_EQ(first_bad.update(ref, {0.0, x, x}, nullptr).u, 0.0) << x;
    EXPECT_TRUE(std::isfinite(first_bad.update(ref, m1, nullptr).u_unsaturated)) << x;
    EXPECT_TRUE(std::isfinite(first_bad.update(ref, m2, nullptr).u_unsaturated)) << x;
  }
}

// needs_truth(): true exactly when a compensation is on, reads the true state, and the model has
// that state (LuGre for z, grinding enabled for Fg).
TEST(SlidingModeTruth, NeedsTruthOnlyForTrueStatesThatAreUsed) {
  struct Case {
    plant::FrictionModel friction;
    bool grinding_enabled;
    bool comp_f, comp_g;
    StateSource fs, gs;
    bool expected;
  };
  using FM = plant::FrictionModel;
  const auto T = StateSource::kTrue;
  const auto O = StateSource::kObserver;
  const Case cases[] = {
      {FM::kLuGre, false, true, true, T, T, true},    // LuGre z read from the plant
      {FM::kLuGre, false, true, true, O, T, false},   // bristle observer instead
      {FM::kLuGre, false, false, true, T, T, false},  // friction compensation off
      {FM::kNone, false, true, true, T, T, false},    // no friction model
      {FM::kStatic, false, true, true, T, T, false},  // static model has no z
      {FM::kNone, true, true, true, T, T, true},      // grinding Fg read from the plant
      {FM::kNone, true, true, true, T, O, false},     // grinding observer
      {FM::kNone, true, true, false, T, T, false},    // grinding compensation off
      {FM::kLuGre, true, true, true, O, O, false},    // both observers
      {FM::kLuGre, true, false, false, T, T, false},  // both compensations off
  };
  for (const Case& c : cases) {
    SlidingModeParams p;
    p.model.friction.model = c.friction;
    p.model.grinding.enabled = c.grinding_enabled;
    p.compensate_friction = c.comp_f;
    p.compensate_grinding = c.comp_g;
    p.friction_state = c.fs;
    p.grinding_state = c.gs;
    SlidingModeController ctl(p);
    SCOPED_TRACE(plant::to_string(c.friction) + " grinding=" + std::to_string(c.grinding_enabled) +
                 " comp_f=" + std::to_string(c.comp_f) + " comp_g=" + std::to_string(c.comp_g) +
                 " fs=" + to_string(c.fs) + " gs=" + to_string(c.gs));
    EXPECT_EQ(ctl.needs_truth(), c.expected);
    const trajectory::Sample ref{1e-3, 0.0, 0.0, 0.0};
    const plant::Measurement meas{0.0, 0.0, 0.0};
    if (c.expected) {
      EXPECT_THROW(ctl.update(ref, meas, nullptr), std::logic_error);
    } else {
      const Command cmd = ctl.update(ref, meas, nullptr);
      EXPECT_TRUE(std::isfinite(cmd.u));
    }
  }
}

// validate(): each bad value throws std::invalid_argument naming the dotted key and the value.
void expect_invalid(const SlidingModeParams& p, const std::string& message) {
  try {
    p.validate();
    ADD_FAILURE() << "validate() accepted a bad value; expected: " << message;
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), message);
  }
  // The constructor validates too.
  EXPECT_THROW(SlidingModeController{p}, std::invalid_argument) << message;
}

TEST(SlidingModeValidate, MessagesNameTheKeyAndValue) {
  SlidingModeParams p;
  EXPECT_NO_THROW(p.validate());

  p = {};
  p.eta = -1.0;
  expect_invalid(p, "controller.eta = -1: must be >= 0");
  p = {};
  p.lambda = 0.0;
  expect_invalid(p, "controller.lambda = 0: must be > 0");
  p = {};
  p.lambda = -2.5;
  expect_invalid(p, "controller.lambda = -2.5: must be > 0");
  p = {};
  p.k = kNaN;
  expect_invalid(p, "controller.k = nan: must be a finite number");
  p = {};
  p.u_min = 1.0;
  p.u_max = 1.0;
  expect_invalid(p, "controller.u_max = 1: must be > u_min");
  p = {};
  p.u_min = 3.0;
  p.u_max = 2.0;
  expect_invalid(p, "controller.u_max = 2: must be > u_min");
  p = {};
  p.switching = Switching::kSaturation;
  p.boundary_layer = 0.0;
  expect_invalid(p, "controller.boundary_layer = 0: must be > 0");
  p = {};
  p.switching = Switching::kTanh;
  p.boundary_layer = -1e-3;
  expect_invalid(p, "controller.boundary_layer = -0.001: must be > 0");
  p = {};
  p.observer_gain = -1.0;
  expect_invalid(p, "controller.observer_gain = -1: must be >= 0");
  p = {};
  p.motion_observer_bandwidth = 0.0;
  expect_invalid(p, "controller.motion_observer_bandwidth = 0: must be > 0");
  p = {};
  p.period = 0.0;
  expect_invalid(p, "controller.period = 0: must be > 0");

  // sgn ignores the boundary layer, so a zero phi is accepted there.
  p = {};
  p.switching = Switching::kSign;
  p.boundary_layer = 0.0;
  EXPECT_NO_THROW(p.validate());

  // The model is validated under the controller's prefix.
  p = {};
  p.model.mass = -1.0;
  try {
    p.validate();
    ADD_FAILURE() << "negative model mass accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("controller.model.mass = -1", 0), 0u) << e.what();
  }

  // A custom prefix is used as given.
  p = {};
  p.lambda = 0.0;
  try {
    p.validate("ctl");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "ctl.lambda = 0: must be > 0");
  }
}

TEST(SlidingModeValidate, EnumNamesRoundTrip) {
  for (Switching s : {Switching::kSign, Switching::kSaturation, Switching::kTanh})
    EXPECT_EQ(fields::enum_from_name<Switching>(to_string(s)), s);
  for (StateSource s : {StateSource::kTrue, StateSource::kObserver})
    EXPECT_EQ(fields::enum_from_name<StateSource>(to_string(s)), s);
  for (MotionSource s : {MotionSource::kMeasured, MotionSource::kObserver})
    EXPECT_EQ(fields::enum_from_name<MotionSource>(to_string(s)), s);
  EXPECT_THROW(fields::enum_from_name<Switching>("sign"), std::invalid_argument);
  EXPECT_THROW(fields::enum_from_name<StateSource>("estimated"), std::invalid_argument);
  EXPECT_THROW(fields::enum_from_name<MotionSource>("encoder"), std::invalid_argument);
}

}  // namespace
}  // namespace feeddrive::controller

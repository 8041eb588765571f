// The adapted friction and inertia feedforward (feedforward_adaptation.hpp): the normalised
// gradient estimator against a residual whose true scales are known, its bounds, and the params
// checks of the two controllers that carry it.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "feeddrive/common/validate.hpp"
#include "feeddrive/controller/cascade.hpp"
#include "feeddrive/controller/feedforward_adaptation.hpp"
#include "feeddrive/controller/friction_observer.hpp"
#include "feeddrive/controller/sliding_mode.hpp"

namespace feeddrive::controller {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The residual the observer would report when the plant's Fs, Fc are `level` x the model's and
// its mass (1 + dm) x: r = (level - theta)*g + (dm - delta_m)*m*a, with the model already adapted
// (g: the model's friction at level 1). Returns {r, the estimate the controller would make}.
struct Residual {
  double r, friction;
};
Residual residual(const FeedforwardAdaptation& a, double level, double dm, double g, double inertial) {
  return {(level - a.friction_level()) * g + (dm - a.mass_error()) * inertial, a.friction_level() * g};
}
void step(FeedforwardAdaptation& a, double level, double dm, double g, double inertial) {
  const Residual res = residual(a, level, dm, g, inertial);
  a.update(res.r, res.friction, inertial);
}

// The regressors of the 1 Hz sine (friction ~ 80 N*sgn(v) with the Stribeck rise near v = 0 left
// out, inertial force 102 kg * 3.95 m/s^2 * cos): persistently exciting, so the estimate
// converges to the true level and mass error. The error obeys e+ = (I - gamma*T*phi*phi'/(F0^2 + |phi|^2))*e;
// the friction scale's averaged rate is gamma times the mean of phi_f^2/(F0^2 + phi_f^2 +
// phi_m^2) = 6400/(12800 + 1.62e5*cos^2) over a period, i.e. 6400/sqrt(12800*1.75e5) = 0.135
// (the mean of 1/(a + b cos^2) is 1/sqrt(a(a + b))): 2.7 1/s at gamma = 20 1/s, the mass
// scale's faster. 6 s is 16 time constants: e^-16 ~ 1e-7 of the initial error. Tolerance 1e-4
// (absolute): well above that decay, far below the offsets (-0.5, +0.5) being identified.
TEST(FeedforwardAdaptation, IdentifiesFrictionAndMassScalesOnASine) {
  const double T = 1e-4;
  FeedforwardAdaptation a(20.0, T, 80.0);
  for (int k = 0; k < 60000; ++k) {
    const double t = k * T;
    const double friction = 80.0 * (std::sin(2 * kPi * t) >= 0.0 ? 1.0 : -1.0);
    const double inertial = 102.04 * 0.1 * 4 * kPi * kPi * std::cos(2 * kPi * t);
    step(a, 0.5, 0.5, friction, inertial);
  }
  EXPECT_NEAR(a.friction_level(), 0.5, 1e-4);
  EXPECT_NEAR(a.mass_error(), 0.5, 1e-4);
}

// With one constant regressor the normalised step is exact: e+ = (1 - gamma*T*phi^2/(F0^2 +
// phi^2))*e, so after n steps e_n = e_0*(1 - c)^n, c = 20*1e-4*80^2/(80^2 + 80^2) = 1e-3.
// Tolerance 1e-12: rounding of 1000 multiplications.
TEST(FeedforwardAdaptation, OneRegressorConvergesGeometrically) {
  FeedforwardAdaptation a(20.0, 1e-4, 80.0);
  for (int k = 0; k < 1000; ++k) step(a, 1.4, 0.0, 80.0, 0.0);
  EXPECT_NEAR(a.friction_level(), 1.4 - 0.4 * std::pow(1.0 - 1e-3, 1000), 1e-12);
  EXPECT_EQ(a.mass_error(), 0.0);  // its regressor was 0: no step
}

// Off (gamma = 0): the model as it is, nothing learnt. Bounds: a residual no level within
// [0.2, 3] and mass error within [-0.5, 1] explains is clamped there. A non-finite input is
// skipped (no information).
TEST(FeedforwardAdaptation, OffBoundedAndSkipsNonFinite) {
  FeedforwardAdaptation off(0.0, 1e-4, 80.0);
  off.update(1e3, 80.0, 100.0);
  EXPECT_EQ(off.friction_level(), 1.0);
  EXPECT_EQ(off.inertial_force(100.0), 0.0);
  FeedforwardAdaptation a(1000.0, 1e-3, 80.0);
  for (int k = 0; k < 10000; ++k) a.update(1e6, 80.0 * a.friction_level(), 80.0);
  EXPECT_EQ(a.friction_level(), 3.0);
  EXPECT_EQ(a.mass_error(), 1.0);
  for (int k = 0; k < 10000; ++k) a.update(-1e6, 80.0 * a.friction_level(), 80.0);
  EXPECT_EQ(a.friction_level(), 0.2);
  EXPECT_EQ(a.mass_error(), -0.5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  a.update(nan, 80.0, 80.0);
  a.update(1e6, nan, 80.0);
  EXPECT_EQ(a.friction_level(), 0.2);
  EXPECT_EQ(a.mass_error(), -0.5);
}

// The level scales the bristle observer's g(v): in steady sliding its estimate is level*g(v)
// + sigma2*v, the LuGre steady state of a plant with Fs, Fc times the level (the exact update
// converges in 2 s at 0.05 m/s to far below the 1e-9 relative tolerance: friction_observer_test).
TEST(FeedforwardAdaptation, LevelScalesTheBristleObserversFriction) {
  const plant::FrictionParams f{};
  FrictionObserver obs(f, 1e-4, 0.0);
  obs.set_level(0.5);
  for (int k = 0; k < 20000; ++k) obs.advance(0.05, 0.0);
  plant::FrictionParams half = f;
  half.static_force *= 0.5;
  half.coulomb_force *= 0.5;
  FrictionObserver ref(half, 1e-4, 0.0);
  for (int k = 0; k < 20000; ++k) ref.advance(0.05, 0.0);
  EXPECT_NEAR(obs.estimate(0.05), ref.estimate(0.05), 1e-9 * std::abs(ref.estimate(0.05)));
  EXPECT_NEAR(obs.z(), ref.z(), 1e-15);
}

// The option needs the residual: the SMC's x,v,d observer, the cascade's disturbance observer.
TEST(FeedforwardAdaptation, ParamsNeedTheDisturbanceObserver) {
  SlidingModeParams s;
  s.adaptation_rate = 10.0;
  s.motion_state = MotionSource::kMeasured;
  try {
    s.validate("controller");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("controller.adaptation_rate = 10: needs motion_state"), std::string::npos)
        << e.what();
  }
  s.motion_state = MotionSource::kObserver;
  s.friction_state = StateSource::kObserver;
  EXPECT_NO_THROW(s.validate("controller"));
  s.adaptation_rate = -1.0;
  EXPECT_THROW(s.validate("controller"), std::invalid_argument);
  CascadeParams c;
  c.adaptation_rate = 10.0;
  EXPECT_THROW(c.validate("controller"), std::invalid_argument);  // w_d = 0: no observer
  c.disturbance_observer_bandwidth = 2000.0;
  c.friction_feedforward = true;
  EXPECT_NO_THROW(c.validate("controller"));
}

template <class Params>
std::string validate_error(const Params& params) {
  try {
    params.validate("controller");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// Where the level can never act, the setting is refused: the SMC with the plant's true z
// (friction_state: true) uses no bristle observer to scale, and the cascade without
// friction_feedforward has no model friction to scale and no bristles to open the learning gate.
TEST(FeedforwardAdaptation, RefusedWhereItCannotAct) {
  SlidingModeParams s;
  s.adaptation_rate = 50.0;
  s.motion_state = MotionSource::kObserver;
  s.friction_state = StateSource::kTrue;
  EXPECT_NE(validate_error(s).find("controller.adaptation_rate = 50: needs friction_state: observer"),
            std::string::npos)
      << validate_error(s);
  CascadeParams c;
  c.adaptation_rate = 50.0;
  c.disturbance_observer_bandwidth = 2000.0;
  c.friction_feedforward = false;
  EXPECT_NE(validate_error(c).find("controller.adaptation_rate = 50: needs friction_feedforward: true"),
            std::string::npos)
      << validate_error(c);
}

// The normalised gradient step contracts the level's error by (1 - gamma*T*phi^2/(F0^2+phi.phi))
// per period: stable only for gamma*T < 2. At T = 100 us the bound is 20000 1/s: 19999 passes,
// 20000 and 1e9 are one-line errors naming the key, the value and the bound.
TEST(FeedforwardAdaptation, RateAboveTheStabilityBoundIsAnError) {
  SlidingModeParams s;
  s.motion_state = MotionSource::kObserver;
  s.friction_state = StateSource::kObserver;
  s.period = 1e-4;
  CascadeParams c;
  c.disturbance_observer_bandwidth = 2000.0;
  c.friction_feedforward = true;
  c.period = 1e-4;
  s.adaptation_rate = c.adaptation_rate = 19999.0;
  EXPECT_EQ(validate_error(s), "");
  EXPECT_EQ(validate_error(c), "");
  for (double rate : {20000.0, 1e9}) {
    s.adaptation_rate = c.adaptation_rate = rate;
    for (const std::string& what : {validate_error(s), validate_error(c)}) {
      EXPECT_EQ(what.find("controller.adaptation_rate = " + validate::format_number(rate) + ": rate * control period"),
                0u)
          << what;
      EXPECT_NE(what.find("must be < 2"), std::string::npos) << what;
      EXPECT_NE(what.find("max 20000 1/s"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace feeddrive::controller

namespace feeddrive::controller {
namespace {

// The learning gate: transient(v) = |z^ - sgn(v) g(v)/sigma0| / (g(v)/sigma0). In steady sliding
// (2 s at 0.05 m/s: converged to rounding, friction_observer_test) it is 0 to 1e-9; right after
// a reversal the bristles still sit at the old steady deflection, so it is 2 to 1e-9 (g is even
// in v: the same |z_ss| on both sides). A model without bristles (static map) has none: 0.
TEST(FeedforwardAdaptation, TransientIsZeroInSlidingAndTwoAtAReversal) {
  const plant::FrictionParams f{};
  FrictionObserver obs(f, 1e-4, 0.0);
  for (int k = 0; k < 20000; ++k) obs.advance(0.05, 0.0);
  EXPECT_NEAR(obs.transient(0.05), 0.0, 1e-9);
  EXPECT_NEAR(obs.transient(-0.05), 2.0, 1e-9);
  EXPECT_LT(obs.transient(0.05), kAdaptationTransient);
  plant::FrictionParams map = f;
  map.model = plant::FrictionModel::kStatic;
  EXPECT_EQ(FrictionObserver(map, 1e-4, 0.0).transient(0.05), 0.0);
}

}  // namespace
}  // namespace feeddrive::controller

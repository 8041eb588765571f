// Sine, step and ramp references, and every validate() message.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ----- Sine -------------------------------------------------------------------------------------

TEST(Sine, AnalyticDerivativesMatchFiniteDifferences) {
  SineParams p;
  p.amplitude = 0.1;
  p.frequency = 1.3;
  p.phase = 0.4;
  p.offset = -0.02;
  p.start_time = 0.25;
  const auto tr = make_sine(p);
  const double w = 2.0 * M_PI * p.frequency;
  // Central differences, step h: truncation error f''' h^2/6 ~ A w^3 h^2/6 ~ 1e-11 relative to
  // A w for h = 1e-5, rounding ~eps A/h ~ 2e-12 relative; 1e-8 relative leaves ample margin.
  constexpr double kH = 1e-5;
  constexpr double kRelTol = 1e-8;
  for (double t = 0.3; t < 3.0; t += 0.0731) {
    const Sample s = tr->sample(t);
    const Sample lo = tr->sample(t - kH);
    const Sample hi = tr->sample(t + kH);
    EXPECT_NEAR(s.velocity, (hi.position - lo.position) / (2 * kH), kRelTol * p.amplitude * w);
    EXPECT_NEAR(s.acceleration, (hi.velocity - lo.velocity) / (2 * kH), kRelTol * p.amplitude * w * w);
    EXPECT_NEAR(s.jerk, (hi.acceleration - lo.acceleration) / (2 * kH), kRelTol * p.amplitude * w * w * w);
    // And the closed form itself (same expression; 1e-16 ~ 1 ulp of 0.1).
    const double theta = w * (t - p.start_time) + p.phase;
    EXPECT_NEAR(s.position, p.offset + p.amplitude * std::sin(theta), 1e-16);
  }
}

TEST(Sine, HoldsTheStartValueBeforeStartTime) {
  SineParams p;
  p.phase = 0.5;
  p.start_time = 2.0;
  const auto tr = make_sine(p);
  const Sample before = tr->sample(1.0);
  EXPECT_EQ(before.position, 0.1 * std::sin(0.5));
  EXPECT_EQ(before.velocity, 0.0);
  EXPECT_EQ(before.acceleration, 0.0);
  EXPECT_EQ(before.jerk, 0.0);
  EXPECT_EQ(tr->sample(2.0).position, before.position);                            // x is continuous at t0
  EXPECT_NEAR(tr->sample(2.0).velocity, 0.1 * 2.0 * M_PI * std::cos(0.5), 1e-15);  // ~2 ulps
  EXPECT_EQ(tr->end_time(), kInf);
}

TEST(Sine, DefaultIsA100mmOneHertzSine) {
  const auto tr = make_sine(SineParams{});
  // sin/cos of 2 pi t with t <= 1.25: theta carries ~1 ulp of 7.9 (9e-16), times A = 0.1,
  // plus ~1 ulp of the result: 1e-16 .. 1e-15.
  EXPECT_EQ(tr->sample(0.0).position, 0.0);
  EXPECT_NEAR(tr->sample(0.25).position, 0.1, 1e-16);
  EXPECT_NEAR(tr->sample(0.0).velocity, 0.2 * M_PI, 1e-15);
  EXPECT_NEAR(tr->sample(1.25).position, 0.1, 1e-15);  // period 1 s
}

TEST(Sine, ZeroFrequencyIsConstant) {
  SineParams p;
  p.frequency = 0.0;
  p.phase = M_PI / 2;
  const auto tr = make_sine(p);
  EXPECT_EQ(tr->sample(3.0).position, 0.1);
  EXPECT_EQ(tr->sample(3.0).velocity, 0.0);
  EXPECT_EQ(tr->end_time(), 0.0);
}

// ----- Step -------------------------------------------------------------------------------------

TEST(Step, JumpsAtStepTime) {
  StepParams p;
  p.amplitude = 0.1;
  p.step_time = 1.0;
  p.initial = 0.02;
  const auto tr = make_step(p);
  EXPECT_EQ(tr->sample(0.0).position, 0.02);
  EXPECT_EQ(tr->sample(std::nextafter(1.0, 0.0)).position, 0.02);
  EXPECT_EQ(tr->sample(1.0).position, 0.02 + 0.1);
  EXPECT_EQ(tr->sample(5.0).position, 0.02 + 0.1);
  for (double t : {0.0, 1.0, 5.0}) {
    EXPECT_EQ(tr->sample(t).velocity, 0.0);
    EXPECT_EQ(tr->sample(t).acceleration, 0.0);
    EXPECT_EQ(tr->sample(t).jerk, 0.0);
  }
  EXPECT_EQ(tr->end_time(), 1.0);
}

// ----- Ramp -------------------------------------------------------------------------------------

TEST(Ramp, ConstantVelocityFromStartTime) {
  const auto def = make_ramp(RampParams{});               // Xie & Liang Fig. 23: 1 um/s
  EXPECT_NEAR(def->sample(0.5).position, 0.5e-6, 1e-22);  // ~1 ulp of 5e-7
  EXPECT_EQ(def->sample(0.5).velocity, 1e-6);

  RampParams p;
  p.velocity = -0.05;
  p.start_time = 1.0;
  p.initial = 0.3;
  const auto tr = make_ramp(p);
  const Sample before = tr->sample(0.5);
  EXPECT_EQ(before.position, 0.3);
  EXPECT_EQ(before.velocity, 0.0);
  EXPECT_EQ(tr->sample(1.0).position, 0.3);
  EXPECT_EQ(tr->sample(1.0).velocity, -0.05);
  EXPECT_NEAR(tr->sample(3.0).position, 0.3 - 0.1, 1e-16);  // two roundings at ~0.2
  EXPECT_EQ(tr->sample(3.0).acceleration, 0.0);
  EXPECT_EQ(tr->sample(3.0).jerk, 0.0);
  EXPECT_EQ(tr->end_time(), kInf);
  EXPECT_EQ(make_ramp({0.0, 2.0, 0.0})->end_time(), 2.0);            // v = 0: constant after t0
  EXPECT_EQ(make_ramp({0.0, 0.0, 0.0})->sample(7.0).position, 0.0);  // the sim's "none"
}

TEST(AllProfiles, NaNTimeGivesNaN) {
  EXPECT_TRUE(std::isnan(make_sine({})->sample(kNaN).position));
  EXPECT_TRUE(std::isnan(make_step({})->sample(kNaN).position));
  EXPECT_TRUE(std::isnan(make_ramp({})->sample(kNaN).velocity));
}

// ----- validate() -------------------------------------------------------------------------------

// The message of the std::invalid_argument thrown by f, or "" if none.
std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Validate, DefaultsAreValid) {
  EXPECT_NO_THROW(SineParams{}.validate());
  EXPECT_NO_THROW(StepParams{}.validate());
  EXPECT_NO_THROW(AccelLimitedParams{}.validate());
  EXPECT_NO_THROW(SCurveParams{}.validate());
  EXPECT_NO_THROW(RampParams{}.validate());
}

TEST(Validate, MessagesNameKeyAndValue) {
  SCurveParams s;
  s.max_jerk = -3.0;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.max_jerk = -3: must be > 0");
  EXPECT_EQ(message_of([&] { s.validate("ref2"); }), "ref2.max_jerk = -3: must be > 0");
  EXPECT_EQ(message_of([&] { make_scurve(s); }), "reference.max_jerk = -3: must be > 0");

  s = SCurveParams{};
  s.max_velocity = 0.0;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.max_velocity = 0: must be > 0");
  s = SCurveParams{};
  s.max_acceleration = kNaN;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.max_acceleration = nan: must be a finite number");
  s = SCurveParams{};
  s.distance = kInf;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.distance = inf: must be a finite number");
  s = SCurveParams{};
  s.start_time = -kInf;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.start_time = -inf: must be a finite number");
  s = SCurveParams{};
  s.initial = kNaN;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.initial = nan: must be a finite number");

  AccelLimitedParams a;
  a.max_acceleration = -0.4;
  EXPECT_EQ(message_of([&] { make_accel_limited(a); }), "reference.max_acceleration = -0.4: must be > 0");
  a = AccelLimitedParams{};
  a.max_velocity = kInf;
  EXPECT_EQ(message_of([&] { a.validate(); }), "reference.max_velocity = inf: must be a finite number");
  a = AccelLimitedParams{};
  a.distance = kNaN;
  EXPECT_EQ(message_of([&] { a.validate(); }), "reference.distance = nan: must be a finite number");

  SineParams sn;
  sn.frequency = -1.0;
  EXPECT_EQ(message_of([&] { make_sine(sn); }), "reference.frequency = -1: must be >= 0");
  sn = SineParams{};
  sn.amplitude = kNaN;
  EXPECT_EQ(message_of([&] { sn.validate(); }), "reference.amplitude = nan: must be a finite number");
  sn = SineParams{};
  sn.phase = kInf;
  EXPECT_EQ(message_of([&] { sn.validate(); }), "reference.phase = inf: must be a finite number");
  sn = SineParams{};
  sn.offset = kNaN;
  EXPECT_EQ(message_of([&] { sn.validate(); }), "reference.offset = nan: must be a finite number");
  sn = SineParams{};
  sn.start_time = kNaN;
  EXPECT_EQ(message_of([&] { sn.validate(); }), "reference.start_time = nan: must be a finite number");

  StepParams st;
  st.step_time = kInf;
  EXPECT_EQ(message_of([&] { make_step(st); }), "reference.step_time = inf: must be a finite number");
  st = StepParams{};
  st.amplitude = kNaN;
  EXPECT_EQ(message_of([&] { st.validate(); }), "reference.amplitude = nan: must be a finite number");
  st = StepParams{};
  st.initial = -kInf;
  EXPECT_EQ(message_of([&] { st.validate(); }), "reference.initial = -inf: must be a finite number");

  RampParams r;
  r.velocity = kNaN;
  EXPECT_EQ(message_of([&] { make_ramp(r); }), "reference.velocity = nan: must be a finite number");
  r = RampParams{};
  r.start_time = kInf;
  EXPECT_EQ(message_of([&] { r.validate(); }), "reference.start_time = inf: must be a finite number");
}

TEST(Validate, ValuesPrintInShortestRoundTripForm) {
  // 0.1 prints as "0.1", not 0.10000000000000001; 1e-300 keeps its exponent.
  SCurveParams s;
  s.max_velocity = -0.1;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.max_velocity = -0.1: must be > 0");
  s.max_velocity = -1e-300;
  EXPECT_EQ(message_of([&] { s.validate(); }), "reference.max_velocity = -1e-300: must be > 0");
}

TEST(Validate, OverflowingMovesAreRejected) {
  // 1e300 m at 1e-300 m/s: the duration overflows to inf.
  SCurveParams s;
  s.distance = 1e300;
  s.max_velocity = 1e-300;
  const std::string m = message_of([&] { s.validate(); });
  EXPECT_EQ(m.rfind("reference.distance = 1e+300: the move's duration overflows", 0), 0u) << m;
  AccelLimitedParams a;
  a.distance = -1e300;
  a.max_velocity = 1e-300;
  EXPECT_EQ(message_of([&] { a.validate(); }).rfind("reference.distance = -1e+300: the move's duration overflows", 0),
            0u);
  a = AccelLimitedParams{};
  a.initial = 1.7e308;
  a.distance = 1e308;
  EXPECT_EQ(message_of([&] { a.validate(); }), "reference.distance = 1e+308: initial + distance overflows");
}

TEST(Validate, EveryMessageIsOneLine) {
  SCurveParams s;
  s.max_jerk = kNaN;
  EXPECT_EQ(message_of([&] { s.validate(); }).find('\n'), std::string::npos);
}

}  // namespace
}  // namespace feeddrive::trajectory

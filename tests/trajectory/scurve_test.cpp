// Jerk-limited double-S move: the paper defaults, the four cases of Biagiotti & Melchiorri
// Sec. 3.4 against hand-computed plans, and a seeded random sweep of the properties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "feeddrive/trajectory/trajectory.hpp"
#include "profile_checks.hpp"

namespace feeddrive::trajectory {
namespace {

using testing::check_profile;
using testing::Limits;
using testing::Move;

// Hand-computed values below are exact in real arithmetic; the plan is a few floating-point
// operations (one sqrt or cbrt) away from them, i.e. a few ulps. 1e-14 relative is 50x that.
constexpr double kPlanTol = 1e-14;
// Sample values of order 1-10 at hand-computed instants, from a handful of operations: 1e-14
// absolute is ~50 ulps, while any formula error would be O(1).
constexpr double kHandTol = 1e-14;

SCurveParams make_params(double d, double vmax, double amax, double jmax, double t0 = 0.0, double initial = 0.0) {
  SCurveParams p;
  p.distance = d;
  p.max_velocity = vmax;
  p.max_acceleration = amax;
  p.max_jerk = jmax;
  p.start_time = t0;
  p.initial = initial;
  return p;
}

void expect_plan(const SCurvePlan& got, double tj, double ta, double tv, double v_peak, double a_peak) {
  const auto near = [](double a, double b) { return std::abs(a - b) <= kPlanTol * std::abs(b); };
  EXPECT_PRED2(near, got.t_jerk_accel, tj);
  EXPECT_PRED2(near, got.t_accel, ta);
  EXPECT_NEAR(got.t_const, tv, kPlanTol * ta);
  EXPECT_EQ(got.t_jerk_decel, got.t_jerk_accel);  // rest-to-rest: symmetric
  EXPECT_EQ(got.t_decel, got.t_accel);
  EXPECT_PRED2(near, got.peak_velocity, v_peak);
  EXPECT_PRED2(near, got.peak_acceleration, a_peak);
  EXPECT_PRED2(near, got.duration(), 2.0 * ta + tv);
}

// Breakpoints of the 7 segments relative to t0.
std::vector<double> breakpoints(const SCurvePlan& p) {
  const double tj = p.t_jerk_accel;
  const double ta = p.t_accel;
  const double t1 = ta + p.t_const;
  const double t = p.duration();
  return {0.0, tj, ta - tj, ta, t1, t1 + tj, t - tj, t};
}

// ----- Paper defaults (notes Sec. 2.7) ----------------------------------------------------------

TEST(SCurve, PaperDefaultsGiveA1p10sPureSMove) {
  // D = 0.1, vmax 0.2, amax 1.15, jmax 2.4: vmax*jmax = 0.48 < amax^2 = 1.3225 and
  // D/vmax = 0.5 < 2 sqrt(vmax/jmax) = 0.577, so vmax is not reached; with amax:
  // Ta = 0.479/2 + sqrt(0.2396^2 + 0.087) = 0.620 < 2 Tj = 0.958, so amax is not reached
  // either: Tj = (D/(2 jmax))^(1/3) = (1/48)^(1/3) = 0.27516 s, T = 4 Tj = 1.10064 s,
  // a_peak = jmax Tj = 0.66039 m/s^2, v_peak = jmax Tj^2 = 0.18171 m/s.
  const SCurveParams p;
  const double tj = std::cbrt(1.0 / 48.0);
  expect_plan(plan_scurve(p), tj, 2.0 * tj, 0.0, 2.4 * tj * tj, 2.4 * tj);
  // The measured value to ~1 ulp (2.2e-16 at 1.1); guards against silent changes of the plan.
  EXPECT_NEAR(plan_scurve(p).duration(), 1.1006424162982087, 1e-15);
  EXPECT_NEAR(plan_scurve(p).duration(), 1.10, 0.005);  // the rounded number in the docs
  // The 4-digit numbers quoted in the docs and the notes: half a unit in the last digit.
  EXPECT_NEAR(plan_scurve(p).peak_velocity, 0.1817, 5e-5);
  EXPECT_NEAR(plan_scurve(p).peak_acceleration, 0.6604, 5e-5);

  const auto tr = make_scurve(p);
  EXPECT_EQ(tr->end_time(), plan_scurve(p).duration());
  EXPECT_EQ(tr->sample(tr->end_time()).position, 0.1);
  // Symmetry: half the distance at half time, at peak velocity, zero acceleration. Values
  // ~0.05-0.7 from a few operations: tolerances of ~1-4 ulps of each quantity's magnitude.
  const Sample mid = tr->sample(0.5 * tr->end_time());
  EXPECT_NEAR(mid.position, 0.05, 1e-16);
  EXPECT_NEAR(mid.velocity, 2.4 * tj * tj, 1e-16);
  EXPECT_NEAR(mid.acceleration, 0.0, 1e-15);
  // First jerk phase: x = j t^3/6.
  const Sample early = tr->sample(0.1);
  EXPECT_NEAR(early.position, 2.4 * 1e-3 / 6.0, 1e-18);
  EXPECT_NEAR(early.velocity, 2.4 * 0.01 / 2.0, 1e-17);
  EXPECT_NEAR(early.acceleration, 0.24, 1e-16);
  EXPECT_EQ(early.jerk, 2.4);
}

TEST(SCurve, NotesTableOfPaperInterpretations) {
  // docs/paper-analysis.md Sec. 2.7: duration and peaks for the other readings.
  struct Row {
    double amax, jmax, t, v_peak, a_peak;
  };
  for (const Row& r : {Row{0.115, 0.24, 2.40, 0.083, 0.115}, Row{1.15, 24.0, 0.72, 0.200, 1.15},
                       Row{0.115, 2.4, 1.91, 0.105, 0.115}}) {
    const SCurvePlan plan = plan_scurve(make_params(0.1, 0.2, r.amax, r.jmax));
    // The notes quote 3 significant digits: half a unit in the last one.
    EXPECT_NEAR(plan.duration(), r.t, 0.005) << r.amax << " " << r.jmax;
    EXPECT_NEAR(plan.peak_velocity, r.v_peak, 0.0005);
    // amax is reached in all three: the peak is amax itself (1e-12: just rounding).
    EXPECT_NEAR(plan.peak_acceleration, r.a_peak, 1e-12);
  }
  // (1.15, 24): cruise 0.278 s.
  EXPECT_NEAR(plan_scurve(make_params(0.1, 0.2, 1.15, 24.0)).t_const, 0.278, 0.0005);
}

// ----- The four cases, hand-computed ------------------------------------------------------------

TEST(SCurve, Case1VelocityAndAccelerationReached) {
  // D=10, vmax=2, amax=1, jmax=1: vmax*jmax = 2 >= amax^2 = 1 -> Tj = 1, Ta = 1 + 2/1 = 3,
  // Tv = 10/2 - 3 = 2 >= 0. T = 8.
  const SCurveParams p = make_params(10.0, 2.0, 1.0, 1.0);
  expect_plan(plan_scurve(p), 1.0, 3.0, 2.0, 2.0, 1.0);
  const auto tr = make_scurve(p);
  // Segment ends: x(1) = j/6; x(1.5) = a/6 (3*1.5*0.5 + 1) = 3.25/6;
  // x(2) = a/6 (3*2*1 + 1) = 7/6, v(2) = 1.5; x(3) = vlim Ta/2 = 3;
  // cruise x(4) = 3 + 2 = 5 (half way); by symmetry x(8 - s) = 10 - x(s).
  struct Point {
    double t, x, v, a, j;
  };
  for (const Point& q :
       {Point{0.0, 0.0, 0.0, 0.0, 1.0}, Point{0.5, 0.125 / 6.0, 0.125, 0.5, 1.0}, Point{1.0, 1.0 / 6.0, 0.5, 1.0, 0.0},
        Point{1.5, 3.25 / 6.0, 1.0, 1.0, 0.0}, Point{2.0, 7.0 / 6.0, 1.5, 1.0, -1.0}, Point{3.0, 3.0, 2.0, 0.0, 0.0},
        Point{4.0, 5.0, 2.0, 0.0, 0.0}, Point{5.0, 7.0, 2.0, 0.0, -1.0}, Point{6.0, 10.0 - 7.0 / 6.0, 1.5, -1.0, 0.0},
        Point{7.0, 10.0 - 1.0 / 6.0, 0.5, -1.0, 1.0}, Point{7.5, 10.0 - 0.125 / 6.0, 0.125, -0.5, 1.0},
        Point{8.0, 10.0, 0.0, 0.0, 0.0}}) {
    const Sample s = tr->sample(q.t);
    EXPECT_NEAR(s.position, q.x, kHandTol) << "t=" << q.t;
    EXPECT_NEAR(s.velocity, q.v, kHandTol) << "t=" << q.t;
    EXPECT_NEAR(s.acceleration, q.a, kHandTol) << "t=" << q.t;
    EXPECT_EQ(s.jerk, q.j) << "t=" << q.t;  // a switching instant belongs to the next segment
  }
}

TEST(SCurve, Case2VelocityReachedAccelerationNot) {
  // D=10, vmax=1, amax=2, jmax=1: vmax*jmax = 1 < amax^2 = 4 -> Tj = sqrt(1/1) = 1, Ta = 2,
  // Tv = 10/1 - 2 = 8 >= 0; a_peak = jmax*Tj = 1 < amax. T = 12.
  const SCurveParams p = make_params(10.0, 1.0, 2.0, 1.0);
  expect_plan(plan_scurve(p), 1.0, 2.0, 8.0, 1.0, 1.0);
  const auto tr = make_scurve(p);
  EXPECT_NEAR(tr->sample(2.0).position, 1.0, kHandTol);  // vlim*Ta/2
  EXPECT_NEAR(tr->sample(6.0).position, 5.0, kHandTol);
  EXPECT_NEAR(tr->sample(1.0).acceleration, 1.0, kHandTol);  // the peak, a triangle
}

TEST(SCurve, Case3AccelerationReachedVelocityNot) {
  // D=6, vmax=10, amax=1, jmax=1: vmax*jmax >= amax^2 -> Tj=1, Ta=11, Tv = 0.6 - 11 < 0.
  // Recompute: Tj = 1, Ta = 1/2 + sqrt(1/4 + 6) = 3 >= 2 Tj: amax reached,
  // v_peak = amax (Ta - Tj) = 2 < vmax. T = 6, D = v_peak*Ta = 6.
  const SCurveParams p = make_params(6.0, 10.0, 1.0, 1.0);
  expect_plan(plan_scurve(p), 1.0, 3.0, 0.0, 2.0, 1.0);
  const auto tr = make_scurve(p);
  EXPECT_NEAR(tr->sample(3.0).position, 3.0, kHandTol);
  EXPECT_NEAR(tr->sample(3.0).velocity, 2.0, kHandTol);
  EXPECT_NEAR(tr->sample(1.5).acceleration, 1.0, kHandTol);
}

TEST(SCurve, Case4NeitherReached) {
  // D=2, vmax=10, amax=2, jmax=1: first Tj=2, Ta=7, Tv = 0.2 - 7 < 0; then Tj=2,
  // Ta = 1 + sqrt(1 + 1) = 2.414 < 2 Tj = 4: amax not reached. Tj = (2/2)^(1/3) = 1, Ta = 2,
  // a_peak = 1, v_peak = 1, T = 4, D = 2 jmax Tj^3 = 2.
  const SCurveParams p = make_params(2.0, 10.0, 2.0, 1.0);
  expect_plan(plan_scurve(p), 1.0, 2.0, 0.0, 1.0, 1.0);
  const auto tr = make_scurve(p);
  EXPECT_NEAR(tr->sample(1.0).position, 1.0 / 6.0, kHandTol);
  EXPECT_NEAR(tr->sample(2.0).position, 1.0, kHandTol);
  EXPECT_NEAR(tr->sample(3.0).position, 2.0 - 1.0 / 6.0, kHandTol);
  EXPECT_EQ(tr->sample(2.0).jerk, -1.0);  // the jerk stays -j through the peak velocity
}

TEST(SCurve, CaseBoundariesAreContinuous) {
  // At vmax*jmax = amax^2 the two vmax-reached formulas coincide (Tj = amax/jmax =
  // sqrt(vmax/jmax)); at D = vmax*Ta (Tv = 0) the vmax-reached and -not-reached plans meet.
  const SCurvePlan a = plan_scurve(make_params(10.0, 1.0, 1.0, 1.0));
  expect_plan(a, 1.0, 2.0, 8.0, 1.0, 1.0);
  // vmax=2, amax=jmax=1: Ta = 3, D = vmax*Ta = 6 -> Tv = 0, identical to case 3's plan
  // (D=6 with vmax = 2 exactly reached).
  expect_plan(plan_scurve(make_params(6.0, 2.0, 1.0, 1.0)), 1.0, 3.0, 0.0, 2.0, 1.0);
  expect_plan(plan_scurve(make_params(6.0, 2.0 * (1.0 + 1e-15), 1.0, 1.0)), 1.0, 3.0, 0.0, 2.0, 1.0);
}

TEST(SCurve, NegativeDistanceMirrors) {
  const SCurveParams pos = make_params(0.3, 0.2, 1.15, 2.4, 0.7, 0.05);
  const SCurveParams neg = make_params(-0.3, 0.2, 1.15, 2.4, 0.7, 0.05);
  const auto a = make_scurve(pos);
  const auto b = make_scurve(neg);
  EXPECT_EQ(a->end_time(), b->end_time());
  for (double t = 0.0; t < 3.0; t += 0.01) {
    const Sample sa = a->sample(t);
    const Sample sb = b->sample(t);
    // Each side rounds twice (initial + sign*x, then - 0.05) at ~0.35: ulp 5.6e-17 each.
    EXPECT_NEAR(sb.position - 0.05, -(sa.position - 0.05), 4e-16) << t;
    EXPECT_EQ(sb.velocity, -sa.velocity);
    EXPECT_EQ(sb.acceleration, -sa.acceleration);
    EXPECT_EQ(sb.jerk, -sa.jerk);
  }
  EXPECT_EQ(b->sample(b->end_time()).position, 0.05 - 0.3);
}

TEST(SCurve, ZeroDistanceIsAZeroLengthMove) {
  const SCurveParams p = make_params(0.0, 0.2, 1.15, 2.4, 2.0, 0.4);
  const SCurvePlan plan = plan_scurve(p);
  EXPECT_EQ(plan.duration(), 0.0);
  EXPECT_EQ(plan.peak_velocity, 0.0);
  const auto tr = make_scurve(p);
  EXPECT_EQ(tr->end_time(), 2.0);
  for (double t : {0.0, 2.0, 5.0}) {
    const Sample s = tr->sample(t);
    EXPECT_EQ(s.position, 0.4);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
}

TEST(SCurve, StartTimeAndInitialShiftTheMove) {
  const auto base = make_scurve(SCurveParams{});
  const auto shifted = make_scurve(make_params(0.1, 0.2, 1.15, 2.4, 1.5, -0.02));
  EXPECT_EQ(shifted->end_time(), 1.5 + base->end_time());
  for (double tau = 0.0; tau < 1.2; tau += 0.013) {
    // t0 + tau - t0 differs from tau by rounding of 1.5 + tau (1 ulp ~ 2e-16 s), moving x by
    // at most vmax * 2e-16; positions of ~0.1 add another ulp.
    EXPECT_NEAR(shifted->sample(1.5 + tau).position, base->sample(tau).position - 0.02, 2e-16);
  }
  EXPECT_EQ(shifted->sample(1.0).position, -0.02);
  EXPECT_EQ(shifted->sample(1.0).velocity, 0.0);
}

TEST(SCurve, NaNTimeGivesNaN) {
  const Sample s = make_scurve(SCurveParams{})->sample(std::nan(""));
  EXPECT_TRUE(std::isnan(s.position) && std::isnan(s.velocity));
}

// ----- Seeded random sweep ----------------------------------------------------------------------

// Accel-limited (trapezoid/triangle) duration for the same vmax and amax.
double trapezoid_duration(double d, double vmax, double amax) {
  d = std::abs(d);
  return d * amax >= vmax * vmax ? d / vmax + vmax / amax : 2.0 * std::sqrt(d / amax);
}

TEST(SCurve, RandomSweepProperties) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto log_uniform = [&](double lo_exp, double hi_exp) {
    return std::pow(10.0, lo_exp + (hi_exp - lo_exp) * unit(rng));
  };
  int counts[2][2] = {{0, 0}, {0, 0}};  // [vmax reached][amax reached]
  constexpr int kSets = 3000;
  for (int n = 0; n < kSets; ++n) {
    // Limits spanning 5-6 decades each, so the ratios (Tj/T, amax^2/(vmax jmax), ...) are
    // extreme in both directions; a tenth of the sets are paper-sized.
    SCurveParams p;
    if (n % 10 == 0) {
      p = make_params(0.1 * log_uniform(-1, 1), 0.2 * log_uniform(-1, 1), 1.15 * log_uniform(-1, 1),
                      2.4 * log_uniform(-1, 1));
    } else {
      p = make_params(log_uniform(-6, 1), log_uniform(-3, 1), log_uniform(-3, 2), log_uniform(-2, 4));
    }
    if (unit(rng) < 0.5) p.distance = -p.distance;
    p.start_time = -5.0 + 10.0 * unit(rng);
    p.initial = -1.0 + 2.0 * unit(rng);

    const SCurvePlan plan = plan_scurve(p);
    const auto tr = make_scurve(p);
    std::ostringstream label;
    label.precision(17);
    label << "set " << n << ": D=" << p.distance << " vmax=" << p.max_velocity << " amax=" << p.max_acceleration
          << " jmax=" << p.max_jerk << " t0=" << p.start_time << " x0=" << p.initial;
    SCOPED_TRACE(label.str());
    const Move move{p.start_time, p.initial, p.distance, plan.duration(), breakpoints(plan)};
    const Limits lim{p.max_velocity, p.max_acceleration, p.max_jerk};
    const testing::Peaks peaks = check_profile(*tr, move, lim, true, "S-curve", 4000);

    // The plan's peaks are the profile's, and within the limits.
    EXPECT_LE(plan.peak_velocity, p.max_velocity * (1.0 + testing::kLimitRelTol));
    EXPECT_LE(plan.peak_acceleration, p.max_acceleration * (1.0 + testing::kLimitRelTol));
    EXPECT_LE(peaks.v, plan.peak_velocity * (1.0 + testing::kLimitRelTol));
    const Sample mid = tr->sample(p.start_time + 0.5 * plan.duration());
    // At mid-move |v| = v_peak; v is flat there (a = 0), so the rounding of the time argument
    // costs only ~jmax*ulp(t)^2: 1e-12 relative is pure rounding margin.
    EXPECT_NEAR(std::abs(mid.velocity), plan.peak_velocity, 1e-12 * plan.peak_velocity);
    // Segment durations are consistent: Ta >= 2 Tj (exact, or 1 ulp in case 1/3 rounding),
    // D = v_peak (Ta + Tv) (Tv = D/vmax - Ta loses a few ulps of Ta: 1e-13 of D is ample).
    EXPECT_GE(plan.t_accel, 2.0 * plan.t_jerk_accel * (1.0 - 1e-15));
    EXPECT_NEAR(plan.peak_velocity * (plan.t_accel + plan.t_const), std::abs(p.distance), 1e-13 * std::abs(p.distance));

    // Time-optimality sanity. Lower bounds: the accel-limited trapezoid (it ignores jerk), and
    // a pure jerk-limited move ignoring vmax and amax (4 (D/(2 jmax))^(1/3)). Upper bound: the
    // trapezoid's velocity smoothed by a moving average of width w obeys all three limits if
    // w >= (largest acceleration jump within w)/jmax; it lasts T_trap + w. The jumps are
    // +-amax, so w = amax/jmax works when the cruise lasts >= w; otherwise (triangle or short
    // cruise) the jump +amax -> -amax of size 2 amax needs w = 2 amax/jmax. (The bound
    // T_trap + amax/jmax does NOT hold for triangles: D=1.395e-6, vmax=0.136, amax=4.26e-3,
    // jmax=0.767 gives T = 0.04216 s > 0.03618 + 0.00556.) Tolerance: a few ulps.
    const double t_trap = trapezoid_duration(p.distance, p.max_velocity, p.max_acceleration);
    const double trap_cruise = t_trap - 2.0 * std::min(p.max_velocity / p.max_acceleration, 0.5 * t_trap);
    const double w = (trap_cruise >= p.max_acceleration / p.max_jerk ? 1.0 : 2.0) * p.max_acceleration / p.max_jerk;
    const double t_pure_s = 4.0 * std::cbrt(std::abs(p.distance) / (2.0 * p.max_jerk));
    const double t = plan.duration();
    EXPECT_GE(t, t_trap * (1.0 - 1e-14));
    EXPECT_GE(t, t_pure_s * (1.0 - 1e-14));
    EXPECT_LE(t, (t_trap + w) * (1.0 + 1e-14));
    // Which of the four cases is it? A limit that is reached is the plan's peak (set to the
    // limit itself, or jmax*(amax/jmax): 1e-15 relative allows that one rounding).
    const bool v_hit = plan.t_const > 0.0;
    const bool a_hit = plan.t_accel > 2.0 * plan.t_jerk_accel;
    if (v_hit) {
      EXPECT_NEAR(plan.peak_velocity, p.max_velocity, 1e-15 * p.max_velocity);
    }
    if (a_hit) {
      EXPECT_NEAR(plan.peak_acceleration, p.max_acceleration, 1e-15 * p.max_acceleration);
    }
    ++counts[v_hit][a_hit];
    if (HasFailure()) break;  // one failing set is enough to debug
  }
  // Every case is exercised by the sweep, each in a sizeable share.
  for (int v = 0; v < 2; ++v)
    for (int a = 0; a < 2; ++a) EXPECT_GE(counts[v][a], kSets / 20) << "case v=" << v << " a=" << a;
}

}  // namespace
}  // namespace feeddrive::trajectory

// Acceleration-limited (trapezoid / triangle) move: the paper default (Xie & Liang Fig. 20),
// hand-computed trapezoids, and a seeded random sweep of the properties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "feeddrive/trajectory/trajectory.hpp"
#include "profile_checks.hpp"

namespace feeddrive::trajectory {
namespace {

using testing::check_profile;
using testing::Limits;
using testing::Move;

AccelLimitedParams make_params(double d, double vmax, double amax, double t0 = 0.0, double initial = 0.0) {
  AccelLimitedParams p;
  p.distance = d;
  p.max_velocity = vmax;
  p.max_acceleration = amax;
  p.start_time = t0;
  p.initial = initial;
  return p;
}

TEST(AccelLimited, PaperDefaultIsA1sTriangle) {
  // 0.1 m at 0.4 m/s^2: vmax^2/amax = 0.15625 > 0.1, so 0.25 m/s is never reached:
  // Ta = sqrt(0.1/0.4) = 0.5 s, T = 1 s, v_peak = 0.4*0.5 = 0.2 m/s.
  const auto tr = make_accel_limited(AccelLimitedParams{});
  // sqrt(0.1/0.4) rounds to exactly 0.5 in binary (0.1/0.4 rounds to 0.25).
  EXPECT_EQ(tr->end_time(), 1.0);
  const Sample before = tr->sample(0.5 - 1e-9);
  const Sample at = tr->sample(0.5);
  EXPECT_EQ(before.acceleration, 0.4);
  EXPECT_EQ(at.acceleration, -0.4);  // the jump +0.4 -> -0.4 belongs to t = 0.5
  // Values 0.05-0.2 from 2-3 operations: 1e-16 is ~1-4 ulps; a formula error would be O(1).
  EXPECT_NEAR(at.velocity, 0.2, 1e-16);
  EXPECT_NEAR(at.position, 0.05, 1e-16);
  // v is continuous through the jump: 1e-9 s before, v differs by amax*1e-9 = 4e-10.
  EXPECT_NEAR(before.velocity, 0.2, 1e-9);
  EXPECT_EQ(tr->sample(0.0).acceleration, 0.4);
  EXPECT_EQ(tr->sample(0.25).position, 0.0125);  // a t^2/2 = 0.4*0.0625/2, exact in binary
  EXPECT_NEAR(tr->sample(0.75).position, 0.1 - 0.0125, 1e-17);
  EXPECT_NEAR(tr->sample(0.75).velocity, 0.1, 1e-16);
  EXPECT_EQ(tr->sample(1.0).position, 0.1);
  EXPECT_EQ(tr->sample(1.0).acceleration, 0.0);
  // The peak velocity over a fine grid is 0.2 m/s, reached at 0.5 s only.
  double v_peak = 0.0;
  for (int k = 0; k <= 10000; ++k) v_peak = std::max(v_peak, tr->sample(k * 1e-4).velocity);
  EXPECT_NEAR(v_peak, 0.2, 1e-16);
  for (int k = 0; k <= 1000; ++k) EXPECT_EQ(tr->sample(k * 1e-3).jerk, 0.0);
}

TEST(AccelLimited, TrapezoidWhenVmaxIsReached) {
  // D = 10, vmax = 2, amax = 1: vmax^2/amax = 4 <= 10 -> Ta = 2, Tv = 10/2 - 2 = 3, T = 7.
  const auto tr = make_accel_limited(make_params(10.0, 2.0, 1.0, 1.0, 3.0));
  EXPECT_EQ(tr->end_time(), 8.0);
  struct Point {
    double t, x, v, a;
  };
  for (const Point& q : {Point{1.0, 3.0, 0.0, 1.0}, Point{2.0, 3.5, 1.0, 1.0}, Point{3.0, 5.0, 2.0, 0.0},
                         Point{4.5, 8.0, 2.0, 0.0}, Point{6.0, 11.0, 2.0, -1.0}, Point{7.0, 12.5, 1.0, -1.0},
                         Point{8.0, 13.0, 0.0, 0.0}, Point{9.0, 13.0, 0.0, 0.0}}) {
    const Sample s = tr->sample(q.t);
    // Values of order 1-10 from 2-3 operations: 1e-14 is ~50 ulps; errors would be O(1).
    EXPECT_NEAR(s.position, q.x, 1e-14) << q.t;
    EXPECT_NEAR(s.velocity, q.v, 1e-14) << q.t;
    EXPECT_EQ(s.acceleration, q.a) << q.t;
  }
}

TEST(AccelLimited, ExactlyReachingVmaxIsATrapezoidWithoutCruise) {
  // D = vmax^2/amax: the triangle's peak equals vmax, Tv = 0.
  const auto tr = make_accel_limited(make_params(4.0, 2.0, 1.0));
  EXPECT_EQ(tr->end_time(), 4.0);
  EXPECT_NEAR(tr->sample(2.0).velocity, 2.0, 1e-15);  // sqrt(4/1)*1: ~2 ulps of 2
}

TEST(AccelLimited, NegativeDistanceMovesBackwards) {
  const auto tr = make_accel_limited(make_params(-0.1, 0.25, 0.4, 0.0, 0.3));
  EXPECT_EQ(tr->end_time(), 1.0);
  EXPECT_EQ(tr->sample(0.2).acceleration, -0.4);
  EXPECT_EQ(tr->sample(0.6).acceleration, 0.4);
  // ~1-2 ulps of the values (0.2, 0.25).
  EXPECT_NEAR(tr->sample(0.5).velocity, -0.2, 1e-16);
  EXPECT_NEAR(tr->sample(0.5).position, 0.25, 1e-16);
  EXPECT_EQ(tr->sample(1.0).position, 0.3 - 0.1);
}

TEST(AccelLimited, ZeroDistanceIsAZeroLengthMove) {
  const auto tr = make_accel_limited(make_params(0.0, 0.25, 0.4, 1.0, 0.7));
  EXPECT_EQ(tr->end_time(), 1.0);
  for (double t : {0.0, 1.0, 2.0}) {
    const Sample s = tr->sample(t);
    EXPECT_EQ(s.position, 0.7);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
  }
}

TEST(AccelLimited, NaNTimeGivesNaN) {
  EXPECT_TRUE(std::isnan(make_accel_limited(AccelLimitedParams{})->sample(NAN).position));
}

// Reference plan, written out independently of the library: trapezoid if D >= vmax^2/amax.
struct Plan {
  double ta, tv, v_peak;
};
Plan reference_plan(double d, double vmax, double amax) {
  d = std::abs(d);
  if (d * amax >= vmax * vmax) return {vmax / amax, d / vmax - vmax / amax, vmax};
  const double ta = std::sqrt(d / amax);
  return {ta, 0.0, amax * ta};
}

TEST(AccelLimited, RandomSweepProperties) {
  std::mt19937_64 rng(987654321);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto log_uniform = [&](double lo_exp, double hi_exp) {
    return std::pow(10.0, lo_exp + (hi_exp - lo_exp) * unit(rng));
  };
  int triangles = 0;
  constexpr int kSets = 3000;
  for (int n = 0; n < kSets; ++n) {
    // 7 decades of distance, 4-5 of the limits: cruise/accel ratios from ~0 to ~1e9.
    AccelLimitedParams p = make_params(log_uniform(-6, 1), log_uniform(-3, 1), log_uniform(-3, 2),
                                       -5.0 + 10.0 * unit(rng), -1.0 + 2.0 * unit(rng));
    if (unit(rng) < 0.5) p.distance = -p.distance;
    std::ostringstream label;
    label.precision(17);
    label << "set " << n << ": D=" << p.distance << " vmax=" << p.max_velocity << " amax=" << p.max_acceleration
          << " t0=" << p.start_time << " x0=" << p.initial;
    SCOPED_TRACE(label.str());

    const auto tr = make_accel_limited(p);
    const Plan plan = reference_plan(p.distance, p.max_velocity, p.max_acceleration);
    const double t = 2.0 * plan.ta + plan.tv;
    triangles += plan.tv == 0.0;
    const Move move{p.start_time, p.initial, p.distance, t, {0.0, plan.ta, plan.ta + plan.tv, t}};
    const Limits lim{p.max_velocity, p.max_acceleration, std::numeric_limits<double>::infinity()};
    const testing::Peaks peaks = check_profile(*tr, move, lim, false, "accel-limited", 4000);

    // Acceleration is bang-coast-bang: exactly +-amax or 0; jerk is 0.
    for (double f : {0.1, 0.4, 0.6, 0.9}) {
      const Sample s = tr->sample(p.start_time + f * t);
      EXPECT_TRUE(s.acceleration == 0.0 || std::abs(s.acceleration) == p.max_acceleration) << s.acceleration;
      EXPECT_EQ(s.jerk, 0.0);
    }
    // Peak: vmax for a trapezoid, sqrt(D amax) for a triangle. The grid (4000 points over
    // 1.1 T) may miss a triangle's apex by dt/2, costing up to amax*dt/2 with T = 2 v_peak/amax:
    // 1.1 v_peak/4000 ~ 2.8e-4 v_peak; 1e-3 leaves margin.
    EXPECT_LE(peaks.v, plan.v_peak * (1.0 + testing::kLimitRelTol));
    EXPECT_GE(peaks.v, plan.v_peak * (1.0 - 1e-3));
    // At the middle of the move |v| = v_peak, up to the rounding of the time argument: for a
    // triangle the apex is sharp, so v moves by amax * (a few ulp of |t|).
    const double t_round = 4.0 * testing::kEps * (std::abs(p.start_time) + t);
    EXPECT_NEAR(std::abs(tr->sample(p.start_time + plan.ta + 0.5 * plan.tv).velocity), plan.v_peak,
                1e-12 * plan.v_peak + p.max_acceleration * t_round);

    // Time-optimality sanity: no faster than cruising at vmax all the way, nor than bang-bang
    // at amax with no velocity limit (1e-14: a few ulps of T); the duration is the
    // closed-form optimum.
    EXPECT_GE(t, std::abs(p.distance) / p.max_velocity * (1.0 - 1e-14));
    EXPECT_GE(t, 2.0 * std::sqrt(std::abs(p.distance) / p.max_acceleration) * (1.0 - 1e-14));
    // end_time() = t0 + T is rounded once, and subtracting t0 again rounds once more.
    EXPECT_NEAR(tr->end_time() - p.start_time, t, 1e-14 * t + 1e-15 * std::abs(p.start_time));
    if (HasFailure()) break;  // one failing set is enough to debug
  }
  // Both shapes are exercised in a sizeable share.
  EXPECT_GE(triangles, kSets / 10);
  EXPECT_LE(triangles, kSets - kSets / 10);
}

}  // namespace
}  // namespace feeddrive::trajectory

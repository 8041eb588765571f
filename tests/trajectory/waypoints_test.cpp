// Natural cubic spline through waypoints, and the CSV reader with its error messages.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

// ----- Spline -----------------------------------------------------------------------------------

TEST(Waypoints, HandComputedThreePointSpline) {
  // (0,0), (1,1), (2,0), natural: 2(h0+h1) M1 = 6((0-1)/1 - (1-0)/1) -> M1 = -3. On [0,1]:
  // x = 1.5 u - 0.5 u^3 (b0 = 1 - (2*0 - 3)/6 = 1.5, d0 = -3/6), so x(0.5) = 0.6875,
  // v(0.5) = 1.5 - 1.5*0.25 = 1.125, a(0.5) = -1.5, jerk -3; v(1) = 0 by symmetry.
  const auto tr = make_waypoints({{0.0, 0.0}, {1.0, 1.0}, {2.0, 0.0}});
  const Sample s = tr->sample(0.5);
  // All these are dyadic rationals computed in a few operations: exact or within an ulp.
  EXPECT_NEAR(s.position, 0.6875, 1e-16);
  EXPECT_NEAR(s.velocity, 1.125, 1e-15);
  EXPECT_NEAR(s.acceleration, -1.5, 1e-15);
  EXPECT_NEAR(s.jerk, -3.0, 1e-15);
  EXPECT_NEAR(tr->sample(1.0).velocity, 0.0, 1e-15);
  EXPECT_NEAR(tr->sample(1.5).position, 0.6875, 1e-15);
  EXPECT_NEAR(tr->sample(1.5).jerk, 3.0, 1e-15);
  EXPECT_EQ(tr->end_time(), 2.0);
}

TEST(Waypoints, TwoPointsAreAStraightLine) {
  const auto tr = make_waypoints({{1.0, 0.5}, {3.0, -0.5}});
  for (double t = 1.0; t < 3.0; t += 0.1) {
    const Sample s = tr->sample(t);
    EXPECT_NEAR(s.position, 0.5 - 0.5 * (t - 1.0), 1e-15);  // a few ulps of values <= 0.5
    EXPECT_EQ(s.velocity, -0.5);
    EXPECT_EQ(s.acceleration, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
}

TEST(Waypoints, HeldOutsideTheKnots) {
  const auto tr = make_waypoints({{1.0, 0.5}, {2.0, 0.7}, {3.0, -0.5}});
  for (double t : {-5.0, 0.999}) {
    const Sample s = tr->sample(t);
    EXPECT_EQ(s.position, 0.5);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
  }
  for (double t : {3.0, 10.0}) {
    const Sample s = tr->sample(t);
    EXPECT_EQ(s.position, -0.5);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
  EXPECT_TRUE(std::isnan(tr->sample(std::nan("")).position));
}

TEST(Waypoints, RandomSplinesInterpolateAreC2AndNatural) {
  std::mt19937_64 rng(424242);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    SCOPED_TRACE("spline " + std::to_string(n));
    // 2..41 knots, spacings varying over 3 decades (stresses the tridiagonal solve).
    const int count = 2 + static_cast<int>(unit(rng) * 40);
    std::vector<Waypoint> pts;
    double t = -1.0 + 2.0 * unit(rng);
    for (int i = 0; i < count; ++i) {
      pts.push_back({t, -1.0 + 2.0 * unit(rng)});
      t += std::pow(10.0, -2.0 + 3.0 * unit(rng));
    }
    const auto tr = make_waypoints(pts);
    double x_scale = 0.0;
    double a_scale = 0.0;
    double j_scale = 0.0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
      x_scale = std::max(x_scale, std::abs(pts[i].x));
      a_scale = std::max(a_scale, std::abs(tr->sample(pts[i].t).acceleration));
      j_scale = std::max(j_scale, std::abs(tr->sample(pts[i].t).jerk));
    }

    // Interpolation: exact at every knot (x_i is the constant term of its piece; the last
    // knot is the held end value).
    for (const Waypoint& w : pts) EXPECT_EQ(tr->sample(w.t).position, w.x);

    // C2 at interior knots: the left piece, Taylor-expanded (exactly, it is a cubic) from the
    // right piece's values at the knot, must reproduce the left samples at t_i - d.
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
      const double d = 0.25 * (pts[i].t - pts[i - 1].t);
      const Sample r = tr->sample(pts[i].t);
      const Sample l = tr->sample(pts[i].t - d);
      const double j = l.jerk;  // constant on the left piece
      // Rounding of the polynomial evaluations: values of order x_scale, v ~ x/h, a ~ x/h^2
      // with h >= 1e-2, products of up to 4 terms; 1e-9 relative to the largest term is a
      // loose bound that a mismatch in x, v or a at the knot (O(1) relative) would blow.
      const double v_scale = std::abs(r.velocity) + a_scale * d + j_scale * d * d;
      EXPECT_NEAR(l.position, r.position - r.velocity * d + r.acceleration * d * d / 2 - j * d * d * d / 6,
                  1e-9 * (x_scale + v_scale * d));
      EXPECT_NEAR(l.velocity, r.velocity - r.acceleration * d + j * d * d / 2, 1e-9 * v_scale);
      EXPECT_NEAR(l.acceleration, r.acceleration - j * d, 1e-9 * (a_scale + j_scale * d));
    }

    // Natural ends: x'' = 0 at t_0 and (from the left) at t_n.
    EXPECT_EQ(tr->sample(pts.front().t).acceleration, 0.0);
    const double eps_t = 1e-9 * (pts.back().t - pts[pts.size() - 2].t);
    const Sample end = tr->sample(pts.back().t - eps_t);
    // a(t_n - e) = -jerk e exactly in real arithmetic; rounding of M + 6 d u ~ 1e-12 a_scale.
    EXPECT_NEAR(end.acceleration, -end.jerk * eps_t, 1e-12 * (a_scale + 1.0));
    if (HasFailure()) break;
  }
}

TEST(Waypoints, InvalidPointsAreRejected) {
  const auto message = [](const std::vector<Waypoint>& pts) -> std::string {
    try {
      make_waypoints(pts);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(message({{0.0, 1.0}}), "waypoints: need at least 2 points, got 1");
  EXPECT_EQ(message({}), "waypoints: need at least 2 points, got 0");
  EXPECT_EQ(message({{0.0, 0.0}, {0.3, 1.0}, {0.2, 1.0}}),
            "waypoints[2].t = 0.2: must be greater than the previous t = 0.3");
  EXPECT_EQ(message({{0.0, 0.0}, {0.0, 1.0}}), "waypoints[1].t = 0: must be greater than the previous t = 0");
  EXPECT_EQ(message({{0.0, 0.0}, {1.0, std::nan("")}}), "waypoints[1].x = nan: must be a finite number");
  EXPECT_EQ(message({{-std::numeric_limits<double>::infinity(), 0.0}, {1.0, 1.0}}),
            "waypoints[0].t = -inf: must be a finite number");
}

}  // namespace
}  // namespace feeddrive::trajectory

#pragma once
// Property checks shared by the S-curve and accel-limited sweeps: limits, exact end state,
// continuity against Lipschitz bounds, and x = x0 + integral of v (Simpson per segment).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory::testing {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// |v| <= vmax etc. may be exceeded by rounding only: a peak like amax*(Ta - Tj) is a few
// floating-point operations away from vmax, i.e. a few ulps. 1e-12 leaves 4 orders of margin
// and would still catch any real violation.
constexpr double kLimitRelTol = 1e-12;

// Rounding floor for comparing two samples of one profile: the values are sums of a handful of
// products of magnitude <= the scale (|initial| + |D| for x, vmax for v, ...), each rounded to
// 0.5 ulp; 64 eps covers those with margin and is still ~1e-14 relative.
constexpr double kRoundRel = 64.0 * kEps;

// Simpson's rule is exact for polynomials of degree <= 3; v is piecewise quadratic and a
// piecewise linear, so the only error is rounding accumulated over the panels (~1e-15
// relative). The brief asks for ~1e-9 relative to |D|, which is what we assert.
constexpr double kSimpsonRelTol = 1e-9;
constexpr int kSimpsonPanelsPerSegment = 16;  // even; exactness does not depend on it
constexpr double kTinySegment = 64.0;         // segments below 64 "time roundings" are not integrated

struct Limits {
  double vmax;
  double amax;
  double jmax;  // +inf for the accel-limited profile
};

struct Move {
  double t0;
  double initial;
  double distance;
  double duration;
  // Segment boundaries relative to t0, from 0 to duration, ascending (zero-length segments
  // allowed).
  std::vector<double> breakpoints;
};

inline bool near_rel(double a, double b, double rel, double abs_floor) {
  return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + abs_floor;
}

// Composite Simpson of f over [a, b] with n (even) panels.
template <class F>
double simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double sum = f(a) + f(b);
  for (int k = 1; k < n; ++k) sum += (k % 2 ? 4.0 : 2.0) * f(a + k * h);
  return sum * h / 3.0;
}

// Runs every property check; `accel_continuous` is false for the accel-limited profile, whose
// acceleration steps. Returns the largest |v| and |a| seen.
struct Peaks {
  double v{0.0};
  double a{0.0};
};
inline Peaks check_profile(const Trajectory& tr, const Move& m, const Limits& lim, bool accel_continuous,
                           const std::string& label, int grid_points = 2000) {
  SCOPED_TRACE(label);
  Peaks peaks;
  const double dir = m.distance < 0.0 ? -1.0 : 1.0;
  const double x_scale = std::abs(m.initial) + std::abs(m.distance);
  const double x_final = m.initial + m.distance;
  const double t_end = m.t0 + m.duration;
  EXPECT_DOUBLE_EQ(tr.end_time(), t_end);

  // Before the start: start state, zero derivatives. At and after the end: EXACTLY the target.
  for (double t : {m.t0 - 1.0, m.t0 - 1e-9 * (1.0 + std::abs(m.t0))}) {
    const Sample s = tr.sample(t);
    EXPECT_EQ(s.position, m.initial);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
  for (double t : {tr.end_time(), t_end + 1e-9, t_end + 1e3}) {
    const Sample s = tr.sample(t);
    EXPECT_EQ(s.position, x_final);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
  if (m.duration == 0.0) return peaks;

  // Dense uniform grid over [t0 - 5 %, end + 5 %]: finite, within limits, monotone, and
  // neighbours within the Lipschitz bounds |dx| <= vmax dt, |dv| <= amax dt, |da| <= jmax dt.
  // The time argument itself carries rounding (t - t0 is computed inside), hence dt_round.
  const double lo = m.t0 - 0.05 * m.duration;
  const double hi = t_end + 0.05 * m.duration;
  const double dt = (hi - lo) / grid_points;
  const double dt_round = 4.0 * kEps * (std::abs(m.t0) + m.duration);
  Sample prev = tr.sample(lo);
  int failures = 0;  // stop reporting after a few, a sweep would otherwise flood the log
  for (int k = 1; k <= grid_points && failures < 5; ++k) {
    const double t = lo + k * dt;
    const Sample s = tr.sample(t);
    const bool finite = std::isfinite(s.position) && std::isfinite(s.velocity) && std::isfinite(s.acceleration) &&
                        std::isfinite(s.jerk);
    const bool within = std::abs(s.velocity) <= lim.vmax * (1.0 + kLimitRelTol) &&
                        std::abs(s.acceleration) <= lim.amax * (1.0 + kLimitRelTol) &&
                        std::abs(s.jerk) <= lim.jmax * (1.0 + kLimitRelTol);
    const double h = dt + dt_round;
    const bool lipschitz =
        std::abs(s.position - prev.position) <= lim.vmax * h * (1.0 + kLimitRelTol) + kRoundRel * x_scale &&
        std::abs(s.velocity - prev.velocity) <= lim.amax * h * (1.0 + kLimitRelTol) + kRoundRel * lim.vmax &&
        (!accel_continuous ||
         std::abs(s.acceleration - prev.acceleration) <= lim.jmax * h * (1.0 + kLimitRelTol) + kRoundRel * lim.amax);
    const bool monotone = dir * (s.position - prev.position) >= -kRoundRel * x_scale && dir * s.velocity >= 0.0;
    if (!(finite && within && lipschitz && monotone)) {
      ++failures;
      ADD_FAILURE() << "t=" << t << " finite=" << finite << " within=" << within << " lipschitz=" << lipschitz
                    << " monotone=" << monotone << " x=" << s.position << " v=" << s.velocity << " a=" << s.acceleration
                    << " j=" << s.jerk;
    }
    peaks.v = std::max(peaks.v, std::abs(s.velocity));
    peaks.a = std::max(peaks.a, std::abs(s.acceleration));
    prev = s;
  }

  // Straddle every breakpoint at +-delta: a jump there would be invisible on the grid if it
  // were smaller than vmax*dt. delta is far below the segment lengths but far above ulp(t).
  double min_segment = m.duration;
  for (std::size_t i = 1; i < m.breakpoints.size(); ++i) {
    const double len = m.breakpoints[i] - m.breakpoints[i - 1];
    if (len > 0.0) min_segment = std::min(min_segment, len);
  }
  const double delta = std::max(1e-6 * min_segment, 64.0 * dt_round);
  for (double b : m.breakpoints) {
    const double t = m.t0 + b;
    const Sample l = tr.sample(t - delta);
    const Sample r = tr.sample(t + delta);
    const double h = 2.0 * delta + dt_round;
    EXPECT_LE(std::abs(r.position - l.position), lim.vmax * h * (1.0 + kLimitRelTol) + kRoundRel * x_scale)
        << "x jumps at t0+" << b;
    EXPECT_LE(std::abs(r.velocity - l.velocity), lim.amax * h * (1.0 + kLimitRelTol) + kRoundRel * lim.vmax)
        << "v jumps at t0+" << b;
    if (accel_continuous) {
      EXPECT_LE(std::abs(r.acceleration - l.acceleration), lim.jmax * h * (1.0 + kLimitRelTol) + kRoundRel * lim.amax)
          << "a jumps at t0+" << b;
    }
  }

  // x(b_k) = x0 + integral of v, v(b_k) = integral of a and a(b_k) = integral of jerk, segment
  // by segment (inside a segment each is a polynomial of degree <= 2), evaluated in absolute
  // time like a user would. x, v (and a for the S-curve) are continuous at the breakpoints.
  double x_integral = m.initial;
  double v_integral = 0.0;
  double a_integral = 0.0;
  for (std::size_t i = 1; i < m.breakpoints.size(); ++i) {
    const double a = m.t0 + m.breakpoints[i - 1];
    const double b = m.t0 + m.breakpoints[i];
    if (!(b > a)) continue;
    // a and jerk may step at a segment's ends, which belong to a neighbour: integrate them
    // over [a + e, b - e] and rescale, exact for a polynomial of degree <= 1 (the mean over a
    // symmetric inset equals the mean over the segment). e must survive rounding of |t|.
    // Segments shorter than kTinySegment ulps (typically zero-length in exact arithmetic, e.g.
    // the constant-acceleration phase of a pure S) are skipped: their contribution is below
    // the rounding allowance `shift` below.
    if (b - a <= kTinySegment * dt_round) continue;
    const double e = std::max(1e-6 * (b - a), 4.0 * dt_round);
    const double scale = (b - a) / (b - a - 2.0 * e);
    x_integral += simpson([&](double t) { return tr.sample(t).velocity; }, a, b, kSimpsonPanelsPerSegment);
    v_integral +=
        scale * simpson([&](double t) { return tr.sample(t).acceleration; }, a + e, b - e, kSimpsonPanelsPerSegment);
    a_integral += scale * simpson([&](double t) { return tr.sample(t).jerk; }, a + e, b - e, kSimpsonPanelsPerSegment);
    const Sample at_b = tr.sample(b);
    // Besides kSimpsonRelTol: in absolute time a segment's length is only known to a few
    // ulp(|t|) (dt_round); that shifts each integral by up to (derivative bound) * dt_round.
    const double shift = static_cast<double>(i) * kTinySegment * dt_round;
    EXPECT_NEAR(at_b.position, x_integral, kSimpsonRelTol * x_scale + lim.vmax * shift)
        << "x != x0 + integral of v at t0+" << m.breakpoints[i];
    EXPECT_NEAR(at_b.velocity, v_integral, kSimpsonRelTol * lim.vmax + lim.amax * shift)
        << "v != integral of a at t0+" << m.breakpoints[i];
    if (accel_continuous) {
      EXPECT_NEAR(at_b.acceleration, a_integral, kSimpsonRelTol * lim.amax + lim.jmax * shift)
          << "a != integral of jerk at t0+" << m.breakpoints[i];
    }
  }
  return peaks;
}

}  // namespace feeddrive::trajectory::testing

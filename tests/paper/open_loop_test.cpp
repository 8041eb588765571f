// Xie & Liang Sec. 4 (open-loop studies) against the paper and the independent check values of
// docs/paper-analysis.md ("[sim]": SciPy Radau, rtol 1e-8). Each tolerance is
// explained where it is used.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "paper_util.hpp"

namespace feeddrive::paper {
namespace {

// Fig. 8: a 12 N step (10 % of Fs) stays in presliding. Static estimate z = F/sigma0 = 6.0 um;
// notes: z -> 6.000 um, x = 6.39 um at 1 s (x - z creeps through the sigma0|v|z/g term).
// 1 % on z: the presliding mode (22 Hz, zeta 0.7) has decayed by e^-98 at 1 s. 2 % on x: the
// slow creep depends on integration details at the 1e-9 m level.
TEST(PaperOpenLoop, PreslidingStep12N) {
  const PaperRun r = simulate("open_loop_step_12N");
  const auto& end = r.r.records.back();
  EXPECT_NEAR(end.z, 6.0e-6, 0.06e-6);
  EXPECT_NEAR(end.x, 6.39e-6, 0.13e-6);
  // The paper: "displacement ... about 6 um", x between 6.0 and 6.8 um throughout the settle.
  EXPECT_LE(r.sum.max_position_m, 6.8e-6);
  EXPECT_GE(end.x, 6.0e-6);
  // Macroscopic displacement almost equals the bristle deflection (stiction regime): < 10 %.
  EXPECT_LT(std::abs(end.x - end.z) / end.z, 0.1);
}

// Fig. 9: a 130 N step breaks away; friction falls from ~Fs to Fc = 80 N by 1 s.
// Notes [sim]: F_f = 119.9 N at 0.05 s, 98.7 N at 0.5 s, 80.1 N at 1 s, 80.3 N at 2 s;
// x(1 s) = 113 mm, v(1 s) = 0.31 m/s; z -> Fc/sigma0 = 40 um. 1 N bands: 1 % of the force.
TEST(PaperOpenLoop, BreakawayStep130NFrictionFallsToCoulomb) {
  const PaperRun r = simulate("open_loop_step_130N");
  EXPECT_NEAR(r.at(0.05).f_friction, 119.9, 1.0);
  EXPECT_NEAR(r.at(0.5).f_friction, 98.7, 1.0);
  EXPECT_NEAR(r.at(1.0).f_friction, 80.1, 1.0);
  EXPECT_NEAR(r.r.records.back().f_friction, 80.3, 1.0);
  // x and v at 1 s within 3 %: they integrate the force difference, whose error is ~1 %.
  EXPECT_NEAR(r.at(1.0).x, 0.113, 0.113 * 0.03);
  EXPECT_NEAR(r.at(1.0).v, 0.31, 0.31 * 0.03);
  EXPECT_NEAR(r.r.records.back().z, 40e-6, 0.5e-6);
  // Macroscopic displacement >> presliding.
  EXPECT_GT(r.at(1.0).x, 1000 * r.at(1.0).z);
}

struct SineFit {
  double amplitude;  ///< of the fundamental of x [m]
  double lag;        ///< phase lag of x behind the force [rad]
};
// Fundamental of x over the last full period of a sine-driven run (discrete Fourier
// projection), relative to the input sin(2 pi f t).
SineFit fundamental(const PaperRun& r, double f) {
  const double period = 1.0 / f;
  const double t1 = r.r.records.back().t;
  const double t0 = t1 - period;
  double a = 0, b = 0, mean = 0;
  int n = 0;
  for (const auto& q : r.r.records)
    if (q.t > t0) {
      mean += q.x;
      ++n;
    }
  mean /= n;
  for (const auto& q : r.r.records)
    if (q.t > t0) {
      a += (q.x - mean) * std::sin(2 * M_PI * f * q.t);
      b += (q.x - mean) * std::cos(2 * M_PI * f * q.t);
    }
  a *= 2.0 / n;
  b *= 2.0 / n;
  return {std::hypot(a, b), -std::atan2(b, a)};
}

// Fig. 10: 12 N sines at 0.1, 1 and 10 Hz give the same presliding amplitude, with a phase lag
// at 10 Hz. Notes [sim]: x spans -5.72/+6.32 um (0.1, 1 Hz) and -5.67/+6.21 um (10 Hz).
TEST(PaperOpenLoop, PreslidingSinesSameAmplitudeLagAt10Hz) {
  std::vector<SineFit> fits;
  std::vector<double> spans;
  for (const char* tag : {"0p1", "1", "10"}) {
    const PaperRun r = simulate(std::string("open_loop_sine_12N_") + tag + "Hz");
    const double f = std::string(tag) == "0p1" ? 0.1 : std::stod(tag);
    fits.push_back(fundamental(r, f));
    spans.push_back(r.sum.max_position_m - r.sum.min_position_m);
  }
  // Same amplitude: the spans agree within 3 % (the notes' values differ by 1.3 %).
  EXPECT_NEAR(spans[0], 12.04e-6, 0.3e-6);
  EXPECT_NEAR(spans[1] / spans[0], 1.0, 0.03);
  EXPECT_NEAR(spans[2] / spans[0], 1.0, 0.03);
  // Phase: the linearised presliding mode (sigma0 spring, 22.3 Hz, zeta 0.7) lags by
  // atan(2 zeta r/(1 - r^2)) = 0.4, 3.6 and 45 deg at r = f/22.3 for 0.1, 1 and 10 Hz. The
  // nonlinear creep term sigma0|v|z/g(v) adds a hysteretic lag of a few degrees (ours: 2.8, 6.1,
  // 41 deg). Bounds: < 10 deg at 0.1 and 1 Hz, > 30 deg and > 5x the 1 Hz lag at 10 Hz.
  const double deg = 180 / M_PI;
  EXPECT_LT(std::abs(fits[0].lag) * deg, 10.0);
  EXPECT_LT(std::abs(fits[1].lag) * deg, 10.0);
  EXPECT_GT(fits[2].lag * deg, 30.0);
  EXPECT_GT(fits[2].lag, 5 * std::abs(fits[1].lag));
}

// Fig. 11: 120 N sines: higher frequency -> lower macroscopic displacement.
// Notes [sim]: max x = 551, 381, 134 um. 5 % bands: the sliding phases integrate a force
// difference near breakaway, which is sensitive to the exact Stribeck crossing.
TEST(PaperOpenLoop, SlidingSinesDisplacementFallsWithFrequency) {
  const double m01 = simulate("open_loop_sine_120N_0p1Hz").sum.max_position_m;
  const double m1 = simulate("open_loop_sine_120N_1Hz").sum.max_position_m;
  const double m10 = simulate("open_loop_sine_120N_10Hz").sum.max_position_m;
  EXPECT_GT(m01, m1);
  EXPECT_GT(m1, m10);
  EXPECT_NEAR(m01, 551e-6, 551e-6 * 0.05);
  EXPECT_NEAR(m1, 381e-6, 381e-6 * 0.05);
  EXPECT_NEAR(m10, 134e-6, 134e-6 * 0.05);
}

// Fig. 12: breakaway force falls as the force rate rises, breakaway = the applied force when v
// first exceeds 1 mm/s (paper-analysis.md Sec. 2.4). Notes [sim]: 120.5, 119.3, 117.2, 98.0,
// 73.3 N for 10, 50, 100, 500, 1000 N/s. 1.5 % bands: the crossing time is resolved to one
// 0.1 ms sample, i.e. 0.1 N at 1000 N/s, and the notes' values carry ~1 % of their own.
TEST(PaperOpenLoop, BreakawayForceFallsWithForceRate) {
  const std::vector<std::pair<int, double>> cases = {{10, 120.5}, {50, 119.3}, {100, 117.2}, {500, 98.0}, {1000, 73.3}};
  double previous = 1e9;
  for (const auto& [rate, expected] : cases) {
    const PaperRun r = simulate("open_loop_breakaway_" + std::to_string(rate) + "Nps");
    double breakaway = std::nan("");
    for (const auto& q : r.r.records)
      if (q.v > 1e-3) {
        breakaway = q.f_thrust;
        break;
      }
    ASSERT_FALSE(std::isnan(breakaway)) << rate << " N/s never broke away";
    EXPECT_NEAR(breakaway, expected, expected * 0.015) << rate << " N/s";
    EXPECT_LT(breakaway, previous) << rate << " N/s";
    previous = breakaway;
  }
}

// Fig. 13: with ripple (phases 0, 0 < x < p/2 so F_r > 0 opposes the input) friction and
// displacement are smaller than with friction only.
TEST(PaperOpenLoop, RippleReducesDisplacementAndFriction) {
  const PaperRun with = simulate("open_loop_ripple_step_130N");
  sim::Scenario s = scenario("open_loop_ripple_step_130N");
  s.plant.ripple.enabled = false;
  const PaperRun without = simulate(s);
  for (double t : {0.5, 1.0, 2.0}) {
    EXPECT_LT(with.at(t).x, without.at(t).x) << t;
    EXPECT_GT(with.at(t).f_ripple, 0.0) << t;
  }
  EXPECT_LT(with.at(2.0).f_friction, without.at(2.0).f_friction);
  // Same order of magnitude: ripple (at most ~9 N here) only trims the ~50 N net sliding force
  // and the near-breakaway phase (ours: x(1 s) is 0.64x the friction-only value).
  EXPECT_GT(with.at(1.0).x / without.at(1.0).x, 0.5);
}

// Fig. 14: u = 130 sin(2 pi t) with ripple: the macroscopic displacement drifts as time
// advances. Without ripple LuGre is odd-symmetric, so after the first cycle every cycle repeats
// and the per-cycle mean position stays put (ours: it moves < 0.1 um per cycle). The
// position-dependent ripple breaks the symmetry: the mean moves the same way every cycle (ours:
// -145, -77, -40, -20 um). Thresholds: > 10 um per cycle with ripple (half the smallest drift
// seen); < 1 um per cycle without (10x what we see, so integration error cannot fail it).
std::vector<double> cycle_means(const PaperRun& r, int cycles) {
  std::vector<double> out;
  for (int c = 0; c < cycles; ++c) {
    double m = 0;
    int n = 0;
    for (const auto& q : r.r.records)
      if (q.t >= c && q.t < c + 1) {
        m += q.x;
        ++n;
      }
    out.push_back(m / n);
  }
  return out;
}

TEST(PaperOpenLoop, RippleSineDisplacementDrifts) {
  const auto with = cycle_means(simulate("open_loop_ripple_sine_130N"), 5);
  sim::Scenario s = scenario("open_loop_ripple_sine_130N");
  s.plant.ripple.enabled = false;
  const auto without = cycle_means(simulate(s), 5);
  const double first = with[1] - with[0];
  for (int c = 1; c < 5; ++c) {
    const double d = with[c] - with[c - 1];
    EXPECT_GT(std::abs(d), 10e-6) << "cycle " << c;
    EXPECT_GT(d * first, 0.0) << "cycle " << c << ": the drift must keep its direction";
    EXPECT_LT(std::abs(without[c] - without[c - 1]), 1e-6) << "cycle " << c;
  }
}

// Fig. 15: 180 N with friction, ripple and grinding: grinding dominates, friction rises, ripple
// negligible. Notes [sim] table: (F_g, F_f, x) = (165, 15, 10.3 um) at 0.1 s, (140, 40, 26) at
// 1 s, (122, 58, 42) at 2 s, (92, 88, 81) at 5 s. Bands: 3 N on forces (2 % of 180 N) and
// 10 % on x (x integrates the creep velocity).
TEST(PaperOpenLoop, AllForces180NGrindingDominates) {
  const PaperRun r = simulate("open_loop_all_forces_180N");
  struct Row {
    double t, fg, ff, x;
  };
  for (const Row& row :
       {Row{0.1, 165, 15, 10.3e-6}, Row{1, 140, 40, 26e-6}, Row{2, 122, 58, 42e-6}, Row{5, 92, 88, 81e-6}}) {
    const auto& q = r.at(row.t);
    EXPECT_NEAR(q.f_grinding, row.fg, 3.0) << row.t;
    EXPECT_NEAR(q.f_friction, row.ff, 3.0) << row.t;
    EXPECT_NEAR(q.x, row.x, 0.1 * row.x) << row.t;
    EXPECT_GT(q.f_grinding, q.f_friction) << row.t;
    EXPECT_LT(std::abs(q.f_ripple), 0.05 * q.f_grinding) << row.t;
  }
  EXPECT_LT(r.at(1).f_friction, r.at(2).f_friction);
  EXPECT_LT(r.at(2).f_friction, r.at(5).f_friction);
}

}  // namespace
}  // namespace feeddrive::paper

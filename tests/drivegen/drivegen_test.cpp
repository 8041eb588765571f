// The independent generator itself (drivegen/): its integrator against analytic
// solutions, its sensor and clock, its determinism and its case mix.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivegen.hpp"

namespace {

// m x'' = F from rest: x = F t^2 / (2 m). RK4 integrates a quadratic exactly, so only rounding
// is left: 1e-12 relative.
TEST(DriveGen, ConstantThrustOnAFreeMassIsAParabola) {
  const auto [x, v] = fdgen::integrate_mass(80.0, 40.0, 0.0, 0.0, 2.0, 200);
  EXPECT_NEAR(x, 40.0 * 4.0 / (2 * 80.0), 1e-12);
  EXPECT_NEAR(v, 40.0 * 2.0 / 80.0, 1e-12);
}

// m v' = -c v: v = v0 exp(-c t/m). RK4's global error is O(h^4): halving the step divides it
// by 16 (between 12 and 20 allows for the higher-order terms at this step size).
TEST(DriveGen, ViscousDecayIsExponentialWithFourthOrderConvergence) {
  const double m = 50.0, c = 500.0, v0 = 0.1, T = 0.5, exact = v0 * std::exp(-c * T / m);
  const double e1 = std::abs(fdgen::integrate_mass(m, 0.0, c, v0, T, 50).second - exact);
  const double e2 = std::abs(fdgen::integrate_mass(m, 0.0, c, v0, T, 100).second - exact);
  EXPECT_LT(e1, 1e-6 * v0);
  EXPECT_GT(e1 / e2, 12.0);
  EXPECT_LT(e1 / e2, 20.0);
}

TEST(DriveGen, SameSeedSameRecordAndQuantizedJitteredSamples) {
  fdgen::CaseSpec s;
  s.seed = 42;
  s.hidden = {"cogging_ripple", "viscous_friction"};
  const fdgen::Generated a = fdgen::generate(s), b = fdgen::generate(s);
  EXPECT_EQ(a.csv(), b.csv());
  ASSERT_EQ(a.t.size(), 10001u);
  const double q = a.knobs.at("quantization_m"), jitter = a.knobs.at("jitter_s");
  for (std::size_t k = 0; k < a.x.size(); ++k) {
    // a multiple of the resolution, up to the rounding of x = q * n
    EXPECT_NEAR(a.x[k] / q, std::round(a.x[k] / q), 1e-6) << k;
    // jittered by at most 2 % of the period plus the 1 us stamp error
    EXPECT_LE(std::abs(a.t[k] - 1e-3 * static_cast<double>(k)), jitter + 1e-6 + 1e-12) << k;
    if (k > 0) {
      EXPECT_GT(a.t[k], a.t[k - 1]) << k;
    }
  }
  ASSERT_EQ(a.truth.size(), 2u);
  for (const auto& e : a.truth)
    for (const auto& [k, v] : e.parameters) EXPECT_TRUE(std::isfinite(v)) << e.name << "." << k;
  EXPECT_NE(a.scenario_yaml.find("mass:"), std::string::npos);
  EXPECT_EQ(a.knobs.at("saturated_fraction"), 0.0);  // the loop runs without limit cycles
  s.seed = 43;
  EXPECT_NE(fdgen::generate(s).csv(), a.csv());
}

// A dwell of the closed loop with a hidden constant force and no friction: the thrust holds the
// force. The integral action settles within the 0.1 s before the end of a dwell; the PID's
// derivative of a quantized position adds noise of a few N. Tolerance: 25 % of F.
TEST(DriveGen, AtADwellTheThrustBalancesAHiddenConstantForce) {
  int checked = 0;
  for (std::uint64_t seed = 1; seed < 40 && checked < 3; ++seed) {
    fdgen::CaseSpec s;
    s.seed = seed;
    s.hidden = {"constant_force"};
    const fdgen::Generated g = fdgen::generate(s);
    if (g.knobs.at("base_static_friction") != 0.0) continue;
    const double F = g.truth.front().parameters.at("force");
    // the longest run of a constant reference: a dwell
    std::size_t best_end = 0, best_len = 0, len = 0;
    for (std::size_t k = 1; k < g.xd.size(); ++k) {
      len = g.xd[k] == g.xd[k - 1] ? len + 1 : 0;
      if (len > best_len) best_len = len, best_end = k;
    }
    ASSERT_GT(best_len, 200u);
    double sum = 0;
    for (std::size_t k = best_end - 50; k <= best_end; ++k) sum += g.force_N[k];
    EXPECT_NEAR(sum / 51.0, F, 0.25 * std::abs(F)) << "seed " << seed;
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

TEST(DriveGen, StandardCasesCoverEveryEffectPairsAndEffectFreeRecords) {
  const auto cases = fdgen::standard_cases(100, 7);
  ASSERT_EQ(cases.size(), 100u);
  std::map<std::string, int> alone;
  int free = 0, pairs = 0;
  std::set<std::uint64_t> seeds;
  for (const auto& c : cases) {
    seeds.insert(c.seed);
    if (c.hidden.empty()) ++free;
    if (c.hidden.size() == 1) ++alone[c.hidden.front()];
    if (c.hidden.size() == 2) {
      ++pairs;
      EXPECT_NE(c.hidden[0], c.hidden[1]);
    }
    for (const auto& h : c.hidden)
      if (h == "grinding_force") {
        EXPECT_TRUE(c.grinding_process);
      }
  }
  EXPECT_EQ(seeds.size(), 100u);
  EXPECT_GE(free, 10);
  EXPECT_GE(pairs, 20);
  for (const auto& e : fdgen::vocabulary()) EXPECT_GE(alone[e], 5) << e;
}

}  // namespace

namespace {

// fd-drivegen's command line: every number checked whole (atof once read "1x" as 1 and "abc" as
// 0), every word known; one line naming the argument and its value.
TEST(DriveGen, TheCommandLineIsCheckedWhole) {
  const fdgen::CaseSpec s =
      fdgen::parse_command_line({"7", "dir", "2.5", "cogging_ripple,none", "onedir", "periods=1.6", "bw=40"});
  EXPECT_EQ(s.seed, 7u);
  EXPECT_EQ(s.duration, 2.5);
  EXPECT_EQ(s.hidden, std::vector<std::string>{"cogging_ripple"});
  EXPECT_TRUE(s.one_direction);
  EXPECT_EQ(s.ripple_periods, 1.6);
  EXPECT_EQ(s.bandwidth_hz, 40.0);
  const auto error = [](const std::vector<std::string>& args) {
    try {
      fdgen::parse_command_line(args);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error({"x1", "dir"}), "SEED = 'x1': not a non-negative integer");
  EXPECT_EQ(error({"-1", "dir"}), "SEED = '-1': not a non-negative integer");
  EXPECT_EQ(error({"99999999999999999999999", "dir"}), "SEED = '99999999999999999999999': not a non-negative integer");
  EXPECT_EQ(error({"1", "dir", "1x"}), "DURATION_S = '1x': not a number");
  EXPECT_EQ(error({"1", "dir", "0"}), "DURATION_S = '0': must be > 0");
  EXPECT_EQ(error({"1", "dir", "1", "none", "periods=abc"}), "periods = 'abc': not a number");
  EXPECT_EQ(error({"1", "dir", "1", "none", "bw=-5"}), "bw = '-5': must be >= 0");
  EXPECT_EQ(error({"1", "dir", "1", "none", "grindng"}),
            "'grindng': expected one of grinding, noform, onedir, periods=P, bw=HZ");
  EXPECT_EQ(error({"1"}), "expected at least SEED DIR");
}

}  // namespace

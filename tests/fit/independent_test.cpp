// feeddrive-fit on records it was not built against: a seeded subset of the independent
// generator's case mix (drivegen/: its own RK4 integrator, PID or cascade loop, dwells,
// reversals and creeping moves, smoother and asymmetric friction, 50-200 nm quantization,
// jitter, a random nominal mass). The full sweep of 100+ records is bench/fit_bench.sh, with its
// figures in docs/fit.md; this subset runs on every CI.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "sweep.hpp"

namespace feeddrive::fit {
namespace {

constexpr int kSubsetSize = 24;
constexpr std::uint64_t kSubsetSeed = 11;

TEST(IndependentRecords, SeededSubsetIsNamedRightWithoutSpuriousEffects) {
  const auto cases = fdgen::standard_cases(kSubsetSize, kSubsetSeed);
  int right = 0, spurious = 0, free = 0, free_named = 0;
  for (const auto& c : cases) {
    const sweep::Outcome o = sweep::run_case(c);
    std::printf("  %s -> %s%s%s  [%s]\n", sweep::names(o.hidden).c_str(), sweep::names(o.named).c_str(),
                o.right ? "" : "  MISS", o.parameter_miss.empty() ? "" : ("  " + o.parameter_miss).c_str(),
                o.description.c_str());
    right += o.right;
    spurious += o.spurious;
    if (o.hidden.empty()) {
      ++free;
      free_named += !o.named.empty();
    }
  }
  const int n = static_cast<int>(cases.size());
  std::printf("named right %d of %d, spurious %d, effect-free naming an effect %d of %d\n", right, n, spurious,
              free_named, free);
  // The issue's targets on 100+ records are >= 90 % right, <= 5 % spurious, <= 5 % of the
  // effect-free records naming an effect; the sweep of bench/fit_bench.sh measures them (94 %,
  // 5 %, 0 %: docs/fit.md). This fixed subset of 24 is a regression guard near its measured
  // figures (22 right, 0 spurious, no effect-free record naming one): it allows one more miss
  // (4 % here) and one spurious effect.
  EXPECT_GE(right, n - 3);
  EXPECT_LE(spurious, 1);
  EXPECT_EQ(free_named, 0);
  EXPECT_GE(free, 2);
}

}  // namespace
}  // namespace feeddrive::fit

namespace feeddrive::fit {
namespace {

// Issue 20's cases (fdgen::issue20_cases): short-travel ripples, asymmetric friction,
// one-direction moves, a mass error with a ripple, 4-14 Hz loops. A handful on every CI (the
// 150-record table is bench/fit_bench.sh ... issue20, docs/fit.md): never a false all-clear --
// no record with a hidden effect is told "explained" or "no discrepancy" while nothing was
// named, or while its gap or force residual is above the noise floor -- and every unexplained
// verdict says what record would settle it.
TEST(IndependentRecords, Issue20CasesGetNoFalseAllClear) {
  const auto all = fdgen::issue20_cases(150, 20);
  // one of each special category (they follow the standard part of the mix), an effect-free and
  // a standard record with effects
  std::vector<fdgen::CaseSpec> cases{all[2], all[20]};
  std::set<std::string> seen;
  for (const auto& c : all)
    if (c.category != "standard" && c.category != "standard, 4-14 Hz loop" && seen.insert(c.category).second)
      cases.push_back(c);
  ASSERT_EQ(seen.size(), 4u);
  int right = 0;
  for (const auto& c : cases) {
    const sweep::Outcome o = sweep::run_case(c);
    std::printf("  %s: %s -> %s, %s%s%s\n", o.category.c_str(), sweep::names(o.hidden).c_str(),
                sweep::names(o.named).c_str(), o.verdict.c_str(),
                o.tie_partners.empty() ? "" : (", tie " + sweep::names(o.tie_partners)).c_str(),
                o.right ? "" : "  MISS");
    right += o.right;
    EXPECT_FALSE(o.nothing_there) << o.description;
    EXPECT_FALSE(o.above_floor_all_clear) << o.description;
    if (o.verdict == "unexplained") {
      EXPECT_TRUE(o.suggestion) << o.description << ": " << o.conclusion;
    }
  }
  // The bench's rate is in docs/fit.md (issue 20's table); on these 6 one miss is allowed.
  EXPECT_GE(right, static_cast<int>(cases.size()) - 1);
}

}  // namespace
}  // namespace feeddrive::fit

namespace feeddrive::fit {
namespace {

// The noise floor is what a perfect model leaves (fit/verdict.hpp): on effect-free records of a
// drive without friction -- the model is then the generator's physics exactly, up to its RK4 --
// the replay gap and the force residual must come out AT the floor, neither far above it (a floor
// too low calls every record unexplained) nor far below (a floor too high would hide an effect).
// The band 0.67-1.5x: the gap is an RMS over 10^4 samples and the force residual over ~500
// independent filter points, so the sampling spread of either is a few per cent; the rest of
// the band is the first-order (v d_k, dF_k d_k) and leading-order (dt^2/12) approximations of
// the floor's terms. Measured: gap 0.98-1.00x, force 0.99-1.15x (docs/fit.md); before the
// filter's discretisation and the stamp error were in the floor, the force residual of the first
// of these records was 5.8x it.
TEST(NoiseFloor, PerfectModelRecordsSitAtTheFloor) {
  const auto all = fdgen::issue20_cases(150, 20);
  int checked = 0;
  for (std::size_t i = 0; i < 10; ++i) {
    const fdgen::Generated g = fdgen::generate(all[i]);
    if (!all[i].hidden.empty() || g.knobs.at("base_static_friction") != 0.0) continue;
    const sweep::Outcome o = sweep::run_case(all[i]);
    ++checked;
    std::printf("  %s: gap %.4g um (floor %.4g), force %.4g N (floor %.4g): %s\n", o.description.c_str(),
                o.gap_final * 1e6, o.gap_floor * 1e6, o.force_final, o.force_floor, o.verdict.c_str());
    EXPECT_TRUE(o.named.empty()) << o.description;
    EXPECT_EQ(o.verdict, "no_discrepancy") << o.description;
    EXPECT_GT(o.gap_final, 0.67 * o.gap_floor) << o.description;
    EXPECT_LT(o.gap_final, 1.5 * o.gap_floor) << o.description;
    EXPECT_GT(o.force_final, 0.67 * o.force_floor) << o.description;
    EXPECT_LT(o.force_final, 1.5 * o.force_floor) << o.description;
  }
  EXPECT_GE(checked, 3);  // seed 20's mix has four such records among its first ten
}

}  // namespace
}  // namespace feeddrive::fit

namespace feeddrive::fit {
namespace {

// The sanity checks before fitting (fit/sanity.hpp) must refuse no record of the independent
// generator: the sweep (bench/fit_sweep.cpp) runs them on every record, and a refusal there is a
// false one (a valid record the user could not fit). Both mixes, as the sweep draws them (10 s
// records), on seeds the sweep does not use by default: its cases span PID and cascade loops at
// 4-60 Hz, dwells, reversals and creeping, 50-200 nm encoders and time-stamp jitter.
TEST(SanityChecks, RefuseNoIndependentRecord) {
  int checked = 0;
  for (const auto& [mix, seed] : {std::pair<const char*, std::uint64_t>{"standard", 101}, {"issue20", 202}}) {
    const auto cases =
        std::string(mix) == "issue20" ? fdgen::issue20_cases(100, seed) : fdgen::standard_cases(100, seed);
    for (const auto& c : cases) {
      const fdgen::Generated g = fdgen::generate(c);
      const sim::Scenario model = sim::parse_scenario(g.scenario_yaml, ".", "indepgen model");
      const MeasuredData data = sweep::measured(g);
      try {
        check_record(data, model.plant, model.control_period);
        check_force_scale(prepare(data), model.plant);
      } catch (const DataError& e) {
        ADD_FAILURE() << mix << " seed " << c.seed << " [" << g.description << "]: " << e.what();
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 200);
}

}  // namespace
}  // namespace feeddrive::fit

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
    std::printf("  %s: %s -> %s, %s%s%s\n", o.category.c_str(), sweep::names(o.hidden).c_str(), sweep::names(o.named).c_str(),
                o.verdict.c_str(), o.tie_partners.empty() ? "" : (", tie " + sweep::names(o.tie_partners)).c_str(),
                o.right ? "" : "  MISS");
    right += o.right;
    EXPECT_FALSE(o.nothing_there) << o.description;
    EXPECT_FALSE(o.above_floor_all_clear) << o.description;
    if (o.verdict == "unexplained") {
      EXPECT_TRUE(o.suggestion) << o.description << ": " << o.conclusion;
    }
  }
  // The bench's rate is >= 95 % (docs/fit.md); on these 6 one miss is allowed.
  EXPECT_GE(right, static_cast<int>(cases.size()) - 1);
}

}  // namespace
}  // namespace feeddrive::fit

// feeddrive-fit on records it was not built against: a seeded subset of the independent
// generator's case mix (tests/fit/drivegen: its own RK4 integrator, PID or cascade loop, dwells,
// reversals and creeping moves, smoother and asymmetric friction, 50-200 nm quantization,
// jitter, a random nominal mass). The full sweep of 100+ records is bench/fit_bench.sh, with its
// figures in docs/fit.md; this subset runs on every CI.
#include <gtest/gtest.h>

#include <cstdio>

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
  // The targets on 100+ records are >= 90 % right, <= 5 % spurious, <= 5 % of the
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

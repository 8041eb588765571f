// The detection-rate sweep of feeddrive-fit on data it was not built against (run by
// bench/fit_bench.sh): N seeded records of the independent generator (tests/fit/indepgen: its
// own RK4 integrator, PID or cascade loop, dwells, reversals and creeping moves, friction forms
// that differ from the model's, 50-200 nm quantization, jitter, a random nominal mass), covering
// every effect alone, pairs of effects and effect-free records. One tab-separated line per record:
//   seed  hidden  named  right  spurious  seconds  parameter_miss  description
// (right/spurious as tests/fit/indepgen/sweep.hpp counts them); fit_bench.sh sums the lines.
//   fit_sweep N SEED [SHARD SHARDS] [DURATION_S]
#include <cstdio>
#include <cstdlib>

#include "sweep.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive::fit;
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const int shard = argc > 3 ? std::atoi(argv[3]) : 0;
  const int shards = argc > 4 ? std::atoi(argv[4]) : 1;
  const double duration = argc > 5 ? std::atof(argv[5]) : 10.0;
  if (n < 1 || shards < 1 || shard < 0 || shard >= shards || !(duration > 0)) {
    std::fprintf(stderr, "usage: fit_sweep N SEED [SHARD SHARDS] [DURATION_S]\n");
    return 2;
  }
  std::vector<fdgen::CaseSpec> cases = fdgen::standard_cases(n, seed);
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (static_cast<int>(i % static_cast<std::size_t>(shards)) != shard) continue;
    cases[i].duration = duration;
    try {
      const sweep::Outcome o = sweep::run_case(cases[i]);
      std::printf("%llu\t%s\t%s\t%d\t%d\t%.2f\t%s\t%s\n", static_cast<unsigned long long>(o.spec.seed),
                  sweep::names(o.hidden).c_str(), sweep::names(o.named).c_str(), o.right ? 1 : 0, o.spurious ? 1 : 0,
                  o.seconds, o.parameter_miss.empty() ? "-" : o.parameter_miss.c_str(), o.description.c_str());
    } catch (const std::exception& e) {
      std::printf("%llu\t?\terror\t0\t0\t0\t%s\t-\n", static_cast<unsigned long long>(cases[i].seed), e.what());
    }
    std::fflush(stdout);
  }
  return 0;
}

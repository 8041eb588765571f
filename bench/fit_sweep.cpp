// The detection-rate sweep of feeddrive-fit on data it was not built against (run by
// bench/fit_bench.sh): N seeded records of the independent generator (drivegen/, fd_drivegen: its
// own RK4 integrator, PID or cascade loop, dwells, reversals and creeping moves, friction forms
// that differ from the model's, 50-200 nm quantization, jitter, a random nominal mass), covering
// every effect alone, pairs of effects and effect-free records (MIX standard), or issue 20's mix
// (MIX issue20: short-travel ripples, asymmetric friction, one-direction moves, a mass error with a
// ripple, 4-14 Hz loops; fdgen::issue20_cases). One tab-separated line per record:
//   seed hidden named right spurious seconds parameter_miss description verdict category
//   false_all_clear above_floor_all_clear suggestion gap_um gap_floor_um force_N force_floor_N
//   tentative ties periods nothing_there
// (as drivegen/sweep.hpp counts them); fit_bench.sh sums the lines.
//   fit_sweep N SEED [SHARD SHARDS] [DURATION_S] [MIX]
// FD_SWEEP_ONLY=i,j,...: only the cases of these indices in the mix (to look at a few records).
// FD_SWEEP_DUMP=DIR: also write each selected case's record and model (DIR/<seed>/data.csv,
// model.yaml), to run feeddrive-fit on it.
// FD_SWEEP_NOFORM=1: the same cases with the model's friction form (no smoother transition,
// asymmetry or other Stribeck exponent), to tell a miss caused by the form from one that is not.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "sweep.hpp"

int main(int argc, char** argv) {
  using namespace feeddrive::fit;
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  const int shard = argc > 3 ? std::atoi(argv[3]) : 0;
  const int shards = argc > 4 ? std::atoi(argv[4]) : 1;
  const double duration = argc > 5 ? std::atof(argv[5]) : 10.0;
  const std::string mix = argc > 6 ? argv[6] : "standard";
  if (n < 1 || shards < 1 || shard < 0 || shard >= shards || !(duration > 0) ||
      (mix != "standard" && mix != "issue20")) {
    std::fprintf(stderr, "usage: fit_sweep N SEED [SHARD SHARDS] [DURATION_S] [standard|issue20]\n");
    return 2;
  }
  std::vector<fdgen::CaseSpec> cases =
      mix == "issue20" ? fdgen::issue20_cases(n, seed) : fdgen::standard_cases(n, seed);
  std::set<std::size_t> only;
  if (const char* o = std::getenv("FD_SWEEP_ONLY")) {
    std::stringstream ss(o);
    std::string item;
    while (std::getline(ss, item, ','))
      if (!item.empty()) only.insert(static_cast<std::size_t>(std::stoul(item)));
  }
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (!only.empty() && !only.count(i)) continue;
    if (static_cast<int>(i % static_cast<std::size_t>(shards)) != shard) continue;
    cases[i].duration = duration;
    if (std::getenv("FD_SWEEP_NOFORM")) cases[i].form_deviation = false;
    if (const char* dump = std::getenv("FD_SWEEP_DUMP")) {
      const fdgen::Generated g = fdgen::generate(cases[i]);
      const std::string dir = std::string(dump) + "/" + std::to_string(cases[i].seed);
      std::filesystem::create_directories(dir);
      std::ofstream(dir + "/data.csv") << g.csv();
      std::ofstream(dir + "/model.yaml") << g.scenario_yaml;
    }
    try {
      // FD_SWEEP_VERBOSE=1: the fit's log on stderr (to look at one case)
      const sweep::Outcome o =
          sweep::run_case(cases[i], {}, [verbose = std::getenv("FD_SWEEP_VERBOSE") != nullptr](const std::string& s) {
            if (verbose) std::fprintf(stderr, "  %s\n", s.c_str());
          });
      std::printf("%llu\t%s\t%s\t%d\t%d\t%.2f\t%s\t%s\t%s\t%s\t%d\t%d\t%d\t%.4g\t%.4g\t%.4g\t%.4g\t%s\t%s\t%.3g\t%d\n",
                  static_cast<unsigned long long>(o.spec.seed), sweep::names(o.hidden).c_str(),
                  sweep::names(o.named).c_str(), o.right ? 1 : 0, o.spurious ? 1 : 0, o.seconds,
                  o.parameter_miss.empty() ? "-" : o.parameter_miss.c_str(), o.description.c_str(), o.verdict.c_str(),
                  o.category.c_str(), o.false_all_clear ? 1 : 0, o.above_floor_all_clear ? 1 : 0, o.suggestion ? 1 : 0,
                  o.gap_final * 1e6, o.gap_floor * 1e6, o.force_final, o.force_floor, sweep::names(o.tentative).c_str(),
                  sweep::names(o.tie_partners).c_str(), o.periods, o.nothing_there ? 1 : 0);
    } catch (const std::exception& e) {
      std::string why = e.what();
      for (char& c : why)
        if (c == '\t' || c == '\n') c = ' ';
      std::printf("%llu\t?\terror\t0\t0\t0\t%s\t-\terror\t%s\t0\t0\t0\t0\t0\t0\t0\t-\t-\t0\t0\n",
                  static_cast<unsigned long long>(cases[i].seed), why.c_str(), cases[i].category.c_str());
    }
    std::fflush(stdout);
  }
  return 0;
}

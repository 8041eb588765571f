// The simulation's own time, the baseline of bench/long_run_bench.sh: the in-process loop
// (reference -> controller -> CVODE plant) of a scenario with every record handed to a sink that
// only keeps a checksum, so nothing is written, summarised or plotted. Prints
// "sim_only_seconds S steps N checksum C cpu_seconds P" (P: the process's CPU time of the loop,
// which other work on a shared machine disturbs less than the wall time S).
#include <chrono>
#include <cstdio>
#include <ctime>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fd-sim-only SCENARIO.yaml\n");
    return 2;
  }
  try {
    const feeddrive::sim::Scenario s = feeddrive::sim::load_scenario(argv[1]);
    double checksum = 0.0;
    timespec c0{}, c1{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    const auto t0 = std::chrono::steady_clock::now();
    const auto st = feeddrive::sim::run(s, [&](const feeddrive::sim::Record& r) { checksum += r.u; });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    const double cpu = static_cast<double>(c1.tv_sec - c0.tv_sec) + 1e-9 * static_cast<double>(c1.tv_nsec - c0.tv_nsec);
    std::printf("sim_only_seconds %.3f steps %ld checksum %.6g cpu_seconds %.6f\n", seconds, st.steps, checksum, cpu);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}

// The simulation's own time, the baseline of bench/long_run_bench.sh: the in-process loop
// (reference -> controller -> CVODE plant) of a scenario with every record handed to a sink that
// only keeps a checksum, so nothing is written, summarised or plotted. Prints
// "sim_only_seconds S steps N".
#include <chrono>
#include <cstdio>

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
    const auto t0 = std::chrono::steady_clock::now();
    const auto st = feeddrive::sim::run(s, [&](const feeddrive::sim::Record& r) { checksum += r.u; });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("sim_only_seconds %.3f steps %ld checksum %.6g\n", seconds, st.steps, checksum);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}

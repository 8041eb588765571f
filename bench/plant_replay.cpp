// feeddrive's plant alone on a given input sequence (bench/integrator_bench.sh): the scenario's
// plant::Plant advanced period by period with the commands u_k of a closed-loop run (one per
// line), measure() called each period as the loop does. The same work as bench/cvode_floor.c,
// through feeddrive's wrapper, so their ratio is the wrapper's cost.
// Usage: fd-plant-replay SCENARIO.yaml U_FILE REPEATS
// Prints one line per repeat: "plant seconds S periods N steps ST rhs RHS jac J x X v V z Z check K
// cpu C" (S wall time, C the process's CPU time, of the loop).
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <vector>

#include "feeddrive/plant/plant.hpp"
#include "feeddrive/sim/scenario.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: fd-plant-replay SCENARIO.yaml U_FILE REPEATS\n");
    return 2;
  }
  try {
    const feeddrive::sim::Scenario s = feeddrive::sim::load_scenario(argv[1]);
    std::ifstream in(argv[2]);
    std::vector<double> u;
    for (double v; in >> v;) u.push_back(v);
    if (u.empty()) {
      std::fprintf(stderr, "fd-plant-replay: no inputs in %s\n", argv[2]);
      return 2;
    }
    const int repeats = std::atoi(argv[3]);
    for (int r = 0; r < repeats; ++r) {
      feeddrive::plant::Plant drive(s.drive(), s.control_period);
      double check = 0.0;
      timespec c0{}, c1{};
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t k = 0; k < u.size(); ++k) {
        check += drive.measure().x;
        drive.advance(u[k], s.time_of(static_cast<long>(k) + 1));
      }
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
      const double cpu =
          static_cast<double>(c1.tv_sec - c0.tv_sec) + 1e-9 * static_cast<double>(c1.tv_nsec - c0.tv_nsec);
      const auto st = drive.integrator_stats();
      const auto x = drive.state();
      std::printf(
          "plant seconds %.6f periods %zu steps %ld rhs %ld jac %ld x %.12g v %.12g z %.12g check %.6g cpu %.6f\n", sec,
          u.size(), st.steps, st.rhs_evals, st.jac_evals, x.x, x.v, x.z, check, cpu);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}

// fd-drivegen: one record of the independent generator (drivegen.hpp) as files, for manual fits
// and bench/fit_bench.sh:  DIR/data.csv (t, x, force_N, xd), DIR/model.yaml, DIR/truth.txt and
// DIR/knobs.txt (everything else drawn, e.g. stamp_error_s for feeddrive-fit --time-stamp-error).
//   fd-drivegen SEED DIR [DURATION_S] [EFFECT[,EFFECT]] [grinding] [noform] [onedir] [periods=P] [bw=HZ]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivegen.hpp"

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  fdgen::CaseSpec spec;
  try {
    spec = fdgen::parse_command_line(args);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr,
                 "error: %s (usage: fd-drivegen SEED DIR [DURATION_S] [EFFECT[,EFFECT]] [grinding] [noform] [onedir] "
                 "[periods=P] [bw=HZ])\n",
                 e.what());
    return 2;
  }
  try {
    const fdgen::Generated g = fdgen::generate(spec);
    std::filesystem::create_directories(args[1]);
    const std::string& dir = args[1];
    std::ofstream(dir + "/data.csv") << g.csv();
    std::ofstream(dir + "/model.yaml") << g.scenario_yaml;
    std::ofstream t(dir + "/truth.txt");
    for (const auto& e : g.truth) {
      t << e.name;
      for (const auto& [k, v] : e.parameters) t << ' ' << k << '=' << v;
      t << '\n';
    }
    std::ofstream k(dir + "/knobs.txt");
    k.precision(10);
    for (const auto& [n, v] : g.knobs) k << n << ' ' << v << '\n';
    std::printf("%s\n", g.description.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}

// fd-drivegen: one record of the independent generator (drivegen.hpp) as files, for manual fits
// and bench/fit_bench.sh:  DIR/data.csv (t, x, force_N, xd), DIR/model.yaml, DIR/truth.txt and
// DIR/knobs.txt (everything else drawn, e.g. stamp_error_s for feeddrive-fit --time-stamp-error).
//   fd-drivegen SEED DIR [DURATION_S] [EFFECT[,EFFECT]] [grinding] [noform] [onedir] [periods=P] [bw=HZ]
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "drivegen.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: fd-drivegen SEED DIR [DURATION_S] [EFFECT[,EFFECT]] [grinding] [noform] [onedir] [periods=P] "
                 "[bw=HZ]\n");
    return 2;
  }
  fdgen::CaseSpec spec;
  spec.seed = std::strtoull(argv[1], nullptr, 10);
  if (argc > 3) spec.duration = std::atof(argv[3]);
  if (argc > 4) {
    std::stringstream ss(argv[4]);
    std::string e;
    while (std::getline(ss, e, ','))
      if (!e.empty() && e != "none") spec.hidden.push_back(e);
  }
  for (int a = 5; a < argc; ++a) {
    const std::string w = argv[a];
    if (w == "grinding") spec.grinding_process = true;
    if (w == "noform")
      spec.form_deviation = false;  // the model's friction form: no transition, asymmetry or exponent change
    if (w == "onedir") spec.one_direction = true;
    if (w.rfind("periods=", 0) == 0) spec.ripple_periods = std::atof(w.c_str() + 8);
    if (w.rfind("bw=", 0) == 0) spec.bandwidth_hz = std::atof(w.c_str() + 3);
  }
  try {
    const fdgen::Generated g = fdgen::generate(spec);
    std::filesystem::create_directories(argv[2]);
    const std::string dir = argv[2];
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

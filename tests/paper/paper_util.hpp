#pragma once
// Helpers of the paper-reproduction tests: load a scenario of scenarios/paper/, run it
// in-process, and read values off the records.
#include <cmath>
#include <functional>
#include <string>

#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::paper {

inline sim::Scenario scenario(const std::string& name) {
  return sim::load_scenario(std::string(FEEDDRIVE_SOURCE_DIR) + "/scenarios/paper/" + name + ".yaml");
}

struct PaperRun {
  sim::Scenario s;
  sim::RunResult r;
  sim::Summary sum;
  /// The record at time t (nearest control step).
  const sim::Record& at(double t) const {
    long k = std::lround(t / s.control_period);
    k = std::max(0L, std::min(k, static_cast<long>(r.records.size()) - 1));
    return r.records[static_cast<std::size_t>(k)];
  }
  /// max over records with t in [t0, t1] of f(record).
  double max_of(const std::function<double(const sim::Record&)>& f, double t0 = -1e300, double t1 = 1e300) const {
    double m = -1e300;
    for (const auto& q : r.records)
      if (q.t >= t0 && q.t <= t1) m = std::max(m, f(q));
    return m;
  }
  double max_abs_error(double t0 = -1e300, double t1 = 1e300) const {
    return max_of([](const sim::Record& q) { return std::abs(q.xd - q.x); }, t0, t1);
  }
};

inline PaperRun simulate(sim::Scenario s) {
  PaperRun out{s, sim::run(s), {}};
  out.sum = sim::summarize(out.r, out.s);
  return out;
}
inline PaperRun simulate(const std::string& name) { return simulate(scenario(name)); }

/// Halves every tolerance of the plant's integrator.
inline sim::Scenario halved_tolerances(sim::Scenario s) {
  auto& i = s.plant.integrator;
  i.rtol /= 2;
  i.atol_position /= 2;
  i.atol_velocity /= 2;
  i.atol_bristle /= 2;
  i.atol_grinding /= 2;
  i.atol_current /= 2;
  return s;
}

}  // namespace feeddrive::paper

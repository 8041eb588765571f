#pragma once
// Helpers of the paper-reproduction tests: load a scenario of scenarios/paper/, run it
// in-process, and read values off the records.
#include <gtest/gtest.h>

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

/// The sub-um claims that hold for every controller configuration the paper runs them with, on
/// its three closed-loop moves (each run of the same configuration):
/// - jerk-limited (Figs. 21-22): |e| <= 0.8 um, control within [-2, 4] V;
/// - accel-limited (Fig. 20): larger than the jerk-limited error, at most 4.4 um;
/// - ramp with all three forces (Fig. 23): the plant starts at rest, so e_v(0) = 1 um/s; the
///   claim holds from the second sample on (notes Sec. 3.5), and < 4 nm/s after 0.25 s.
inline void expect_sub_um_claims(const PaperRun& jerk, const PaperRun& accel, const PaperRun& ramp) {
  EXPECT_LE(jerk.sum.position_error_max_abs_m, 0.8e-6);
  EXPECT_GE(jerk.sum.control_min, -2.0);
  EXPECT_LE(jerk.sum.control_max, 4.0);
  EXPECT_GT(accel.sum.position_error_max_abs_m, jerk.sum.position_error_max_abs_m);
  EXPECT_LE(accel.sum.position_error_max_abs_m, 4.4e-6);
  EXPECT_LT(ramp.sum.velocity_error_max_abs_after_first_mps, 150e-9);
  EXPECT_LT(ramp.sum.velocity_error_max_abs_settled_mps, 4e-9);
}

}  // namespace feeddrive::paper

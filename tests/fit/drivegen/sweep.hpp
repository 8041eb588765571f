#pragma once
// feeddrive-fit on records of the independent generator (drivegen.hpp): one case, judged against
// the hidden truth. Shared by the ctest subset (tests/fit/independent_test.cpp) and the sweep of
// bench/fit_sweep.cpp, so both count "named right" and "spurious" the same way.
//
// A record is named right when the set of named effects equals the hidden set and every main
// parameter is within its tolerance (docs/fit.md, "What the tests establish"):
//   pitch 2 %; mass 5 %; levels, amplitudes, gains, stiffnesses and delays 20 %; the presliding
//   bristle stiffness 50 % (it sets a displacement of microns, seen through a 50-200 nm encoder).
// One equivalence: a constant force F and a spring k (x - x_rest) are the spring
// k (x - (x_rest - F/k)) -- no data can tell them apart -- so that pair is expected as a spring.
// A spurious effect is a named effect that is not hidden.

#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/workflow.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "drivegen.hpp"

namespace feeddrive::fit::sweep {

struct Outcome {
  fdgen::CaseSpec spec;
  std::string description;
  std::set<std::string> hidden, named;
  bool right{false};            ///< named set == hidden set, parameters within tolerance
  bool spurious{false};         ///< something named that is not hidden
  std::string parameter_miss;   ///< first parameter out of tolerance, if any
  double seconds{0.0};          ///< wall time of the fit
  std::string conclusion;
};

/// Main parameters and their relative tolerances, per effect.
inline const std::map<std::string, std::vector<std::pair<std::string, double>>>& tolerances() {
  static const std::map<std::string, std::vector<std::pair<std::string, double>>> t{
      {"constant_force", {{"force_N", 0.2}}},
      {"coulomb_friction", {{"coulomb_N", 0.2}}},
      {"viscous_friction", {{"viscous_Ns_per_m", 0.2}}},
      {"stribeck_friction", {{"static_N", 0.2}}},
      {"presliding", {{"bristle_stiffness_N_per_m", 0.5}}},
      {"cogging_ripple", {{"pitch_m", 0.02}, {"amplitude_N", 0.2}}},
      {"reluctance_ripple", {{"pitch_m", 0.02}, {"relative_amplitude", 0.2}}},
      {"grinding_force", {{"gain_Ns_per_m", 0.2}}},
      {"spring_force", {{"stiffness_N_per_m", 0.2}}},
      {"mass_error", {{"mass_kg", 0.05}}},
      {"input_delay", {{"delay_s", 0.2}}},
  };
  return t;
}

inline MeasuredData measured(const fdgen::Generated& g) {
  MeasuredData d;
  d.source = "indepgen";
  d.t = g.t;
  d.x = g.x;
  d.input = g.force_N;
  d.input_kind = InputKind::kForce;
  d.xd = g.xd;
  validate(d);
  return d;
}

inline Outcome run_case(const fdgen::CaseSpec& spec, FitOptions opt = {}) {
  Outcome o;
  o.spec = spec;
  const fdgen::Generated g = fdgen::generate(spec);
  o.description = g.description;
  std::map<std::string, std::map<std::string, double>> truth;
  for (const auto& e : g.truth) truth[e.name] = e.parameters;
  if (truth.count("constant_force") && truth.count("spring_force")) {
    auto& s = truth["spring_force"];
    s["rest_position_m"] -= truth["constant_force"]["force_N"] / s["stiffness_N_per_m"];
    truth.erase("constant_force");
  }
  for (const auto& [n, p] : truth) o.hidden.insert(n);
  const sim::Scenario model = sim::parse_scenario(g.scenario_yaml, ".", "indepgen model");
  opt.plausibility.grinding_process = model.grinding_process;
  const MeasuredData data = measured(g);
  const auto t0 = std::chrono::steady_clock::now();
  const FitResult r = run_fit(prepare(data), model.plant, opt);
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  o.conclusion = r.conclusion;
  std::map<std::string, std::map<std::string, double>> found;
  for (const auto& e : r.effects) {
    o.named.insert(e.name);
    found[e.name] = e.parameters;
  }
  for (const auto& n : o.named)
    if (!o.hidden.count(n)) o.spurious = true;
  o.right = o.named == o.hidden;
  if (o.right) {
    for (const auto& [n, want] : truth)
      for (const auto& [k, tol] : tolerances().at(n)) {
        const double w = want.at(k), got = found[n][k];
        if (!(std::abs(got - w) <= tol * std::abs(w)) && o.parameter_miss.empty()) {
          std::ostringstream s;
          s << n << "." << k << " = " << got << " (true " << w << ", tolerance " << tol * 100 << " %)";
          o.parameter_miss = s.str();
        }
      }
    o.right = o.parameter_miss.empty();
  }
  return o;
}

inline std::string names(const std::set<std::string>& s) {
  std::string out;
  for (const auto& n : s) out += (out.empty() ? "" : "+") + n;
  return out.empty() ? "none" : out;
}

}  // namespace feeddrive::fit::sweep

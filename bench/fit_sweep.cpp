// The large sweep of feeddrive-fit (run by bench/fit_bench.sh): every effect of the vocabulary,
// hidden with seeded random parameters in closed-loop recordings (tests/fit/fit_util.hpp: 50 nm
// encoder, 20 nm noise, jittered 1 kHz stamps, a seeded rich reference), plus effect-free
// records. Prints, per effect, how often the tool names it first, recovers its main parameter
// within the documented tolerance and shrinks the gap at least 5x; and the false-positive rate.
//   fit_sweep [SEEDS] [DURATION_S]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>

#include "feeddrive/fit/workflow.hpp"
#include "fit_util.hpp"

using namespace feeddrive;
using fit::Effect;

namespace {

struct Draw {
  std::string name;
  std::function<Effect(std::mt19937_64&)> draw;
  std::string main_param;
  double tolerance;  // relative
  bool static_model{false};
};

double U(std::mt19937_64& g, double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }

std::vector<Draw> draws() {
  const double pi = 3.14159265358979323846;
  return {
      {"constant_force", [](auto& g) { return Effect{"constant_force", {{"force_N", (U(g, 0, 1) < 0.5 ? -1 : 1) * U(g, 3, 20)}}}; },
       "force_N", 0.2},
      {"coulomb_friction", [](auto& g) { return Effect{"coulomb_friction", {{"coulomb_N", U(g, 3, 20)}}}; }, "coulomb_N", 0.2},
      {"viscous_friction", [](auto& g) { return Effect{"viscous_friction", {{"viscous_Ns_per_m", U(g, 30, 300)}}}; },
       "viscous_Ns_per_m", 0.2},
      {"stribeck_friction",
       [](auto& g) {
         const double fc = U(g, 3, 10);
         return Effect{"stribeck_friction",
                       {{"coulomb_N", fc}, {"static_N", fc + U(g, 10, 30)}, {"stribeck_velocity_mps", U(g, 0.002, 0.02)}}};
       },
       "static_N", 0.2},
      {"presliding",
       [](auto& g) {
         return Effect{"presliding", {{"bristle_stiffness_N_per_m", U(g, 2e5, 2e6)}, {"bristle_damping_Ns_per_m", U(g, 500, 5000)}}};
       },
       "bristle_stiffness_N_per_m", 0.2, true},
      {"cogging_ripple",
       [pi](auto& g) {
         const double a = U(g, 2, 6);
         return Effect{"cogging_ripple",
                       {{"pitch_m", U(g, 0.015, 0.05)}, {"amplitude_N", a}, {"phase_rad", U(g, -pi, pi)},
                        {"third_harmonic_N", U(g, 0, 0.4 * a)}, {"third_phase_rad", U(g, -pi, pi)}}};
       },
       "pitch_m", 0.02},
      {"reluctance_ripple",
       [pi](auto& g) {
         return Effect{"reluctance_ripple",
                       {{"pitch_m", U(g, 0.015, 0.05)}, {"relative_amplitude", U(g, 0.02, 0.06)}, {"phase_rad", U(g, -pi, pi)}}};
       },
       "pitch_m", 0.02},
      {"grinding_force",
       [](auto& g) {
         return Effect{"grinding_force",
                       {{"gain_Ns_per_m", U(g, 100, 500)}, {"stiffness_N_per_m", U(g, 1e4, 1e5)}, {"contact_position_m", U(g, 0.03, 0.09)}}};
       },
       "gain_Ns_per_m", 0.2},
      {"spring_force",
       [](auto& g) { return Effect{"spring_force", {{"stiffness_N_per_m", U(g, 150, 600)}, {"rest_position_m", U(g, 0, 0.1)}}}; },
       "stiffness_N_per_m", 0.2},
      {"mass_error",
       [](auto& g) { return Effect{"mass_error", {{"mass_kg", 102.04 * (U(g, 0, 1) < 0.5 ? U(g, 0.8, 0.95) : U(g, 1.05, 1.25))}}}; },
       "mass_kg", 0.05},
      {"input_delay", [](auto& g) { return Effect{"input_delay", {{"delay_s", U(g, 1e-3, 2.5e-3)}}}; }, "delay_s", 0.2},
  };
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 10;
  const double duration = argc > 2 ? std::atof(argv[2]) : 10.0;
  const std::string tmp = fit::test::temp_dir();
  int total = 0, total_named = 0, total_ok = 0;
  std::vector<double> times;
  std::printf("%-20s %8s %8s %10s %10s\n", "effect", "trials", "named", "recovered", "gap<=1/5");
  const char* only = std::getenv("FIT_SWEEP_ONLY");  // one effect's name, for a closer look
  for (const Draw& d : draws()) {
    if (only && d.name != only) continue;
    int named = 0, recovered = 0, shrunk = 0;
    for (int s = 1; s <= seeds; ++s) {
      std::mt19937_64 g(static_cast<std::uint64_t>(s) * 1000003ULL + std::hash<std::string>{}(d.name) % 1000);
      const Effect e = d.draw(g);
      plant::PlantParams model = fit::test::base_model();
      if (d.static_model) model.friction.model = plant::FrictionModel::kStatic;
      plant::PlantParams truth = model;
      plant::set_effect(truth.effects, e);
      fit::test::Recording ro;
      ro.seed = static_cast<std::uint64_t>(100 + s);
      ro.duration = duration;
      fit::MeasuredData data;
      try {
        data = fit::test::record(truth, ro, tmp);
      } catch (const std::exception& ex) {
        std::printf("  %s seed %d: recording failed (%s)\n", d.name.c_str(), s, ex.what());
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      fit::FitOptions opt;
      opt.max_effects = 2;
      const fit::FitResult r = fit::run_fit(fit::prepare(data), model, opt);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      const bool is_named = !r.effects.empty() && r.effects.front().name == d.name;
      named += is_named;
      bool shrank = false;
      if (is_named) {
        const double want = e.parameters.at(d.main_param), got = r.effects.front().parameters.at(d.main_param);
        recovered += std::abs(got - want) <= d.tolerance * std::abs(want);
        shrank = r.steps.front().gap_after <= r.steps.front().gap_before / 5.0;
        shrunk += shrank;
      } else {
        std::printf("  %s seed %d: named %s;", d.name.c_str(), s, r.effects.empty() ? "nothing" : r.effects.front().name.c_str());
        for (std::size_t i = 0; i < r.steps.front().ranking.size() && i < 3; ++i)
          std::printf(" %s %.4g", r.steps.front().ranking[i].effect.name.c_str(), r.steps.front().ranking[i].score);
        std::printf("\n    %s\n", r.steps.front().verdict.c_str());
      }
      ++total;
      total_named += is_named;
      total_ok += shrank;
    }
    std::printf("%-20s %8d %8d %10d %10d\n", d.name.c_str(), seeds, named, recovered, shrunk);
    std::fflush(stdout);
  }
  int false_pos = 0;
  for (int s = 1; s <= seeds * 2; ++s) {
    const plant::PlantParams model = fit::test::base_model();
    fit::test::Recording ro;
    ro.seed = static_cast<std::uint64_t>(5000 + s);
    ro.duration = duration;
    const fit::MeasuredData data = fit::test::record(model, ro, tmp);
    fit::FitOptions opt;
    opt.max_effects = 1;
    false_pos += !fit::run_fit(fit::prepare(data), model, opt).effects.empty();
  }
  std::sort(times.begin(), times.end());
  std::printf("detection rate: %d of %d (%.1f %%) named first; %d also shrank the gap >= 5x\n", total_named, total,
              100.0 * total_named / std::max(1, total), total_ok);
  std::printf("effect-free records naming an effect: %d of %d\n", false_pos, seeds * 2);
  if (!times.empty())
    std::printf("fit time per record (%.0f s at 1 kHz, up to 2 effects): median %.2f s, max %.2f s\n", duration,
                times[times.size() / 2], times.back());
  return 0;
}

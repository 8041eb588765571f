#pragma once
// Hidden-effect data for the fit tests: the CVODE plant with an effect the model lacks, in closed
// loop under the cascade controller, following a rich seeded reference (random waypoints through
// a natural cubic spline: reversals, low and high speeds, travel over several magnet pitches),
// recorded like a real drive: encoder quantization, position noise, time stamps with jitter.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::fit::test {

struct Recording {
  double duration{10.0};       ///< [s]
  double period{1e-3};         ///< sample = control period [s]
  double quantization{50e-9};  ///< encoder resolution [m]
  double noise{20e-9};         ///< position noise standard deviation [m]
  double jitter{0.005};        ///< time-stamp jitter, uniform +-jitter*period (5 us at 1 kHz)
  std::uint64_t seed{1};
};

/// The model the tool is given: the paper's LuGre drive (Table 1), no ripple, no grinding.
inline plant::PlantParams base_model() {
  plant::PlantParams p;
  p.ripple.enabled = false;
  p.grinding.enabled = false;
  return p;
}

/// Seeded random waypoints over [0, 0.12] m, 0.3-0.7 s apart, at rest at both ends.
inline std::vector<trajectory::Waypoint> rich_waypoints(double duration, std::uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + 17);
  std::uniform_real_distribution<double> dt(0.3, 0.7), x(0.0, 0.12);
  // held at 0 for 0.3 s: the spline then leaves rest smoothly
  std::vector<trajectory::Waypoint> w{{0.0, 0.0}, {0.1, 0.0}, {0.2, 0.0}, {0.3, 0.0}};
  double t = 0.3;
  while (t + 0.7 < duration - 0.4) {  // the last random point stays before the final hold
    t += dt(rng);
    w.push_back({t, x(rng)});
  }
  for (double b : {0.3, 0.2, 0.1, 0.0}) w.push_back({duration - b, 0.0});
  return w;
}

/// The scenario of a recording of plant `truth` (the cascade controller at the sample rate).
inline sim::Scenario recording_scenario(const plant::PlantParams& truth, const Recording& r,
                                        const std::string& waypoints_csv) {
  sim::Scenario s;
  s.name = "hidden";
  s.duration = r.duration;
  s.control_period = r.period;
  s.plant = truth;
  s.plant.sensor.quantization = r.quantization;
  s.plant.sensor.noise_stddev = r.noise;
  s.plant.sensor.seed = r.seed;
  s.controller.type = sim::ControllerType::kCascade;
  s.controller.cascade.period = r.period;
  s.controller.cascade.mass = truth.mass;
  s.controller.cascade.thrust_gain = truth.thrust_gain();
  s.reference.type = sim::ReferenceType::kWaypoints;
  s.reference.waypoints_file = waypoints_csv;
  s.reference.waypoints = sim::read_waypoints_file(waypoints_csv);
  return s;
}

inline std::string write_waypoints(const std::vector<trajectory::Waypoint>& w, const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fprintf(f, "t,x\n");
  for (const auto& p : w) std::fprintf(f, "%.17g,%.17g\n", p.t, p.x);
  std::fclose(f);
  return path;
}

/// Runs the recording and returns what the tool sees (t with jitter, measured x, u, xd).
inline MeasuredData record(const plant::PlantParams& truth, const Recording& r, const std::string& tmp_dir) {
  // one file per process and seed: ctest runs test cases in parallel processes
  const std::string wp = write_waypoints(
      rich_waypoints(r.duration, r.seed),
      tmp_dir + "/feeddrive-waypoints-" + std::to_string(::getpid()) + "-" + std::to_string(r.seed) + ".csv");
  sim::RunResult run;
  try {
    run = sim::run(recording_scenario(truth, r, wp));
  } catch (...) {
    std::remove(wp.c_str());
    throw;
  }
  std::remove(wp.c_str());
  std::mt19937_64 rng(r.seed * 104729 + 3);
  std::uniform_real_distribution<double> jit(-r.jitter * r.period, r.jitter * r.period);
  MeasuredData d;
  d.source = "hidden-effect recording";
  for (const auto& rec : run.records) {
    d.t.push_back(rec.t + jit(rng));
    d.x.push_back(rec.x_measured);
    d.input.push_back(rec.u);
    d.xd.push_back(rec.xd);
  }
  validate(d);
  return d;
}

inline std::string temp_dir() {
  const char* t = std::getenv("TMPDIR");
  return t ? t : "/tmp";
}

}  // namespace feeddrive::fit::test

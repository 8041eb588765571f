#pragma once
// An independent generator of "measured" drive records for testing feeddrive-fit on data it was
// not built against. It links no feeddrive library and shares no code with plant/: it differs
// from the project's plant the way a real drive's data does.
//
//   * Physics: one axis, m x'' = F(t - d) - F_friction(v, z) - F_hidden(x, v, F), integrated by
//     classic fixed-step RK4 with at least 10 sub-steps per sample (more where a bristle or
//     grinding state is stiff: h * rate <= 1), the thrust held over each sample interval and
//     switched at t_k + d inside it (input delay d).
//   * Friction forms that differ from the model's tanh(v/1e-5): every Coulomb-type term uses
//     the algebraic transition v/sqrt(v^2 + vt^2) with vt drawn in 20-300 um/s, a direction
//     asymmetry (level x(1+a) for v > 0, x(1-a) for v < 0, |a| <= 0.02), and a Stribeck exponent
//     differing from the model's 2 by up to 0.3 (knobs: form_deviation = false turns them off).
//   * Closed loop under its own controller: a PID position loop commanding force (triple pole
//     at the bandwidth, derivative on a filtered difference of the quantized position, integral
//     with anti-windup) or a P/PI cascade with a differenced velocity; gains from the NOMINAL
//     mass; acceleration feed-forward on half the records; a one-sample computation delay on
//     about a third; +-1500 N saturation.
//   * References: full-travel moves (trapezoidal profiles) alternating with dwells, short
//     back-and-forth reversals, slow creeping moves (0.05-0.5 mm/s) and (1 - cos) sine segments.
//   * Sensor and clock: 50-200 nm quantization, <= 20 nm noise, sample instants jittered by
//     +-2 % of the period and recorded with a further +-1 us stamp error.
// Every draw comes from std::mt19937_64 seeded by CaseSpec::seed: the same spec gives the same
// record, bit for bit.

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace fdgen {

struct Effect {
  std::string name;
  std::map<std::string, double> parameters;  ///< the vocabulary's names and SI units (docs/fit.md)
};

struct CaseSpec {
  std::uint64_t seed{1};
  std::vector<std::string> hidden;  ///< effect names of the vocabulary, 0-2 of them
  double duration{10.0};            ///< [s]
  double sample_rate{1000.0};       ///< [Hz]
  bool grinding_process{false};     ///< the scenario describes a grinding process (forced on with grinding_force)
  bool form_deviation{true};        ///< smoother Coulomb transition, asymmetry, other Stribeck exponent
  /// > 0: the travel spans this many periods of the hidden ripple (e.g. 1.5-3: near or below the
  /// two periods the fit needs to resolve a pitch); 0: pitches of 10-40 mm over 60-150 mm.
  double ripple_periods{0.0};
  /// Moves in one direction only (forward moves, creeping and dwells, no reversal): a Coulomb
  /// friction and a constant force are then the same force while moving.
  bool one_direction{false};
  /// > 0: the loop's bandwidth [Hz] (PID triple pole, or the cascade's position loop); 0: drawn.
  double bandwidth_hz{0.0};
  std::string category{"standard"};  ///< a label for the sweep's table
};

struct Generated {
  std::vector<double> t, x, force_N,
      xd;                     ///< recorded stamps [s], quantized position [m], applied thrust [N], reference [m]
  std::string scenario_yaml;  ///< the model the fit starts from (the known drive, no hidden effect)
  std::vector<Effect> truth;  ///< the hidden effects, in the vocabulary's parametrisation
  std::map<std::string, double> knobs;  ///< everything else that was drawn
  std::string description;              ///< one line
  std::string csv() const;              ///< "t,x,force_N,xd" with %.17g
};

Generated generate(const CaseSpec& spec);

/// The case of fd-drivegen's command line, its arguments after the program's name:
///   SEED DIR [DURATION_S] [EFFECT[,EFFECT]] [grinding] [noform] [onedir] [periods=P] [bw=HZ]
/// (DIR is the caller's). Every number is checked whole: throws std::invalid_argument, one line
/// naming the argument and its value ("DURATION_S = '1x': not a number"), for a bad number, a
/// word that is none of the above or fewer than two arguments.
CaseSpec parse_command_line(const std::vector<std::string>& args);

/// A seeded mix of n cases: about 12 % effect-free, every effect alone at least n/20 times, the
/// rest pairs of distinct effects (not coulomb + stribeck, which is one Stribeck curve).
std::vector<CaseSpec> standard_cases(int n, std::uint64_t seed);

/// The mix of issue 20 (n >= 20): about 55 % the standard mix, a third of it with the loop's
/// bandwidth drawn in 4-14 Hz; 15 % ripples (cogging or reluctance, alone or with viscous
/// friction) over short travels of 1.5-3 periods; 10 % asymmetric friction (Coulomb friction and
/// a constant force); 10 % one-direction moves (a Coulomb friction or a constant force, alone or
/// with viscous friction); 10 % a mass error with a cogging ripple.
std::vector<CaseSpec> issue20_cases(int n, std::uint64_t seed);

/// The vocabulary, in the order of docs/fit.md.
const std::vector<std::string>& vocabulary();

/// The generator's own integrator on a bare mass m with a viscous friction c under a constant
/// thrust F, from x = 0, v = v0, over `duration` in `steps` RK4 steps: {x, v} at the end (for
/// its analytic tests).
std::pair<double, double> integrate_mass(double m, double F, double c, double v0, double duration, int steps);

}  // namespace fdgen

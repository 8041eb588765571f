// The model-discrepancy effects (effects.hpp): the force laws against their formulas written out,
// their gradients against finite differences, and the CVODE plant against closed-form solutions.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "feeddrive/plant/effects.hpp"
#include "feeddrive/plant/plant.hpp"
#include "jacobian_check.hpp"

namespace feeddrive::plant {
namespace {

// A frictionless mass without ripple or grinding, thrust = u [N].
PlantParams free_mass() {
  PlantParams p;
  p.friction.model = FrictionModel::kNone;
  p.amplifier_gain = 1.0;
  p.force_constant = 1.0;
  return p;
}

// Every additive effect on, with values of the order of a real drive's.
PlantParams all_additive() {
  PlantParams p;
  p.friction.static_smoothing_velocity = 1e-2;  // smooth enough for finite differences
  p.friction.stribeck_exponent = 1.5;           // not the delta = 2 fast path
  EffectsParams& e = p.effects;
  e.constant_force = {true, 7.0};
  e.coulomb_friction = {true, 30.0};
  e.viscous_friction = {true, 15.0};
  e.stribeck_friction = {true, 50.0, 20.0, 0.02};
  e.cogging_ripple = {true, 0.024, 2.0, 0.3, 0.5, -0.7};
  e.reluctance_ripple = {true, 0.024, 0.04, 1.1};
  e.spring_force = {true, 300.0, 0.01};
  return p;
}

// --- extra_force against the formulas of effects.hpp, one effect at a time -----------------------
// The test evaluates the same expressions in another order: 1e-12 relative covers the rounding.

double rel(double v) { return 1e-12 * std::max(1.0, std::abs(v)); }

TEST(Effects, EachAdditiveEffectMatchesItsFormula) {
  const double x = 0.0137, v = 0.004, F = 180.0;
  const double eps = 1e-5;  // friction.static_smoothing_velocity default
  {
    PlantParams p;
    p.effects.constant_force = {true, -12.5};
    EXPECT_NEAR(extra_force(p, x, v, F), -12.5, rel(12.5));
  }
  {
    PlantParams p;
    p.effects.coulomb_friction = {true, 30.0};
    const double want = 30.0 * std::tanh(v / eps);
    EXPECT_NEAR(extra_force(p, x, v, F), want, rel(want));
    EXPECT_EQ(extra_force(p, x, 0.0, F), 0.0);  // tanh(0) = 0: no stiction jump at rest
  }
  {
    PlantParams p;
    p.effects.viscous_friction = {true, 15.0};
    EXPECT_NEAR(extra_force(p, x, v, F), 15.0 * v, rel(15.0 * v));
  }
  for (const double delta : {2.0, 1.5}) {
    PlantParams p;
    p.friction.stribeck_exponent = delta;
    p.effects.stribeck_friction = {true, 50.0, 20.0, 0.02};
    for (const double vv : {v, -v, 0.05}) {
      const double want = std::tanh(vv / eps) * (20.0 + 30.0 * std::exp(-std::pow(std::abs(vv / 0.02), delta)));
      EXPECT_NEAR(extra_force(p, x, vv, F), want, rel(want)) << "delta " << delta << " v " << vv;
    }
  }
  {
    PlantParams p;
    p.effects.cogging_ripple = {true, 0.024, 2.0, 0.3, 0.5, -0.7};
    const double want = 2.0 * std::sin(2 * M_PI * x / 0.024 + 0.3) + 0.5 * std::sin(6 * M_PI * x / 0.024 - 0.7);
    EXPECT_NEAR(extra_force(p, x, v, F), want, rel(want));
  }
  {
    PlantParams p;
    p.effects.reluctance_ripple = {true, 0.024, 0.04, 1.1};
    const double want = F * 0.04 * std::sin(2 * M_PI * x / 0.024 + 1.1);
    EXPECT_NEAR(extra_force(p, x, v, F), want, rel(want));
    EXPECT_EQ(extra_force(p, x, v, 0.0), 0.0);  // proportional to the thrust
  }
  {
    PlantParams p;
    p.effects.spring_force = {true, 300.0, 0.01};
    EXPECT_NEAR(extra_force(p, x, v, F), 300.0 * (x - 0.01), rel(1.0));
  }
  {
    // All additive effects together: the sum of the single ones.
    const PlantParams all = all_additive();
    double sum = 0.0;
    const EffectsParams none;
    for (int k = 0; k < 7; ++k) {
      PlantParams one = all;
      one.effects = none;
      switch (k) {
        case 0: one.effects.constant_force = all.effects.constant_force; break;
        case 1: one.effects.coulomb_friction = all.effects.coulomb_friction; break;
        case 2: one.effects.viscous_friction = all.effects.viscous_friction; break;
        case 3: one.effects.stribeck_friction = all.effects.stribeck_friction; break;
        case 4: one.effects.cogging_ripple = all.effects.cogging_ripple; break;
        case 5: one.effects.reluctance_ripple = all.effects.reluctance_ripple; break;
        case 6: one.effects.spring_force = all.effects.spring_force; break;
      }
      sum += extra_force(one, x, v, F);
    }
    EXPECT_NEAR(extra_force(all, x, v, F), sum, rel(sum));
  }
}

TEST(Effects, NothingEnabledMeansNoExtraForceAndUnchangedParams) {
  PlantParams p = all_additive();
  p.effects = EffectsParams{};
  EXPECT_FALSE(p.effects.any());
  EXPECT_EQ(extra_force(p, 0.01, 0.1, 100.0), 0.0);
  const ExtraForceGradient g = extra_force_gradient(p, 0.01, 0.1, 100.0);
  EXPECT_EQ(g.dx, 0.0);
  EXPECT_EQ(g.dv, 0.0);
  EXPECT_EQ(g.dthrust, 0.0);
  const PlantParams e = effective_params(p);
  EXPECT_EQ(e.mass, p.mass);
  EXPECT_EQ(e.friction.model, p.friction.model);
  EXPECT_EQ(e.grinding.enabled, p.grinding.enabled);
  // The folding effects are not additive: they leave F_extra at 0.
  p.effects.presliding.enabled = true;
  p.effects.grinding_force.enabled = true;
  p.effects.mass_error.enabled = true;
  p.effects.input_delay.enabled = true;
  EXPECT_TRUE(p.effects.any());
  EXPECT_EQ(extra_force(p, 0.01, 0.1, 100.0), 0.0);
}

// Central differences with step h: truncation O(h^2 f''') and round-off ~1e-16*|F|/h. With
// h = 1e-7 (x, relative to a 24 mm pitch), 1e-7 m/s (v, against the 1e-2 m/s smoothing) and
// 1e-3 N (thrust, F_extra is linear in it) both stay below 1e-6 of the derivative's scale.
TEST(Effects, GradientMatchesCentralDifferences) {
  const PlantParams p = all_additive();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(-0.05, 0.05), uv(-0.1, 0.1), uF(-500.0, 500.0);
  for (int trial = 0; trial < 300; ++trial) {
    const double x = ux(rng), v = uv(rng), F = uF(rng);
    const ExtraForceGradient g = extra_force_gradient(p, x, v, F);
    const double hx = 1e-7, hv = 1e-7, hF = 1e-3;
    const double dx = (extra_force(p, x + hx, v, F) - extra_force(p, x - hx, v, F)) / (2 * hx);
    const double dv = (extra_force(p, x, v + hv, F) - extra_force(p, x, v - hv, F)) / (2 * hv);
    const double dF = (extra_force(p, x, v, F + hF) - extra_force(p, x, v, F - hF)) / (2 * hF);
    EXPECT_NEAR(g.dx, dx, 1e-6 * std::max(1.0, std::abs(g.dx))) << "x " << x << " v " << v;
    EXPECT_NEAR(g.dv, dv, 1e-6 * std::max(1.0, std::abs(g.dv))) << "x " << x << " v " << v;
    EXPECT_NEAR(g.dthrust, dF, 1e-9) << "x " << x;
  }
}

// derivative() and jacobian() with every effect that enters f on (the additive ones, presliding
// and grinding_force folded in, mass_error) and the electrical option (d/di of the reluctance
// effect): the analytic Jacobian against central differences (jacobian_check.hpp), and the
// EffectiveParams overload against the PlantParams one.
TEST(Effects, DynamicsJacobianMatchesFiniteDifferences) {
  PlantParams p = all_additive();
  p.friction.model = FrictionModel::kStatic;
  p.effects.presliding = {true, 1e6, 1e4};
  p.effects.grinding_force = {true, 5e6, 3e7, -1.0};
  p.effects.mass_error = {true, 90.0};
  p.electrical.enabled = true;
  p.ripple = feeddrive::plant::RippleParams::paper();
  const EffectiveParams ep(p);
  ASSERT_EQ(ep.params().friction.model, FrictionModel::kLuGre);
  test::expect_jacobian_matches_differences(p, 11, 0.1, [&](const State& s, double u, const Jacobian& J) {
    EXPECT_EQ(J, jacobian(ep, s, u));  // both overloads fold the same effects
  });
}

TEST(Effects, ForcesReportTheExtraForceAndTheAccelerationSubtractsIt) {
  PlantParams p = free_mass();
  p.effects.constant_force = {true, 40.0};
  const State s{0.0, 0.0, 0.0, 0.0, 0.0};
  const Forces f = forces(p, s, 100.0);
  EXPECT_EQ(f.thrust, 100.0);
  EXPECT_EQ(f.extra, 40.0);
  EXPECT_DOUBLE_EQ(derivative(p, s, 100.0)[kV], 60.0 / p.mass);
}

// --- the CVODE plant against closed-form solutions -----------------------------------------------
// rtol = 1e-8 bounds the local error of each step; over the ~100-1000 restarts of a run (each
// starting again at BDF order 1) the global error grows to ~1e-6 relative (plant_test.cpp measured
// 1.2e-6 on a free mass), so the bounds below are 1e-5 relative to the quantity's scale.

// constant_force on a free mass: m x'' = -F, so x(t) = -F t^2/(2m) (F_extra is subtracted).
TEST(EffectsPlant, ConstantForceAcceleratesAgainstItsSign) {
  PlantParams p = free_mass();
  p.effects.constant_force = {true, 25.0};
  const double T = 1e-2, F = 25.0;
  Plant plant(p, T);
  for (int k = 1; k <= 100; ++k) {
    plant.advance(0.0, k * T);
    const double t = k * T;
    const double x = -F * t * t / (2 * p.mass);
    ASSERT_NEAR(plant.state().x, x, 1e-5 * std::abs(x)) << "t=" << t;
  }
  EXPECT_NEAR(plant.state().v, -F / p.mass, 1e-5 * F / p.mass);
  EXPECT_EQ(plant.forces(0.0).extra, F);
}

// spring_force on a free mass released at rest from x0: x(t) = rest + (x0 - rest) cos(w t),
// w = sqrt(k/m). The bound is 1e-5 of the 2 mm amplitude, as above.
TEST(EffectsPlant, SpringForceOscillatesAtSqrtKOverM) {
  PlantParams p = free_mass();
  const double k = 1e4, rest = 0.003, x0 = 0.005;
  p.effects.spring_force = {true, k, rest};
  p.initial.position = x0;
  const double w = std::sqrt(k / p.mass), T = 1e-3;  // w = 9.9 rad/s: 1.6 cycles in 1 s
  Plant plant(p, T);
  for (int j = 1; j <= 1000; ++j) {
    plant.advance(0.0, j * T);
    const double t = j * T;
    ASSERT_NEAR(plant.state().x, rest + (x0 - rest) * std::cos(w * t), 1e-5 * (x0 - rest)) << "t=" << t;
    ASSERT_NEAR(plant.state().v, -(x0 - rest) * w * std::sin(w * t), 1e-5 * (x0 - rest) * w) << "t=" << t;
  }
}

// viscous_friction on a free mass coasting from v0: v(t) = v0 exp(-t/tau), tau = m/c, and
// x(t) = v0 tau (1 - exp(-t/tau)). Bounds 1e-5 of v0 and of the coasting distance v0 tau.
TEST(EffectsPlant, ViscousFrictionDecaysExponentiallyWithTimeConstantMOverC) {
  PlantParams p = free_mass();
  const double c = 1000.0, v0 = 0.05;
  p.effects.viscous_friction = {true, c};
  p.initial.velocity = v0;
  const double tau = p.mass / c, T = 1e-3;  // tau = 0.102 s; run 3 tau
  Plant plant(p, T);
  for (int j = 1; j <= 300; ++j) {
    plant.advance(0.0, j * T);
    const double t = j * T;
    ASSERT_NEAR(plant.state().v, v0 * std::exp(-t / tau), 1e-5 * v0) << "t=" << t;
    ASSERT_NEAR(plant.state().x, v0 * tau * (1 - std::exp(-t / tau)), 1e-5 * v0 * tau) << "t=" << t;
  }
}

// mass_error: the same thrust accelerates the true mass: a = F/mass, v(t) = F t/mass.
TEST(EffectsPlant, MassErrorUsesTheTrueMass) {
  PlantParams p = free_mass();
  const double F = 60.0, m_true = 120.0;
  p.effects.mass_error = {true, m_true};
  EXPECT_EQ(effective_params(p).mass, m_true);
  EXPECT_EQ(p.mass, 102.04);  // the params themselves keep the nominal mass
  EXPECT_DOUBLE_EQ(derivative(p, State{}, F)[kV], F / m_true);
  Plant plant(p, 1e-2);
  for (int k = 1; k <= 100; ++k) plant.advance(F, k * 1e-2);
  EXPECT_NEAR(plant.state().v, F / m_true, 1e-5 * F / m_true);
  EXPECT_NEAR(plant.state().x, F / (2 * m_true), 1e-5 * F / (2 * m_true));
}

// input_delay on a free mass under a thrust step at t = 0: x(t) = 0 for t <= d and
// F (t - d)^2/(2m) after. d = 2.5 T is not a multiple of the period, so every advance() switches
// inside the period. Bound: 1e-5 relative as above, plus 1e-15 m absolute for the zero phase
// (CVODE's deviation variables integrate exact zeros there: the bound is only round-off).
TEST(EffectsPlant, InputDelayStepStartsAfterTheDelay) {
  PlantParams p = free_mass();
  const double T = 1e-3, d = 2.5e-3, F = 50.0;
  p.effects.input_delay = {true, d};
  Plant plant(p, T);
  EXPECT_EQ(plant.forces(F).thrust, 0.0);  // u = 0 before t0 + d
  const std::size_t bound = static_cast<std::size_t>(d / T) + 2;
  for (int k = 1; k <= 2000; ++k) {
    plant.advance(F, k * T);
    const double t = k * T;
    const double x = t <= d ? 0.0 : F * (t - d) * (t - d) / (2 * p.mass);
    ASSERT_NEAR(plant.state().x, x, 1e-5 * x + 1e-15) << "t=" << t;
    ASSERT_LE(plant.input_history_size(), bound) << "t=" << t;  // memory stays bounded
  }
  EXPECT_EQ(plant.forces(F).thrust, F);
}

// The exact motion of a free mass under a piecewise-constant force: each piece adds
// v += a*dt and x += v*dt + a*dt^2/2.
struct Piece {
  double t_start;
  double force;
};
double free_mass_position(const std::vector<Piece>& pieces, double m, double t) {
  double x = 0.0, v = 0.0, t_prev = 0.0, a = 0.0;
  for (const Piece& pc : pieces) {
    if (pc.t_start >= t) break;
    const double dt = pc.t_start - t_prev;
    x += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    t_prev = pc.t_start;
    a = pc.force / m;
  }
  const double dt = t - t_prev;
  return x + v * dt + 0.5 * a * dt * dt;
}

// input_delay under a command that changes every period (a seeded random sequence): the plant
// must apply u_{k} over [kT + d, (k+1)T + d) exactly, for a delay inside a period (2.5 T), one
// on the period grid (2 T: the switch times t_k + d hit the boundaries up to rounding) and a
// delay shorter than one period. Over 1000 periods the bound is 1e-5 of the largest |x|
// plus 1e-12 m (the atol-level error of the many restarts near x = 0).
TEST(EffectsPlant, InputDelayShiftsAnyCommandSequence) {
  const double T = 1e-3;
  for (const double d : {2.5e-3, 2e-3, 0.3e-3}) {
    PlantParams p = free_mass();
    p.effects.input_delay = {true, d};
    Plant plant(p, T);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> uu(-40.0, 60.0);
    std::vector<Piece> pieces;
    double x_max = 0.0;
    for (int k = 0; k < 1000; ++k) {
      const double u = uu(rng);
      pieces.push_back({k * T + d, u});
      plant.advance(u, (k + 1) * T);
      const double want = free_mass_position(pieces, p.mass, (k + 1) * T);
      x_max = std::max(x_max, std::abs(want));
      ASSERT_NEAR(plant.state().x, want, 1e-5 * x_max + 1e-12) << "d=" << d << " k=" << k;
      ASSERT_LE(plant.input_history_size(), static_cast<std::size_t>(d / T) + 2);
    }
  }
}

// A zero delay takes the piecewise path but must give the undelayed plant's numbers exactly.
TEST(EffectsPlant, ZeroInputDelayIsBitForBitTheUndelayedPlant) {
  PlantParams p;
  p.ripple = feeddrive::plant::RippleParams::paper();
  p.grinding.enabled = true;
  PlantParams q = p;
  q.effects.input_delay = {true, 0.0};
  Plant a(p, 1e-4), b(q, 1e-4);
  for (int k = 0; k < 200; ++k) {
    const double u = 0.3 * std::sin(0.05 * k);
    a.advance(u, (k + 1) * 1e-4);
    b.advance(u, (k + 1) * 1e-4);
    ASSERT_EQ(a.state().to_vector(), b.state().to_vector()) << "k=" << k;
  }
}

// presliding on a `static` friction model: the friction becomes LuGre with the effect's sigma0 and
// sigma1, keeping Fs, Fc, vs, delta and sigma2.
TEST(EffectsPlant, PreslidingTurnsStaticFrictionIntoLuGre) {
  PlantParams p;
  p.friction.model = FrictionModel::kStatic;
  p.friction.static_force = 110.0;
  p.friction.viscous = 0.7;
  p.effects.presliding = {true, 1e6, 3.0e4};
  const PlantParams e = effective_params(p);
  EXPECT_EQ(e.friction.model, FrictionModel::kLuGre);
  EXPECT_EQ(e.friction.bristle_stiffness, 1e6);
  EXPECT_EQ(e.friction.bristle_damping, 3.0e4);
  EXPECT_EQ(e.friction.static_force, 110.0);
  EXPECT_EQ(e.friction.coulomb_force, p.friction.coulomb_force);
  EXPECT_EQ(e.friction.stribeck_velocity, p.friction.stribeck_velocity);
  EXPECT_EQ(e.friction.stribeck_exponent, p.friction.stribeck_exponent);
  EXPECT_EQ(e.friction.viscous, 0.7);
  EXPECT_TRUE(active_states(p)[kZ]);  // z now evolves
}

// A force step F = 12 N < Fs = 120 N at rest: LuGre's steady state is v = 0, friction
// sigma0*z = F, so the bristles deflect z = F/sigma0 (the presliding displacement). With
// sigma1 = 3e4 N*s/m the presliding mode has damping ratio 1.5*sqrt(1 - F/Fs) > 1, so the slide
// creeps forward without reversing; on such a monotone path dz/dx = 1 - sigma0*z/g with
// g = Fs (|v| < 1e-3 m/s keeps g within 1e-4 relative of Fs), so
//   x = -(Fs/sigma0)*ln(1 - F/Fs)   (= F/sigma0*(1 + F/(2 Fs) + ...), 5 % above F/sigma0).
// After 1 s the slowest pole (-38 /s) has decayed by e^-38. Bounds: z to 1e-6 relative
// (the atol_bristle 1e-13 m on 1.2e-5 m, with margin), x to 1e-4 relative (the g = Fs
// approximation, 1e-4 times the 5 % correction, plus the integration error).
TEST(EffectsPlant, PreslidingForceStepSettlesAtForceOverStiffness) {
  PlantParams p = free_mass();
  p.friction.model = FrictionModel::kStatic;
  const double sigma0 = 1e6, F = 12.0, Fs = p.friction.static_force;
  p.effects.presliding = {true, sigma0, 3.0e4};
  Plant plant(p, 1e-3);
  for (int k = 1; k <= 1000; ++k) plant.advance(F, k * 1e-3);
  EXPECT_NEAR(plant.state().z, F / sigma0, 1e-6 * F / sigma0);
  EXPECT_NEAR(plant.forces(F).friction, F, 1e-6 * F);
  const double x = -(Fs / sigma0) * std::log(1.0 - F / Fs);
  EXPECT_NEAR(plant.state().x, x, 1e-4 * x);
  EXPECT_NEAR(plant.state().v, 0.0, 1e-9);
}

// grinding_force: the grinding section's Hahn-Lindsay model with the effect's C, ke and contact
// position, on even with grinding.enabled = false. At a constant infeed velocity v0 (a mass so
// large that v stays v0) Fg(t) = C v0 (1 - exp(-t/tau)), tau = C/ke = 0.05 s; after 2 s = 40 tau
// it is the steady state C v0. Bound: 1e-6 of C v0 (the rtol-level error, as in plant_test.cpp).
TEST(EffectsPlant, GrindingForceReachesCTimesInfeedVelocity) {
  PlantParams p = free_mass();
  p.mass = 1e15;
  const double C = 5e6, ke = 1e8, v0 = 2e-6;
  p.effects.grinding_force = {true, C, ke, -1.0};
  p.initial.velocity = v0;
  const PlantParams e = effective_params(p);
  EXPECT_TRUE(e.grinding.enabled);
  EXPECT_NEAR(e.grinding.damping(), C, 1e-12 * C);  // dullness*pi*dw*bs round trip
  EXPECT_EQ(e.grinding.stiffness, ke);
  EXPECT_EQ(e.grinding.contact_position, -1.0);
  EXPECT_TRUE(active_states(p)[kFg]);
  Plant plant(p, 1e-2);
  for (int k = 1; k <= 200; ++k) {
    plant.advance(0.0, k * 1e-2);
    const double t = k * 1e-2;
    ASSERT_NEAR(plant.state().fg, C * v0 * (1 - std::exp(-t * ke / C)), 1e-6 * C * v0) << "t=" << t;
  }
  EXPECT_NEAR(plant.forces(0.0).grinding, C * v0, 1e-6 * C * v0);
}

// --- validation -------------------------------------------------------------------------------------

std::string error_of(const PlantParams& p) {
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(EffectsParams, ValidateNamesKeyAndValue) {
  PlantParams p;
  p.effects.cogging_ripple.pitch = -1.0;
  EXPECT_EQ(error_of(p), "(no error)");  // only enabled effects are checked
  p.effects.cogging_ripple.enabled = true;
  EXPECT_EQ(error_of(p), "plant.effects.cogging_ripple.pitch = -1: must be > 0");

  p = PlantParams{};
  p.effects.stribeck_friction = {true, 10.0, 20.0, 0.01};
  EXPECT_EQ(error_of(p), "plant.effects.stribeck_friction.static_force = 10: must be >= coulomb_force");
  p.effects.stribeck_friction = {true, 30.0, 20.0, 0.0};
  EXPECT_EQ(error_of(p), "plant.effects.stribeck_friction.stribeck_velocity = 0: must be > 0");
  p.effects.stribeck_friction = {true, 30.0, -1.0, 0.01};
  EXPECT_EQ(error_of(p), "plant.effects.stribeck_friction.coulomb_force = -1: must be >= 0");

  p = PlantParams{};
  p.effects.mass_error = {true, 0.0};
  EXPECT_EQ(error_of(p), "plant.effects.mass_error.mass = 0: must be > 0");
  p = PlantParams{};
  p.effects.input_delay = {true, -0.001};
  EXPECT_EQ(error_of(p), "plant.effects.input_delay.delay = -0.001: must be >= 0");
  p = PlantParams{};
  p.effects.presliding = {true, 2e6, -5.0};
  EXPECT_EQ(error_of(p), "plant.effects.presliding.bristle_damping = -5: must be >= 0");
  p = PlantParams{};
  p.effects.grinding_force = {true, 7.85e6, 0.0, 0.0};
  EXPECT_EQ(error_of(p), "plant.effects.grinding_force.stiffness = 0: must be > 0");
  p = PlantParams{};
  p.effects.constant_force = {true, std::nan("")};
  EXPECT_EQ(error_of(p), "plant.effects.constant_force.force = nan: must be a finite number");
  p = PlantParams{};
  p.effects.reluctance_ripple = {true, 0.03, 1.5, 0.0};
  EXPECT_EQ(error_of(p),
            "plant.effects.reluctance_ripple.reluctance_amplitude = 1.5: |reluctance_amplitude| must be < 1");

  // The sections the effects use are checked even where they are off themselves.
  p = PlantParams{};
  p.friction.model = FrictionModel::kNone;
  p.friction.static_force = 50.0;  // below Fc = 80: fine without friction, not for LuGre
  EXPECT_EQ(error_of(p), "(no error)");
  p.effects.presliding.enabled = true;
  EXPECT_EQ(error_of(p), "plant.friction.static_force = 50: must be >= coulomb_force");
  p = PlantParams{};
  p.friction.static_smoothing_velocity = 0.0;  // unused by LuGre
  p.effects.coulomb_friction.enabled = true;
  EXPECT_EQ(error_of(p), "plant.friction.static_smoothing_velocity = 0: must be > 0");
  p.friction.static_smoothing_velocity = 1e-5;
  p.friction.static_smoothing_shape = 1.5;  // a blend weight of tanh and the algebraic form
  EXPECT_EQ(error_of(p), "plant.friction.static_smoothing_shape = 1.5: must be in [0, 1]");
}

}  // namespace
}  // namespace feeddrive::plant

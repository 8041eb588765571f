// Force laws against their closed forms and the analytic Jacobian against finite differences.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "feeddrive/plant/dynamics.hpp"
#include "feeddrive/plant/forces.hpp"
#include "jacobian_check.hpp"

namespace feeddrive::plant {
namespace {

TEST(Stribeck, LimitsAreStaticAndCoulomb) {
  const FrictionParams p;
  EXPECT_DOUBLE_EQ(stribeck(p, 0.0), p.static_force);
  // exp(-(10/0.1)^2) underflows to 0: g is exactly Fc far above vs.
  EXPECT_DOUBLE_EQ(stribeck(p, 10.0), p.coulomb_force);
  // At v = vs: g = Fc + (Fs - Fc)/e.
  EXPECT_NEAR(stribeck(p, -0.1), 80.0 + 40.0 / M_E, 1e-12);
}

TEST(LuGre, SteadyStateEqualsStaticMap) {
  // At dz/dt = 0, z = sgn(v) g(v)/sigma0 and F = g(v) sgn(v) + sigma2 v (Canudas de Wit 1995 eq. 4).
  const FrictionParams p;
  for (double v : {-0.5, -0.01, 1e-4, 0.1, 0.8}) {
    const double z = std::copysign(stribeck(p, v) / p.bristle_stiffness, v);
    EXPECT_NEAR(lugre_zdot(p, v, z), 0.0, 1e-15);
    EXPECT_NEAR(friction_force(p, v, z), std::copysign(stribeck(p, v), v) + p.viscous * v, 1e-9);
  }
}

TEST(LuGre, ZeroVelocityFreezesBristle) {
  const FrictionParams p;
  EXPECT_EQ(lugre_zdot(p, 0.0, 3e-5), 0.0);
  EXPECT_DOUBLE_EQ(friction_force(p, 0.0, 3e-5), p.bristle_stiffness * 3e-5);
}

TEST(LuGre, MicroDampingDecays) {
  FrictionParams p;
  p.damping_decay_velocity = 1e-3;
  EXPECT_DOUBLE_EQ(micro_damping(p, 0.0), p.bristle_damping);
  EXPECT_NEAR(micro_damping(p, 1e-3), p.bristle_damping / M_E, 1e-9);
  p.damping_decay_velocity = 0.0;
  EXPECT_DOUBLE_EQ(micro_damping(p, 1.0), p.bristle_damping);
}

TEST(Ripple, MatchesEquations14And15) {
  RippleParams p;
  p.enabled = true;
  const double x = 0.0071, fdes = 200.0;
  const double th = 2 * M_PI * x / p.pitch;
  const double cog = p.cogging_amplitude * std::sin(th) + p.cogging_third * std::sin(3 * th);
  const double rel = fdes * (p.reluctance_amplitude * std::sin(th) + p.reluctance_third * std::sin(3 * th));
  EXPECT_NEAR(ripple_force(p, x, fdes), cog + rel, 1e-12);
  // Periodic in the pitch.
  EXPECT_NEAR(ripple_force(p, x + 5 * p.pitch, fdes), cog + rel, 1e-9);
  p.enabled = false;
  EXPECT_EQ(ripple_force(p, x, fdes), 0.0);
}

TEST(Grinding, ContactAndSteadyState) {
  GrindingParams p;
  p.enabled = true;
  EXPECT_NEAR(p.damping(), 2.5e9 * M_PI * 0.05 * 0.02, 1e-3);  // C = c*pi*dw*bs = 7.85e6 N*s/m
  EXPECT_NEAR(p.time_constant(), p.damping() / 2e7, 1e-15);
  // Steady state Fg = C*v makes the rate vanish (eq. 13 at s = 0).
  const double v = 1e-6;
  EXPECT_NEAR(grinding_rate(p, 0.0, v, p.damping() * v), 0.0, 1e-12);
  p.contact_position = 1e-3;
  EXPECT_EQ(grinding_force(p, 0.0, 5.0), 0.0);
  EXPECT_EQ(grinding_force(p, 2e-3, 5.0), 5.0);
  // The wheel engages over contact_width (1 um): s rises linearly, so the force is continuous;
  // half-way it is half of Fg, and the rate's ke*v term is scaled alike.
  EXPECT_EQ(contact_fraction(p, 1e-3), 0.0);
  EXPECT_NEAR(grinding_force(p, 1e-3 + 0.5e-6, 5.0), 2.5, 1e-9);
  EXPECT_NEAR(grinding_rate(p, 1e-3 + 0.5e-6, v, 0.0), 0.5 * p.stiffness * v, 1e-9 * p.stiffness * v);
  EXPECT_NEAR(contact_fraction_dx(p, 1e-3 + 0.5e-6), 1e6, 1e-6);
  EXPECT_EQ(contact_fraction_dx(p, 2e-3), 0.0);
  p.contact_width = 0.0;  // a step
  EXPECT_EQ(grinding_force(p, 1e-3 + 1e-12, 5.0), 5.0);
}

// Inside the engagement band the Jacobian has the dFg/dx terms: central differences on states
// within the band (h = 1e-9 m, far inside the 1 um band; tolerance as below).
TEST(Dynamics, JacobianInsideTheContactBand) {
  PlantParams p;
  p.friction.model = FrictionModel::kNone;
  p.grinding.enabled = true;
  p.grinding.contact_position = 1e-3;
  const State s{1e-3 + 0.4e-6, 2e-3, 0.0, 40.0, 0.0};
  const Jacobian J = jacobian(p, s, 1.0);
  for (int c : {kX, kV, kFg}) {
    const double h = c == kX ? 1e-9 : (c == kV ? 1e-7 : 1e-5);
    StateVector yp = s.to_vector(), ym = s.to_vector();
    yp[c] += h;
    ym[c] -= h;
    const StateVector fp = derivative(p, State::from_vector(yp), 1.0), fm = derivative(p, State::from_vector(ym), 1.0);
    for (int r : {kV, kFg}) {
      const double fd = (fp[r] - fm[r]) / (2 * h);
      EXPECT_NEAR(J[r][c], fd, 1e-6 * std::abs(J[r][c]) + 1e-14 * std::abs(fp[r]) / h + 1e-12) << r << "," << c;
    }
  }
}

// The smoothed sign's two ends are the closed forms (b = 0: tanh(v/eps), b = 1: v/sqrt(v^2 + eps^2),
// to the last bits: 1e-15), a blend is their weighted sum, and its derivative matches central
// differences (h = 1e-4 eps: truncation O(h^2/eps^3) ~ 1e-8/eps relative, far inside 1e-6).
TEST(Forces, SmoothedSignBlendsTanhAndTheAlgebraicForm) {
  FrictionParams p;
  p.model = FrictionModel::kStatic;
  p.static_smoothing_velocity = 2e-4;
  const double eps = p.static_smoothing_velocity;
  for (double v : {-3e-3, -2e-4, -1e-5, 0.0, 7e-5, 6e-4, 0.05}) {
    p.static_smoothing_shape = 0.0;
    const double th = smoothed_sign(p, v);
    EXPECT_NEAR(th, std::tanh(v / eps), 1e-15) << v;
    p.static_smoothing_shape = 1.0;
    const double al = smoothed_sign(p, v);
    EXPECT_NEAR(al, v / std::sqrt(v * v + eps * eps), 1e-15) << v;
    p.static_smoothing_shape = 0.3;
    EXPECT_NEAR(smoothed_sign(p, v), 0.7 * th + 0.3 * al, 1e-15) << v;
    for (double b : {0.0, 0.3, 1.0}) {
      p.static_smoothing_shape = b;
      const double h = 1e-4 * eps;
      const double fd = (smoothed_sign(p, v + h) - smoothed_sign(p, v - h)) / (2 * h);
      EXPECT_NEAR(smoothed_sign_derivative(p, v), fd, 1e-6 * std::abs(fd) + 1e-9 / eps) << v << " b " << b;
    }
  }
  // the algebraic form is the slower one: at v = 3 eps it is still 5 % short of 1, tanh 0.5 %
  p.static_smoothing_shape = 1.0;
  EXPECT_NEAR(smoothed_sign(p, 3 * eps), 3.0 / std::sqrt(10.0), 1e-12);
  EXPECT_LT(smoothed_sign(p, 3 * eps), 0.95);
  p.static_smoothing_shape = 0.0;
  EXPECT_GT(smoothed_sign(p, 3 * eps), 0.995);
}

// Central finite differences of derivative() against jacobian(), on seeded random states with
// every sub-model on. Step h_j = 1e-6 * scale_j; the tolerance 1e-5 relative to the row scale
// covers the O(h^2) truncation and the cancellation error (~1e-16/h relative).
TEST(Dynamics, AnalyticJacobianMatchesFiniteDifferences) {
  for (FrictionModel fm : {FrictionModel::kLuGre, FrictionModel::kStatic}) {
    PlantParams p;
    p.friction.model = fm;
    p.friction.damping_decay_velocity = 0.05;
    p.ripple = feeddrive::plant::RippleParams::paper();
    p.grinding.enabled = true;
    p.grinding.contact_position = -1.0;
    p.electrical.enabled = true;
    p.friction.static_smoothing_velocity = 1e-2;
    SCOPED_TRACE("friction " + to_string(fm));
    test::expect_jacobian_matches_differences(p, 42, 0.5);
  }
}

TEST(Params, ValidateNamesKeyAndValue) {
  PlantParams p;
  p.mass = -1.0;
  try {
    p.validate();
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "plant.mass = -1: must be > 0");
  }
  p = PlantParams{};
  p.friction.bristle_stiffness = std::nan("");
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = PlantParams{};
  p.friction.static_force = 50.0;  // below Fc = 80
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("plant.friction.static_force = 50"), std::string::npos);
  }
}

}  // namespace
}  // namespace feeddrive::plant

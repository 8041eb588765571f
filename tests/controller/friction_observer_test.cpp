// The bristle observer (exact exponential update of the LuGre z-equation with v held) and the
// grinding-force observer (exact update of Xie & Liang eq. 13), against their analytic solutions.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "controller_util.hpp"
#include "feeddrive/controller/friction_observer.hpp"

namespace feeddrive::controller {
namespace {

using test::hand_lugre;
using test::hand_stribeck;

plant::FrictionParams lugre() { return plant::FrictionParams{}; }  // Table 1, delta = 2

// With v held, z^ converges to the LuGre steady state z_ss = sgn(v)*g(v)/sigma0. The slowest case,
// |v| = 3 mm/s, has the rate a = sigma0*|v|/g(v) = 2e6*0.003/120 = 50 1/s, so 2 s (20000 periods
// of 1e-4 s) is 100 time constants: the remaining transient e^-100 is far below rounding.
// Tolerance: 1e-12 relative (each exact update is a convex combination: no error growth).
TEST(FrictionObserver, ConvergesToTheLuGreSteadyState) {
  const auto f = lugre();
  for (double v : {0.05, -0.05, 0.003, -0.8}) {
    FrictionObserver obs(f, 1e-4, 0.0);
    for (int k = 0; k < 20000; ++k) obs.advance(v, 0.0);
    const double zs = (v > 0 ? 1.0 : -1.0) * hand_stribeck(f, v) / f.bristle_stiffness;
    EXPECT_NEAR(obs.z(), zs, 1e-12 * std::abs(zs)) << v;
    // At the steady state dz/dt = 0, so F^f = sigma0*z_ss + sigma2*v = sgn(v) g(v) + sigma2 v.
    const double fss = (v > 0 ? 1.0 : -1.0) * hand_stribeck(f, v) + f.viscous * v;
    EXPECT_NEAR(obs.estimate(v), fss, 1e-9 * std::abs(fss)) << v;  // sigma1*zdot: 2e4 * (1e-12*z rate)
  }
}

// The update is the exact solution of dz/dt = v - a z (a = sigma0|v|/g(v)) over each period, so
// after n periods z^ equals z(t) = zs + (z0 - zs)*exp(-a t) at t = n T for every n, not only in
// the limit. A slow case (|v| = 2e-3 m/s, a = 33.3 1/s at T = 1e-3 s) checked during the
// transient. Tolerance: 1e-15 m absolute (~1e-11 of |z0 - zs| = 1.2e-4 m; rounding of up to 200
// products is ~1e-18 m). An explicit-Euler update would be off by ~1e-6 m at n = 30.
TEST(FrictionObserver, ExactExponentialMatchesTheAnalyticSolution) {
  const auto f = lugre();
  const double T = 1e-3;
  const double v1 = 0.02, v2 = -2e-3;
  FrictionObserver obs(f, T, 0.0);
  // First bring z^ to a known non-zero value z0 (the steady state of v1).
  for (int k = 0; k < 2000; ++k) obs.advance(v1, 0.0);
  const double z0 = obs.z();
  ASSERT_NEAR(z0, hand_stribeck(f, v1) / f.bristle_stiffness, 1e-15);
  const double a = f.bristle_stiffness * std::abs(v2) / hand_stribeck(f, v2);
  const double zs = -hand_stribeck(f, v2) / f.bristle_stiffness;
  int n = 0;
  for (int check : {1, 2, 5, 10, 30, 100, 200}) {
    while (n < check) {
      obs.advance(v2, 0.0);
      ++n;
    }
    const double t = n * T;
    EXPECT_NEAR(obs.z(), zs + (z0 - zs) * std::exp(-a * t), 1e-15) << "n = " << n;
  }
  // The estimate is the LuGre force at (v, z^) with dz/dt evaluated there (eq. 2).
  EXPECT_NEAR(obs.estimate(v2), hand_lugre(f, v2, obs.z()), 1e-9);
}

// At v = 0 the bristle equation is dz/dt = 0: z^ keeps its value (presliding memory).
TEST(FrictionObserver, HoldsAtZeroVelocity) {
  const auto f = lugre();
  FrictionObserver obs(f, 1e-4, 0.0);
  for (int k = 0; k < 50; ++k) obs.advance(1e-3, 0.0);
  const double z = obs.z();
  ASSERT_GT(z, 0.0);
  for (int k = 0; k < 1000; ++k) obs.advance(0.0, 0.0);
  EXPECT_EQ(obs.z(), z);
  EXPECT_EQ(obs.estimate(0.0), f.bristle_stiffness * z);  // F = sigma0 z at rest
}

// The z-equation is stiff: a = sigma0*|v|/g(v) reaches 2e4 1/s at 0.8 m/s. With a period of
// 1e-2 s (a*T = 200) explicit Euler's factor 1 - a*T = -199 explodes, while the exact update is
// a convex combination of z^ and z_ss with |z_ss| = g(v)/sigma0 <= Fs/sigma0, so |z^| can never
// exceed Fs/sigma0 = 60 um. Seeded random velocities in [-1, 1] m/s, with exact zeros mixed in.
TEST(FrictionObserver, StaysBoundedWhenStiffWhereEulerExplodes) {
  const auto f = lugre();
  const double T = 1e-2;
  const double bound = f.static_force / f.bristle_stiffness;
  FrictionObserver obs(f, T, 0.0);
  std::mt19937_64 rng(20240607);
  std::uniform_real_distribution<double> vel(-1.0, 1.0);
  double z_euler = 0.0;
  double euler_max = 0.0;
  for (int k = 0; k < 10000; ++k) {
    const double v = (k % 17 == 0) ? 0.0 : vel(rng);
    obs.advance(v, 0.0);
    ASSERT_LE(std::abs(obs.z()), bound * (1 + 1e-12)) << "step " << k;
    ASSERT_TRUE(std::isfinite(obs.estimate(v)));
    if (k < 20) {  // explicit Euler on the same inputs, for contrast
      z_euler += T * (v - f.bristle_stiffness * std::abs(v) * z_euler / hand_stribeck(f, v));
      euler_max = std::max(euler_max, std::abs(z_euler));
    }
  }
  EXPECT_GT(euler_max, 1e3 * bound);  // Euler is useless at this step
  // A sustained 0.8 m/s: one step lands on z_ss (e^-200 = 0).
  obs.advance(0.8, 0.0);
  EXPECT_NEAR(obs.z(), hand_stribeck(f, 0.8) / f.bristle_stiffness, 1e-18);
}

// The correction term. For the SMC, m dS/dt = -m(eta sw + kS) + sigma0*(z - z^) (to first order),
// and V = m S^2/2 + sigma0 (z - z^)^2/(2L) decreases only if dz^/dt carries +L*e_v with
// e_v = v_d - v_m (Canudas de Wit 1995's -k*e with e = v - v_d): when the drive lags (e_v > 0),
// friction is under-estimated and z^ must grow. Checked at v = 0 (a = 0, z^+ = z^ + T*L*e_v) and
// in sliding (z^ converges to (v + L e_v)/a).
TEST(FrictionObserver, CorrectionRaisesTheEstimateWhenTheDriveLags) {
  const auto f = lugre();
  const double T = 1e-4, L = 50.0;
  FrictionObserver obs(f, T, L);
  obs.advance(0.0, 1e-3);
  EXPECT_NEAR(obs.z(), T * L * 1e-3, 1e-20);
  FrictionObserver moving(f, T, L);
  const double v = 0.05, ev = 2e-3;
  for (int k = 0; k < 1000; ++k) moving.advance(v, ev);
  const double a = f.bristle_stiffness * v / hand_stribeck(f, v);
  EXPECT_NEAR(moving.z(), (v + L * ev) / a, 1e-12 * (v + L * ev) / a);
  // A non-finite correction carries no information and is dropped.
  FrictionObserver nan_err(f, T, L);
  nan_err.advance(v, std::numeric_limits<double>::quiet_NaN());
  FrictionObserver no_err(f, T, 0.0);
  no_err.advance(v, 0.0);
  EXPECT_EQ(nan_err.z(), no_err.z());
}

// Static and no-friction models have no state: advance() is a no-op and the estimate is the map.
TEST(FrictionObserver, StatelessModels) {
  auto f = lugre();
  f.model = plant::FrictionModel::kNone;
  FrictionObserver none(f, 1e-4, 0.0);
  none.advance(0.1, 0.0);
  EXPECT_EQ(none.z(), 0.0);
  EXPECT_EQ(none.estimate(0.1), 0.0);
  f.model = plant::FrictionModel::kStatic;
  FrictionObserver st(f, 1e-4, 0.0);
  st.advance(0.1, 0.0);
  EXPECT_EQ(st.z(), 0.0);
  // g(v)*tanh(v/eps) + sigma2 v with v/eps = 1e4: tanh = 1 in double precision.
  EXPECT_NEAR(st.estimate(0.1), hand_stribeck(f, 0.1) + f.viscous * 0.1, 1e-12);
}

// Grinding observer: with v held and in contact, F^g -> C*v with C = c*pi*dw*bs and time
// constant tau = C/ke (eq. 13: dFg/dt = ke v - Fg/tau). With T = tau/1000, after 1000 periods
// (one tau) F^g = C v (1 - e^-1) = 63.2 % of C v; after 10 tau 1 - e^-10. Tolerance 1e-12
// relative: rounding of 1000 exact updates.
TEST(GrindingObserver, ConvergesWithTheHahnLindsayTimeConstant) {
  plant::GrindingParams g;
  g.enabled = true;
  const double C = g.dullness * test::kPi * g.workpiece_diameter * g.wheel_width;
  const double tau = C / g.stiffness;
  EXPECT_NEAR(C, 7.853981633974483e6, 1e-3);  // 2.5e9*pi*0.05*0.02 (notes Sec. 1)
  const double T = tau / 1000.0;
  const double v = 1e-6;  // Fig. 23's 1 um/s infeed
  GrindingObserver obs(g, T);
  for (int k = 0; k < 1000; ++k) obs.advance(0.0, v);
  EXPECT_NEAR(obs.estimate(0.0), C * v * (1.0 - std::exp(-1.0)), 1e-12 * C * v);
  EXPECT_NEAR(obs.estimate(0.0) / (C * v), 0.6321205588, 1e-9);
  for (int k = 0; k < 9000; ++k) obs.advance(0.0, v);
  EXPECT_NEAR(obs.estimate(0.0), C * v * (1.0 - std::exp(-10.0)), 1e-11 * C * v);
}

// Out of contact (x <= contact_position) the force on the slide is 0 and the state relaxes to 0
// with the same tau; disabled grinding estimates 0 and never moves.
TEST(GrindingObserver, ContactAndDisabled) {
  plant::GrindingParams g;
  g.enabled = true;
  g.contact_position = 0.01;
  const double tau = g.time_constant();
  const double T = tau / 100.0;
  GrindingObserver obs(g, T);
  for (int k = 0; k < 10000; ++k) obs.advance(0.02, 1e-5);  // in contact: converged to C v
  const double fg = obs.estimate(0.02);
  EXPECT_NEAR(fg, g.damping() * 1e-5, 1e-12 * fg);
  EXPECT_EQ(obs.estimate(0.0), 0.0);                     // out of contact: no force
  for (int k = 0; k < 100; ++k) obs.advance(0.0, 1e-5);  // one tau out of contact
  EXPECT_NEAR(obs.estimate(0.02), fg * std::exp(-1.0), 1e-12 * fg);

  g.enabled = false;
  GrindingObserver off(g, T);
  for (int k = 0; k < 100; ++k) off.advance(0.02, 1e-5);
  EXPECT_EQ(off.estimate(0.02), 0.0);
}

}  // namespace
}  // namespace feeddrive::controller

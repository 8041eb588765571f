// Issue 10 point 1: the sliding-mode controller under model mismatch. The controller keeps the
// nominal model while the CVODE plant has Fs, Fc +-30 %, mass +-20 % or sigma0, sigma1 +-30 %;
// on the paper's jerk-limited move (Xie & Liang Figs. 21-22) the error must stay within a bound
// derived from the reaching law, in every compensation mode (true z, bristle observer, none) and
// for every switching law. Before the fix the true-z modes reached 6.8-14.4 mm here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "controller_util.hpp"
#include "feeddrive/controller/sliding_mode.hpp"

namespace feeddrive::controller {
namespace {

constexpr double kPeriod = 1e-4;           // T [s]: 10 kHz for every switching law
constexpr double kDuration = 1.5;          // [s]: the move (1.10 s) and its settling
constexpr double kMaxAcceleration = 1.15;  // [m/s^2] of the move
constexpr double kMaxVelocity = 0.2;       // [m/s]

trajectory::SCurveParams jerk_limited_move() {
  trajectory::SCurveParams r;  // 0.1 m, 0.2 m/s, 1.15 m/s^2, 2.4 m/s^3 (Xie & Liang Sec. 5.3)
  return r;
}

struct Mismatch {
  std::string name;
  double mass{1.0}, friction{1.0}, bristle{1.0};  // plant value / model value
};

const Mismatch kMismatches[] = {{"nominal"},
                                {"Fs,Fc +30%", 1.0, 1.3, 1.0},
                                {"Fs,Fc -30%", 1.0, 0.7, 1.0},
                                {"mass +20%", 1.2, 1.0, 1.0},
                                {"mass -20%", 0.8, 1.0, 1.0},
                                {"sigma0,sigma1 +30%", 1.0, 1.0, 1.3},
                                {"sigma0,sigma1 -30%", 1.0, 1.0, 0.7}};

enum class Mode { kTrueZ, kObserver, kNone };
std::string mode_name(Mode m) {
  return m == Mode::kTrueZ ? "true z" : (m == Mode::kObserver ? "observer" : "no compensation");
}

// The bound on max |e| over the move, from the reaching law (docs/controllers.md, "Model
// mismatch"). With the plant m*x'' = Ka*Kf*u - Ff and the law of eq. 19 with the model m^, F^f:
//   m*dS/dt = -m^*(eta*sw(S) + k*S) + dF,   dF = (m - m^)*(xd'' + lambda*de/dt) + (Ff - F^f)
// and de/dt = -lambda*e + S with e(0) = 0, so |e| <= max|S|/lambda.
//  * dF_max: the force error the loop must absorb. We take the *uncompensated* one,
//      dF_max = Fs_plant + sigma2*v_max + |m - m^|*a_max,
//    for every mode: a compensation may reduce the force error, never make it larger than no
//    compensation at all (the failure this test guards against was sigma1*zdot ~ 1,200 N).
//  * sat / tanh (boundary layer phi): inside the layer the law is the linear loop
//      S+ = (1 - K*T*m^/m)*S + T*dF/m,   K = eta/phi + k   (tanh: K >= eta*tanh(1)/phi + k while
//      |S| <= phi, the chord slope of tanh on [0, phi])
//    with the command held over T; |S| <= T*dF_max/(m*(1 - |1 - K*T*m^/m|)) (a geometric series;
//    it needs |1 - K*T*m^/m| < 1, checked below). For T -> 0 this is dF_max/(m^*K).
//  * sgn: once S has reached 0 (dF_max < m^*eta, checked), each period moves S by at most
//    T*(m^*(eta + k*|S|) + dF_max)/m, so |S| stays below that one-period overshoot.
// The bound is far below the millimetres of the defect (3.5-5.9 um for the boundary layer,
// 17 um for hard sgn at 10 kHz) and the measured errors lie below it (0.002-4.2 um).
double error_bound(const SlidingModeParams& c, const plant::PlantParams& plant) {
  const double m = plant.mass;
  const double mh = c.model.mass;
  const double df =
      plant.friction.static_force + plant.friction.viscous * kMaxVelocity + std::abs(m - mh) * kMaxAcceleration;
  double s_max = 0.0;
  if (c.switching == Switching::kSign) {
    EXPECT_LT(df, mh * c.eta) << "the reaching condition";
    const double s_guess = 1e-3;  // |S| of the hard-sgn chatter, O(eta*T) = 5e-4 m/s; k*S << eta
    s_max = kPeriod * (mh * (c.eta + c.k * s_guess) + df) / m;
    EXPECT_LE(s_max, s_guess);  // the guess used for the k*S term is consistent
  } else {
    const double slope = c.switching == Switching::kSaturation ? 1.0 : std::tanh(1.0);
    const double gain = c.eta * slope / c.boundary_layer + c.k;
    const double pole = std::abs(1.0 - gain * kPeriod * mh / m);
    EXPECT_LT(pole, 1.0) << "the discrete loop is stable";
    s_max = kPeriod * df / (m * (1.0 - pole));
    EXPECT_LE(s_max, c.boundary_layer) << "S stays in the layer (the linear-loop premise)";
  }
  return s_max / c.lambda;
}

std::string test_name(Switching s, Mode m) {
  return to_string(s) + (m == Mode::kTrueZ ? "_TrueZ" : (m == Mode::kObserver ? "_Observer" : "_None"));
}

class SlidingModeMismatch : public ::testing::TestWithParam<std::tuple<Switching, Mode>> {};

TEST_P(SlidingModeMismatch, ErrorStaysWithinTheReachingLawBound) {
  const auto [switching, mode] = GetParam();
  const plant::PlantParams nominal;  // LuGre, Xie & Liang's parameters (docs/parameters.md)
  SlidingModeParams c;
  c.switching = switching;
  c.boundary_layer = 5e-4;  // m/s: the near-deadbeat layer of smc_bl_* ((lambda + eta/phi + k)*T = 1.006)
  c.compensate_friction = mode != Mode::kNone;
  c.friction_state = mode == Mode::kObserver ? StateSource::kObserver : StateSource::kTrue;
  c.model = nominal;  // the controller keeps the nominal model in every case
  c.period = kPeriod;
  const auto reference = trajectory::make_scurve(jerk_limited_move());
  const long n = std::lround(kDuration / kPeriod);
  for (const Mismatch& mm : kMismatches) {
    plant::PlantParams plant = nominal;
    plant.mass *= mm.mass;
    plant.friction.static_force *= mm.friction;
    plant.friction.coulomb_force *= mm.friction;
    plant.friction.bristle_stiffness *= mm.bristle;
    plant.friction.bristle_damping *= mm.bristle;
    SlidingModeController controller(c);
    const auto run = test::run_loop(plant, controller, *reference, kPeriod, n);
    const double e = test::max_abs_error(run, 0.0, kDuration);
    const double bound = error_bound(c, plant);
    SCOPED_TRACE(to_string(switching) + ", " + mode_name(mode) + ", " + mm.name);
    EXPECT_LE(e, bound) << "max|e| = " << e * 1e6 << " um, bound " << bound * 1e6 << " um";
    // Graceful, not just bounded: the final error is within the same bound (no drift).
    EXPECT_LE(std::abs(run.back().xd - run.back().x), bound);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryModeAndSwitchingLaw, SlidingModeMismatch,
                         ::testing::Combine(::testing::Values(Switching::kSign, Switching::kSaturation,
                                                              Switching::kTanh),
                                            ::testing::Values(Mode::kTrueZ, Mode::kObserver, Mode::kNone)),
                         [](const auto& info) { return test_name(std::get<0>(info.param), std::get<1>(info.param)); });

}  // namespace
}  // namespace feeddrive::controller

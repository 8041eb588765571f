#pragma once
// Helpers of the controller tests: the model forces of Xie & Liang eq. 19 written out by hand
// from their formulas (deliberately not calling plant/forces.hpp, so the tests check the
// controller against the equations, not against the library's own force functions), and a
// closed loop on the CVODE plant in the order of sim::run.
#include <cmath>
#include <vector>

#include "feeddrive/controller/controller.hpp"
#include "feeddrive/plant/params.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::controller::test {

constexpr double kPi = 3.14159265358979323846;

/// Stribeck curve g(v) = Fc + (Fs - Fc)*exp(-|v/vs|^delta)  (Canudas de Wit 1995 eq. 3).
inline double hand_stribeck(const plant::FrictionParams& f, double v) {
  return f.coulomb_force + (f.static_force - f.coulomb_force) *
                               std::exp(-std::pow(std::abs(v / f.stribeck_velocity), f.stribeck_exponent));
}

/// LuGre force sigma0*z + sigma1*dz/dt + sigma2*v with dz/dt = v - sigma0*|v|*z/g(v)
/// (Canudas de Wit 1995 eqs. 1-2, constant sigma1).
inline double hand_lugre(const plant::FrictionParams& f, double v, double z) {
  const double zdot = v - f.bristle_stiffness * std::abs(v) * z / hand_stribeck(f, v);
  return f.bristle_stiffness * z + f.bristle_damping * zdot + f.viscous * v;
}

/// Cogging Fcog(x) = ac*sin(2 pi x/p + phi_c1) + bc*sin(6 pi x/p + phi_c3)  (eq. 15).
inline double hand_cogging(const plant::RippleParams& r, double x) {
  return r.cogging_amplitude * std::sin(2 * kPi * x / r.pitch + r.cogging_phase) +
         r.cogging_third * std::sin(6 * kPi * x / r.pitch + r.cogging_third_phase);
}

/// Relative reluctance ripple r(x) = af*sin(2 pi x/p + phi11) + bf*sin(6 pi x/p + phi12)  (eq. 14).
inline double hand_reluctance(const plant::RippleParams& r, double x) {
  return r.reluctance_amplitude * std::sin(2 * kPi * x / r.pitch + r.reluctance_phase) +
         r.reluctance_third * std::sin(6 * kPi * x / r.pitch + r.reluctance_third_phase);
}

/// A drive with nothing but its mass: m x'' = Ka*Kf*u.
inline plant::PlantParams pure_mass() {
  plant::PlantParams p;
  p.friction.model = plant::FrictionModel::kNone;
  p.ripple.enabled = false;
  p.grinding.enabled = false;
  return p;
}

/// One step of a closed-loop run.
struct LoopSample {
  double t{0.0};
  double xd{0.0}, vd{0.0};
  double x{0.0}, v{0.0};
  double u{0.0}, u_unsaturated{0.0}, sliding{0.0};
};

/// Runs reference -> controller -> CVODE plant for n steps of period T, in the order of
/// sim::run (measure at t_k, update, advance to t_{k+1} with u held). The controller gets the
/// plant's true z and Fg.
inline std::vector<LoopSample> run_loop(const plant::PlantParams& plant_params, Controller& c,
                                        const trajectory::Trajectory& ref, double period, long n) {
  plant::Plant drive(plant_params, period);
  std::vector<LoopSample> out;
  out.reserve(static_cast<std::size_t>(n));
  for (long k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * period;
    const trajectory::Sample r = ref.sample(t);
    const plant::Measurement m = drive.measure();
    const plant::State st = drive.state();
    const Truth truth{st.z, st.fg};
    const Command cmd = c.update(r, m, &truth);
    out.push_back({t, r.position, r.velocity, st.x, st.v, cmd.u, cmd.u_unsaturated, cmd.sliding});
    drive.advance(cmd.u, static_cast<double>(k + 1) * period);
  }
  return out;
}

/// max |xd - x| over the samples with t in [t0, t1].
inline double max_abs_error(const std::vector<LoopSample>& run, double t0, double t1) {
  double m = 0.0;
  for (const auto& s : run)
    if (s.t >= t0 && s.t <= t1) m = std::max(m, std::abs(s.xd - s.x));
  return m;
}

}  // namespace feeddrive::controller::test

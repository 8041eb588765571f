#pragma once
// The model along the measured motion (docs/fit.md, "Force residual").
//
// For a plant model p (plant::PlantParams, effects included) and a measured record, the filtered
// force residual at the filter bank's points tau_i is
//     r_i = m * A_i - Int h(tau_i - t) F_thrust(t) dt + Int h(tau_i - t) F_model(t) dt
// with A_i = Int h''(tau_i - t) x(t) dt (signals.hpp) and
//     F_model = F_friction(v^, z) + F_ripple(x^, F_thrust) + F_grinding(x^, Fg) + F_extra(x^, v^, F_thrust)
// evaluated at every interval midpoint. The internal states z (LuGre) and Fg (Hahn-Lindsay) are
// integrated along the measured velocity v^ exactly for v^ held over each half interval:
//     z(t+h)  = z_ss + (z - z_ss) exp(-sigma0 |v| h / g(v)),   z_ss = g(v) sgn(v)/sigma0
//     Fg(t+h) = Fg_ss + (Fg - Fg_ss) exp(-(ke/C) h),          Fg_ss = C v in contact, else 0.
// If the model were the drive, r_i would be the filtered measurement noise only: m x'' =
// F_thrust - F_model. An extra force F_x the model lacks shows as r_i = -(filtered F_x).
// The thrust is Ka*Kf*u (or the measured force_N), delayed by effects.input_delay if enabled;
// the optional R-L circuit is not modelled here (the fit assumes thrust follows u).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/signals.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {

/// Everything about a record that does not depend on the model.
struct Record {
  const MeasuredData* data{nullptr};
  Motion motion;
  FilterBank bank;
  Eigen::VectorXd input;  ///< input per interval (u or force), size n-1
  double period{0.0};     ///< median sample period [s]
  double x_min{0.0}, x_max{0.0};
  double v_max_abs{0.0}, a_max_abs{0.0};
  /// Filter points left out of the residual (set to 0): those whose window holds a stick phase
  /// of a static friction model, where friction balances the other forces and is not a
  /// function of v (see mask_stiction). Empty: none.
  std::vector<char> masked;
  long active_points() const;  ///< filter points not masked

  /// The filtered friction and grinding forces of the last model seen (force_residual).
  struct Cache {
    bool friction_valid{false}, grinding_valid{false};
    plant::FrictionParams friction;
    plant::GrindingParams grinding;
    double bristle0{0.0}, grinding0{0.0};
    Eigen::VectorXd friction_filtered, grinding_filtered;
    std::vector<double> z, fg;
  };
  std::shared_ptr<Cache> cache;
};

struct RecordOptions {
  double filter_half_width{0.0};  ///< L [s]; 0: max(10 ms, 10 sample periods)
  int motion_half_window{0};      ///< M samples; 0: about 2 ms worth, at least 3
};

/// Prepares a record (motion estimates, filter bank). Throws DataError if it is too short.
Record prepare(const MeasuredData& d, const RecordOptions& opt = {});

/// Below this |v^| [m/s] the drive counts as sticking: max(0.1 mm/s, 20 eps), eps the model's
/// Coulomb smoothing velocity (friction.static_smoothing_velocity).
double stick_velocity(const plant::PlantParams& model);

/// Masks the filter points whose window holds an interval with |v^| below stick_velocity() at
/// both ends (stiction): there a static friction (of the model or of a candidate effect) balances
/// the other forces and is not a function of v, so those windows cannot tell candidates apart.
/// The same points are masked for every candidate, so their BIC scores stay comparable.
void mask_stiction(Record& r, const plant::PlantParams& model);

/// Thrust [N] per unit of the record's input.
double thrust_per_input(const Record& r, const plant::PlantParams& p);

/// The internal states along the motion at every sample (for replay initial states).
struct Internal {
  std::vector<double> z, fg;
  Eigen::VectorXd unmasked;  ///< r_i at every filter point, the masked (sticking) ones included
};

/// r_i above, for model p. If internal != nullptr it receives z and Fg at the samples, and r
/// before the stiction mask.
Eigen::VectorXd force_residual(const Record& r, const plant::PlantParams& p, Internal* internal = nullptr);

}  // namespace feeddrive::fit

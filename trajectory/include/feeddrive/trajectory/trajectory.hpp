#pragma once
// Reference trajectories: each profile gives position, velocity, acceleration and jerk at any
// time t [s] (before its start it holds the start state, after its end the final state).
// Every parameter struct has defaults in place and one validate() that throws
// std::invalid_argument naming the bad field and value.

#include <memory>
#include <string>
#include <vector>

#include "feeddrive/common/fields.hpp"

namespace feeddrive::trajectory {

/// One sample of a reference.
struct Sample {
  double position{0.0};      ///< [m]
  double velocity{0.0};      ///< [m/s]
  double acceleration{0.0};  ///< [m/s^2]
  double jerk{0.0};          ///< [m/s^3]
};

/// A reference trajectory.
class Trajectory {
 public:
  virtual ~Trajectory() = default;
  virtual Sample sample(double t) const = 0;
  /// Time [s] after which the profile is constant (infinity for periodic or unbounded ones).
  virtual double end_time() const = 0;
};

/// x = offset + A*sin(2*pi*f*(t - t0) + phase) for t >= t0, analytic derivatives.
struct SineParams {
  double amplitude{0.1};   ///< A [m]
  double frequency{1.0};   ///< f [Hz]
  double phase{0.0};       ///< [rad]
  double offset{0.0};      ///< [m]
  double start_time{0.0};  ///< t0 [s]; before it the sample is the t0 value with zero derivatives
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(amplitude).unit("m").plausible(-2, 2, "mm"));
    a->Visit(FD_FIELD(frequency).unit("Hz").non_negative().plausible(0, 1000));
    a->Visit(FD_FIELD(phase).unit("rad").plausible(-7, 7, "deg"));
    a->Visit(FD_FIELD(offset).unit("m").plausible(-5, 5, "mm"));
    a->Visit(FD_FIELD(start_time).unit("s"));
  }
  void validate(const std::string& prefix = "reference") const;
};
std::unique_ptr<Trajectory> make_sine(const SineParams& p);

/// x = initial for t < t_step, initial + amplitude after; all derivatives 0 (the jump has no
/// derivative; Xie & Liang Fig. 19 is reproduced qualitatively only).
struct StepParams {
  double amplitude{0.1};  ///< [m]
  double step_time{1.0};  ///< [s]
  double initial{0.0};    ///< [m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(amplitude).unit("m").plausible(-5, 5, "mm"));
    a->Visit(FD_FIELD(step_time).unit("s"));
    a->Visit(FD_FIELD(initial).unit("m").plausible(-5, 5, "mm"));
  }
  void validate(const std::string& prefix = "reference") const;
};
std::unique_ptr<Trajectory> make_step(const StepParams& p);

/// The fields both rest-to-rest moves (acceleration- and jerk-limited) share, in one list:
/// distance (sign = direction) [m], max_velocity [m/s], max_acceleration [m/s^2].
template <class Archive>
void visit_move_limits(Archive* a, double& distance, double& max_velocity, double& max_acceleration) {
  a->Visit(FD_FIELD(distance).unit("m").plausible(-5, 5, "mm", "", "the travel of any linear feed drive"));
  a->Visit(
      FD_FIELD(max_velocity).unit("m/s").positive().at_most(1000).plausible(0, 10, "mm/s", "", "any linear drive"));
  a->Visit(FD_FIELD(max_acceleration)
               .unit("m/s^2")
               .positive()
               .at_most(1e5)
               .plausible(0, 500, "mm/s^2", "", "any linear drive"));
}

/// Acceleration-limited (bang-coast-bang) rest-to-rest move of `distance` (sign = direction)
/// with |v| <= max_velocity and |a| <= max_acceleration, time-optimal: a trapezoidal velocity
/// profile, or a triangle when max_velocity is not reached. Jerk is 0 (acceleration steps).
/// Default: Xie & Liang Fig. 20, 0.1 m in 1 s at 0.4 m/s^2 (triangle, v_peak = 0.2 m/s).
struct AccelLimitedParams {
  double distance{0.1};          ///< [m]
  double max_velocity{0.25};     ///< [m/s]
  double max_acceleration{0.4};  ///< [m/s^2]
  double start_time{0.0};        ///< [s]
  double initial{0.0};           ///< start position [m]
  template <class Archive>
  void Serialize(Archive* a) {
    visit_move_limits(a, distance, max_velocity, max_acceleration);
    a->Visit(FD_FIELD(start_time).unit("s"));
    a->Visit(FD_FIELD(initial).unit("m").plausible(-5, 5, "mm"));
  }
  void validate(const std::string& prefix = "reference") const;
};
std::unique_ptr<Trajectory> make_accel_limited(const AccelLimitedParams& p);

/// Jerk-limited 7-segment double-S rest-to-rest move (Biagiotti & Melchiorri 2008, Sec. 3.4),
/// time-optimal under |v| <= vmax, |a| <= amax, |j| <= jmax, in all four cases (vmax and amax
/// each reached or not). Default: D = 0.1 m, vmax 0.2 m/s, amax 1.15 m/s^2, jmax 2.4 m/s^3
/// (a 1.10 s move; see docs/paper-analysis.md Sec. 2.7 on the garbled paper values).
struct SCurveParams {
  double distance{0.1};           ///< [m]
  double max_velocity{0.2};       ///< [m/s]
  double max_acceleration{1.15};  ///< [m/s^2]
  double max_jerk{2.4};           ///< [m/s^3]
  double start_time{0.0};         ///< [s]
  double initial{0.0};            ///< [m]
  template <class Archive>
  void Serialize(Archive* a) {
    visit_move_limits(a, distance, max_velocity, max_acceleration);
    a->Visit(
        FD_FIELD(max_jerk).unit("m/s^3").positive().at_most(1e8).plausible(0, 1e5, "mm/s^3", "", "any linear drive"));
    a->Visit(FD_FIELD(start_time).unit("s"));
    a->Visit(FD_FIELD(initial).unit("m").plausible(-5, 5, "mm"));
  }
  void validate(const std::string& prefix = "reference") const;
};
/// The segment durations of a planned S-curve.
struct SCurvePlan {
  double t_jerk_accel{0.0};       ///< Tj1: duration of each jerk phase while accelerating [s]
  double t_accel{0.0};            ///< Ta: whole acceleration phase [s]
  double t_const{0.0};            ///< Tv: constant-velocity phase [s]
  double t_jerk_decel{0.0};       ///< Tj2 [s] (= Tj1 for rest-to-rest)
  double t_decel{0.0};            ///< Td [s] (= Ta for rest-to-rest)
  double peak_velocity{0.0};      ///< [m/s], magnitude
  double peak_acceleration{0.0};  ///< [m/s^2], magnitude
  double duration() const { return t_accel + t_const + t_decel; }
};
SCurvePlan plan_scurve(const SCurveParams& p);
std::unique_ptr<Trajectory> make_scurve(const SCurveParams& p);

/// Constant-velocity ramp: x = initial + velocity*(t - t0) for t >= t0 (Xie & Liang Fig. 23:
/// 1 um/s). The velocity steps at t0 (acceleration and jerk reported as 0).
struct RampParams {
  double velocity{1e-6};   ///< [m/s]
  double start_time{0.0};  ///< [s]
  double initial{0.0};     ///< [m]
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(velocity).unit("m/s").plausible(-10, 10, "mm/s", "", "any linear drive"));
    a->Visit(FD_FIELD(start_time).unit("s"));
    a->Visit(FD_FIELD(initial).unit("m").plausible(-5, 5, "mm"));
  }
  void validate(const std::string& prefix = "reference") const;
};
std::unique_ptr<Trajectory> make_ramp(const RampParams& p);

/// Waypoints (t_i, x_i), interpolated by a natural cubic spline (C2: position, velocity and
/// acceleration continuous, jerk piecewise constant). Held constant outside [t_0, t_n].
struct Waypoint {
  double t{0.0};
  double x{0.0};
};
/// (The scenario layer reads them from a CSV file with feeddrive::csv; this library reads no files.)
std::unique_ptr<Trajectory> make_waypoints(const std::vector<Waypoint>& points);

}  // namespace feeddrive::trajectory

// Jerk-limited 7-segment "double S" rest-to-rest move.
//
// Source: L. Biagiotti, C. Melchiorri, "Trajectory Planning for Automatic Machines and Robots",
// Springer 2008, Sec. 3.4 (trajectory with double S velocity profile), specialised to
// v0 = v1 = 0 (so Tj1 = Tj2 = Tj and Ta = Td), where every case has a closed form and the
// book's iterative reduction of amax is not needed.
//
// Plan, with D = |distance| > 0, limits vmax, amax, jmax (all > 0):
//   vmax reached? assume it:
//     if vmax*jmax >= amax^2:  Tj = amax/jmax,        Ta = Tj + vmax/amax   (amax reached)
//     else:                    Tj = sqrt(vmax/jmax),  Ta = 2 Tj             (amax not reached)
//     Tv = D/vmax - Ta;  if Tv >= 0 the assumption holds: v_lim = vmax.
//   otherwise (Tv < 0: vmax not reached), Tv = 0 and
//     Tj = amax/jmax,  Ta = Tj/2 + sqrt((Tj/2)^2 + D/amax);
//     if Ta >= 2 Tj:  amax reached:      a_lim = amax,     v_lim = amax (Ta - Tj)
//     else:           amax not reached:  Tj = (D/(2 jmax))^(1/3),  Ta = 2 Tj,
//                                        a_lim = jmax Tj,  v_lim = jmax Tj^2
//   T = 2 Ta + Tv, and always a_lim = jmax Tj, v_lim = a_lim (Ta - Tj), D = v_lim (Ta + Tv).
//
// Evaluation, acceleration phase, sigma in [0, Ta] (time since the start), j = jmax:
//   0 <= sigma < Tj:        x = j sigma^3/6,                       v = j sigma^2/2,
//                           a = j sigma,                           jerk = +j
//   Tj <= sigma < Ta - Tj:  x = a_lim (3 sigma (sigma - Tj) + Tj^2)/6,
//                           v = a_lim (sigma - Tj/2),  a = a_lim,  jerk = 0
//   Ta - Tj <= sigma < Ta:  with r = Ta - sigma:
//                           x = v_lim (Ta/2 - r) + j r^3/6,        v = v_lim - j r^2/2,
//                           a = j r,                               jerk = -j
// Constant velocity, Ta <= tau < Ta + Tv:  x = v_lim (tau - Ta/2), v = v_lim, a = jerk = 0.
// Deceleration, by the point symmetry of a rest-to-rest profile about (T/2, D/2), with
// s = T - tau (time to the end):  x = D - x_acc(s), v = v_acc(s), a = -a_acc(s),
// jerk = jerk_acc(s). Writing the last phase from the end makes x -> D exactly as t -> t0 + T
// (and for t >= t0 + T the sample is exactly initial + distance). Each piece is a cubic in a
// local time that starts at 0, so neighbouring pieces agree to rounding (~1e-16 relative).
// The sign of the distance multiplies x, v, a and jerk.

#include <cmath>
#include <memory>

#include "check.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

// Position, velocity, acceleration, jerk of the acceleration phase at sigma in [0, Ta], as
// magnitudes (positive direction). With right_closed the segments are (start, end] instead of
// [start, end): used for the mirrored deceleration phase, so that in forward time a switching
// instant always belongs to the segment that starts there.
Sample accel_phase(const SCurvePlan& plan, double jerk, double sigma, bool right_closed) {
  const double tj = plan.t_jerk_accel;
  const double ta = plan.t_accel;
  const double a_lim = plan.peak_acceleration;
  const double v_lim = plan.peak_velocity;
  const auto before = [right_closed](double s, double edge) { return right_closed ? s <= edge : s < edge; };
  if (before(sigma, tj)) {
    return {jerk * sigma * sigma * sigma / 6.0, 0.5 * jerk * sigma * sigma, jerk * sigma, jerk};
  }
  if (before(sigma, ta - tj)) {
    return {a_lim * (3.0 * sigma * (sigma - tj) + tj * tj) / 6.0, a_lim * (sigma - 0.5 * tj), a_lim, 0.0};
  }
  const double r = std::fmax(ta - sigma, 0.0);
  return {v_lim * (0.5 * ta - r) + jerk * r * r * r / 6.0, v_lim - 0.5 * jerk * r * r, jerk * r, -jerk};
}

class SCurve final : public Trajectory {
 public:
  explicit SCurve(const SCurveParams& p)
      : p_(p),
        plan_(plan_scurve(p)),
        sign_(p.distance < 0.0 ? -1.0 : 1.0),
        abs_distance_(std::abs(p.distance)),
        duration_(plan_.duration()),
        end_(p.start_time + duration_) {}

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.start_time) return {p_.initial, 0.0, 0.0, 0.0};
    if (t >= end_) return {p_.initial + p_.distance, 0.0, 0.0, 0.0};  // exact target
    const double tau = t - p_.start_time;
    Sample m;  // magnitudes, positive direction
    if (tau < plan_.t_accel) {
      m = accel_phase(plan_, p_.max_jerk, tau, false);
    } else if (tau < plan_.t_accel + plan_.t_const) {
      m = {plan_.peak_velocity * (tau - 0.5 * plan_.t_accel), plan_.peak_velocity, 0.0, 0.0};
    } else {
      // Clamp: rounding of t - t0 may put tau a hair beyond T, or s a hair beyond Ta.
      const double s = std::fmin(std::fmax(duration_ - tau, 0.0), plan_.t_decel);
      const Sample r = accel_phase(plan_, p_.max_jerk, s, true);
      m = {abs_distance_ - r.position, r.velocity, -r.acceleration, r.jerk};
    }
    return {p_.initial + sign_ * m.position, sign_ * m.velocity, sign_ * m.acceleration, sign_ * m.jerk};
  }
  double end_time() const override { return end_; }

 private:
  SCurveParams p_;
  SCurvePlan plan_;
  double sign_;          // direction of the move, +1 or -1
  double abs_distance_;  // D = |distance| [m]
  double duration_;      // T [s]
  double end_;           // t0 + T [s]
};

}  // namespace

SCurvePlan plan_scurve(const SCurveParams& p) {
  SCurvePlan plan;
  const double d = std::abs(p.distance);
  if (!(d > 0.0)) return plan;  // zero-length move: every duration 0
  const double vmax = p.max_velocity;
  const double amax = p.max_acceleration;
  const double jmax = p.max_jerk;

  // Assume vmax is reached.
  double tj = 0.0;
  double ta = 0.0;
  double a_lim = 0.0;
  if (vmax * jmax >= amax * amax) {
    tj = amax / jmax;
    ta = tj + vmax / amax;
    a_lim = amax;
  } else {
    tj = std::sqrt(vmax / jmax);
    ta = 2.0 * tj;
    a_lim = jmax * tj;
  }
  double tv = d / vmax - ta;
  double v_lim = vmax;

  if (tv < 0.0) {
    // vmax not reached: no cruise. Try with amax reached.
    tv = 0.0;
    tj = amax / jmax;
    const double half_tj = 0.5 * tj;
    ta = half_tj + std::sqrt(half_tj * half_tj + d / amax);
    if (ta >= 2.0 * tj) {
      a_lim = amax;
      v_lim = amax * (ta - tj);
    } else {
      // Neither vmax nor amax reached: a pure S (two jerk pulses per half).
      tj = std::cbrt(d / (2.0 * jmax));
      ta = 2.0 * tj;
      a_lim = jmax * tj;
      v_lim = a_lim * tj;
    }
  }

  plan.t_jerk_accel = tj;
  plan.t_accel = ta;
  plan.t_const = tv;
  plan.t_jerk_decel = tj;
  plan.t_decel = ta;
  plan.peak_velocity = v_lim;
  plan.peak_acceleration = a_lim;
  return plan;
}

std::unique_ptr<Trajectory> make_scurve(const SCurveParams& p) {
  p.validate();
  return std::make_unique<SCurve>(p);
}

}  // namespace feeddrive::trajectory

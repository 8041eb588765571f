// Sine, step, ramp and acceleration-limited references, and the validate() functions of every
// parameter struct (see docs/trajectories.md for the equations and the defaults' sources).
//
// Conventions shared by every profile here:
//  * Segments are half-open [start, end): at a switching instant the sample belongs to the
//    segment that starts there (the accel-limited default jumps +0.4 -> -0.4 m/s^2 AT t = 0.5 s).
//  * Before its start a profile returns its start state with zero derivatives; at and after
//    end_time() its final state with zero derivatives.
//  * sample(NaN) returns an all-NaN sample (a bad time is never silently clamped).

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "check.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::trajectory {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 2.0 * M_PI;

// ------------------------------------------------------------------------------------------
// Sine: x = offset + A sin(theta), theta = 2 pi f (t - t0) + phase, for t >= t0.
//   v = A w cos(theta), a = -A w^2 sin(theta), j = -A w^3 cos(theta), w = 2 pi f.
// For t < t0 the sample is x(t0) = offset + A sin(phase) with zero derivatives.
class Sine final : public Trajectory {
 public:
  explicit Sine(const SineParams& p) : p_(p), omega_(kTwoPi * p.frequency) {}

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.start_time) return {p_.offset + p_.amplitude * std::sin(p_.phase), 0.0, 0.0, 0.0};
    const double theta = omega_ * (t - p_.start_time) + p_.phase;
    const double s = std::sin(theta);
    const double c = std::cos(theta);
    const double aw = p_.amplitude * omega_;
    return {p_.offset + p_.amplitude * s, aw * c, -aw * omega_ * s, -aw * omega_ * omega_ * c};
  }

  // Periodic, hence never constant -- unless it is degenerate (f = 0 or A = 0).
  double end_time() const override { return (p_.frequency == 0.0 || p_.amplitude == 0.0) ? p_.start_time : kInfinity; }

 private:
  SineParams p_;
  double omega_;  // w = 2 pi f [rad/s]
};

// ------------------------------------------------------------------------------------------
// Step: x = initial for t < t_step, initial + amplitude for t >= t_step; derivatives all 0.
class Step final : public Trajectory {
 public:
  explicit Step(const StepParams& p) : p_(p) {}

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    return {t < p_.step_time ? p_.initial : p_.initial + p_.amplitude, 0.0, 0.0, 0.0};
  }
  double end_time() const override { return p_.step_time; }

 private:
  StepParams p_;
};

// ------------------------------------------------------------------------------------------
// Ramp: x = initial + V (t - t0) for t >= t0, x = initial before; v = V after t0, a = j = 0.
class Ramp final : public Trajectory {
 public:
  explicit Ramp(const RampParams& p) : p_(p) {}

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.start_time) return {p_.initial, 0.0, 0.0, 0.0};
    return {p_.initial + p_.velocity * (t - p_.start_time), p_.velocity, 0.0, 0.0};
  }
  // Unbounded, unless the velocity is 0 (a constant).
  double end_time() const override { return p_.velocity == 0.0 ? p_.start_time : kInfinity; }

 private:
  RampParams p_;
};

// ------------------------------------------------------------------------------------------
// Acceleration-limited rest-to-rest move (bang-coast-bang), time-optimal under |v| <= vmax,
// |a| <= amax (Biagiotti & Melchiorri 2008, Sec. 3.2, trajectory with trapezoidal velocity profile;
// the classic trapezoidal velocity profile). With D = |distance|:
//   if D >= vmax^2/amax (trapezoid): Ta = vmax/amax, Tv = D/vmax - Ta, v_peak = vmax;
//   else                 (triangle): Ta = sqrt(D/amax), Tv = 0,        v_peak = amax*Ta;
//   T = 2 Ta + Tv.
// With tau = t - t0 and s = T - tau (time to the end):
//   accel  0 <= tau < Ta:        x = amax tau^2/2,        v = amax tau,  a = +amax
//   cruise Ta <= tau < Ta + Tv:  x = v_peak (tau - Ta/2), v = v_peak,    a = 0
//   decel  Ta + Tv <= tau < T:   x = D - amax s^2/2,      v = amax s,    a = -amax
// The decel phase is written from the end, so x -> D exactly as t -> t0 + T; the sign of the
// distance multiplies x, v and a. Jerk is 0 (the acceleration steps).
struct AccelPlan {
  double t_accel{0.0};        // Ta [s] (= decel duration)
  double t_const{0.0};        // Tv [s]
  double peak_velocity{0.0};  // [m/s], magnitude
  double duration() const { return 2.0 * t_accel + t_const; }
};

AccelPlan plan_accel_limited(const AccelLimitedParams& p) {
  AccelPlan plan;
  const double d = std::abs(p.distance);
  if (d == 0.0) return plan;  // zero-length move: T = 0
  const double t_const = d / p.max_velocity - p.max_velocity / p.max_acceleration;
  if (t_const > 0.0) {
    plan.t_accel = p.max_velocity / p.max_acceleration;
    plan.t_const = t_const;
    plan.peak_velocity = p.max_velocity;
  } else {
    plan.t_accel = std::sqrt(d / p.max_acceleration);
    plan.peak_velocity = p.max_acceleration * plan.t_accel;
  }
  return plan;
}

class AccelLimited final : public Trajectory {
 public:
  explicit AccelLimited(const AccelLimitedParams& p)
      : p_(p),
        plan_(plan_accel_limited(p)),
        sign_(p.distance < 0.0 ? -1.0 : 1.0),
        abs_distance_(std::abs(p.distance)),
        end_(p.start_time + plan_.duration()) {}

  Sample sample(double t) const override {
    if (std::isnan(t)) return detail::nan_sample();
    if (t < p_.start_time) return {p_.initial, 0.0, 0.0, 0.0};
    if (t >= end_) return {p_.initial + p_.distance, 0.0, 0.0, 0.0};  // exact target
    const double ta = plan_.t_accel;
    const double amax = p_.max_acceleration;
    const double tau = t - p_.start_time;
    double x = 0.0;
    double v = 0.0;
    double a = 0.0;
    if (tau < ta) {
      x = 0.5 * amax * tau * tau;
      v = amax * tau;
      a = amax;
    } else if (tau < ta + plan_.t_const) {
      x = plan_.peak_velocity * (tau - 0.5 * ta);
      v = plan_.peak_velocity;
    } else {
      // Clamp: rounding of t - t0 may put tau a hair beyond T (or s beyond Ta).
      const double s = std::fmin(std::fmax(plan_.duration() - tau, 0.0), ta);
      x = abs_distance_ - 0.5 * amax * s * s;
      v = amax * s;
      a = -amax;
    }
    return {p_.initial + sign_ * x, sign_ * v, sign_ * a, 0.0};
  }
  double end_time() const override { return end_; }

 private:
  AccelLimitedParams p_;
  AccelPlan plan_;
  double sign_;          // direction of the move, +1 or -1
  double abs_distance_;  // D = |distance| [m]
  double end_;           // t0 + T [s]
};

// A planned move must end at a finite time (huge distance over tiny limits can overflow).
void require_finite_end(const std::string& prefix, double distance, double start_time, double duration) {
  if (!std::isfinite(duration) || !std::isfinite(start_time + duration))
    detail::fail(prefix + ".distance", distance,
                 "the move's duration overflows for these limits (" + detail::format_number(duration) + " s)");
}

}  // namespace

// ------------------------------------------------------------------------------------------
// validate(): every number must be finite; limits must be > 0; a frequency must be >= 0.

void SineParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

void StepParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

void AccelLimitedParams::validate(const std::string& prefix) const {
  fields::check_fields(*this, prefix);
  if (!std::isfinite(initial + distance)) detail::fail(prefix + ".distance", distance, "initial + distance overflows");
  require_finite_end(prefix, distance, start_time, plan_accel_limited(*this).duration());
}

void SCurveParams::validate(const std::string& prefix) const {
  fields::check_fields(*this, prefix);
  if (!std::isfinite(initial + distance)) detail::fail(prefix + ".distance", distance, "initial + distance overflows");
  require_finite_end(prefix, distance, start_time, plan_scurve(*this).duration());
}

void RampParams::validate(const std::string& prefix) const { fields::check_fields(*this, prefix); }

// ------------------------------------------------------------------------------------------

std::unique_ptr<Trajectory> make_sine(const SineParams& p) {
  p.validate();
  return std::make_unique<Sine>(p);
}

std::unique_ptr<Trajectory> make_step(const StepParams& p) {
  p.validate();
  return std::make_unique<Step>(p);
}

std::unique_ptr<Trajectory> make_accel_limited(const AccelLimitedParams& p) {
  p.validate();
  return std::make_unique<AccelLimited>(p);
}

std::unique_ptr<Trajectory> make_ramp(const RampParams& p) {
  p.validate();
  return std::make_unique<Ramp>(p);
}

}  // namespace feeddrive::trajectory

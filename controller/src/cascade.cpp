#include "feeddrive/controller/cascade.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "check.hpp"

namespace feeddrive::controller {

double saturate(double u, double lo, double hi) {
  if (std::isnan(u)) return 0.0;
  return std::clamp(u, lo, hi);
}

void CascadeParams::validate(const std::string& prefix) const {
  using namespace detail;
  fields::check_fields(*this, prefix);  // the list's ranges (cascade.hpp)
  require_non_negative(prefix + ".model.sensor.quantization", quantization);
  require_non_negative(prefix + ".computation_delay", computation_delay);
  if (adaptation_rate > 0.0 && !(disturbance_observer_bandwidth > 0.0))
    fail(prefix + ".adaptation_rate", adaptation_rate,
         "needs disturbance_observer_bandwidth > 0 (the residual d^ of the observer)");
  if (adaptation_rate > 0.0 && !friction_feedforward)
    fail(prefix + ".adaptation_rate", adaptation_rate,
         "needs friction_feedforward: true (the level scales the model friction, whose bristles gate the "
         "learning; without it it never acts)");
  if (motion_state == MotionSource::kObserver && !(disturbance_observer_bandwidth > 0.0))
    throw std::invalid_argument(prefix +
                                ".motion_state = observer: needs disturbance_observer_bandwidth > 0 (the observer)");
  require_positive(prefix + ".model.mass", mass);
  require_positive(prefix + ".model.thrust_gain", thrust_gain);
  if (friction_feedforward) friction.validate(prefix + ".model.friction");
  require_range(prefix, u_min, u_max);
  require_positive(prefix + ".period", period);
  require_adaptation_stable(prefix + ".adaptation_rate", adaptation_rate, period);
}

void apply_tuning(CascadeParams& p, bool differenced_velocity) {
  if (p.tuning != CascadeTuning::kRule) return;
  const bool observer = p.motion_state == MotionSource::kObserver;
  const double delay = observer && p.compensate_delay ? 0.0 : p.computation_delay;
  const double lag =
      p.velocity_filter_cutoff > 0.0 ? 1.0 / (2.0 * 3.14159265358979323846 * p.velocity_filter_cutoff) : 0.0;
  const CascadeGains g = cascade_tuning(p.period, delay, differenced_velocity && !observer, p.bandwidth_scale, lag);
  p.kp = g.kp;
  p.kv = g.kv;
  p.ki = g.ki;
}

CascadeGains cascade_tuning(double period, double computation_delay, bool differenced_velocity, double scale,
                            double extra_lag) {
  const double tau = computation_delay + 0.5 * period + (differenced_velocity ? 0.5 * period : 0.0) + extra_lag;
  const double pi = 3.14159265358979323846;
  const double wv = scale * (pi / 4.0 - std::atan(0.25)) / tau;
  const double kv = wv / std::sqrt(1.0 + 1.0 / 16.0);
  return {wv / 4.0, kv, kv * wv / 4.0};
}

CascadeController::CascadeController(const CascadeParams& p)
    : p_((p.validate("controller"), p)),
      friction_ff_(p.friction, p.period, 0.0),
      observer_(p.disturbance_observer_bandwidth > 0.0 ? p.disturbance_observer_bandwidth : 1.0, p.period, true,
                p.quantization),
      delay_line_(p.compensate_delay ? p.computation_delay : 0.0, 1e-9 * p.period),
      adaptation_(p.disturbance_observer_bandwidth > 0.0 ? p.adaptation_rate : 0.0, p.period, p.friction.coulomb_force),
      velocity_filter_gain_(p.velocity_filter_cutoff > 0.0
                                ? -std::expm1(-2.0 * 3.14159265358979323846 * p.velocity_filter_cutoff * p.period)
                                : 1.0) {}

double CascadeController::filter_velocity(double v) {
  if (!std::isfinite(v)) return v;  // a non-finite sample is not kept (saturate() gives u = 0)
  if (!v_filter_started_) {
    v_filtered_ = v;
    v_filter_started_ = true;
  } else {
    v_filtered_ += velocity_filter_gain_ * (v - v_filtered_);
  }
  return v_filtered_;
}

Command CascadeController::update(const trajectory::Sample& ref_now, const plant::Measurement& meas,
                                  const Truth* /*truth*/) {
  const bool delayed = p_.compensate_delay && p_.computation_delay > 0.0 && std::isfinite(meas.t);
  // The feedforward forces are for when the command acts (t_k + d): "feedforward with preview".
  const trajectory::Sample ahead = delayed ? preview(ref_now, p_.computation_delay) : ref_now;
  const bool dob = p_.disturbance_observer_bandwidth > 0.0;
  if (dob) observer_.correct(meas.x, meas.v);
  const double d_hat = dob && observer_.initialised() ? observer_.disturbance() : 0.0;
  // The adapted feedforward (cascade.hpp): the friction at the adapted level, the inertial force.
  const bool adapt = adaptation_.enabled() && observer_.initialised();
  if (adapt) friction_ff_.set_level(adaptation_.friction_level());
  const double f_model = p_.friction_feedforward ? friction_ff_.estimate(ahead.velocity) : 0.0;
  const double inertial = p_.mass * ahead.acceleration;
  const double f_ff = f_model + (adapt ? adaptation_.inertial_force(inertial) : 0.0);
  // Model: m^*x'' = Ka*Kf*u_acting - F^f_ff (held over the period); d^ takes up the rest.
  const auto model_acceleration = [&](double u) { return (p_.thrust_gain * u - f_ff) / p_.mass; };

  // The state and reference the feedback acts on: the measurement and the reference now, or the
  // observer's estimate (predicted to t_k + d with the reference previewed there).
  double x = meas.x;
  double v = meas.v;
  trajectory::Sample ref = ref_now;
  if (p_.motion_state == MotionSource::kObserver && dob && observer_.initialised()) {
    x = observer_.position();
    v = observer_.velocity();
    if (delayed) {
      for (const DelayLine::Piece& piece : delay_line_.pieces(meas.t, meas.t + p_.computation_delay)) {
        const double tau = piece.t1 - piece.t0;
        const double a = model_acceleration(piece.u) + d_hat;
        x += v * tau + 0.5 * a * tau * tau;
        v += a * tau;
      }
      ref = ahead;
    }
  }
  v = filter_velocity(v);

  const double v_cmd = p_.velocity_feedforward * ref.velocity + p_.kp * (ref.position - x);
  const double ev = v_cmd - v;
  const double force =
      p_.mass * (p_.kv * ev + p_.ki * integral_ + p_.acceleration_feedforward * ahead.acceleration - d_hat) + f_ff;
  Command cmd;
  cmd.u_unsaturated = force / p_.thrust_gain;
  cmd.u = saturate(cmd.u_unsaturated, p_.u_min, p_.u_max);
  // Conditional integration: integrate unless saturated and the error would push further out.
  const bool high = cmd.u_unsaturated > p_.u_max && ev > 0.0;
  const bool low = cmd.u_unsaturated < p_.u_min && ev < 0.0;
  if (!high && !low) integral_ += ev * p_.period;

  if (p_.friction_feedforward) friction_ff_.advance(ahead.velocity, 0.0);
  if (dob && observer_.initialised()) {
    if (delayed) {
      delay_line_.push(meas.t, cmd.u);
      const double t_end = meas.t + p_.period;
      const DelayLine::Increments inc = delay_line_.increments(meas.t, t_end, model_acceleration);
      observer_.predict_increments(inc.dv, inc.dx);
      delay_line_.forget_before(t_end);
    } else {
      observer_.predict(model_acceleration(cmd.u));
    }
  }
  // Learn in sliding only (feedforward_adaptation.hpp); the bristles here follow the reference.
  if (adapt && friction_ff_.transient(ahead.velocity) < kAdaptationTransient)
    adaptation_.update(-p_.mass * d_hat, f_model, inertial);
  return cmd;
}

}  // namespace feeddrive::controller

#include "feeddrive/plant/plant.hpp"

namespace feeddrive::plant {
namespace {
StateVector initial_vector(const PlantParams& p) {
  return State{p.initial.position, p.initial.velocity, p.initial.bristle, p.initial.grinding, p.initial.current}
      .to_vector();
}
}  // namespace

Plant::Plant(const PlantParams& params, double period, double t0)
    : params_((params.validate(), params)),
      effective_(params_),
      integrator_(params_, t0, initial_vector(params_)),
      sensor_(params_.sensor, period),
      delayed_(params_.effects.input_delay.enabled),
      delay_(params_.effects.input_delay.delay),
      // A switch t_j + d computed in floating point may miss the period boundary it equals
      // (e.g. d = 2T) by a few ulps; 1e-9 T is far above that and far below any step CVODE takes,
      // and it avoids restarting CVODE for an interval of a few ulps.
      snap_(1e-9 * period) {}

Measurement Plant::measure() {
  const State s = state();
  return sensor_.sample(time(), s.x, s.v);
}

Forces Plant::forces(double u) const {
  // The command u issued now acts now only if the delay is (within snap_) zero.
  const double acting = !delayed_ || delay_ <= snap_ ? u : delayed_input(time());
  return plant::forces(effective_, state(), acting);
}

void Plant::advance(double u, double t_next) {
  if (!delayed_) {
    integrator_.advance(u, t_next);
    return;
  }
  advance_delayed(u, t_next);
}

double Plant::delayed_input(double tau) const {
  double u = 0.0;
  for (const HeldCommand& c : history_) {
    if (c.t + delay_ > tau + snap_) break;
    u = c.u;
  }
  return u;
}

void Plant::advance_delayed(double u, double t_next) {
  if (!(t_next > time())) {  // nothing to integrate (or an error the integrator reports)
    integrator_.advance(u, t_next);
    return;
  }
  history_.push_back({time(), u});
  // Piecewise: from t, hold u_d(t) until the next switch t_j + d inside (t, t_next), restart
  // there. Each piece ends at t_next or at a switch > t + snap_, so the loop ends.
  do {
    const double t = time();
    double u_now = 0.0;
    double t_end = t_next;
    for (const HeldCommand& c : history_) {
      const double t_switch = c.t + delay_;
      if (t_switch <= t + snap_) {
        u_now = c.u;
      } else {
        if (t_switch < t_next - snap_) t_end = t_switch;
        break;
      }
    }
    integrator_.advance(u_now, t_end);
  } while (time() != t_next);
  // Commands followed by one that already acts at t_next are no longer needed.
  while (history_.size() >= 2 && history_[1].t + delay_ <= t_next + snap_) history_.pop_front();
}

void Plant::prime_input_history(const std::vector<std::pair<double, double>>& commands) {
  if (!delayed_) return;
  for (const auto& [t, u] : commands) history_.push_back({t, u});
}

}  // namespace feeddrive::plant

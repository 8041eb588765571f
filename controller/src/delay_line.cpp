#include "feeddrive/controller/delay_line.hpp"

namespace feeddrive::controller {

DelayLine::DelayLine(double delay, double snap) : delay_(delay), snap_(snap) {}

void DelayLine::push(double t, double u) { issued_.push_back({t, u}); }

std::vector<DelayLine::Piece> DelayLine::pieces(double t0, double t1) const {
  std::vector<Piece> out;
  double t = t0;
  double u = 0.0;  // before the first command acts
  std::size_t j = 0;
  // The command acting at t0: the last one whose switch time is <= t0 (within snap).
  while (j < issued_.size() && issued_[j].t + delay_ <= t + snap_) u = issued_[j++].u;
  while (t < t1) {
    double end = t1;
    if (j < issued_.size() && issued_[j].t + delay_ < t1 - snap_) end = issued_[j].t + delay_;
    out.push_back({t, end, u});
    t = end;
    if (end < t1) u = issued_[j++].u;
  }
  return out;
}

DelayLine::Increments DelayLine::increments(double t0, double t1,
                                            const std::function<double(double)>& acceleration) const {
  Increments out;
  for (const Piece& piece : pieces(t0, t1)) {
    const double tau = piece.t1 - piece.t0;
    const double a = acceleration(piece.u);
    out.dv += a * tau;
    out.dx += a * tau * (0.5 * tau + (t1 - piece.t1));
  }
  return out;
}

void DelayLine::forget_before(double t) {
  // Keep the last command acting at t and everything after it.
  while (issued_.size() >= 2 && issued_[1].t + delay_ <= t + snap_) issued_.pop_front();
}

trajectory::Sample preview(const trajectory::Sample& s, double h) {
  trajectory::Sample p;
  p.position = s.position + h * (s.velocity + h * (0.5 * s.acceleration + h * s.jerk / 6.0));
  p.velocity = s.velocity + h * (s.acceleration + 0.5 * h * s.jerk);
  p.acceleration = s.acceleration + h * s.jerk;
  p.jerk = s.jerk;
  return p;
}

}  // namespace feeddrive::controller

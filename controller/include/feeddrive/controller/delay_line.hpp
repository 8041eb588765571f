#pragma once
// The controller's record of its own commands under a known computation delay d: the command
// computed from the sample at t_j acts over [t_j + d, t_{j+1} + d) (zero before the first one
// acts). The plant applies the same timing (plant.hpp, input_delay); this is the controller's
// copy, which it needs to predict its own state over the delay (a Smith-predictor style model
// prediction, Smith 1957; Astrom & Hagglund 2006, Sec. 7.8).
//
// pieces(t0, t1) splits [t0, t1] at the switch times t_j + d inside it and gives the command
// acting on each piece; a switch within `snap` of a piece's end is taken as that end (the
// plant's rule: floating-point t_j + d may miss a period boundary by a few ulps).

#include <deque>
#include <functional>
#include <vector>

#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::controller {

class DelayLine {
 public:
  struct Piece {
    double t0, t1;  ///< [s]
    double u;       ///< the command acting over [t0, t1) [V]
  };
  /// delay: d [s] (>= 0); snap: switch-time tolerance [s].
  DelayLine(double delay, double snap);

  /// Records the command issued at t (times strictly increasing).
  void push(double t, double u);
  /// The pieces of [t0, t1] with their acting command.
  std::vector<Piece> pieces(double t0, double t1) const;
  /// The velocity and position increments over [t0, t1] of the model acceleration a(u) of the
  /// command acting on each piece (piecewise constant: the double integral of a piecewise-constant
  /// acceleration):  dv = sum_i a_i*tau_i,  dx = sum_i a_i*tau_i*(tau_i/2 + (t1 - t1_i)), with
  /// tau_i = t1_i - t0_i the length of piece i. What StateObserver::predict_increments takes.
  struct Increments {
    double dv = 0.0;  ///< [m/s]
    double dx = 0.0;  ///< [m]
  };
  Increments increments(double t0, double t1, const std::function<double(double)>& acceleration) const;
  /// Drops the commands that no longer act at or after t.
  void forget_before(double t);
  double delay() const { return delay_; }

 private:
  struct Issued {
    double t, u;
  };
  double delay_;
  double snap_;
  std::deque<Issued> issued_;
};

/// The reference previewed by h [s] from its sample at t, by its Taylor expansion with the jerk
/// held:  xd(t+h) = xd + vd*h + ad*h^2/2 + jd*h^3/6,  vd(t+h) = vd + ad*h + jd*h^2/2,
///        ad(t+h) = ad + jd*h.
/// Exact within a polynomial segment of degree <= 3 (every profile of trajectory/ between its
/// switch points); across a jerk switch the error is at most dj*h^3/6 in position (0.8 nm for
/// the jerk-limited move's dj = 4.8 m/s^3 at h = 1 ms). It needs only the sample, so it works
/// with any trajectory source, including the LCM trajectory process.
trajectory::Sample preview(const trajectory::Sample& s, double h);

}  // namespace feeddrive::controller

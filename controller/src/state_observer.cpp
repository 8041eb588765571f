#include "feeddrive/controller/state_observer.hpp"

#include <cmath>
#include <stdexcept>

#include "feeddrive/common/fields.hpp"

namespace feeddrive::controller {

std::string to_string(MotionSource s) { return fields::enum_name(s); }

StateObserver::StateObserver(double bandwidth, double period, bool with_disturbance, double quantization)
    : period_(period), half_cell_(0.5 * quantization) {
  const double p = std::exp(-bandwidth * period);
  const double q = 1.0 - p;
  if (with_disturbance) {
    l1_ = 1.0 - p * p * p;
    l2_ = 1.5 * q * q * (1.0 + p) / period;
    l3_ = q * q * q / (period * period);
  } else {
    l1_ = 1.0 - p * p;
    l2_ = q * q / period;
    l3_ = 0.0;
  }
}

void StateObserver::correct(double x_measured, double v0) {
  // A non-finite sample carries no information: skip the correction (coast on the prediction),
  // or stay uninitialised until the first finite sample.
  if (!std::isfinite(x_measured)) return;
  if (!initialised_) {
    x_ = x_measured;
    v_ = std::isfinite(v0) ? v0 : 0.0;
    d_ = 0.0;
    initialised_ = true;
    return;
  }
  const double lo = x_measured - half_cell_;
  const double hi = x_measured + half_cell_;
  const double r = x_ < lo ? lo - x_ : (x_ > hi ? hi - x_ : 0.0);
  x_ += l1_ * r;
  v_ += l2_ * r;
  d_ += l3_ * r;
}

void StateObserver::predict(double a) {
  const double total = a + d_;
  x_ += v_ * period_ + 0.5 * total * period_ * period_;
  v_ += total * period_;
}

void StateObserver::predict_increments(double dv, double dx) {
  x_ += v_ * period_ + dx + 0.5 * d_ * period_ * period_;
  v_ += dv + d_ * period_;
}

}  // namespace feeddrive::controller

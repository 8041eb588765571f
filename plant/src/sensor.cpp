#include "feeddrive/plant/sensor.hpp"

#include <cmath>

namespace feeddrive::plant {

Sensor::Sensor(const SensorParams& params, double period)
    : params_(params),
      period_(period),
      difference_velocity_(params.differenced_velocity()),
      rng_(params.seed),
      noise_(0.0, 1.0) {}

Measurement Sensor::sample(double t, double x, double v) {
  double xm = x;
  if (params_.noise_stddev > 0.0) xm += params_.noise_stddev * noise_(rng_);
  if (params_.quantization > 0.0) xm = params_.quantization * std::round(xm / params_.quantization);
  double vm = v;
  if (difference_velocity_) {
    vm = last_x_ ? (xm - *last_x_) / period_ : 0.0;
  }
  last_x_ = xm;
  return {t, xm, vm};
}

}  // namespace feeddrive::plant

#pragma once
// Encoder model: quantization and seeded Gaussian noise on the measured position.
//   x_meas[k] = q * round((x(t_k) + n_k) / q),  n_k ~ N(0, sigma^2)   (q = 0: no rounding)
//   v_meas[k] = v(t_k)                              ("true")
//             = (x_meas[k] - x_meas[k-1]) / T       ("difference"; v_meas[0] = 0)
// Controllers see only Measurement, never the true state.

#include <optional>
#include <random>

#include "feeddrive/plant/params.hpp"

namespace feeddrive::plant {

/// What a controller may see of the drive at one sample instant.
struct Measurement {
  double t{0.0};  ///< sample time [s]
  double x{0.0};  ///< measured position [m]
  double v{0.0};  ///< measured velocity [m/s]
};

class Sensor {
 public:
  /// period: the sample period T [s] used by the "difference" velocity.
  Sensor(const SensorParams& params, double period);

  /// Samples the sensor at time t for true position x and velocity v. Call once per period:
  /// it draws from the noise generator and remembers x_meas for the difference velocity.
  Measurement sample(double t, double x, double v);

 private:
  SensorParams params_;
  double period_;
  bool difference_velocity_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_;
  std::optional<double> last_x_;
};

}  // namespace feeddrive::plant

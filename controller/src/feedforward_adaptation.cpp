#include "feeddrive/controller/feedforward_adaptation.hpp"

#include <algorithm>
#include <cmath>

namespace feeddrive::controller {

FeedforwardAdaptation::FeedforwardAdaptation(double rate, double period, double force_scale)
    : rate_(rate), period_(period), force_scale_(force_scale > 0.0 ? force_scale : 1.0) {}

void FeedforwardAdaptation::update(double residual, double friction, double inertial) {
  if (!enabled()) return;
  if (!std::isfinite(residual) || !std::isfinite(friction) || !std::isfinite(inertial)) return;
  // Normalised gradient step (feedforward_adaptation.hpp): phi = [F^f/theta, m^*xd''].
  const double phi_f = friction / theta_;
  const double norm = force_scale_ * force_scale_ + phi_f * phi_f + inertial * inertial;
  const double step = rate_ * period_ * residual / norm;
  theta_ = std::clamp(theta_ + step * phi_f, 0.2, 3.0);
  delta_m_ = std::clamp(delta_m_ + step * inertial, -0.5, 1.0);
}

}  // namespace feeddrive::controller

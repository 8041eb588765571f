#include "feeddrive/plant/plant.hpp"

namespace feeddrive::plant {
namespace {
StateVector initial_vector(const PlantParams& p) {
  return State{p.initial.position, p.initial.velocity, p.initial.bristle, p.initial.grinding,
               p.initial.current}
      .to_vector();
}
}  // namespace

Plant::Plant(const PlantParams& params, double period, double t0)
    : params_((params.validate(), params)),
      integrator_(params_, t0, initial_vector(params_)),
      sensor_(params_.sensor, period) {}

Measurement Plant::measure() {
  const State s = state();
  return sensor_.sample(time(), s.x, s.v);
}

Forces Plant::forces(double u) const { return plant::forces(params_, state(), u); }

void Plant::advance(double u, double t_next) { integrator_.advance(u, t_next); }

}  // namespace feeddrive::plant

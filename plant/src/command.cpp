#include "feeddrive/plant/command.hpp"

#include <cmath>

namespace feeddrive::plant {

AdmittedCommand admit_command(double u, double input_limit, double fallback) {
  if (!std::isfinite(u)) return {fallback, CommandStatus::kRejected};
  if (u > input_limit) return {input_limit, CommandStatus::kSaturated};
  if (u < -input_limit) return {-input_limit, CommandStatus::kSaturated};
  return {u, CommandStatus::kApplied};
}

}  // namespace feeddrive::plant

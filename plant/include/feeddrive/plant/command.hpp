#pragma once
// What a drive does with a command before applying it. A real amplifier must never apply a
// NaN or infinite input, and clips at its input range:
//   u not finite        -> rejected: the fallback is applied instead (0 V in lockstep)
//   |u| > input_limit   -> saturated to +-input_limit
//   otherwise           -> applied as is
// Used by the in-process simulator and by the plant process, so both apply the same thing.

namespace feeddrive::plant {

enum class CommandStatus { kApplied, kSaturated, kRejected };

struct AdmittedCommand {
  double u{0.0};  ///< the input actually applied [V]
  CommandStatus status{CommandStatus::kApplied};
};

AdmittedCommand admit_command(double u, double input_limit, double fallback = 0.0);

}  // namespace feeddrive::plant

#pragma once
// The exit codes of every tool and the base of the typed errors that are the input's fault.
// What maps an error to its exit code and its one line is feeddrive::tool::report
// (common/tool/, the only place that does; docs/cli.md lists the codes).

#include <stdexcept>

namespace feeddrive {

inline constexpr int kExitOk = 0;        ///< done
inline constexpr int kExitFailed = 1;    ///< the run failed (not the input's fault)
inline constexpr int kExitBadInput = 2;  ///< bad input: one line naming the key or line and the value
// 3: feeddrive-fit's unexplained discrepancy (fit::kExitUnexplained); 128 + signal: interrupted.

/// An error that is the input's fault (a scenario key, a data line, a model that cannot be
/// integrated, a study file): exit 2. sim::ScenarioError, plant::IntegrationError,
/// fit::DataError and study::StudyError derive from it; std::invalid_argument counts as one too.
class BadInput : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace feeddrive

#pragma once
// The controller process: any feeddrive::controller::Controller behind the message contract.
// Answers drive_state_t k with control_command_t k once reference_t k is known; answers a
// repeated state with the same command (a controller is stateful: it is never run twice for a
// step); asks for a missing reference on <prefix>_RESEND. In real-time mode the plant does not
// wait, so the controller always answers the newest state it has.

#include <map>
#include <memory>
#include <optional>
#include <set>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/controller/controller.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/service/node.hpp"

namespace feeddrive::service {

class ControllerNode : public Node {
 public:
  /// `shared_lcm`: see Node (in-process tests); nullptr in the process.
  ControllerNode(std::unique_ptr<controller::Controller> c, const NodeOptions& opt, lcm_t* shared_lcm = nullptr);
  void run();

 private:
  void try_answer();

  std::unique_ptr<controller::Controller> controller_;
  Outbox<control_command_t> commands_;
  std::optional<drive_state_t> pending_;  ///< newest unanswered state
  std::int64_t pending_since_us_{0};
  std::int64_t last_ref_request_us_{0};
  std::map<std::int64_t, reference_t> refs_;
  StepLedger<drive_state_t> state_ledger_;    ///< every state received, for conflicts
  StepLedger<reference_t> reference_ledger_;  ///< every reference received, for conflicts
  std::int64_t next_seq_{0};                  ///< first step not answered yet
  /// Steps >= next_seq_ for which a command of another publisher was seen on the command channel
  /// (a forged or stray answer: the plant may then move on without this controller's command).
  std::set<std::int64_t> answered_by_others_;
  /// A state of this run was heard: from then on a state beyond next_seq_ is a skip, not a late join.
  bool heard_state_{false};
  std::int64_t last_progress_us_{0};
  bool end_{false};
};

}  // namespace feeddrive::service

#pragma once
// The reference-generator process: a feeddrive::trajectory::Trajectory behind the message
// contract. Publishes the references in aligned blocks of kBlock steps (reference_block_t),
// always at least half a block ahead of the newest state, so a reference is never on a step's
// critical path; re-publishes the block(s) covering state k when state k is repeated, and any
// block asked for on <prefix>_RESEND.

#include <memory>
#include <set>

#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/service/node.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/trajectory/trajectory.hpp"

namespace feeddrive::service {

class TrajectoryNode : public Node {
 public:
  static constexpr std::int64_t kBlock = 16;
  TrajectoryNode(const sim::Scenario& s, const NodeOptions& opt);
  void run();

 private:
  /// Publishes block b (steps b*kBlock ..) unless sent already; resend = publish again.
  void send_block(std::int64_t b, bool resend);

  sim::Scenario s_;
  std::unique_ptr<trajectory::Trajectory> reference_;
  Outbox<reference_block_t> blocks_;
  std::int64_t highest_state_{-1};
  std::int64_t last_progress_us_{0};
  bool end_{false};
};

}  // namespace feeddrive::service

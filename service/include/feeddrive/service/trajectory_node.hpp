#pragma once
// The reference-generator process: a feeddrive::trajectory::Trajectory behind the message
// contract. Publishes the references in aligned blocks of kBlock steps (reference_block_t),
// kLead steps ahead of the newest state it has seen, so a reference is never on a step's
// critical path although the trajectory reads the bus in batches (Receive::kBatched, every
// millisecond: 256 steps cover 10 ms at 25,000 steps/s); re-publishes the block(s) covering
// state k when state k is repeated, and on a request on <prefix>_RESEND for step k, the
// block of k and the later blocks already published, up to kLead steps (a late or overflowed
// subscriber lacks them all).

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
  static constexpr std::int64_t kLead = 256;
  /// `shared_lcm`: see Node (in-process tests); nullptr in the process.
  TrajectoryNode(const sim::Scenario& s, const NodeOptions& opt, lcm_t* shared_lcm = nullptr);
  void run();

 private:
  /// Publishes block b (steps b*kBlock ..) unless sent already; resend = publish again.
  void send_block(std::int64_t b, bool resend);
  /// Publishes every block not yet sent up to step k + kLead.
  void send_ahead(std::int64_t k);

  sim::Scenario s_;
  std::unique_ptr<trajectory::Trajectory> reference_;
  Outbox<reference_block_t> blocks_;
  std::int64_t highest_state_{-1};
  StepLedger<drive_state_t> state_ledger_;  ///< every state received, for conflicts
  std::int64_t next_block_{0};              ///< the first block not yet published
  std::int64_t last_progress_us_{0};
  bool end_{false};
};

}  // namespace feeddrive::service

// The reference generator's protocol over memq:// (trajectory_node.hpp): blocks of 16
// references, at most 256 steps ahead of the newest state seen; a repeated state or a resend
// request re-publishes the blocks; joining the run from the plant's heartbeat; conflicts,
// foreign states and the timeouts that name the plant. A scripted plant publishes the states.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/service/trajectory_node.hpp"
#include "feeddrive/service/translate.hpp"
#include "protocol_util.hpp"

namespace feeddrive::protocol_test {
namespace {

using service::TrajectoryNode;

drive_state_t state(std::int64_t k, long steps) {
  drive_state_t m{};
  m.seq = k;
  m.t = static_cast<double>(k) * 1e-4;
  m.steps = steps;
  m.end_of_run = k >= steps;
  m.x_measured = 1e-6 * static_cast<double>(k);
  m.previous = service::no_applied();
  return m;
}

/// Every block received (copies too), in order.
struct Blocks {
  std::unique_ptr<service::Bus> bus;
  std::vector<reference_block_t> got;
  explicit Blocks(const Memq& m) : bus(peer(m)) {
    bus->subscribe<reference_block_t>(kCh.reference,
                                      [this](const reference_block_t& b, std::int64_t) { got.push_back(b); });
  }
  std::map<std::int64_t, int> copies() const {
    std::map<std::int64_t, int> c;
    for (const reference_block_t& b : got) ++c[b.first_seq];
    return c;
  }
};

/// Each step 0..N-1 in exactly one aligned block of up to 16, with the reference the scenario's
/// trajectory gives at t_k (the same code on the same input: bit-identical); copies identical.
void expect_blocks_cover_the_trajectory(const sim::Scenario& s, const std::vector<reference_block_t>& got) {
  const auto traj = sim::make_reference(s);
  std::map<std::int64_t, reference_block_t> first;
  for (const reference_block_t& b : got) {
    EXPECT_EQ(b.first_seq % TrajectoryNode::kBlock, 0) << "aligned blocks";
    EXPECT_EQ(b.count, std::min<std::int64_t>(TrajectoryNode::kBlock, s.steps() - b.first_seq));
    const auto [it, fresh] = first.emplace(b.first_seq, b);
    if (fresh) continue;
    for (std::size_t i = 0; i < b.refs.size(); ++i) {
      EXPECT_EQ(b.refs[i].position, it->second.refs[i].position) << "a copy of block " << b.first_seq << " differs";
    }
  }
  std::int64_t k = 0;
  for (const auto& [first_seq, b] : first) {
    for (const reference_t& r : b.refs) {
      ASSERT_EQ(r.seq, k) << "steps in order, none missing";
      const trajectory::Sample want = traj->sample(s.time_of(k));
      EXPECT_EQ(r.t, s.time_of(k));
      EXPECT_EQ(r.position, want.position) << "step " << k;
      EXPECT_EQ(r.velocity, want.velocity) << "step " << k;
      EXPECT_EQ(r.acceleration, want.acceleration) << "step " << k;
      EXPECT_EQ(r.jerk, want.jerk) << "step " << k;
      ++k;
    }
  }
  EXPECT_EQ(k, s.steps());
}

// Lockstep, 600 steps: the plant publishes state k+1 only after state k reached everyone (the
// trajectory subscribed first, so it has handled state k by then). When a block arrives the
// newest state is k: it never starts beyond k + 256 (the lead); and by the time state k+1
// arrives, every block up to step k + 256 has (the references are never on a step's path).
TEST(TrajectoryProtocol, LockstepKeepsTheReferencesALeadAhead) {
  Memq memq;
  constexpr long kSteps = 600;
  const sim::Scenario s = scenario(kSteps);
  TrajectoryNode node(s, node_options(), memq.lcm);
  Blocks blocks(memq);
  auto plant = peer(memq);
  std::int64_t seen = -1;        // the newest state dispatched
  std::int64_t sent_up_to = -1;  // the last step of the blocks received
  plant->subscribe<drive_state_t>(kCh.state, [&](const drive_state_t& m, std::int64_t) {
    if (m.end_of_run) return;
    if (seen >= 0) {
      EXPECT_GE(sent_up_to, std::min<std::int64_t>(seen + TrajectoryNode::kLead, kSteps - 1))
          << "state " << m.seq << " arrived before the references up to state " << seen << " + 256";
    }
    seen = m.seq;
    plant->publish(kCh.state, state(m.seq + 1, kSteps));
  });
  plant->subscribe<reference_block_t>(kCh.reference, [&](const reference_block_t& b, std::int64_t) {
    EXPECT_LE(b.first_seq, seen + TrajectoryNode::kLead) << "block beyond the lead of state " << seen;
    sent_up_to = std::max<std::int64_t>(sent_up_to, b.first_seq + b.count - 1);
  });
  plant->publish(kCh.state, state(0, kSteps));
  node.run();
  EXPECT_EQ(seen, kSteps - 1);
  expect_blocks_cover_the_trajectory(s, blocks.got);
  for (const auto& [first, n] : blocks.copies()) EXPECT_EQ(n, 1) << "block " << first << " sent more than once";
  EXPECT_EQ(node.duplicates, 0);
  EXPECT_EQ(node.resends, 0);
}

// A repeated state (its command or reference got lost) re-publishes the block of that step; a
// resend request for step 20 re-publishes its block and the later ones already sent.
TEST(TrajectoryProtocol, ARepeatedStateOrARequestRepublishesTheBlocks) {
  Memq memq;
  constexpr long kSteps = 40;  // blocks 0, 16, 32: all sent at state 0
  const sim::Scenario s = scenario(kSteps);
  TrajectoryNode node(s, node_options(), memq.lcm);
  Blocks blocks(memq);
  auto plant = peer(memq);
  for (std::int64_t k = 0; k <= 6; ++k) plant->publish(kCh.state, state(k, kSteps));
  plant->publish(kCh.state, state(5, kSteps));  // again: block 0 again
  resend_request_t r{};
  r.requester = "monitor";
  r.channel = kCh.reference;
  r.seq = 20;  // block 16, and 32 after it
  plant->publish(kCh.resend, r);
  for (std::int64_t k = 7; k <= kSteps; ++k) plant->publish(kCh.state, state(k, kSteps));
  node.run();
  expect_blocks_cover_the_trajectory(s, blocks.got);
  EXPECT_EQ(blocks.copies(), (std::map<std::int64_t, int>{{0, 2}, {16, 2}, {32, 2}}));
  EXPECT_EQ(node.duplicates, 1);
  EXPECT_EQ(node.resends, 3);
}

// Real time: a repeated state is the plant answering a monitor's resend request, not a sign that
// a reference got lost (the controller asks for those on FD_RESEND): no block goes out again for
// it. A resend request while the plant runs re-publishes the block asked for, not the later ones
// as well (a monitor starved on the chain's core catches up after the end).
TEST(TrajectoryProtocol, InRealTimeOnlyARequestRepublishesTheBlocks) {
  Memq memq;
  constexpr long kSteps = 40;  // blocks 0, 16, 32: all sent at state 0
  const sim::Scenario s = scenario(kSteps);
  service::NodeOptions opt = node_options();
  opt.realtime = true;
  opt.realtime_scheduling = false;  // the protocol, without SCHED_FIFO for the test process
  TrajectoryNode node(s, opt, memq.lcm);
  Blocks blocks(memq);
  auto plant = peer(memq);
  for (std::int64_t k = 0; k <= 6; ++k) plant->publish(kCh.state, state(k, kSteps));
  plant->publish(kCh.state, state(5, kSteps));  // again: no block
  resend_request_t r{};
  r.requester = "monitor";
  r.channel = kCh.reference;
  r.seq = 20;  // block 16 only
  plant->publish(kCh.resend, r);
  for (std::int64_t k = 7; k <= kSteps; ++k) plant->publish(kCh.state, state(k, kSteps));
  node.run();
  expect_blocks_cover_the_trajectory(s, blocks.got);
  EXPECT_EQ(blocks.copies(), (std::map<std::int64_t, int>{{0, 1}, {16, 2}, {32, 1}}));
  EXPECT_EQ(node.duplicates, 1);
  EXPECT_EQ(node.resends, 1);
}

// Without --run-id the trajectory joins the run of the plant's first fresh heartbeat, then
// takes that run's states (before, every state is dropped uncounted).
TEST(TrajectoryProtocol, JoinsTheRunOfThePlantsHeartbeat) {
  Memq memq;
  constexpr long kSteps = 20;
  const sim::Scenario s = scenario(kSteps);
  service::NodeOptions opt = node_options();
  opt.run_id = 0;
  TrajectoryNode node(s, opt, memq.lcm);
  Blocks blocks(memq);
  auto plant = peer(memq);
  process_status_t hb{};
  hb.utime = service::wall_utime();  // fresh: within 5 s of this clock
  hb.role = "plant";
  hb.state = "running";
  hb.contract_version = service::kContractVersion;
  plant->publish(kCh.status, hb);
  for (std::int64_t k = 0; k <= kSteps; ++k) plant->publish(kCh.state, state(k, kSteps));
  node.run();
  EXPECT_EQ(node.bus().run_id(), kRunId);
  expect_blocks_cover_the_trajectory(s, blocks.got);
}

// Two different states for one step: the run fails naming channel, step and field.
TEST(TrajectoryProtocol, TwoDifferentStatesForOneStepFailTheRun) {
  Memq memq;
  constexpr long kSteps = 20;
  TrajectoryNode node(scenario(kSteps), node_options(), memq.lcm);
  auto plant = peer(memq);
  for (std::int64_t k = 0; k <= 5; ++k) plant->publish(kCh.state, state(k, kSteps));
  drive_state_t other = state(5, kSteps);
  other.x_measured = 1.0;
  plant->publish(kCh.state, other);
  const std::string what = failure_of([&] { node.run(); });
  expect_conflict(what, kCh.state, 5, "drive_state_t", "x_measured");
  EXPECT_EQ(node.conflicts, 1);
}

// A plant of another run: its state 0 (which would conflict with this run's) is counted as
// foreign and ignored.
TEST(TrajectoryProtocol, StatesOfAnotherRunAreCountedAndIgnored) {
  Memq memq;
  constexpr long kSteps = 20;
  const sim::Scenario s = scenario(kSteps);
  TrajectoryNode node(s, node_options(), memq.lcm);
  Blocks blocks(memq);
  auto other = peer(memq, 99);
  drive_state_t foreign = state(0, kSteps);
  foreign.x_measured = 1.0;
  other->publish(kCh.state, foreign);
  auto plant = peer(memq);
  for (std::int64_t k = 0; k <= kSteps; ++k) plant->publish(kCh.state, state(k, kSteps));
  node.run();
  EXPECT_EQ(node.bus().foreign(), 1);
  EXPECT_EQ(node.conflicts, 0);
  expect_blocks_cover_the_trajectory(s, blocks.got);
}

// No state at all: --start-timeout, naming the plant. Lower bound: the protocol; upper: a hang.
TEST(TrajectoryProtocol, NoPlantFailsAfterTheStartTimeout) {
  Memq memq;
  service::NodeOptions opt = node_options();
  opt.start_timeout_s = 0.3;
  TrajectoryNode node(scenario(20), opt, memq.lcm);
  expect_failure_after(0.3, "no state from the plant for step 0 within 0.3 s",
                       [&] { return failure_of([&] { node.run(); }); });
}

// Without --run-id and no plant heartbeat: the run cannot be joined; --start-timeout says how
// to fix it.
TEST(TrajectoryProtocol, NoPlantHeartbeatToJoinFailsAfterTheStartTimeout) {
  Memq memq;
  service::NodeOptions opt = node_options();
  opt.run_id = 0;
  opt.start_timeout_s = 0.3;
  TrajectoryNode node(scenario(20), opt, memq.lcm);
  expect_failure_after(
      0.3,
      "no heartbeat from the plant within 0.3 s to join its run (start the plant, or give every process "
      "the same --run-id)",
      [&] { return failure_of([&] { node.run(); }); });
}

// States 0..3, then nothing (and no heartbeat): --step-timeout at step 4.
TEST(TrajectoryProtocol, ASilentPlantFailsAfterTheStepTimeout) {
  Memq memq;
  constexpr long kSteps = 20;
  service::NodeOptions opt = node_options();
  opt.step_timeout_s = 0.2;
  TrajectoryNode node(scenario(kSteps), opt, memq.lcm);
  auto plant = peer(memq);
  for (std::int64_t k = 0; k <= 3; ++k) plant->publish(kCh.state, state(k, kSteps));
  expect_failure_after(0.2, "no state from the plant for step 4 within 0.2 s",
                       [&] { return failure_of([&] { node.run(); }); });
}

}  // namespace
}  // namespace feeddrive::protocol_test

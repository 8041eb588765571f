// The plant's lockstep protocol over memq:// (plant_node.hpp): publish state k, wait for command
// k re-publishing state k every resend interval, apply it, publish state k+1; conflicts,
// foreign messages, the monitor's flow control and the timeouts that name the missing role.
// A scripted controller (a Bus on the same memq:// instance) answers inside the plant's poll.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/service/plant_node.hpp"
#include "protocol_util.hpp"

namespace feeddrive::protocol_test {
namespace {

using service::PlantNode;

constexpr long kSteps = 20;

control_command_t command(std::int64_t k, double u) {
  control_command_t c{};
  c.seq = k;
  c.t = static_cast<double>(k) * 1e-4;
  c.u = c.u_unsaturated = u;
  c.sliding = c.z_estimate = 0.0;
  return c;
}

/// A scripted controller: records every state (copies too) and answers state k according to
/// `answer(k, copy)` (copy: 1 for the first time state k arrives), which returns the commands to
/// send (none: stay silent). It hears the states of any run (Admit::kAnyRun): one of another
/// run (run_id) answers this run's plant, as a second run on the same group would.
struct Controller {
  std::unique_ptr<service::Bus> bus;
  std::vector<drive_state_t> states;
  std::map<std::int64_t, int> copies;
  Controller(const Memq& m, std::function<std::vector<control_command_t>(std::int64_t, int)> answer,
             std::int64_t run_id = kRunId)
      : bus(peer(m, run_id)) {
    bus->subscribe<drive_state_t>(
        kCh.state,
        [this, answer](const drive_state_t& s, std::int64_t) {
          states.push_back(s);
          if (s.end_of_run) return;
          for (const control_command_t& c : answer(s.seq, ++copies[s.seq])) bus->publish(kCh.command, c);
        },
        service::Admit::kAnyRun);
  }
  /// After the plant's run(): takes what it published last (the end-of-run marker: the plant,
  /// with no monitor to linger for, does not poll again), waiting at most 5 s for it.
  void wait_for_the_end() {
    EXPECT_TRUE(poll_until(*bus, [this] { return !states.empty() && states.back().end_of_run; }))
        << "no end-of-run state within 5 s";
  }
  /// The first copy of each state, by step.
  std::map<std::int64_t, drive_state_t> firsts() const {
    std::map<std::int64_t, drive_state_t> m;
    for (const drive_state_t& s : states) m.emplace(s.seq, s);
    return m;
  }
};

/// Checks the plant's states against plant::Plant driven directly with the same commands: the
/// node adds transport, not physics. Same code, same inputs, same order: bit-identical, so
/// EXPECT_EQ on doubles. Also step numbers, times, and what state k+1 says was applied.
void expect_states_of_a_plant_driven_by(const sim::Scenario& s, const std::map<std::int64_t, drive_state_t>& got,
                                        const std::function<double(std::int64_t)>& u) {
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kSteps + 1)) << "states 0..N, each step once at least";
  plant::Plant ref(s.drive(), s.control_period);
  for (std::int64_t k = 0; k <= kSteps; ++k) {
    const drive_state_t& m = got.at(k);
    EXPECT_EQ(m.steps, kSteps);
    EXPECT_EQ(m.end_of_run, k == kSteps) << k;
    EXPECT_DOUBLE_EQ(m.t, s.time_of(k)) << k;
    if (k < kSteps) {
      const plant::Measurement meas = ref.measure();
      EXPECT_EQ(m.x_measured, meas.x) << "step " << k;
      EXPECT_EQ(m.v_measured, meas.v) << "step " << k;
    }
    EXPECT_EQ(m.truth.x, ref.state().x) << "step " << k;
    EXPECT_EQ(m.truth.v, ref.state().v) << "step " << k;
    if (k > 0) {
      EXPECT_EQ(m.previous.seq, k - 1);
      EXPECT_EQ(m.previous.u, u(k - 1)) << "state " << k << " carries what was applied during step " << k - 1;
    } else {
      EXPECT_EQ(m.previous.seq, -1) << "nothing applied before step 0";
    }
    if (k < kSteps) ref.advance(u(k), s.time_of(k + 1));
  }
}

/// The controller's usual answer: command k with u_of(k), once, to the first copy of state k.
std::vector<control_command_t> answer_first_copy(std::int64_t k, int copy) {
  return copy == 1 ? std::vector<control_command_t>{command(k, u_of(k))} : std::vector<control_command_t>{};
}

/// Each test: one memq:// instance, the short scenario and the plant node under test on it.
class PlantProtocol : public ::testing::Test {
 protected:
  Memq memq;
  const sim::Scenario s = scenario(kSteps);
  std::unique_ptr<PlantNode> plant_;

  /// The node under test: the scenario's plant over memq, with `opt`.
  PlantNode& make_plant(const service::NodeOptions& opt = node_options()) {
    plant_ = std::make_unique<PlantNode>(s, opt, memq.lcm);
    return *plant_;
  }
  /// Runs the plant to the end of the run and checks the states `ctl` heard against a plant
  /// driven directly by u_of (expect_states_of_a_plant_driven_by).
  void run_to_end(Controller& ctl) {
    plant_->run();
    ctl.wait_for_the_end();
    expect_states_of_a_plant_driven_by(s, ctl.firsts(), u_of);
  }
};

// Lockstep: state k, command k, state k+1 ... the end-of-run marker N; every state once (the
// controller answers at once, within the plant's poll), nothing counted as duplicate or conflict.
TEST_F(PlantProtocol, LockstepStepsApplyEachCommandToItsStep) {
  PlantNode& plant = make_plant();
  Controller ctl(memq, answer_first_copy);
  run_to_end(ctl);
  EXPECT_EQ(ctl.states.front().seq, 0);
  EXPECT_TRUE(ctl.states.back().end_of_run);
  EXPECT_EQ(plant.duplicates, 0);
  EXPECT_EQ(plant.conflicts, 0);
  EXPECT_EQ(plant.rejected_commands(), 0);
}

// A lost command: the controller ignores the first copy of every state, so the plant must
// re-publish each state (every resend interval, 2 ms) until it is answered; the copies are the
// same message (the sensor noise is drawn once per step) and the run is the same.
TEST_F(PlantProtocol, ResendsAStateUntilItIsAnswered) {
  PlantNode& plant = make_plant();
  Controller ctl(memq, [](std::int64_t k, int copy) {
    return copy == 2 ? std::vector<control_command_t>{command(k, u_of(k))} : std::vector<control_command_t>{};
  });
  run_to_end(ctl);
  EXPECT_GE(plant.resends, kSteps) << "each of the N states went out again at least once";
  for (std::int64_t k = 0; k < kSteps; ++k) EXPECT_GE(ctl.copies[k], 2) << k;
  const auto firsts = ctl.firsts();
  for (const drive_state_t& m : ctl.states) {
    EXPECT_EQ(m.x_measured, firsts.at(m.seq).x_measured) << "a copy of state " << m.seq << " differs";
  }
  EXPECT_EQ(plant.conflicts, 0);
}

// A command sent twice (the controller re-publishes it) is applied once: a duplicate, counted,
// the run unchanged.
TEST_F(PlantProtocol, ARepeatedCommandIsADuplicate) {
  PlantNode& plant = make_plant();
  Controller ctl(memq, [](std::int64_t k, int copy) {
    return copy == 1 ? std::vector<control_command_t>{command(k, u_of(k)), command(k, u_of(k))}
                     : std::vector<control_command_t>{};
  });
  run_to_end(ctl);
  // The second copy of command k is handled at the plant's next poll (the last one at the
  // controller's poll for the end, wait_for_the_end, at the latest).
  EXPECT_EQ(plant.duplicates, kSteps);
  EXPECT_EQ(plant.conflicts, 0);
}

// Two different commands for one step (a second publisher): by default the run fails naming the
// channel, the step and the fields; state 4 is never published.
TEST_F(PlantProtocol, TwoDifferentCommandsForOneStepFailTheRun) {
  PlantNode& plant = make_plant();
  Controller ctl(memq, [](std::int64_t k, int copy) {
    std::vector<control_command_t> v;
    if (copy == 1) v.push_back(command(k, u_of(k)));
    if (copy == 1 && k == 3) v.push_back(command(k, -1.0));
    return v;
  });
  const std::string what = failure_of([&] { plant.run(); });
  expect_conflict(what, kCh.command, 3, "control_command_t", "u, u_unsaturated");
  EXPECT_EQ(plant.conflicts, 1);
  EXPECT_EQ(ctl.states.back().seq, 3) << "no state after the conflicting step";
}

// --on-conflict keep-first: the second command is dropped and counted; the first one acts.
TEST_F(PlantProtocol, KeepFirstAppliesTheFirstOfTwoCommands) {
  service::NodeOptions opt = node_options();
  opt.on_conflict = service::ConflictPolicy::kKeepFirst;
  PlantNode& plant = make_plant(opt);
  Controller ctl(memq, [](std::int64_t k, int copy) {
    std::vector<control_command_t> v;
    if (copy == 1) v.push_back(command(k, u_of(k)));
    if (copy == 1 && k == 3) v.push_back(command(k, -1.0));
    return v;
  });
  run_to_end(ctl);
  EXPECT_EQ(plant.conflicts, 1);
}

// A controller of another run answering first on the same channels: its commands are counted as
// foreign and never applied; this run's controller drives the plant.
TEST_F(PlantProtocol, CommandsOfAnotherRunAreCountedAndIgnored) {
  PlantNode& plant = make_plant();
  Controller other(
      memq,
      [](std::int64_t k, int copy) {
        return copy == 1 ? std::vector<control_command_t>{command(k, -2.0)} : std::vector<control_command_t>{};
      },
      99);
  Controller ctl(memq, answer_first_copy);
  run_to_end(ctl);
  EXPECT_EQ(plant.bus().foreign(), kSteps) << "one foreign command per step";
  EXPECT_EQ(plant.conflicts, 0);
}

// A command for a step the plant has not reached: the controller's protocol error, named.
TEST_F(PlantProtocol, ACommandAheadOfTheStepFailsTheRun) {
  PlantNode& plant = make_plant();
  Controller ctl(memq, [](std::int64_t k, int copy) {
    return copy == 1 ? std::vector<control_command_t>{command(k == 3 ? 5 : k, u_of(k))}
                     : std::vector<control_command_t>{};
  });
  const std::string what = failure_of([&] { plant.run(); });
  EXPECT_EQ(what, "the controller answered step 5 while the plant is at step 3");
}

// No controller: the plant fails after --start-timeout at step 0, naming the controller. The
// lower bound is the protocol (it never gives up early, re-publishing state 0 meanwhile); the
// upper bound only catches a hang (10 s: generous for a loaded machine).
TEST_F(PlantProtocol, NoControllerFailsAfterTheStartTimeout) {
  service::NodeOptions opt = node_options();
  opt.start_timeout_s = 0.3;
  PlantNode& plant = make_plant(opt);
  Controller silent(memq, [](std::int64_t, int) { return std::vector<control_command_t>{}; });
  expect_failure_after(0.3, "no command from the controller for step 0 within 0.3 s",
                       [&] { return failure_of([&] { plant.run(); }); });
  EXPECT_GE(silent.copies[0], 2) << "state 0 was re-published while waiting";
}

// A controller that stops answering mid-run (and sends no heartbeat, so it is not waiting on
// someone else): --step-timeout at that step.
TEST_F(PlantProtocol, ASilentControllerFailsAfterTheStepTimeout) {
  service::NodeOptions opt = node_options();
  opt.step_timeout_s = 0.2;
  PlantNode& plant = make_plant(opt);
  Controller ctl(memq, [](std::int64_t k, int copy) {
    return copy == 1 && k < 5 ? std::vector<control_command_t>{command(k, u_of(k))} : std::vector<control_command_t>{};
  });
  expect_failure_after(0.2, "no command from the controller for step 5 within 0.2 s",
                       [&] { return failure_of([&] { plant.run(); }); });
}

// The monitor's flow control (--monitor-window 4): the plant never runs more than 4 steps ahead
// of the monitor's acknowledged step. The scripted monitor acknowledges step 2 and no more: the
// plant publishes states 0..5 and then fails after --step-timeout naming the monitor.
TEST_F(PlantProtocol, StaysWithinTheMonitorsWindowAndFailsWithoutItsAcknowledgement) {
  service::NodeOptions opt = node_options();
  opt.monitor_window = 4;
  opt.step_timeout_s = 0.2;
  PlantNode& plant = make_plant(opt);
  auto monitor = peer(memq);
  const auto ack = [&](std::int64_t acked) {
    process_status_t st{};
    st.role = "monitor";
    st.state = "running";
    st.seq = acked;
    st.acked_seq = acked;
    st.contract_version = service::kContractVersion;
    monitor->publish(kCh.status, st);
  };
  ack(0);  // queued before run(): heard at the plant's first poll
  Controller ctl(memq, [&](std::int64_t k, int copy) {
    if (copy == 1 && k == 1) ack(2);  // one acknowledgement, then silence
    return copy == 1 ? std::vector<control_command_t>{command(k, u_of(k))} : std::vector<control_command_t>{};
  });
  const std::string what = failure_of([&] { plant.run(); });
  EXPECT_EQ(what, "no acknowledgement from the monitor for step 2 within 0.2 s (is feeddrive-monitor running?)");
  EXPECT_EQ(ctl.states.back().seq, 5) << "step 6 - acked step 2 = the window: state 6 must wait";
}

// No monitor at all with a window: the plant waits --start-timeout for the first acknowledgement.
TEST_F(PlantProtocol, NoMonitorFailsAfterTheStartTimeout) {
  service::NodeOptions opt = node_options();
  opt.monitor_window = 4;
  opt.start_timeout_s = 0.3;
  PlantNode& plant = make_plant(opt);
  Controller ctl(memq, [](std::int64_t k, int) { return std::vector<control_command_t>{command(k, u_of(k))}; });
  expect_failure_after(0.3,
                       "no acknowledgement from the monitor for step 0 within 0.3 s (is feeddrive-monitor running?)",
                       [&] { return failure_of([&] { plant.run(); }); });
  EXPECT_TRUE(ctl.states.empty()) << "no state before the monitor is up";
}

}  // namespace
}  // namespace feeddrive::protocol_test

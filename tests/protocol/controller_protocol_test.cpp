// The controller's lockstep protocol over memq:// (controller_node.hpp): answer state k with
// command k once reference k is there, answer a repeated state with the same command (never run
// the controller twice for a step), ask for a missing reference; conflicts, foreign messages,
// the plant's protocol errors and the timeouts that name the missing role. A scripted plant
// (plant::Plant behind a Bus) and a scripted trajectory answer inside the controller's poll.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/service/controller_node.hpp"
#include "feeddrive/service/translate.hpp"
#include "protocol_util.hpp"

namespace feeddrive::protocol_test {
namespace {

using service::ControllerNode;

constexpr long kSteps = 20;

/// The scenario's trajectory as reference_t messages, step by step.
std::vector<reference_t> references(const sim::Scenario& s) {
  const auto traj = sim::make_reference(s);
  std::vector<reference_t> v;
  for (long k = 0; k < s.steps(); ++k) v.push_back(service::to_message(k, s.time_of(k), traj->sample(s.time_of(k))));
  return v;
}

/// A scripted trajectory: publishes reference k as a block of one (the contract allows 1..16),
/// all of them at once except the `withheld` ones, which it sends only when asked on FD_RESEND.
struct Trajectory {
  std::unique_ptr<service::Bus> bus;
  std::vector<reference_t> refs;
  std::vector<resend_request_t> requests;
  Trajectory(const Memq& m, const sim::Scenario& s, std::set<std::int64_t> withheld = {})
      : bus(peer(m)), refs(references(s)) {
    bus->subscribe<resend_request_t>(kCh.resend, [this, withheld](const resend_request_t& r, std::int64_t) {
      if (r.channel != kCh.reference) return;
      requests.push_back(r);
      if (withheld.count(r.seq) && r.seq < static_cast<std::int64_t>(refs.size())) send(r.seq);
    });
    for (std::int64_t k = 0; k < static_cast<std::int64_t>(refs.size()); ++k)
      if (!withheld.count(k)) send(k);
  }
  void send(std::int64_t k) {
    reference_block_t b{};
    b.first_seq = k;
    b.count = 1;
    b.refs = {refs[static_cast<std::size_t>(k)]};
    bus->publish(kCh.reference, b);
  }
};

/// A scripted plant: plant::Plant behind a Bus. Publishes state 0 at once and state k+1 when
/// the first command k arrives (state N: the end-of-run marker), each state `copies` times.
/// `next_step(plant, k)` may publish something else instead (a skipped step, a conflict): it
/// returns true when it did. Computes, as each state goes out, the command a second controller built
/// from the same scenario gives for it (`expected`): the node's must be bit-identical.
struct Plant {
  std::unique_ptr<service::Bus> bus;
  sim::Scenario s;
  plant::Plant drive;
  std::unique_ptr<controller::Controller> twin;
  std::vector<reference_t> refs;
  int copies;
  std::map<std::int64_t, drive_state_t> sent;
  std::map<std::int64_t, controller::Command> expected;
  std::vector<control_command_t> commands;  ///< every command received, copies too
  std::function<bool(Plant&, std::int64_t)> next_step;
  Plant(const Memq& m, const sim::Scenario& sc, int copies_ = 1, std::function<bool(Plant&, std::int64_t)> hook = {})
      : bus(peer(m)),
        s(sc),
        drive(sc.drive(), sc.control_period),
        twin(sim::make_controller(sc)),
        refs(references(sc)),
        copies(copies_),
        next_step(std::move(hook)) {
    bus->subscribe<control_command_t>(kCh.command, [this](const control_command_t& c, std::int64_t) {
      commands.push_back(c);
      if (sent.count(c.seq + 1) || c.seq >= s.steps()) return;  // answered already
      if (next_step && next_step(*this, c.seq + 1)) return;
      drive.advance(c.u, s.time_of(c.seq + 1));
      publish(state(c.seq + 1));
    });
  }
  drive_state_t state(std::int64_t k) {
    drive_state_t m{};
    m.seq = k;
    m.t = s.time_of(k);
    m.steps = s.steps();
    m.end_of_run = k >= s.steps();
    const plant::Measurement meas = drive.measure();
    m.x_measured = meas.x;
    m.v_measured = meas.v;
    m.truth = service::to_truth_message(drive.state());
    m.previous = service::no_applied();
    return m;
  }
  void publish(const drive_state_t& m) {
    sent[m.seq] = m;
    if (!m.end_of_run) {
      const controller::Truth truth = service::to_truth(m.truth);
      expected[m.seq] =
          twin->update(service::to_sample(refs[static_cast<std::size_t>(m.seq)]), service::to_measurement(m), &truth);
    }
    for (int i = 0; i < copies; ++i) bus->publish(kCh.state, m);
  }
  void start() { publish(state(0)); }
  /// The first copy of each command, by step.
  std::map<std::int64_t, control_command_t> firsts() const {
    std::map<std::int64_t, control_command_t> m;
    for (const control_command_t& c : commands) m.emplace(c.seq, c);
    return m;
  }
};

/// Every step 0..N-1 answered with the command the twin controller computed: bit-identical (same
/// code, same inputs in the same order), so a step answered twice, skipped or answered with
/// another step's reference shows.
void expect_twin_commands(const Plant& p) {
  const auto got = p.firsts();
  ASSERT_EQ(got.size(), static_cast<std::size_t>(kSteps));
  for (std::int64_t k = 0; k < kSteps; ++k) {
    EXPECT_EQ(got.at(k).u, p.expected.at(k).u) << "step " << k;
    EXPECT_EQ(got.at(k).u_unsaturated, p.expected.at(k).u_unsaturated) << "step " << k;
    EXPECT_DOUBLE_EQ(got.at(k).t, p.s.time_of(k));
  }
}

/// Each test: one memq:// instance, the short scenario and the controller node under test on it.
class ControllerProtocol : public ::testing::Test {
 protected:
  Memq memq;
  const sim::Scenario s = scenario(kSteps);
  std::unique_ptr<ControllerNode> node_;

  /// The node under test: the scenario's controller over memq, with `opt`.
  ControllerNode& make_node(const service::NodeOptions& opt = node_options()) {
    node_ = std::make_unique<ControllerNode>(sim::make_controller(s), opt, memq.lcm);
    return *node_;
  }
  /// Starts `plant`, runs the node to the end of the run and checks every command against the
  /// twin's (expect_twin_commands).
  void run_to_end(Plant& plant) {
    plant.start();
    node_->run();
    expect_twin_commands(plant);
  }
  /// Starts `plant` and runs the node; returns its failure line ("" if the run ended).
  std::string run_to_failure(Plant& plant) {
    plant.start();
    return failure_of([&] { node_->run(); });
  }
};

// Lockstep: state k (with reference k there) -> command k -> state k+1 ... -> end of run.
TEST_F(ControllerProtocol, LockstepAnswersEachStateOnceWithItsCommand) {
  ControllerNode& node = make_node();
  Trajectory traj(memq, s);
  Plant plant(memq, s);
  run_to_end(plant);
  EXPECT_EQ(plant.commands.size(), static_cast<std::size_t>(kSteps)) << "one command per step";
  EXPECT_EQ(node.duplicates, 0);
  EXPECT_EQ(node.resends, 0);
  EXPECT_TRUE(traj.requests.empty()) << "no reference was missing";
}

// A repeated state (the plant re-publishes it: the command was lost) gets the same command
// again, from the outbox: the controller is not run twice (the twin's commands still match at
// every later step). A resend request on FD_CMD (the monitor's) re-publishes that command too.
TEST_F(ControllerProtocol, ARepeatedStateGetsTheSameCommandAgain) {
  ControllerNode& node = make_node();
  Trajectory traj(memq, s);
  auto monitor = peer(memq);
  Plant plant(memq, s, 2, [&](Plant&, std::int64_t k) {
    if (k == 8) {
      resend_request_t r{};
      r.requester = "monitor";
      r.channel = kCh.command;
      r.seq = 2;
      monitor->publish(kCh.resend, r);
    }
    return false;
  });
  run_to_end(plant);
  std::map<std::int64_t, int> copies;
  for (const control_command_t& c : plant.commands) {
    ++copies[c.seq];
    EXPECT_EQ(c.u, plant.firsts().at(c.seq).u) << "a copy of command " << c.seq << " differs";
  }
  for (std::int64_t k = 0; k < kSteps; ++k) EXPECT_EQ(copies[k], k == 2 ? 3 : 2) << "step " << k;
  // Each state's second copy is a duplicate answered from the outbox; the end-of-run marker's
  // second copy comes after the end. Plus the one request.
  EXPECT_EQ(node.duplicates, kSteps);
  EXPECT_EQ(node.resends, kSteps + 1);
}

// Real time: the plant has moved on when a state comes again (a monitor's resend request made the
// plant repeat it), so the controller answers only the start handshake's state 0 again. Each
// repeated later state answered would double the bus load of a monitor catching up on the
// chain's core (docs/lcm-contract.md, "Real time against the machine").
TEST_F(ControllerProtocol, InRealTimeARepeatedStateAfterTheHandshakeIsNotAnsweredAgain) {
  service::NodeOptions opt = node_options();
  opt.realtime = true;
  opt.realtime_scheduling = false;  // the protocol, without SCHED_FIFO for the test process
  ControllerNode& node = make_node(opt);
  Trajectory traj(memq, s);
  Plant plant(memq, s, 2);
  run_to_end(plant);
  std::map<std::int64_t, int> copies;
  for (const control_command_t& c : plant.commands) ++copies[c.seq];
  for (std::int64_t k = 0; k < kSteps; ++k) EXPECT_EQ(copies[k], k == 0 ? 2 : 1) << "step " << k;
  EXPECT_EQ(node.duplicates, kSteps);  // every second copy, the end-of-run marker's included
  EXPECT_EQ(node.resends, 1);          // state 0's
}

// A lost reference: the controller holds state 5 and asks for reference 5 on FD_RESEND (after
// one resend interval); the trajectory sends it, the step is answered, the run goes on.
TEST_F(ControllerProtocol, AsksForAMissingReference) {
  make_node();
  Trajectory traj(memq, s, {5});
  Plant plant(memq, s);
  run_to_end(plant);
  ASSERT_FALSE(traj.requests.empty());
  EXPECT_EQ(traj.requests.front().seq, 5);
  EXPECT_EQ(traj.requests.front().requester, "controller");
}

// Two different states for one step (another plant on the bus): the run fails, naming the
// channel, the step and the field.
TEST_F(ControllerProtocol, TwoDifferentStatesForOneStepFailTheRun) {
  ControllerNode& node = make_node();
  Trajectory traj(memq, s);
  Plant plant(memq, s, 1, [](Plant& pl, std::int64_t k) {
    if (k != 3) return false;
    drive_state_t m = pl.state(3);
    pl.publish(m);
    m.x_measured += 1e-6;
    pl.bus->publish(kCh.state, m);
    return true;
  });
  const std::string what = run_to_failure(plant);
  expect_conflict(what, kCh.state, 3, "drive_state_t", "x_measured");
  EXPECT_EQ(node.conflicts, 1);
}

// A state that skips a step (state 4 while step 3 has no command): the plant's protocol error,
// named as the plant's, not left to look like the controller's stall.
TEST_F(ControllerProtocol, ASkippedStepIsThePlantsProtocolError) {
  make_node();
  Trajectory traj(memq, s);
  Plant plant(memq, s, 1, [](Plant& pl, std::int64_t k) {
    if (k != 3) return false;
    pl.publish(pl.state(4));
    return true;
  });
  const std::string what = run_to_failure(plant);
  EXPECT_EQ(what.rfind("protocol error of the plant: it published state 4 while step 3 has no command yet", 0), 0u)
      << what;
}

// A controller that subscribes late (CI, stop 28: the launcher's controller was slower to start
// than a forger without --key, which answered states 0..10 first): the first state it hears is
// beyond step 0 with no command of another publisher seen. It joined late; that is not the
// plant's skipped step. It answers the state it has, and its commands go on from there.
TEST_F(ControllerProtocol, ALateJoinerAnswersTheFirstStateItHearsAndDoesNotBlameThePlant) {
  auto forger = peer(memq);
  Plant plant(memq, s);
  std::int64_t forged = 0;
  forger->subscribe<drive_state_t>(kCh.state, [&](const drive_state_t& m, std::int64_t) {
    if (m.end_of_run || m.seq >= 5 || m.seq < forged) return;
    control_command_t c{};
    c.seq = m.seq;
    c.t = m.t;
    c.u = c.u_unsaturated = 0.5;
    c.sliding = c.z_estimate = std::nan("");
    forger->publish(kCh.command, c);
    forged = m.seq + 1;
  });
  plant.start();
  ASSERT_TRUE(poll_until(*forger, [&] { return plant.sent.count(5) == 1; })) << "the forger drove states 0..4";
  make_node();                                      // subscribes now: states 0..5 and commands 0..4 went by
  Trajectory traj(memq, s);                         // after the node, which would miss references sent before it
  plant.bus->publish(kCh.state, plant.sent.at(5));  // the plant's re-publication of the unanswered state
  const std::string what = failure_of([&] { node_->run(); });
  EXPECT_EQ(what, "") << "a late join taken for the plant's error";
  std::set<std::int64_t> answered;
  for (const control_command_t& c : plant.commands)
    if (c.u != 0.5 || c.seq >= 5) answered.insert(c.seq);
  ASSERT_FALSE(answered.empty());
  EXPECT_EQ(*answered.begin(), 5) << "the node's first answer is the first state it heard";
  EXPECT_EQ(*answered.rbegin(), kSteps - 1) << "and it answered to the end";
}

// A plant of another run publishing its own state 0 first: counted as foreign, not answered, not
// a conflict with this run's state 0.
TEST_F(ControllerProtocol, StatesOfAnotherRunAreCountedAndIgnored) {
  ControllerNode& node = make_node();
  Trajectory traj(memq, s);
  auto other = peer(memq, 99);
  drive_state_t foreign{};
  foreign.seq = 0;
  foreign.steps = kSteps;
  foreign.x_measured = 0.5;
  foreign.previous = service::no_applied();
  other->publish(kCh.state, foreign);
  Plant plant(memq, s);
  run_to_end(plant);
  EXPECT_EQ(node.bus().foreign(), 1);
  EXPECT_EQ(node.conflicts, 0);
}

// No plant: --start-timeout, naming the plant. Lower bound: the protocol; upper: a hang (10 s).
TEST_F(ControllerProtocol, NoPlantFailsAfterTheStartTimeout) {
  service::NodeOptions opt = node_options();
  opt.start_timeout_s = 0.3;
  ControllerNode& node = make_node(opt);
  expect_failure_after(0.3, "no state from the plant for step 0 within 0.3 s",
                       [&] { return failure_of([&] { node.run(); }); });
}

// State 0 but no trajectory: the controller asks for reference 0 meanwhile (every resend
// interval), then fails naming the trajectory.
TEST_F(ControllerProtocol, NoTrajectoryFailsAfterTheStartTimeout) {
  service::NodeOptions opt = node_options();
  opt.start_timeout_s = 0.3;
  ControllerNode& node = make_node(opt);
  std::vector<resend_request_t> asked;
  auto listener = peer(memq);
  listener->subscribe<resend_request_t>(kCh.resend,
                                        [&](const resend_request_t& r, std::int64_t) { asked.push_back(r); });
  Plant plant(memq, s);
  plant.start();
  expect_failure_after(0.3, "no reference from the trajectory for step 0 within 0.3 s",
                       [&] { return failure_of([&] { node.run(); }); });
  ASSERT_FALSE(asked.empty());
  EXPECT_EQ(asked.front().requester, "controller");
  EXPECT_EQ(asked.front().channel, kCh.reference);
  EXPECT_EQ(asked.front().seq, 0);
}

// A plant that stops after step 3 (no heartbeat either): --step-timeout, naming the plant.
TEST_F(ControllerProtocol, ASilentPlantFailsAfterTheStepTimeout) {
  service::NodeOptions opt = node_options();
  opt.step_timeout_s = 0.2;
  ControllerNode& node = make_node(opt);
  Trajectory traj(memq, s);
  Plant plant(memq, s, 1, [](Plant&, std::int64_t k) { return k >= 4; });
  plant.start();
  expect_failure_after(0.2, "no state from the plant for step 4 within 0.2 s",
                       [&] { return failure_of([&] { node.run(); }); });
}

}  // namespace
}  // namespace feeddrive::protocol_test

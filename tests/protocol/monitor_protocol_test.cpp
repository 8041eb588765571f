// The monitor's protocol over memq:// (monitor_node.hpp): record every step from state k,
// reference k, command k and state k+1, ask on FD_RESEND for what is missing, acknowledge the
// recorded steps, publish run_info_t and run_summary_t; duplicates, conflicts (which command the
// plant applied), foreign messages, and the timeouts that name the missing message and role.
// The run's messages come from a script: plant::Plant driven by known commands, the scenario's
// trajectory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "../support/scratch.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/monitor/monitor_node.hpp"
#include "feeddrive/plant/plant.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/run_info_t.hpp"
#include "feeddrive/run_summary_t.hpp"
#include "feeddrive/service/contract.hpp"
#include "feeddrive/service/translate.hpp"
#include "protocol_util.hpp"

namespace feeddrive::protocol_test {
namespace {

using monitor::MonitorNode;

constexpr long kSteps = 20;

/// The messages of a whole run: plant::Plant driven by u_of(k), the scenario's trajectory.
struct Script {
  sim::Scenario s = scenario(kSteps);
  std::vector<drive_state_t> states;  ///< 0..N (N: the end-of-run marker)
  std::vector<reference_t> refs;
  std::vector<control_command_t> commands;
  Script() {
    plant::Plant p(s.drive(), s.control_period);
    const auto traj = sim::make_reference(s);
    applied_t previous = service::no_applied();
    for (std::int64_t k = 0; k <= kSteps; ++k) {
      drive_state_t m{};
      m.seq = k;
      m.t = s.time_of(k);
      m.steps = kSteps;
      m.end_of_run = k == kSteps;
      const plant::Measurement meas = p.measure();
      m.x_measured = meas.x;
      m.v_measured = meas.v;
      m.truth = service::to_truth_message(p.state());
      m.previous = previous;
      states.push_back(m);
      if (k == kSteps) break;
      refs.push_back(service::to_message(k, s.time_of(k), traj->sample(s.time_of(k))));
      controller::Command c;
      c.u = c.u_unsaturated = u_of(k);
      commands.push_back(service::to_message(k, s.time_of(k), c));
      previous = service::to_applied(k, u_of(k), p.forces(u_of(k)));
      p.advance(u_of(k), s.time_of(k + 1));
    }
  }
  /// Publishes every message on `bus` (states, then references in blocks of one, then commands)
  /// except those `skip` returns true for ("state"/"reference"/"command", step).
  void publish(service::Bus& bus, const std::function<bool(const std::string&, std::int64_t)>& skip = {}) const {
    const auto skipped = [&](const char* what, std::int64_t k) { return skip && skip(what, k); };
    for (const drive_state_t& m : states)
      if (!skipped("state", m.seq)) bus.publish(kCh.state, m);
    for (const reference_t& r : refs)
      if (!skipped("reference", r.seq)) send_reference(bus, r);
    for (const control_command_t& c : commands)
      if (!skipped("command", c.seq)) bus.publish(kCh.command, c);
  }
  static void send_reference(service::Bus& bus, const reference_t& r) {
    reference_block_t b{};
    b.first_seq = r.seq;
    b.count = 1;
    b.refs = {r};
    bus.publish(kCh.reference, b);
  }
};

/// What the monitor publishes: its statuses, run_info_t, run_summary_t, its resend requests.
struct Listener {
  std::unique_ptr<service::Bus> bus;
  std::vector<process_status_t> statuses;
  std::vector<run_info_t> infos;
  std::vector<run_summary_t> summaries;
  std::vector<resend_request_t> requests;
  explicit Listener(const Memq& m) : bus(peer(m)) {
    bus->subscribe<process_status_t>(kCh.status, [this](const process_status_t& s, std::int64_t) {
      if (s.role == "monitor") statuses.push_back(s);
    });
    bus->subscribe<run_info_t>(kCh.info, [this](const run_info_t& i, std::int64_t) { infos.push_back(i); });
    bus->subscribe<run_summary_t>(kCh.summary,
                                  [this](const run_summary_t& s, std::int64_t) { summaries.push_back(s); });
    bus->subscribe<resend_request_t>(kCh.resend,
                                     [this](const resend_request_t& r, std::int64_t) { requests.push_back(r); });
  }
  /// Waits (at most 5 s) for the monitor's closing messages, published as run() returned: its
  /// summary and its last status.
  void wait_for_the_end() {
    EXPECT_TRUE(poll_until(*bus, [this] {
      return !summaries.empty() && !statuses.empty() &&
             (statuses.back().state == "done" || statuses.back().state == "failed");
    })) << "no run_summary_t and closing status from the monitor within 5 s";
  }
};

std::filesystem::path out_dir(const std::string& name) {
  static const std::filesystem::path root = test_support::make_scratch("protocol");
  return root / name;
}

monitor::MonitorOptions monitor_options(const std::string& name) {
  monitor::MonitorOptions m;
  m.out_dir = out_dir(name).string();
  m.plots = false;
  return m;
}

/// Column `name` of timeseries.csv, as numbers.
std::vector<double> column(const std::filesystem::path& csv, const std::string& name) {
  std::ifstream in(csv);
  std::string line, cell;
  std::getline(in, line);
  std::stringstream hs(line);
  int index = -1;
  for (int i = 0; std::getline(hs, cell, ','); ++i)
    if (cell == name) index = i;
  EXPECT_GE(index, 0) << "no column " << name << " in " << csv;
  std::vector<double> v;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    for (int i = 0; std::getline(ls, cell, ','); ++i)
      if (i == index) v.push_back(std::stod(cell));
  }
  return v;
}

/// The record holds every step with the command of that step, applied during it: u (the
/// plant's applied input, from state k+1) and u_unsaturated (from command k). 1e-12 V: the CSV
/// prints each number so that it reads back to within a few ulps of 0.5 V.
void expect_complete_record(const std::string& name) {
  const std::filesystem::path csv = out_dir(name) / "timeseries.csv";
  const std::vector<double> u = column(csv, "u"), uu = column(csv, "u_unsaturated");
  ASSERT_EQ(u.size(), static_cast<std::size_t>(kSteps));
  ASSERT_EQ(uu.size(), static_cast<std::size_t>(kSteps));
  for (std::int64_t k = 0; k < kSteps; ++k) {
    EXPECT_NEAR(u[static_cast<std::size_t>(k)], u_of(k), 1e-12) << "row " << k;
    EXPECT_NEAR(uu[static_cast<std::size_t>(k)], u_of(k), 1e-12) << "row " << k;
  }
}

/// Each test: one memq:// instance, the run's script, a listener for what the monitor
/// publishes, a peer to publish the run's messages on, and the monitor under test.
class MonitorProtocol : public ::testing::Test {
 protected:
  Memq memq;
  const Script script;
  Listener listener{memq};
  std::unique_ptr<service::Bus> run = peer(memq);
  std::unique_ptr<MonitorNode> node_;

  /// The monitor under test, recording to out_dir(name), with `opt`.
  MonitorNode& make_node(const std::string& name, const service::NodeOptions& opt = node_options()) {
    node_ = std::make_unique<MonitorNode>(script.s, opt, monitor_options(name), memq.lcm);
    return *node_;
  }
  /// Publishes the script (Script::publish, with `skip`), runs the monitor and waits for its
  /// closing messages; returns what run() returned (true: the run completed).
  bool run_script(const std::function<bool(const std::string&, std::int64_t)>& skip = {}) {
    script.publish(*run, skip);
    const bool completed = node_->run();
    listener.wait_for_the_end();
    return completed;
  }
};

// Lockstep: every step recorded, the run announced done with every step acknowledged, its
// self-description (run_info_t) and summary published.
TEST_F(MonitorProtocol, RecordsEveryStepAndAcknowledgesIt) {
  MonitorNode& node = make_node("lockstep");
  EXPECT_TRUE(run_script());
  const run_summary_t& sum = node.summary();
  EXPECT_TRUE(sum.completed) << sum.failure;
  EXPECT_EQ(sum.steps, kSteps);
  EXPECT_EQ(sum.stopped_at_seq, kSteps);
  EXPECT_EQ(sum.duplicates, 0);
  EXPECT_EQ(sum.lost, 0);
  EXPECT_EQ(sum.conflicts, 0);
  expect_complete_record("lockstep");
  ASSERT_FALSE(listener.summaries.empty());
  EXPECT_TRUE(listener.summaries.back().completed);
  EXPECT_EQ(listener.summaries.back().steps, kSteps);
  EXPECT_EQ(listener.statuses.back().state, "done");
  EXPECT_EQ(listener.statuses.back().acked_seq, kSteps) << "every step acknowledged (the plant's flow control)";
  EXPECT_TRUE(listener.requests.empty()) << "nothing was missing";
  ASSERT_FALSE(listener.infos.empty()) << "run_info_t at the start";
  EXPECT_EQ(listener.infos.front().scenario, "protocol");
  EXPECT_EQ(listener.infos.front().steps, kSteps);
  EXPECT_EQ(listener.infos.front().contract_version, service::kContractVersion);
}

// A participant of contract version 3: its heartbeat decodes (process_status_t did not change in
// version 4) and says contract_version 3; the monitor names it in one line with both versions
// and what to do, and the run fails at once instead of at a timeout.
TEST_F(MonitorProtocol, AVersion3ParticipantIsNamedAndTheRunFails) {
  MonitorNode& node = make_node("version3");
  process_status_t hb{};
  hb.role = "controller";
  hb.state = "running";
  hb.seq = -1;
  hb.acked_seq = -1;
  hb.contract_version = 3;
  run->publish(kCh.status, hb);
  EXPECT_FALSE(node.run());
  listener.wait_for_the_end();
  const std::string& why = node.summary().failure;
  EXPECT_NE(why.find("the controller speaks contract version 3; this run speaks 4: rebuild it with this feeddrive's "
                     "lcmtypes/ (docs/lcm-contract.md, Versions)"),
            std::string::npos)
      << why;
  EXPECT_EQ(why.find('\n'), std::string::npos) << "one line";
}

// A run_info_t of contract version 3 (a monitor of an older feeddrive on the group) does not decode
// as version 4's (its drive's parameters were fields); its fingerprint names it, with both versions.
TEST(Contract, AVersion3RunInfoIsRecognisedByItsFingerprint) {
  std::vector<std::uint8_t> v3(200, 0);
  const std::uint64_t fp = 0x2a2e53f13bd0f348ULL;  // lcm-gen's run_info_t of lcmtypes/ at fad0b3a (contract 3)
  for (int i = 0; i < 8; ++i) v3[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(fp >> (56 - 8 * i));
  const auto older = service::older_contract(kCh, kCh.info, v3.data(), v3.size());
  ASSERT_TRUE(older);
  EXPECT_EQ(older->version, 3);
  const std::string line = service::describe_older(*older, kCh.info);
  EXPECT_EQ(line.rfind("a participant speaks contract version 3 (a run_info_t of 26 November 2026", 0), 0u) << line;
  EXPECT_NE(line.find("this run speaks 4: rebuild it"), std::string::npos) << line;

  run_info_t now{};
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(now.getEncodedSize()));
  now.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_FALSE(service::older_contract(kCh, kCh.info, bytes.data(), bytes.size())) << "this contract's is not older";
}

// A lost command: the monitor asks for it on FD_RESEND (only for it: every other message of the
// run is there), the controller re-sends it, the record is complete. A state that arrives twice
// is a duplicate, recorded once.
TEST_F(MonitorProtocol, AsksForWhatIsMissingAndIgnoresDuplicates) {
  MonitorNode& node = make_node("resend");
  run->subscribe<resend_request_t>(kCh.resend, [&](const resend_request_t& r, std::int64_t) {
    if (r.channel == kCh.command && r.seq == 7) run->publish(kCh.command, script.commands[7]);
  });
  script.publish(*run, [](const std::string& what, std::int64_t k) { return what == "command" && k == 7; });
  run->publish(kCh.state, script.states[5]);  // again
  EXPECT_TRUE(node.run());
  listener.wait_for_the_end();
  EXPECT_TRUE(node.summary().completed) << node.summary().failure;
  expect_complete_record("resend");
  ASSERT_FALSE(listener.requests.empty());
  for (const resend_request_t& r : listener.requests) {
    EXPECT_EQ(r.requester, "monitor");
    EXPECT_EQ(r.channel, kCh.command);
    EXPECT_EQ(r.seq, 7);
  }
  EXPECT_GE(node.summary().lost, 1) << "the request is counted";
  EXPECT_GE(node.summary().duplicates, 1) << "state 5 twice";
}

// Real time, states 3..12 lost: while the plant runs the monitor asks for two of a kind a round
// (each message re-sent costs the chain's processes time on their core), so before the end it
// asks only for states 3 and 4, again and again; after the end-of-run state it asks for the rest
// at once, and the record is complete (docs/lcm-contract.md, "Real time against the machine").
TEST_F(MonitorProtocol, InRealTimeItAsksForTwoOfAKindARoundUntilTheEnd) {
  service::NodeOptions opt = node_options();
  opt.realtime = true;
  opt.realtime_scheduling = false;  // the protocol, without SCHED_FIFO for the test process
  MonitorNode& node = make_node("realtime_requests", opt);
  std::vector<drive_state_t> states = script.states;
  for (drive_state_t& m : states) m.realtime = true;
  const auto lost = [](std::int64_t k) { return k >= 3 && k <= 12; };
  std::set<std::int64_t> asked_before_the_end;
  int rounds = 0;
  bool ended = false;
  run->subscribe<resend_request_t>(kCh.resend, [&](const resend_request_t& r, std::int64_t) {
    if (r.channel != kCh.state) return;
    if (!ended) {
      asked_before_the_end.insert(r.seq);
      if (r.seq == 3 && ++rounds == 5) {  // five rounds of requests, then the plant ends
        ended = true;
        run->publish(kCh.state, states.back());
      }
      return;
    }
    run->publish(kCh.state, states.at(static_cast<std::size_t>(r.seq)));
  });
  for (const drive_state_t& m : states)
    if (!lost(m.seq) && !m.end_of_run) run->publish(kCh.state, m);
  for (const reference_t& r : script.refs) Script::send_reference(*run, r);
  for (const control_command_t& c : script.commands) run->publish(kCh.command, c);
  EXPECT_TRUE(node.run());
  listener.wait_for_the_end();
  EXPECT_EQ(rounds, 5);
  EXPECT_EQ(asked_before_the_end, (std::set<std::int64_t>{3, 4}));
  expect_complete_record("realtime_requests");
}

// Two different states for one step: the run fails naming it; what was recorded is kept.
TEST_F(MonitorProtocol, TwoDifferentStatesForOneStepFailTheRun) {
  MonitorNode& node = make_node("state_conflict");
  drive_state_t other = script.states[5];
  other.x_measured += 1e-6;
  EXPECT_FALSE(run_script([&](const std::string& what, std::int64_t k) {
    if (what == "state" && k == 6) run->publish(kCh.state, other);  // after state 5
    return false;
  }));
  expect_conflict(node.summary().failure, kCh.state, 5, "drive_state_t", "x_measured");
  EXPECT_FALSE(node.summary().completed);
  EXPECT_EQ(node.summary().conflicts, 1);
  EXPECT_EQ(listener.statuses.back().state, "failed");
  EXPECT_FALSE(listener.summaries.back().completed);
}

// Two different commands for one step (a forged one raced the controller's): the run fails and
// the failure says which one the plant applied (its state 6 says: the first, 0.55 V).
TEST_F(MonitorProtocol, ACommandConflictNamesTheCommandThePlantApplied) {
  MonitorNode& node = make_node("command_conflict");
  control_command_t forged = script.commands[5];
  forged.u = forged.u_unsaturated = -1.0;
  EXPECT_FALSE(run_script([&](const std::string& what, std::int64_t k) {
    if (what == "command" && k == 6) run->publish(kCh.command, forged);  // after command 5
    return false;
  }));
  const std::string failure = node.summary().failure;
  EXPECT_EQ(failure.rfind("conflict on FD_CMD step 5", 0), 0u) << failure;
  EXPECT_NE(failure.find("the plant applied u = 0.55 V from an unknown sender at step 5 (the other command, u = -1 V"),
            std::string::npos)
      << failure;
}

// Messages of another run (a second run on the group): counted as foreign, never recorded, the
// run completes.
TEST_F(MonitorProtocol, MessagesOfAnotherRunAreCountedAndIgnored) {
  MonitorNode& node = make_node("foreign");
  auto other = peer(memq, 99);
  drive_state_t foreign = script.states[3];
  foreign.x_measured = 1.0;
  other->publish(kCh.state, foreign);
  EXPECT_TRUE(run_script());
  EXPECT_TRUE(node.summary().completed) << node.summary().failure;
  EXPECT_EQ(node.summary().foreign, 1);
  EXPECT_EQ(node.summary().conflicts, 0);
  expect_complete_record("foreign");
}

// A command that never comes (and no controller heartbeat: nobody is waiting on someone else):
// after --step-timeout the run fails naming the message and its role, having asked for it
// meanwhile; the steps before it are recorded. Lower bound: the protocol; upper: a hang (10 s).
TEST_F(MonitorProtocol, AMissingCommandFailsAfterTheStepTimeout) {
  service::NodeOptions opt = node_options();
  opt.step_timeout_s = 0.3;
  MonitorNode& node = make_node("step_timeout", opt);
  script.publish(*run, [](const std::string& what, std::int64_t k) { return what == "command" && k == 7; });
  expect_failure_after(0.3, "step 7 incomplete for 0.3 s: no command 7 from the controller", [&] {
    EXPECT_FALSE(node.run());
    return node.summary().failure;
  });
  listener.wait_for_the_end();
  EXPECT_EQ(node.summary().stopped_at_seq, 7);
  EXPECT_EQ(node.summary().steps, 7) << "steps 0..6 recorded";
  EXPECT_FALSE(listener.requests.empty()) << "asked for command 7 meanwhile";
}

// Nothing at all: --start-timeout, naming what step 0 lacks, the plant's state first.
TEST_F(MonitorProtocol, NoRunFailsAfterTheStartTimeout) {
  service::NodeOptions opt = node_options();
  opt.start_timeout_s = 0.3;
  MonitorNode& node = make_node("start_timeout", opt);
  expect_failure_after(0.3, "step 0 incomplete for 0.3 s: no state 0 from the plant", [&] {
    EXPECT_FALSE(node.run());
    return node.summary().failure;
  });
  listener.wait_for_the_end();
}

}  // namespace
}  // namespace feeddrive::protocol_test
